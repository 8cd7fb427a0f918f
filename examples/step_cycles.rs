//! Steps the 61 x 41 throughput cloth in blocks of 1000 steps and prints the fastest block in
//! ns per particle-step: the least noisy figure on a shared machine, for comparing two builds
//! while optimising (the benchmark of record is `examples/throughput.rs`, which reports medians).
//! `cargo run --release --example step_cycles -- [fractional|regular] [blocks]`.

use fraccloth::history::Scheme;
use fraccloth::scenes::Variant;
use fraccloth::topology::grid_index;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, RegularDrag, Vec3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let regular = args.get(1).is_some_and(|a| a == "regular");
    let blocks: u64 = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let (w, h) = (61u32, 41u32);
    let topology = GridSpec {
        width: w,
        height: h,
        spacing: 0.01,
        total_mass: 0.24,
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
        scheme: if regular { Scheme::Off } else { Scheme::DEFAULT },
        integrator: Integrator::SymplecticEuler,
        ..ClothConfig::default()
    };
    let mut cloth = Cloth::new(topology, config)?;
    let top: Vec<u32> = (0..w).map(|i| grid_index(w, i, 0)).collect();
    cloth.set_pinned(&top)?;
    let mut best = f64::INFINITY;
    for _ in 0..blocks {
        let start = std::time::Instant::now();
        for _ in 0..1000 {
            cloth.step(5e-4)?;
        }
        best = best.min(start.elapsed().as_secs_f64() / (1000.0 * cloth.vertex_count() as f64));
    }
    println!(
        "fastest block: {:.2} ns per particle-step ({:.2} M/s)",
        best * 1e9,
        1e-6 / best
    );
    Ok(())
}
