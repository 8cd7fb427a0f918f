//! Where the swing's hang goes: the towel's centre column, row by row, time-averaged over the
//! second half of a 12 s bake of the underwater preset (61 x 41, swung 4 cm, symplectic Euler
//! at 0.5 ms, as `tests/water_scenes.rs`). For each band of rows it prints the vertical drop,
//! the column's length (the sum of its segments) and the mean out-of-plane and sideways
//! extents of its segments: a hang short of the rest length by more than the column's own
//! stretch is the column tilted out of the vertical (docs/underwater.md).
//!
//! `cargo run --release --example hang_budget -- [FREQUENCY_HZ ...]` (default 0.5 and 2)

use fraccloth::{Integrator, Vec3};
use fraccloth_tools::scenes::{Drive, SceneKind, SceneSpec, Variant};

const FPS: f64 = 30.0;
const SECONDS: f64 = 12.0;

/// Sums of the column's segments over the sampled frames: drop, length, |dz|, |dx|.
struct Bands {
    sums: Vec<[f64; 4]>,
    frames: f64,
}

impl Bands {
    fn mean(&self, rows: std::ops::Range<usize>, k: usize) -> f64 {
        self.sums[rows].iter().map(|s| s[k]).sum::<f64>() / self.frames
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let freqs: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let freqs = if freqs.is_empty() { vec![0.5, 2.0] } else { freqs };
    for f in freqs {
        let drive = Drive {
            amplitude: 0.04,
            frequency: f,
            ..Drive::of(SceneKind::Swing, Variant::Underwater)
        };
        let spec = SceneSpec {
            integrator: Integrator::SymplecticEuler,
            dt: 5e-4,
            drive,
            ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
        };
        let mut scene = spec.build()?;
        let rest = scene.cloth.topology().rest_positions.clone();
        let (lo, hi) = rest
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
        let cx = 0.5 * (lo + hi);
        // The centre column, top row first.
        let mut column: Vec<usize> = (0..rest.len())
            .filter(|&i| (rest[i].x - cx).abs() < 1e-9)
            .collect();
        column.sort_by(|&a, &b| rest[b].y.total_cmp(&rest[a].y));
        let n = column.len();
        if n < 2 {
            return Err("no vertex column at the towel's centre".into());
        }
        let mut bands = Bands {
            sums: vec![[0.0; 4]; n - 1],
            frames: 0.0,
        };
        for frame in 1..=(SECONDS * FPS) as usize {
            let t = frame as f64 / FPS;
            scene.run_until(t)?;
            if t < 0.5 * SECONDS {
                continue;
            }
            let x = scene.cloth.positions();
            for (k, s) in bands.sums.iter_mut().enumerate() {
                let d: Vec3 = x[column[k]] - x[column[k + 1]];
                for (acc, value) in s.iter_mut().zip([d.y, d.norm(), d.z.abs(), d.x.abs()]) {
                    *acc += value;
                }
            }
            bands.frames += 1.0;
        }
        let rest_length = rest[column[0]].y - rest[column[n - 1]].y;
        println!(
            "{f} Hz: hang {:.4} m, column length {:.4} m, rest length {rest_length:.4} m",
            bands.mean(0..n - 1, 0),
            bands.mean(0..n - 1, 1)
        );
        println!("  rows     drop (m)  length (m)  lost to tilt (m)  mean |dz| (m)  mean |dx| (m)");
        let cuts = [0, 5, 10, 20, 30, n - 1];
        for w in cuts.windows(2) {
            let r = w[0]..w[1];
            let (drop, length) = (bands.mean(r.clone(), 0), bands.mean(r.clone(), 1));
            println!(
                "  {:>2}-{:<2}   {drop:.4}    {length:.4}      {:.4}            {:.4}         {:.4}",
                w[0],
                w[1],
                length - drop,
                bands.mean(r.clone(), 2),
                bands.mean(r, 3)
            );
        }
    }
    Ok(())
}
