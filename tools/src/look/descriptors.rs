//! The look of a column driven at its top, from its motion: how many half-waves it carries,
//! how fast they travel down, how deep the motion reaches, how rough the column is.
//!
//! Everything is measured in absolute coordinates (never relative to the top edge, which
//! would make a still bottom read as a large displacement) from the complex amplitude
//! `Z_j` at the drive frequency of each row j, found by least squares over whole drive
//! periods ([`super::harmonic`]). For a travelling wave `A e^{-y/l} sin(w (t - y/c))`,
//! `Z_j = A e^{-y_j/l} e^{-i w y_j / c}`: the phase lag grows by `w/c` per metre whatever
//! the decay `l`, which is what makes the phase the robust measure of travel.

use nalgebra::Complex;

/// A row counts as visible while its amplitude is at least this fraction of the top's.
pub const VISIBLE_FRACTION: f64 = 0.1;
/// The half-wave count weighs each row-to-row phase step by how visible its two rows are:
/// fully at or above `VISIBLE_FRACTION * VISIBLE_RAMP` of the top's amplitude, not at all at or
/// below `VISIBLE_FRACTION / VISIBLE_RAMP`, linearly in the logarithm of the amplitude between.
/// A hard cut at 10 % made the count jump by one or two half-waves with a 1 % change of one
/// row's amplitude wherever the column hovers about 10 % (a 1.5 Hz swing: 3.82 or 4.81 for two
/// bakes whose rows agree within 0.035 of the top in amplitude and 0.15 pi in lag to 0.3 m).
pub const VISIBLE_RAMP: f64 = 1.5;
/// Side-view extrema are counted with this hysteresis, m.
pub const BULGE_HYSTERESIS: f64 = 0.005;
/// No wave is said to travel when the visible column lags the top by less than this (rad),
/// an eighth of a wavelength: a shorter stretch of wave cannot be told from a bend.
pub const MIN_TRAVEL_LAG: f64 = std::f64::consts::FRAC_PI_4;
/// No wave is said to travel when the column's complex amplitude is a straight line in
/// depth within this relative residual: the column then moves as a rigid (possibly lagging)
/// line, translating and tilting, which is not a wave.
pub const MAX_STRAIGHT_RESIDUAL: f64 = 0.03;

/// The motion of a column of particles over whole drive periods.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ColumnMotion {
    /// Rest (material) distance of each row below the top row, m; increasing, `depths[0] = 0`.
    pub depths: Vec<f64>,
    /// Frame times, s.
    pub times: Vec<f64>,
    /// `offsets[frame][row]`: out-of-plane coordinate, m, absolute.
    pub offsets: Vec<Vec<f64>>,
    /// `heights[frame][row]`: vertical coordinate (up), m, absolute.
    pub heights: Vec<Vec<f64>>,
}

impl ColumnMotion {
    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.times.len()
    }
}

/// One row's harmonic at the drive frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowHarmonic {
    /// Rest distance below the top row, m.
    pub depth: f64,
    /// Amplitude at the drive frequency, m.
    pub amplitude: f64,
    /// Phase lag behind the top row, rad, unwrapped down the column.
    pub lag: f64,
}

/// The look descriptors of one column (see `docs/look.md` for their definitions).
#[derive(Clone, Debug, PartialEq)]
pub struct Descriptors {
    /// Phase lag from the top down the visible column, over pi: the sum of the row-to-row lags,
    /// each weighed by its rows' visibility ([`visibility`]; 1 wherever the amplitude is at least
    /// 15 % of the top's, so down to there it is the lag of the lowest such row).
    pub half_waves: f64,
    /// Drive angular frequency over the amplitude-weighted phase slope along the visible
    /// rows, m/s; `None` when no wave travels.
    pub travel_speed: Option<f64>,
    /// Depth where the amplitude first falls under half the top's, m; `None` if never.
    pub half_amplitude_depth: Option<f64>,
    /// Amplitude at half the column's depth over the top's.
    pub mid_ratio: f64,
    /// Amplitude of the bottom row over the top's.
    pub bottom_ratio: f64,
    /// Curvature of the oscillating column against the curvature of a smooth wave of the
    /// wavelength its slope implies (1 for any smooth exponential or sinusoidal wave, far
    /// above 1 when grid-scale ripples ride on it, near 0 for a straight column); `None`
    /// with fewer than 5 visible rows or no motion.
    pub zigzag: Option<f64>,
    /// Side-view extrema along the column (5 mm hysteresis), averaged over the frames.
    pub bulges: f64,
    /// Mean vertical distance from the top row to the bottom row, m.
    pub hang_depth: f64,
    /// Depth down to which rows are visible (interpolated), m.
    pub visible_depth: f64,
    /// Amplitude of the top row at the drive frequency, m.
    pub top_amplitude: f64,
    /// Every row's harmonic.
    pub rows: Vec<RowHarmonic>,
}

