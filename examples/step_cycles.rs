//! Steps the 61 x 41 throughput cloth in blocks of 1000 steps and prints the fastest block in
//! ns per particle-step: the least noisy figure on a shared machine, for comparing two builds
//! while optimising (the benchmark of record is `examples/throughput.rs`, which reports medians).
//! `cargo run --release --example step_cycles -- [fractional|regular|memoryless] [blocks] [WxH]`
//! (default 61x41; blocks of 1000 steps, fewer for big cloths). `memoryless` is the fractional
//! model with the history switched off (`Scheme::Off`): the same step without the fractional
//! memory's work and bytes, to tell what the history costs at a size from what the rest does.

use fraccloth::history::Scheme;
use fraccloth::scenes::Variant;
use fraccloth::topology::grid_index;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, RegularDrag, Vec3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let variant_arg = args.get(1).map_or("fractional", String::as_str);
    let regular = variant_arg == "regular";
    let memoryless = variant_arg == "memoryless";
    if !matches!(variant_arg, "fractional" | "regular" | "memoryless") {
        return Err(format!("unknown variant {variant_arg}: fractional, regular or memoryless").into());
    }
    let blocks: u64 = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let (w, h) = match args.get(3) {
        Some(size) => {
            let (w, h) = size.split_once('x').ok_or("size must be WxH")?;
            (w.parse::<u32>()?, h.parse::<u32>()?)
        }
        None => (61, 41),
    };
    let steps_per_block = (2_500_000 / (w as u64 * h as u64)).clamp(1, 1000);
    let topology = GridSpec {
        width: w,
        height: h,
        spacing: 0.01,
        // The same mass per particle at every size, so the same dt is stable.
        total_mass: 0.24 * (w * h) as f64 / (61.0 * 41.0),
    }
    .build()?;
    let variant = if regular {
        Variant::Regular(RegularDrag::Normal)
    } else {
        Variant::Fractional
    };
    let mut model = variant.model(0.01);
    model.current = Vec3::new(0.0, 0.0, 0.2);
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
    let mut cloth = Cloth::new(topology, config)?;
    let top: Vec<u32> = (0..w).map(|i| grid_index(w, i, 0)).collect();
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
