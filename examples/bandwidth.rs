//! Measures this machine's single-thread memory bandwidth for the access pattern of the SOE
//! history fold (every stored number read and written back in place, arrays far larger than
//! the caches), and prints what that bandwidth alone costs a step of a cloth too large for the
//! caches: the floor under the time per particle-step of the scaling plot.
//! `cargo run --release --example bandwidth`.

use std::hint::black_box;
use std::time::Instant;

fn main() {
    // 48 M numbers (384 MB): far beyond any cache.
    let n = 48 << 20;
    let mut a = vec![1.0f64; n];
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = Instant::now();
        for x in a.iter_mut() {
            *x = *x * 0.999 + 1e-3;
        }
        black_box(&mut a);
        best = best.min(start.elapsed().as_secs_f64());
    }
    let gbs = 2.0 * 8.0 * n as f64 / best / 1e9;
    println!("in-place update, one thread: {gbs:.1} GB/s (read + write counted)");
    // 16 modes x 3 components x 8 bytes, read and written once per step by the fold.
    let modes = 16.0 * 3.0 * 8.0;
    println!(
        "SOE modes (default tolerance, f64): {:.0} B read + {modes:.0} B written per particle-step -> at least {:.1} ns per particle-step from them alone",
        modes,
        2.0 * modes / gbs
    );
}
