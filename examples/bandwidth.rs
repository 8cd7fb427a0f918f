//! Measures this machine's memory bandwidth for the access pattern of the SOE history fold
//! (every stored number read and written back in place, arrays far larger than the caches), on
//! one thread and on two, and prints what that bandwidth alone costs a step of a cloth too large
//! for the caches: the floor under the time per particle-step of the scaling plot.
//! `cargo run --release --example bandwidth`.

use std::hint::black_box;
use std::time::Instant;

use fraccloth::history::{History, Scheme};

/// Best of five in-place sweeps over `a`, split into `threads` equal parts, in GB/s (read and
/// write both counted).
fn in_place(a: &mut [f64], threads: usize) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = Instant::now();
        std::thread::scope(|s| {
            for part in a.chunks_mut(a.len().div_ceil(threads)) {
                s.spawn(move || {
                    for x in part.iter_mut() {
                        *x = *x * 0.999 + 1e-3;
                    }
                    black_box(part);
                });
            }
        });
        best = best.min(start.elapsed().as_secs_f64());
    }
    2.0 * 8.0 * a.len() as f64 / best / 1e9
}

fn main() -> Result<(), fraccloth::Error> {
    // 48 M numbers (384 MB): far beyond any cache.
    let mut a = vec![1.0f64; 48 << 20];
    let one = in_place(&mut a, 1);
    let two = in_place(&mut a, 2);
    println!("in-place update (read + write counted): one thread {one:.1} GB/s, two threads {two:.1} GB/s ({:.2}x)", two / one);
    // The default kernel's modes x 3 components x 8 bytes, read and written once per step.
    let k = History::new(Scheme::DEFAULT, 1)?.mode_count();
    let modes = (k * 3 * 8) as f64;
    for (threads, gbs) in [(1, one), (2, two)] {
        println!(
            "SOE modes (default tolerance: {k} modes, f64): {modes:.0} B read + {modes:.0} B written per particle-step -> on {threads} thread(s) at least {:.1} ns per particle-step from them alone",
            2.0 * modes / gbs
        );
    }
    Ok(())
}