/// Linear interpolation of `(x, y)` pairs at the crossing of `ys` through `level` between
/// indices `j - 1` and `j`.
fn crossing(x0: f64, x1: f64, y0: f64, y1: f64, level: f64) -> f64 {
    if y1 == y0 {
        x1
    } else {
        x0 + (x1 - x0) * ((level - y0) / (y1 - y0)).clamp(0.0, 1.0)
    }
}

/// How visible a stretch of column moving with `ratio` of the top's amplitude is, 0 to 1
/// (see [`VISIBLE_RAMP`]); 1/2 at `VISIBLE_FRACTION`. Symmetric in the logarithm, so on an
/// exponentially decaying column the weighted lag is the lag at the 10 % depth.
pub fn visibility(ratio: f64) -> f64 {
    if ratio.is_nan() || ratio <= 0.0 {
        return 0.0;
    }
    (0.5 + (ratio / VISIBLE_FRACTION).ln() / (2.0 * VISIBLE_RAMP.ln())).clamp(0.0, 1.0)
}

/// The half-wave count as the meter read it before 0.9.23: the lag at the first row whose
/// amplitude falls under `fraction` of the top's (interpolated to the crossing), or the bottom
/// row's, over pi. Kept to show where that cut jumps ([`VISIBLE_RAMP`]); 0 for no rows.
pub fn half_waves_cut_at(rows: &[RowHarmonic], fraction: f64) -> f64 {
    let Some(top) = rows.first() else { return 0.0 };
    let limit = fraction * top.amplitude;
    let lag = match rows.iter().position(|r| r.amplitude < limit) {
        None => rows[rows.len() - 1].lag,
        Some(0) => 0.0,
        Some(j) => {
            let (a, b) = (&rows[j - 1], &rows[j]);
            let f = crossing(0.0, 1.0, a.amplitude, b.amplitude, limit);
            a.lag + f * (b.lag - a.lag)
        }
    };
    lag / std::f64::consts::PI
}

/// Phase lags behind the first entry, unwrapped entry to entry.
pub fn unwrapped_lags(z: &[Complex<f64>]) -> Vec<f64> {
    let mut lags = Vec::with_capacity(z.len());
    let mut lag = 0.0;
    for (j, zj) in z.iter().enumerate() {
        if j > 0 {
            lag -= (z[j - 1].conj() * zj).arg();
        }
        lags.push(lag);
    }
    lags
}

/// Relative residual of the best straight line `a + b y` through the complex amplitudes.
pub fn straight_line_residual(depths: &[f64], z: &[Complex<f64>]) -> f64 {
    let n = z.len() as f64;
    if z.len() < 3 {
        return 0.0;
    }
    let ym = depths.iter().sum::<f64>() / n;
    let zm = z.iter().sum::<Complex<f64>>() / n;
    let syy: f64 = depths.iter().map(|y| (y - ym).powi(2)).sum();
    let szy: Complex<f64> = depths.iter().zip(z).map(|(y, zj)| (zj - zm) * (y - ym)).sum();
    let b = if syy > 0.0 {
        szy / syy
    } else {
        Complex::new(0.0, 0.0)
    };
    let spread: f64 = z.iter().map(|zj| (zj - zm).norm_sqr()).sum();
    let rss: f64 = depths
        .iter()
        .zip(z)
        .map(|(y, zj)| (zj - zm - b * (y - ym)).norm_sqr())
        .sum();
    if spread > 0.0 {
        (rss / spread).sqrt()
    } else {
        0.0
    }
}

/// Side-view extrema of a profile with hysteresis `h`: a maximum or minimum counts once the
/// profile has moved back from it by at least `h`.
pub fn extrema_with_hysteresis(profile: &[f64], h: f64) -> usize {
    #[derive(PartialEq)]
    enum Dir {
        Unknown,
        Up,
        Down,
    }
    let Some(&first) = profile.first() else { return 0 };
    let (mut dir, mut ext, mut count) = (Dir::Unknown, first, 0);
    let (mut lo, mut hi) = (first, first);
    for &v in &profile[1..] {
        match dir {
            Dir::Unknown => {
                lo = lo.min(v);
                hi = hi.max(v);
                if v - lo >= h {
                    dir = Dir::Up;
                    ext = v;
                } else if hi - v >= h {
                    dir = Dir::Down;
                    ext = v;
                }
            }
            Dir::Up => {
                if v > ext {
                    ext = v;
                } else if ext - v >= h {
                    count += 1;
                    dir = Dir::Down;
                    ext = v;
                }
            }
            Dir::Down => {
                if v < ext {
                    ext = v;
                } else if v - ext >= h {
                    count += 1;
                    dir = Dir::Up;
                    ext = v;
                }
            }
        }
    }
    count
}

