//! Cost per frame of the implicit integrator stepping once per frame (dt = 1/24 s) on the
//! fractional swing, at 61 x 41 and 201 x 201, on 1 and 2 threads, with the CG iterations
//! it needed. `cargo run --release --example implicit_cost`

use fraccloth::history::Scheme;
use fraccloth::Integrator;
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};

fn main() {
    for ((w, h), threads) in [((61u32, 41u32), 1), ((201, 201), 1), ((201, 201), 2)] {
        let spec = SceneSpec {
            width: w,
            height: h,
            scheme: Scheme::DEFAULT,
            integrator: Integrator::ImplicitEuler,
            dt: 1.0 / 24.0,
            ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
        };
        let mut scene = spec.build().expect("scene");
        let frames = 48;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let mut iterations = vec![];
        let per_frame = pool.install(|| {
            let start = std::time::Instant::now();
            for _ in 0..frames {
                scene.step().expect("implicit step");
                iterations.push(scene.cloth.solver_stats().iterations);
            }
            start.elapsed().as_secs_f64() / f64::from(frames)
        });
        let max = iterations.iter().max().copied().unwrap_or(0);
        let mean = f64::from(iterations.iter().sum::<u32>()) / f64::from(frames);
        println!(
            "{w} x {h}, {threads} thread(s): {:.1} ms per frame, CG iterations per frame: mean {mean:.1}, max {max} (cap {})",
            per_frame * 1e3,
            spec.build().expect("scene").cloth.config().solver.max_iterations
        );
    }
}
