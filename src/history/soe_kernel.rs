//! Sum-of-exponentials approximation of the kernel `t^{-1/2} / sqrt(pi)` on `[delta, horizon]`.
//!
//! Construction, computed when a cloth is created (no tables):
//! 1. **Trapezoid rule in log-rate.** `t^{-1/2}/sqrt(pi) = (1/pi) integral_R exp(x/2 - t e^x) dx`;
//!    the trapezoid rule with step `hx` converges geometrically. With `eps1 = tolerance / 3`:
//!    `hx = pi^2 / ln(2 sqrt(2) / eps1)`, lower limit `a = 2 ln(eps1 sqrt(pi) / (2 sqrt(T)))` (the left
//!    tail bounded at t = T), upper limit `b = ln(erfcinv(eps1)^2 / delta)` (the right tail is
//!    exactly `erfc(sqrt(delta e^b))` relative). Rates `s_j = e^{x_j}`, weights `w_j = hx e^{x_j/2} / pi`.
//!    (Jiang, Zhang, Zhang & Zhang, Commun. Comput. Phys. 21, 2017.)
//! 2. **Compression of the slow modes.** Modes with `s_j T` small are nearly polynomial in s
//!    over the whole window, so the discrete measure `sum_j w_j delta(s - s_j)` over the slowest
//!    `c` modes is replaced by its L-point Gauss rule (Golub-Welsch on the Lanczos matrix of the
//!    measure). Gauss rules of a positive measure have positive weights and nodes inside the
//!    measure's range, so rates and weights stay positive. Every cut-off c and every L are tried;
//!    the smallest total count whose measured error meets the tolerance wins (in the spirit of
//!    McLean, "Exponential sum approximations for t^{-beta}", 2018).
//! 3. **Verification.** The maximum relative error over 64 log-spaced points per decade of
//!    `[delta, horizon]` is measured and stored; if the raw rule misses the tolerance, eps1 is
//!    halved and the construction repeated.

use nalgebra::{DMatrix, SymmetricEigen};

use crate::error::{check_positive, Error};

/// Rates and weights of the exponential sum, slowest first.
#[derive(Clone, Debug, PartialEq)]
pub struct SoeKernel {
    /// Decay rates s_l, 1/s, ascending.
    pub rates: Vec<f64>,
    /// Weights w_l (already include 1/sqrt(pi)), s^{-1/2}.
    pub weights: Vec<f64>,
    /// Modes before compression.
    pub raw_count: usize,
    /// Measured maximum relative error of the sum on `[delta, horizon]`.
    pub max_relative_error: f64,
    pub delta: f64,
    pub horizon: f64,
}

/// Smallest tolerance accepted (below it f64 rounding dominates).
pub const MIN_TOLERANCE: f64 = 1e-12;
/// Largest tolerance accepted.
pub const MAX_TOLERANCE: f64 = 0.1;

fn exact(t: f64) -> f64 {
    1.0 / (std::f64::consts::PI * t).sqrt()
}

fn erfcinv(y: f64) -> f64 {
    // Newton on erfc from the asymptotic guess; erfc' = -2/sqrt(pi) e^{-x^2}.
    let mut x = (-y.ln()).sqrt();
    for _ in 0..100 {
        let f = libm::erfc(x) - y;
        let d = -2.0 / std::f64::consts::PI.sqrt() * (-x * x).exp();
        let step = f / d;
        x -= step;
        if step.abs() < 1e-15 * x.abs() {
            break;
        }
    }
    x
}

fn test_times(delta: f64, horizon: f64) -> Vec<f64> {
    let decades = (horizon / delta).log10().max(1e-3);
    let count = (64.0 * decades).ceil() as usize + 1;
    (0..count)
        .map(|i| delta * (horizon / delta).powf(i as f64 / (count - 1) as f64))
        .collect()
}