/// Curvature against slope of the oscillating part of a column, over rows `0..rows`:
/// `sqrt(sum |D2|^2 * sum |d|^2) / sum |D1|^2`, with D1 and D2 the first and second
/// divided differences in depth of each frame's deviation `d` from the row's mean. For any
/// wave `e^{k y}` (k complex: travelling, decaying, both) it is 1 up to O((k dy)^2).
pub fn zigzag(motion: &ColumnMotion, rows: usize) -> Option<f64> {
    let y = &motion.depths;
    if rows < 5 || motion.offsets.is_empty() {
        return None;
    }
    let frames = motion.offsets.len() as f64;
    let mean: Vec<f64> = (0..rows)
        .map(|j| motion.offsets.iter().map(|f| f[j]).sum::<f64>() / frames)
        .collect();
    let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
    for f in &motion.offsets {
        let d = |j: usize| f[j] - mean[j];
        for j in 1..rows - 1 {
            let (ha, hb) = (y[j] - y[j - 1], y[j + 1] - y[j]);
            let d1 = (d(j + 1) - d(j - 1)) / (ha + hb);
            let d2 = 2.0 * ((d(j + 1) - d(j)) / hb - (d(j) - d(j - 1)) / ha) / (ha + hb);
            s0 += d(j) * d(j);
            s1 += d1 * d1;
            s2 += d2 * d2;
        }
    }
    (s1 > 0.0).then(|| (s2 * s0).sqrt() / s1)
}

