//! `SumOfExponentials`: full memory at O(K) cost per particle, independent of time.
//!
//! The integral is split at the last sample t_{n-1}. The last panel [t_{n-1}, t_n] is done
//! exactly as in [`super::Full`] (PI-trap, `sqrt(g/pi) (2/3 v_{n-1} + 4/3 v_n)` for a gap g).
//! Everything older goes through the kernel's exponential sum
//! `t^{-1/2}/sqrt(pi) ~ sum_l w_l exp(-s_l t)` ([`SoeKernel`]): each mode keeps
//! `G_l = integral_0^{t_{n-1}} exp(-s_l (t_{n-1} - s)) v(s) ds`, updated recursively and exactly
//! for piecewise-linear velocity when a panel of width g leaves the exact window:
//!
//! ```text
//! G_l <- e^{-z} G_l + g [phi_o(z) v_{n-1} + phi_n(z) v_n],  z = s_l g,
//! phi_o(z) = (1 - e^{-z}(1 + z)) / z^2,  phi_n(z) = (z - 1 + e^{-z}) / z^2
//! ```
//!
//! and `D_n = 4/3 sqrt(g/pi) v_n + 2/3 sqrt(g/pi) v_{n-1} + sum_l w_l e^{-s_l g} G_l`.
//! Steps may change size freely (every mode is updated every step, so a later, smaller
//! step finds every mode correct). The kernel is accurate on `[min_dt, horizon]`; past the
//! horizon the oldest memory fades faster than t^{-1/2}. Modes with `s_l g > 50` cannot
//! contribute to D (their factor is below e^{-50}) and are left out of its sum.

use std::sync::Arc;

use super::soe_kernel::SoeKernel;
use super::HalfDerivative;
use crate::Vec3;

/// Modes whose decay over one step exceeds this are skipped.
const SKIP_EXPONENT: f64 = 50.0;

fn phi(z: f64) -> (f64, f64) {
    if z < 0.05 {
        // Taylor series: phi_o = sum (-z)^k (k+1)/(k+2)!, phi_n = sum (-z)^k / (k+2)!.
        let mut fact = 2.0; // (k+2)!
        let mut pow = 1.0;
        let (mut o, mut n) = (0.0, 0.0);
        for k in 0..10 {
            o += pow * (k as f64 + 1.0) / fact;
            n += pow / fact;
            pow *= -z;
            fact *= k as f64 + 3.0;
        }
        (o, n)
    } else {
        let e = (-z).exp();
        ((1.0 - e * (1.0 + z)) / (z * z), (z - 1.0 + e) / (z * z))
    }
}

/// SOE history of `n` particles.
#[derive(Debug)]
pub struct SumOfExponentials {
    n: usize,
    /// Shared and immutable: cloning the history (substep snapshots) does not copy it.
    kernel: Arc<SoeKernel>,
    /// Mode-major: mode l of every particle is `modes[l*n .. (l+1)*n]`.
    modes: Vec<Vec3>,
    prev: Vec<Vec3>,
    has_prev: bool,
    /// Width of the exact window: time from the last sample to now.
    gap: f64,
    /// Prepared per step: `w_l e^{-s_l g}` for the active modes.
    coef: Vec<f64>,
    w0: f64,
    w_prev: f64,
}

/// Field-wise, so that `clone_from` reuses the buffers (the substep snapshot must not allocate).
impl Clone for SumOfExponentials {
    fn clone(&self) -> Self {
        Self {
            n: self.n,
            kernel: self.kernel.clone(),
            modes: self.modes.clone(),
            prev: self.prev.clone(),
            has_prev: self.has_prev,
            gap: self.gap,
            coef: self.coef.clone(),
            w0: self.w0,
            w_prev: self.w_prev,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.n = source.n;
        self.kernel.clone_from(&source.kernel);
        self.modes.clone_from(&source.modes);
        self.prev.clone_from(&source.prev);
        self.has_prev = source.has_prev;
        self.gap = source.gap;
        self.coef.clone_from(&source.coef);
        self.w0 = source.w0;
        self.w_prev = source.w_prev;
    }
}

impl SumOfExponentials {
    pub fn new(kernel: SoeKernel, n: usize) -> Self {
        let k = kernel.len();
        Self {
            n,
            kernel: Arc::new(kernel),
            modes: vec![Vec3::zeros(); k * n],
            prev: vec![Vec3::zeros(); n],
            has_prev: false,
            gap: 0.0,
            coef: Vec::with_capacity(k),
            w0: 0.0,
            w_prev: 0.0,
        }
    }

    /// Number of exponential modes.
    pub fn mode_count(&self) -> usize {
        self.kernel.len()
    }

    /// The kernel approximation in use.
    pub fn kernel(&self) -> &SoeKernel {
        &self.kernel
    }

    fn active_modes(&self, g: f64) -> usize {
        self.kernel
            .rates
            .iter()
            .take_while(|&&s| s * g <= SKIP_EXPONENT)
            .count()
    }
}

impl HalfDerivative for SumOfExponentials {
    fn prepare(&mut self) {
        self.coef.clear();
        if !self.has_prev {
            self.w0 = 0.0;
            self.w_prev = 0.0;
            return;
        }
        let g = self.gap;
        let c = (g / std::f64::consts::PI).sqrt();
        self.w0 = 4.0 / 3.0 * c;
        self.w_prev = 2.0 / 3.0 * c;
        let active = self.active_modes(g);
        for l in 0..active {
            self.coef
                .push(self.kernel.weights[l] * (-self.kernel.rates[l] * g).exp());
        }
    }

    fn current_weight(&self) -> f64 {
        self.w0
    }

    fn past(&self, out: &mut [Vec3]) {
        for (o, p) in out.iter_mut().zip(&self.prev) {
            *o = self.w_prev * p;
        }
        for (l, &c) in self.coef.iter().enumerate() {
            for (o, m) in out.iter_mut().zip(&self.modes[l * self.n..(l + 1) * self.n]) {
                *o += c * m;
            }
        }
    }

    fn push(&mut self, v: &[Vec3], h: f64) {
        if self.has_prev {
            let g = self.gap;
            for l in 0..self.kernel.len() {
                let mode = &mut self.modes[l * self.n..(l + 1) * self.n];
                let z = self.kernel.rates[l] * g;
                let decay = (-z).exp();
                let (po, pn) = phi(z);
                let (a, b) = (g * po, g * pn);
                for ((m, p), vn) in mode.iter_mut().zip(&self.prev).zip(v) {
                    *m = decay * *m + a * p + b * vn;
                }
            }
        }
        self.prev.copy_from_slice(&v[..self.n]);
        self.has_prev = true;
        self.gap = h;
    }

    fn bytes_per_particle(&self) -> usize {
        (self.kernel.len() + 1) * std::mem::size_of::<Vec3>()
    }

    fn reset(&mut self) {
        self.modes.fill(Vec3::zeros());
        self.prev.fill(Vec3::zeros());
        self.has_prev = false;
        self.gap = 0.0;
        self.coef.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phi_series_and_closed_form_agree_at_the_switch() {
        let (o1, n1) = phi(0.05 - 1e-12);
        let z: f64 = 0.05;
        let e = (-z).exp();
        approx::assert_relative_eq!(o1, (1.0 - e * (1.0 + z)) / (z * z), max_relative = 1e-9);
        approx::assert_relative_eq!(n1, (z - 1.0 + e) / (z * z), max_relative = 1e-9);
        assert_eq!(phi(0.0), (0.5, 0.5));
    }
}
