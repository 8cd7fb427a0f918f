//! Harmonic analysis at one frequency: the complex amplitude of a sampled signal, and the
//! dominant frequency of a signal.
//!
//! Both are least-squares fits of `a + b cos(w t) + c sin(w t)` to the samples, so they are
//! exact for a pure harmonic whatever the sampling (a window that is not a whole number of
//! frames, few periods), where a discrete Fourier sum is exact only over whole periods of
//! equally spaced samples.

use nalgebra::{Complex, DMatrix, DVector};

/// Overtones fitted beside the fundamental, so that a periodic but not sinusoidal motion
/// (a whip at the edge, a jerk at each turn) does not leak into the fundamental's estimate.
pub const OVERTONES: usize = 2;

/// The complex amplitude `Z` of the fundamental in the best fit
/// `z(t) ~ mean + Re(Z e^{i w t}) + overtones` to the samples `(t_k, z_k)`; `None` when the
/// fit is degenerate (too few distinct samples for the basis).
pub fn complex_amplitude(times: &[f64], values: &[f64], omega: f64) -> Option<Complex<f64>> {
    let (coef, _) = fit(times, values, omega, 1 + OVERTONES)?;
    // b cos + c sin = Re((b - i c) e^{i w t}).
    Some(Complex::new(coef[1], -coef[2]))
}

/// Least-squares fit of `[1, cos w t, sin w t, ..., cos h w t, sin h w t]`; returns the
/// coefficients and the residual sum of squares.
fn fit(times: &[f64], values: &[f64], omega: f64, harmonics: usize) -> Option<(DVector<f64>, f64)> {
    let m = 1 + 2 * harmonics;
    if times.len() != values.len() || times.len() < m {
        return None;
    }
    let basis = |t: f64, row: &mut DVector<f64>| {
        row[0] = 1.0;
        for h in 1..=harmonics {
            let a = h as f64 * omega * t;
            row[2 * h - 1] = a.cos();
            row[2 * h] = a.sin();
        }
    };
    let mut ata = DMatrix::zeros(m, m);
    let mut atb = DVector::zeros(m);
    let mut row = DVector::zeros(m);
    for (&t, &z) in times.iter().zip(values) {
        basis(t, &mut row);
        ata += &row * row.transpose();
        atb += &row * z;
    }
    // A badly conditioned system means the basis is degenerate on these samples.
    let scale = ata.diagonal().max();
    let chol = ata.cholesky()?;
    if chol
        .l()
        .diagonal()
        .iter()
        .any(|d| d.is_nan() || d * d <= 1e-9 * scale)
    {
        return None;
    }
    let coef = chol.solve(&atb);
    let rss = times
        .iter()
        .zip(values)
        .map(|(&t, &z)| {
            basis(t, &mut row);
            (z - row.dot(&coef)).powi(2)
        })
        .sum();
    Some((coef, rss))
}

/// The angular frequency (rad/s) of the strongest harmonic of `values` sampled at the
/// equally spaced `times`: the `w` whose fit leaves the least residual, searched from about
/// one period over the record up to the Nyquist frequency, then refined. `None` when the
/// signal does not vary.
pub fn dominant_frequency(times: &[f64], values: &[f64]) -> Option<f64> {
    let n = times.len();
    if n < 4 || values.len() != n {
        return None;
    }
    let span = times[n - 1] - times[0];
    let dt = span / (n - 1) as f64;
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let total: f64 = values.iter().map(|z| (z - mean).powi(2)).sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    // The grid fits the fundamental alone (with overtones, half the frequency would fit as
    // well); the refinement fits the overtones too, so they do not bias it.
    let rss1 = |w: f64| fit(times, values, w, 1).map_or(f64::INFINITY, |(_, r)| r);
    let rss = |w: f64| fit(times, values, w, 1 + OVERTONES).map_or(f64::INFINITY, |(_, r)| r);
    // Grid in steps of a tenth of the Fourier resolution 2 pi / span, from 0.8 periods over
    // the record up to just under Nyquist.
    let step = 0.1 * std::f64::consts::TAU / span;
    let (lo, hi) = (
        0.8 * std::f64::consts::TAU / span,
        0.98 * std::f64::consts::PI / dt,
    );
    let mut best = (f64::INFINITY, lo);
    let mut w = lo;
    while w <= hi {
        let r = rss1(w);
        if r < best.0 {
            best = (r, w);
        }
        w += step;
    }
    // Golden-section refinement within one grid step either side.
    let (mut a, mut b) = (best.1 - step, best.1 + step);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (rss(c), rss(d));
    for _ in 0..60 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = rss(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = rss(d);
        }
    }
    let w = 0.5 * (a + b);
    (w.is_finite() && w > 0.0).then_some(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize, dt: f64, f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| 1.3 + k as f64 * dt).collect();
        let z = t.iter().map(|&t| f(t)).collect();
        (t, z)
    }

    #[test]
    fn amplitude_and_phase_of_a_pure_harmonic_over_a_window_of_odd_length() {
        // 2.37 periods: not whole, so a plain Fourier sum would leak.
        let w = 3.0;
        let (t, z) = sample(71, 0.07, |t| 0.4 + 0.02 * (w * t - 0.7).cos());
        let zc = complex_amplitude(&t, &z, w).unwrap();
        assert!((zc.norm() - 0.02).abs() < 1e-12, "{zc}");
        assert!((zc.arg() + 0.7).abs() < 1e-10, "{zc}");
    }

    #[test]
    fn dominant_frequency_of_a_noisy_harmonic_with_a_weaker_overtone() {
        let w = std::f64::consts::PI; // 0.5 Hz
        let (t, z) = sample(121, 1.0 / 30.0, |t| {
            0.08 * (w * t).sin() + 0.01 * (3.0 * w * t + 1.0).sin() + 0.001 * (37.0 * t).sin()
        });
        let found = dominant_frequency(&t, &z).unwrap();
        assert!((found - w).abs() < 2e-3 * w, "{found}");
        // A constant has none.
        assert_eq!(dominant_frequency(&t, &vec![1.0; t.len()]), None);
    }
}
