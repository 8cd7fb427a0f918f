//! Prints how many exponential modes the SOE kernel needs for several tolerances and windows.
//! `cargo run --release --example soe_modes`

use fraccloth::history::SoeKernel;

fn main() {
    println!("| tolerance | min_dt (s) | horizon (s) | raw modes | used | measured error | build time |");
    println!("|---|---|---|---|---|---|---|");
    for &(tol, d, t) in &[
        (1e-2, 1e-4, 3600.0),
        (1e-3, 1e-3, 10.0),
        (1e-3, 1e-4, 600.0),
        (1e-3, 1e-4, 3600.0),
        (1e-4, 1e-4, 3600.0),
        (1e-6, 1e-6, 1.0),
        (1e-6, 1e-4, 3600.0),
        (1e-8, 1e-5, 3600.0),
    ] {
        let t0 = std::time::Instant::now();
        match SoeKernel::build(tol, d, t) {
            Ok(k) => println!(
                "| {tol:e} | {d:e} | {t} | {} | {} | {:.2e} | {:.1} ms |",
                k.raw_count,
                k.len(),
                k.max_relative_error,
                t0.elapsed().as_secs_f64() * 1e3
            ),
            Err(e) => println!("| {tol:e} | {d:e} | {t} | error: {e} |"),
        }
    }
}
