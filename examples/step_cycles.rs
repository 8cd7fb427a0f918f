//! Steps the 61 x 41 throughput cloth in blocks of 1000 steps and prints the fastest block in
//! ns per particle-step: the least noisy figure on a shared machine, for comparing two builds
//! while optimising (the benchmark of record is `examples/throughput.rs`, which reports medians).
//! `cargo run --release --example step_cycles -- [fractional|regular|memoryless|underwater|underwater-self|strain] [blocks] [WxH] [shuffled|jittered]`
//! (default 61x41; blocks of 1000 steps, fewer for big cloths; `jittered` builds it as the
//! scenes' irregular triangle mesh, the grid's vertices in its order with random diagonals; `shuffled` builds the grid as a
//! quad mesh with its vertices in a scrambled order, so the force pass cannot walk it in tiles). `memoryless` is the fractional
//! model with the history switched off (`Scheme::Off`): the same step without the fractional
//! memory's work and bytes, to tell what the history costs at a size from what the rest does.
//! `underwater` is the underwater preset (normal added mass, form and skin drag, no history);
//! `underwater-self` the same with self-collision at 0.4 spacings (what it costs a cloth that
//! does not fold: its checks each step; the first block also holds its first look).
//! Prints the seconds `Cloth::new` took (self-collision's rest lists are made there) to stderr.
//! `strain` is the fractional model with rotation-invariant fractional springs (a history per
//! spring beside the particles').

use fraccloth::history::Scheme;
use fraccloth::topology::{grid_index, MeshMass, MeshSpec};
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, RegularDrag, Vec3};
use fraccloth_tools::scenes::Variant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let variant_arg = args.get(1).map_or("fractional", String::as_str);
    let regular = variant_arg == "regular";
    let memoryless = variant_arg == "memoryless";
    let self_collision = variant_arg == "underwater-self";
    let underwater = variant_arg == "underwater" || self_collision;
    let strain = variant_arg == "strain";
    if !matches!(
        variant_arg,
        "fractional" | "regular" | "memoryless" | "underwater" | "underwater-self" | "strain"
    ) {
        return Err(format!(
            "unknown variant {variant_arg}: fractional, regular, memoryless, underwater, underwater-self or strain"
        )
        .into());
    }
    let blocks: u64 = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let (w, h) = match args.get(3) {
        Some(size) => {
            let (w, h) = size.split_once('x').ok_or("size must be WxH")?;
            (w.parse::<u32>()?, h.parse::<u32>()?)
        }
        None => (61, 41),
    };
    let shuffled = args.get(4).is_some_and(|a| a == "shuffled");
    let jittered = args.get(4).is_some_and(|a| a == "jittered");
    let steps_per_block = (2_500_000 / (w as u64 * h as u64)).clamp(1, 1000);
    // The same mass per particle at every size, so the same dt is stable.
    let total_mass = 0.24 * (w * h) as f64 / (61.0 * 41.0);
    let grid = GridSpec {
        width: w,
        height: h,
        spacing: 0.01,
        total_mass,
    }
    .build()?;
    // Vertex k of the mesh is grid vertex perm[k] (a stride coprime with n scrambles them).
    let n = (w * h) as usize;
    let stride = (1..).map(|s| 7919 + 2 * s).find(|s| gcd(*s, n) == 1).unwrap_or(1);
    let perm: Vec<usize> = (0..n)
        .map(|k| if shuffled { (k * stride) % n } else { k })
        .collect();
    let mut inv = vec![0u32; n];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new as u32;
    }
    let topology = if shuffled {
        let positions: Vec<Vec3> = perm.iter().map(|&o| grid.rest_positions[o]).collect();
        let mut indices = vec![];
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let quad = [j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i];
                indices.extend(quad.iter().map(|&v| inv[v as usize]));
            }
        }
        MeshSpec {
            positions: &positions,
            indices: &indices,
            face_size: 4,
            mass: MeshMass::Total(total_mass),
        }
        .build()?
    } else if jittered {
        // The grid's vertices, in its order, moved and triangulated with random diagonals.
        fraccloth_tools::scenes::jittered_mesh(
            &grid,
            w,
            total_mass / (0.01 * 0.01 * ((w - 1) * (h - 1)) as f64),
            7,
        )?
    } else {
        grid
    };
    let variant = if regular {
        Variant::Regular(RegularDrag::Normal)
    } else if underwater {
        Variant::Underwater
    } else {
        Variant::Fractional
    };
    let mut model = variant.model(0.01);
    model.current = Vec3::new(0.0, 0.0, 0.2);
    if self_collision {
        model.self_collision_relative = 0.4;
    }
    if strain {
        model.spring_damping_mode = fraccloth::SpringDamping::FractionalStrain;
    }
    let config = ClothConfig {
        model,
        scheme: if regular || memoryless {
            Scheme::Off
        } else {
            Scheme::DEFAULT
        },
        integrator: Integrator::SymplecticEuler,
        ..ClothConfig::default()
    };
    let made = std::time::Instant::now();
    let mut cloth = Cloth::new(topology, config)?;
    eprintln!("Cloth::new: {:.3} s", made.elapsed().as_secs_f64());
    let top: Vec<u32> = (0..w).map(|i| inv[grid_index(w, i, 0) as usize]).collect();
    cloth.set_pinned(&top)?;
    let mut best = f64::INFINITY;
    for _ in 0..blocks {
        let start = std::time::Instant::now();
        for _ in 0..steps_per_block {
            cloth.step(5e-4)?;
        }
        let per = steps_per_block as f64 * cloth.vertex_count() as f64;
        best = best.min(start.elapsed().as_secs_f64() / per);
    }
    println!(
        "fastest block: {:.2} ns per particle-step ({:.2} M/s)",
        best * 1e9,
        1e-6 / best
    );
    Ok(())
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}
