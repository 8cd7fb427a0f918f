//! Quantitative descriptors of the look of a swinging cloth (the paper's Figs. 5 and 7).
//!
//! Input: a field `d[t][j]`, the out-of-plane displacement of row j of the centre column at
//! frame t, measured from the top edge (so the swing of the whole cloth is removed).
//! - **bumps**: the number of runs of one sign along the column, ignoring rows whose |d| is
//!   below a threshold, averaged over the frames (one smooth bend = 1; an S = 2; ...);
//! - **half-amplitude distance**: from the row where the envelope `max_t |d|` peaks, how far
//!   down the cloth (m) until the envelope falls below half that peak (None: never, the
//!   motion covers the whole cloth);
//! - **travel speed**: the speed (m/s) at which the pattern moves down the cloth, from the
//!   time lag that best correlates the displacement of a row a quarter of the way down with
//!   one three quarters of the way down.

/// Runs of one sign among the entries with |d| >= threshold.
pub fn bump_count(profile: &[f64], threshold: f64) -> usize {
    let mut runs = 0;
    let mut last = 0.0f64;
    for &d in profile {
        if d.abs() < threshold {
            continue;
        }
        if last == 0.0 || d.signum() != last.signum() {
            runs += 1;
        }
        last = d;
    }
    runs
}

/// Distance (m) below the envelope's peak at which it first drops under half the peak.
pub fn half_amplitude_distance(envelope: &[f64], spacing: f64) -> Option<f64> {
    let (peak_row, peak) = envelope
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    envelope[peak_row..]
        .iter()
        .position(|&a| a < 0.5 * peak)
        .map(|k| k as f64 * spacing)
}

/// Speed (m/s) of the pattern between rows `j1 < j2`: the lag (1 ..= max_lag frames) that
/// maximises the correlation of d[t][j1] with d[t + lag][j2]. None if nothing correlates.
pub fn travel_speed(
    field: &[Vec<f64>],
    j1: usize,
    j2: usize,
    frame_dt: f64,
    spacing: f64,
    max_lag: usize,
) -> Option<f64> {
    let n = field.len();
    let mut best: Option<(usize, f64)> = None;
    for lag in 1..=max_lag.min(n.saturating_sub(2)) {
        let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
        for t in 0..n - lag {
            let a = field[t][j1];
            let b = field[t + lag][j2];
            ab += a * b;
            aa += a * a;
            bb += b * b;
        }
        if aa == 0.0 || bb == 0.0 {
            continue;
        }
        let r = ab / (aa * bb).sqrt();
        if r > best.map_or(0.2, |b| b.1) {
            best = Some((lag, r));
        }
    }
    best.map(|(lag, _)| (j2 - j1) as f64 * spacing / (lag as f64 * frame_dt))
}

/// All three descriptors of one bake.
#[derive(Clone, Debug, PartialEq)]
pub struct Look {
    pub mean_bumps: f64,
    pub half_amplitude_distance: Option<f64>,
    pub travel_speed: Option<f64>,
    /// Largest |d| anywhere, m.
    pub max_displacement: f64,
}

/// Describes a field `d[t][j]` (rows `spacing` apart, frames `frame_dt` apart); rows with
/// |d| below `threshold` (m) do not count as bumps.
pub fn describe(field: &[Vec<f64>], spacing: f64, frame_dt: f64, threshold: f64) -> Look {
    let rows = field.first().map_or(0, Vec::len);
    let mean_bumps = if field.is_empty() {
        0.0
    } else {
        field.iter().map(|p| bump_count(p, threshold) as f64).sum::<f64>() / field.len() as f64
    };
    let envelope: Vec<f64> = (0..rows)
        .map(|j| field.iter().map(|p| p[j].abs()).fold(0.0, f64::max))
        .collect();
    let max_displacement = envelope.iter().copied().fold(0.0, f64::max);
    let max_lag = ((2.0 / frame_dt) as usize).max(1); // up to 2 s
    Look {
        mean_bumps,
        half_amplitude_distance: half_amplitude_distance(&envelope, spacing),
        travel_speed: if rows >= 4 {
            travel_speed(field, rows / 4, 3 * rows / 4, frame_dt, spacing, max_lag)
        } else {
            None
        },
        max_displacement,
    }
}