/// The descriptors of a column given each row's complex amplitude at the drive angular
/// frequency `omega` (rad/s). `amplitudes` and `motion.depths` have one entry per row.
pub fn describe(motion: &ColumnMotion, amplitudes: &[Complex<f64>], omega: f64) -> Descriptors {
    let y = &motion.depths;
    let n = amplitudes.len().min(y.len());
    let amp: Vec<f64> = amplitudes[..n].iter().map(|z| z.norm()).collect();
    let lags = unwrapped_lags(&amplitudes[..n]);
    let top = amp.first().copied().unwrap_or(0.0);
    let rows: Vec<RowHarmonic> = (0..n)
        .map(|j| RowHarmonic {
            depth: y[j],
            amplitude: amp[j],
            lag: lags[j],
        })
        .collect();

    // Visible: rows from the top while the amplitude is at least 10 % of the top's; the
    // depth at the limit is interpolated between the last visible row and the next.
    let limit = VISIBLE_FRACTION * top;
    let last = amp.iter().position(|&a| a < limit).map_or(n, |j| j).max(1) - 1;
    let visible_depth = if last + 1 < n {
        crossing(y[last], y[last + 1], amp[last], amp[last + 1], limit)
    } else {
        y[last]
    };

    // The lag the eye follows down the column: each row-to-row step weighed by the visibility
    // of the two rows' geometric mean amplitude (a node, where the phase turns by pi between
    // two nearly still rows, weighs nothing).
    let lag_weighted: f64 = (1..n)
        .map(|j| {
            let ratio = if top > 0.0 {
                (amp[j - 1] * amp[j]).sqrt() / top
            } else {
                0.0
            };
            visibility(ratio) * (lags[j] - lags[j - 1])
        })
        .sum();

    // Travel: the amplitude-weighted phase slope along the visible rows.
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..last {
        let w = amp[j] * amp[j + 1];
        num += w * (lags[j + 1] - lags[j]);
        den += w * (y[j + 1] - y[j]);
    }
    let travels = lag_weighted.abs() >= MIN_TRAVEL_LAG
        && straight_line_residual(&y[..=last], &amplitudes[..=last]) > MAX_STRAIGHT_RESIDUAL
        && num != 0.0
        && den > 0.0;
    let travel_speed = travels.then(|| omega * den / num);

    let half_amplitude_depth = amp
        .iter()
        .position(|&a| a < 0.5 * top)
        .filter(|&j| j > 0)
        .map(|j| crossing(y[j - 1], y[j], amp[j - 1], amp[j], 0.5 * top));

    let ratio_at = |depth: f64| -> f64 {
        if top.is_nan() || top <= 0.0 {
            return 0.0;
        }
        let j = y[..n].iter().position(|&d| d >= depth).unwrap_or(n - 1).max(1);
        let f = if y[j] > y[j - 1] {
            ((depth - y[j - 1]) / (y[j] - y[j - 1])).clamp(0.0, 1.0)
        } else {
            1.0
        };
        (amp[j - 1] + f * (amp[j] - amp[j - 1])) / top
    };
    let (mid_ratio, bottom_ratio) = if n >= 2 {
        (ratio_at(0.5 * y[n - 1]), amp[n - 1] / top.max(f64::MIN_POSITIVE))
    } else {
        (1.0, 1.0)
    };

    let frames = motion.offsets.len().max(1) as f64;
    let bulges = motion
        .offsets
        .iter()
        .map(|p| extrema_with_hysteresis(&p[..n], BULGE_HYSTERESIS) as f64)
        .sum::<f64>()
        / frames;
    let hang_depth =
        motion.heights.iter().map(|h| h[0] - h[n - 1]).sum::<f64>() / motion.heights.len().max(1) as f64;

    Descriptors {
        half_waves: lag_weighted / std::f64::consts::PI,
        travel_speed,
        half_amplitude_depth,
        mid_ratio,
        bottom_ratio,
        zigzag: zigzag(motion, last + 1),
        bulges,
        hang_depth,
        visible_depth,
        top_amplitude: top,
        rows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extrema_count_turns_beyond_the_hysteresis_only() {
        assert_eq!(extrema_with_hysteresis(&[0.0, 0.01, 0.02, 0.03], 0.005), 0);
        assert_eq!(extrema_with_hysteresis(&[0.0, 0.02, 0.0], 0.005), 1);
        assert_eq!(extrema_with_hysteresis(&[0.0, 0.02, 0.0, 0.02, 0.0], 0.005), 3);
        // Wiggles of 2 mm on a straight line are not bulges.
        let wiggly: Vec<f64> = (0..40)
            .map(|j| 0.001 * j as f64 + if j % 2 == 0 { 0.001 } else { -0.001 })
            .collect();
        assert_eq!(extrema_with_hysteresis(&wiggly, 0.005), 0);
    }

    #[test]
    fn visibility_ramps_in_the_logarithm_from_a_fifteenth_to_fifteen_hundredths() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(visibility(VISIBLE_FRACTION), 0.5));
        assert!(close(visibility(VISIBLE_FRACTION * VISIBLE_RAMP), 1.0));
        assert!(close(visibility(VISIBLE_FRACTION / VISIBLE_RAMP), 0.0));
        assert_eq!(visibility(1.0), 1.0);
        assert_eq!(visibility(0.01), 0.0);
        for bad in [0.0, -0.2, f64::NAN] {
            assert_eq!(visibility(bad), 0.0);
        }
        // Symmetric in the logarithm about 10 %: r and 0.01 / r weigh 1 together.
        for r in [0.07, 0.08, 0.09, 0.1, 0.12, 0.14] {
            assert!(close(visibility(r) + visibility(0.01 / r), 1.0), "{r}");
        }
    }

    #[test]
    fn the_old_cut_reads_the_lag_at_the_first_crossing() {
        let row = |depth, amplitude, lag| RowHarmonic {
            depth,
            amplitude,
            lag,
        };
        let pi = std::f64::consts::PI;
        let rows = [
            row(0.0, 1.0, 0.0),
            row(0.01, 0.5, 1.0),
            row(0.02, 0.05, 2.0),
            row(0.03, 0.5, 3.0),
        ];
        // Under 10 % between the second and third rows, 8/9 of the way.
        assert!((half_waves_cut_at(&rows, 0.1) - (1.0 + 8.0 / 9.0) / pi).abs() < 1e-12);
        // Never under 1 %: the bottom row's lag.
        assert!((half_waves_cut_at(&rows, 0.01) - 3.0 / pi).abs() < 1e-12);
        assert_eq!(half_waves_cut_at(&[], 0.1), 0.0);
    }

    #[test]
    fn a_rigid_line_is_straight_and_an_arc_is_not() {
        let y: Vec<f64> = (0..20).map(|j| 0.01 * j as f64).collect();
        let line: Vec<Complex<f64>> = y.iter().map(|&y| Complex::new(0.05, -0.3 * y)).collect();
        assert!(straight_line_residual(&y, &line) < 1e-12);
        let arc: Vec<Complex<f64>> = y
            .iter()
            .map(|&y| Complex::from_polar(0.05, -std::f64::consts::FRAC_PI_4 * y / 0.19))
            .collect();
        let r = straight_line_residual(&y, &arc);
        assert!(r > MAX_STRAIGHT_RESIDUAL, "{r}");
    }
}
