//! Measures this machine's memory bandwidth for the access pattern of the SOE history fold
//! (every stored number read and written back in place, arrays far larger than the caches), on
//! one thread and on two, and prints what that bandwidth alone costs a step of a cloth too large
//! for the caches: the floor under the time per particle-step of the scaling plot. Then the
//! same total work spread over k arrays swept together (a tile of 512 numbers of each in turn),
//! as a step's passes sweep their 10 to 16 arrays: how the number of concurrent streams, not
//! only the bytes, bounds one thread.
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

/// Best of four in-place sweeps over `k` arrays of `total / k` numbers together, tile by tile,
/// on one thread, in GB/s.
fn streams(total: usize, k: usize) -> f64 {
    let n = total / k;
    let mut arrays: Vec<Vec<f64>> = (0..k).map(|_| vec![1.0f64; n]).collect();
    let mut best = f64::INFINITY;
    for _ in 0..4 {
        let start = Instant::now();
        for i in (0..n).step_by(512) {
            let e = (i + 512).min(n);
            for a in arrays.iter_mut() {
                for x in &mut a[i..e] {
                    *x = *x * 0.999 + 1e-3;
                }
            }
        }
        black_box(&mut arrays);
        best = best.min(start.elapsed().as_secs_f64());
    }
    2.0 * 8.0 * (n * k) as f64 / best / 1e9
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
    let rates: Vec<String> = [1, 2, 4, 8, 10, 12, 16, 32]
        .iter()
        .map(|&k| format!("{k}: {:.1}", streams(48 << 20, k)))
        .collect();
    println!(
        "one thread, k arrays swept together (k: GB/s): {}",
        rates.join(", ")
    );
    Ok(())
}