fn max_error(rates: &[f64], weights: &[f64], times: &[f64]) -> f64 {
    times
        .iter()
        .map(|&t| {
            let approx: f64 = rates.iter().zip(weights).map(|(s, w)| w * (-s * t).exp()).sum();
            ((approx - exact(t)) / exact(t)).abs()
        })
        .fold(0.0, f64::max)
}

/// L-point Gauss rule of the discrete measure `sum w_j delta(s - s_j)` (Lanczos with full
/// reorthogonalisation, then the eigen-decomposition of the Jacobi matrix).
fn gauss_rule(s: &[f64], w: &[f64], l: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let m = s.len();
    let mu0: f64 = w.iter().sum();
    let mut q: Vec<Vec<f64>> = vec![w.iter().map(|x| (x / mu0).sqrt()).collect()];
    let mut alpha = Vec::with_capacity(l);
    let mut beta: Vec<f64> = Vec::with_capacity(l);
    for k in 0..l {
        let qk = &q[k];
        let mut r: Vec<f64> = (0..m).map(|i| s[i] * qk[i]).collect();
        let a: f64 = r.iter().zip(qk).map(|(x, y)| x * y).sum();
        alpha.push(a);
        if k + 1 == l {
            break;
        }
        // Full reorthogonalisation against every previous vector (twice for safety).
        for _ in 0..2 {
            for qj in &q {
                let c: f64 = r.iter().zip(qj).map(|(x, y)| x * y).sum();
                for (ri, qi) in r.iter_mut().zip(qj) {
                    *ri -= c * qi;
                }
            }
        }
        let b = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        if b.is_nan() || b <= 1e-300 {
            return None;
        }
        beta.push(b);
        q.push(r.into_iter().map(|x| x / b).collect());
    }
    let n = alpha.len();
    let mut jac = DMatrix::<f64>::zeros(n, n);
    for i in 0..n {
        jac[(i, i)] = alpha[i];
        if i + 1 < n {
            jac[(i, i + 1)] = beta[i];
            jac[(i + 1, i)] = beta[i];
        }
    }
    let eig = SymmetricEigen::new(jac);
    let mut pairs: Vec<(f64, f64)> = (0..n)
        .map(|i| (eig.eigenvalues[i], mu0 * eig.eigenvectors[(0, i)].powi(2)))
        .collect();
    if pairs.iter().any(|&(x, w)| !(x > 0.0 && w > 0.0)) {
        return None;
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(pairs.into_iter().unzip())
}

/// Checks the parameters of [`SoeKernel::build`] without building.
pub fn check_parameters(tolerance: f64, delta: f64, horizon: f64) -> Result<(), Error> {
    check_positive("SOE tolerance", tolerance)?;
    check_positive("SOE min_dt", delta)?;
    check_positive("SOE horizon", horizon)?;
    if !(MIN_TOLERANCE..=MAX_TOLERANCE).contains(&tolerance) {
        return Err(Error::invalid(format!(
            "SOE tolerance must lie in [{MIN_TOLERANCE}, {MAX_TOLERANCE}], got {tolerance}"
        )));
    }
    if horizon <= delta {
        return Err(Error::invalid(format!(
            "SOE horizon ({horizon} s) must exceed min_dt ({delta} s)"
        )));
    }
    if horizon / delta > 1e15 {
        return Err(Error::invalid("SOE horizon / min_dt must not exceed 1e15"));
    }
    Ok(())
}

impl SoeKernel {
    /// Builds the smallest sum this method finds with relative error <= `tolerance` on `[delta, horizon]`.
    pub fn build(tolerance: f64, delta: f64, horizon: f64) -> Result<Self, Error> {
        check_parameters(tolerance, delta, horizon)?;
        let times = test_times(delta, horizon);
        let mut eps1 = tolerance / 3.0;
        for _ in 0..8 {
            let hx = std::f64::consts::PI.powi(2) / (2.0 * 2f64.sqrt() / eps1).ln();
            let a = 2.0 * (eps1 * std::f64::consts::PI.sqrt() / (2.0 * horizon.sqrt())).ln();
            let b = (erfcinv(eps1).powi(2) / delta).ln();
            let count = ((b - a) / hx).ceil() as usize + 1;
            let xs: Vec<f64> = (0..count).map(|j| a + j as f64 * hx).collect();
            let rates: Vec<f64> = xs.iter().map(|x| x.exp()).collect();
            let weights: Vec<f64> = xs
                .iter()
                .map(|x| hx * (x / 2.0).exp() / std::f64::consts::PI)
                .collect();
            let raw_error = max_error(&rates, &weights, &times);
            if raw_error > tolerance {
                eps1 /= 2.0;
                continue;
            }
            let mut best = (rates.clone(), weights.clone(), raw_error);
            for cut in 2..=count {
                for l in 1..cut {
                    if l + (count - cut) >= best.0.len() {
                        break;
                    }
                    let Some((gs, gw)) = gauss_rule(&rates[..cut], &weights[..cut], l) else {
                        break;
                    };
                    let rs: Vec<f64> = gs.iter().chain(&rates[cut..]).copied().collect();
                    let ws: Vec<f64> = gw.iter().chain(&weights[cut..]).copied().collect();
                    let err = max_error(&rs, &ws, &times);
                    if err <= tolerance {
                        best = (rs, ws, err);
                        break;
                    }
                }
            }
            return Ok(Self {
                rates: best.0,
                weights: best.1,
                raw_count: count,
                max_relative_error: best.2,
                delta,
                horizon,
            });
        }
        Err(Error::invalid(format!(
            "could not build an exponential sum for tolerance {tolerance} on [{delta}, {horizon}] s"
        )))
    }

    /// Number of modes.
    pub fn len(&self) -> usize {
        self.rates.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rates.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meets_its_tolerance_with_fewer_modes_than_the_raw_rule() {
        for &(tol, delta, horizon) in &[
            (1e-3, 1e-3, 10.0),
            (1e-6, 1e-4, 100.0),
            (1e-3, 1e-4, 600.0),
            (1e-8, 1e-5, 1e3),
        ] {
            let k = SoeKernel::build(tol, delta, horizon).unwrap();
            // Re-measure independently on a denser grid than the construction used.
            let times: Vec<f64> = (0..=5000)
                .map(|i| delta * (horizon / delta).powf(i as f64 / 5000.0))
                .collect();
            let err = max_error(&k.rates, &k.weights, &times);
            assert!(err <= 1.05 * tol, "tol {tol}: error {err}");
            assert!(
                k.len() < k.raw_count,
                "tol {tol}: no compression ({} modes)",
                k.len()
            );
            assert!(k
                .rates
                .iter()
                .chain(&k.weights)
                .all(|&x| x > 0.0 && x.is_finite()));
            assert!(k.rates.windows(2).all(|p| p[0] < p[1]));
        }
    }

    #[test]
    fn gauss_rule_matches_moments() {
        let s = [0.1, 0.3, 0.4, 0.9, 1.7, 2.0];
        let w = [1.0, 0.5, 2.0, 0.25, 0.125, 1.5];
        let (gs, gw) = gauss_rule(&s, &w, 3).unwrap();
        for p in 0..6 {
            let exact: f64 = s.iter().zip(&w).map(|(x, y)| y * x.powi(p)).sum();
            let quad: f64 = gs.iter().zip(&gw).map(|(x, y)| y * x.powi(p)).sum();
            approx::assert_relative_eq!(quad, exact, max_relative = 1e-12);
        }
    }

    #[test]
    fn erfcinv_inverts_erfc() {
        for &y in &[1e-12, 1e-6, 3.3e-4, 0.1, 0.5] {
            approx::assert_relative_eq!(libm::erfc(erfcinv(y)), y, max_relative = 1e-12);
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(SoeKernel::build(0.0, 1e-3, 1.0).is_err());
        assert!(SoeKernel::build(1e-3, 1.0, 0.5).is_err());
        assert!(SoeKernel::build(f64::NAN, 1e-3, 1.0).is_err());
        assert!(SoeKernel::build(0.5, 1e-3, 1.0).is_err());
    }
}
