//! The paper's Eq. 6 (Coimbra 2003), with the history truncated to the last `u` states.
//!
//! Eq. 6 reads, with h the step and v_k the velocity at t_k = k h:
//!
//! ```text
//! D^{1/2}x_n = h/(6 sqrt(pi)) sum_{i=1}^{n-1} [ v_{i-1}/((n-i+1)h)^{1/2}
//!                                             + 2(v_{i-1}+v_i)/((n-i+1/2)h)^{1/2}
//!                                             + v_i/((n-i)h)^{1/2} ]
//!            + 0.15h/sqrt(pi) [ v_{n-1}/h^{1/2} + 2(v_{n-1}+v_n)/(0.55h)^{1/2} + v_n/(0.1h)^{1/2} ]
//!            + 0.05h/sqrt(pi) [ 8 sqrt(2)/3 v_n/(0.05h)^{1/2} - 4/3 v_n/(0.1h)^{1/2} ]
//! ```
//!
//! How we read it (checked term by term, no typo found):
//! - each summand is Simpson's rule on the past panel [t_{i-1}, t_i] of
//!   `v(s) (t_n - s)^{-1/2}`, with the mid-panel velocity taken as (v_{i-1} + v_i)/2;
//! - the second bracket is Simpson's rule on [t_{n-1}, t_n - 0.1h] (width 0.9h, so
//!   0.9h/6 = 0.15h; its right end uses v_n);
//! - the third bracket is a two-node rule on the last 0.1h that integrates
//!   `(t_n - s)^{-1/2}` exactly (it equals 2 sqrt(0.1h) for v = 1).
//!
//! "u states": the paper says that for a given u "the summation index i will vary from
//! n + 1 - u to n - 1". So the sum keeps the last `u - 1` past panels and the
//! velocities used are v_{n-u} .. v_n: the u previous states and the current one.
//! u = 1 keeps only the local brackets. Before u steps have been taken the sum starts
//! at i = 1 as printed, and at n = 0 the integral is empty, so D^{1/2}x_0 = 0.
//!
//! The scheme assumes a constant step h (the size of the last step taken); if the
//! step changes, the stored velocities are weighted as if they had been sampled at
//! the newest step size.

use super::HalfDerivative;
use crate::math::Vec3;

/// Eq. 6 state: the last `u` velocities of every particle.
#[derive(Debug)]
pub struct Truncated {
    u: usize,
    n: usize,
    /// `u` slots of `n` velocities; slot `(head + u - k) % u` holds v_{step-k} (k = 1..=u).
    slots: Vec<Vec3>,
    head: usize,
    /// Velocities pushed so far (saturates at u for storage, counts on for Eq. 6's start-up).
    pushed: u64,
    /// weights[k] multiplies v_{n-k}; weights[0] = w0.
    weights: Vec<f64>,
    /// The step h of Eq. 6: the size of the last step pushed.
    h: f64,
}

/// Field-wise, so that `clone_from` reuses the buffers (the substep snapshot must not allocate).
impl Clone for Truncated {
    fn clone(&self) -> Self {
        Self {
            u: self.u,
            n: self.n,
            slots: self.slots.clone(),
            head: self.head,
            pushed: self.pushed,
            weights: {
                // Room for all u + 1 weights, as `new` makes: a copy taken while the history
                // fills must not allocate when `clone_from` later copies more weights into it.
                let mut w = Vec::with_capacity(self.u + 1);
                w.extend_from_slice(&self.weights);
                w
            },
            h: self.h,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.u = source.u;
        self.n = source.n;
        self.slots.clone_from(&source.slots);
        self.head = source.head;
        self.pushed = source.pushed;
        self.weights.clone_from(&source.weights);
        self.h = source.h;
    }
}

/// Eq. 6 weights for step h with `panels` past panels (`panels = min(u-1, n-1)`, n >= 1):
/// `out[k]` multiplies v_{n-k}, k = 0 ..= panels + 1.
pub fn eq6_weights(h: f64, panels: usize, out: &mut Vec<f64>) {
    let sp = std::f64::consts::PI.sqrt();
    let r = |a: f64| 1.0 / (a * h).sqrt();
    out.clear();
    out.resize(panels + 2, 0.0);
    // Local brackets.
    out[0] = 0.15 * h / sp * (2.0 * r(0.55) + r(0.1))
        + 0.05 * h / sp * (8.0 * 2f64.sqrt() / 3.0 * r(0.05) - 4.0 / 3.0 * r(0.1));
    out[1] = 0.15 * h / sp * (r(1.0) + 2.0 * r(0.55));
    // Past panel at distance m = n - i: v_{n-m-1} and v_{n-m}.
    for m in 1..=panels {
        let mf = m as f64;
        let c = h / (6.0 * sp);
        out[m + 1] += c * (r(mf + 1.0) + 2.0 * r(mf + 0.5));
        out[m] += c * (2.0 * r(mf + 0.5) + r(mf));
    }
}

impl Truncated {
    /// History of the last `u` (>= 1) velocities for `n` particles.
    pub fn new(u: usize, n: usize) -> Self {
        let u = u.max(1);
        Self {
            u,
            n,
            slots: vec![Vec3::zeros(); u * n],
            head: 0,
            pushed: 0,
            weights: Vec::with_capacity(u + 1),
            h: 0.0,
        }
    }

    /// The `u` of this history.
    pub fn u(&self) -> usize {
        self.u
    }

    /// Writes the state a later step depends on (weights are recomputed by `prepare`).
    pub(crate) fn write_state(&self, w: &mut crate::bytes::ByteWriter) {
        w.vec3s(&self.slots);
        w.u64(self.head as u64);
        w.u64(self.pushed);
        w.f64(self.h);
    }

    /// Checks a state read from a snapshot: every sample finite, the step size positive once
    /// a sample was taken.
    pub(crate) fn check_state(&self) -> Result<(), crate::Error> {
        if let Some(p) = self.slots.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(crate::Error::invalid(format!(
                "snapshot: truncated history sample {p} is not finite"
            )));
        }
        if !self.h.is_finite() || self.h < 0.0 || (self.pushed > 0 && self.h == 0.0) {
            return Err(crate::Error::invalid(format!(
                "snapshot: truncated history step size {} is not > 0",
                self.h
            )));
        }
        Ok(())
    }

    /// Reads what `write_state` wrote, for the same u and particle count.
    pub(crate) fn read_state(&mut self, r: &mut crate::bytes::ByteReader<'_>) -> Result<(), crate::Error> {
        r.vec3s_into(Some(self.u * self.n), &mut self.slots)?;
        let head = r.u64()?;
        if head >= self.u as u64 {
            return Err(crate::Error::invalid(
                "snapshot: truncated history head out of range",
            ));
        }
        self.head = head as usize;
        self.pushed = r.u64()?;
        self.h = r.f64()?;
        self.weights.clear();
        Ok(())
    }

    fn slot(&self, k: usize) -> &[Vec3] {
        let s = (self.head + self.u - k) % self.u;
        &self.slots[s * self.n..(s + 1) * self.n]
    }
}

impl HalfDerivative for Truncated {
    fn prepare(&mut self) {
        let h = self.h;
        if self.pushed == 0 {
            self.weights.clear();
            self.weights.push(0.0);
            return;
        }
        let panels = (self.u - 1).min((self.pushed - 1) as usize);
        eq6_weights(h, panels, &mut self.weights);
    }

    fn current_weight(&self) -> f64 {
        self.weights.first().copied().unwrap_or(0.0)
    }

    fn past_range(&self, first: usize, out: &mut [Vec3]) {
        out.fill(Vec3::zeros());
        for (k, &w) in self.weights.iter().enumerate().skip(1) {
            for (o, v) in out.iter_mut().zip(&self.slot(k)[first..]) {
                *o += w * v;
            }
        }
    }

    fn push(&mut self, v: &[Vec3], h: f64) {
        self.h = h;
        let h = self.head;
        self.slots[h * self.n..(h + 1) * self.n].copy_from_slice(&v[..self.n]);
        self.head = (self.head + 1) % self.u;
        self.pushed += 1;
    }

    fn bytes_per_particle(&self) -> usize {
        self.u * std::mem::size_of::<Vec3>()
    }

    fn reset(&mut self) {
        self.slots.fill(Vec3::zeros());
        self.head = 0;
        self.pushed = 0;
        self.weights.clear();
        self.h = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 6 exactly as printed, for one scalar velocity history v_0..v_n, keeping the
    /// panels i = max(1, n+1-u) .. n-1.
    fn printed_eq6(v: &[f64], h: f64, u: usize) -> f64 {
        let n = v.len() - 1;
        if n == 0 {
            return 0.0;
        }
        let sp = std::f64::consts::PI.sqrt();
        let nf = n as f64;
        let mut sum = 0.0;
        let first = (n + 1).saturating_sub(u).max(1);
        for i in first..n {
            let f = i as f64;
            sum += v[i - 1] / ((nf * h - (f - 1.0) * h).sqrt())
                + 2.0 * (v[i - 1] + v[i]) / ((nf * h - (f - 0.5) * h).sqrt())
                + v[i] / ((nf * h - f * h).sqrt());
        }
        h / (6.0 * sp) * sum
            + 0.15 * h / sp
                * (v[n - 1] / h.sqrt()
                    + 2.0 * (v[n - 1] + v[n]) / (0.55 * h).sqrt()
                    + v[n] / (0.1 * h).sqrt())
            + 0.05 * h / sp
                * (8.0 * 2f64.sqrt() / 3.0 * v[n] / (0.05 * h).sqrt() - 4.0 / 3.0 * v[n] / (0.1 * h).sqrt())
    }

    fn run(vel: impl Fn(usize) -> f64, steps: usize, h: f64, u: usize) {
        let mut t = Truncated::new(u, 1);
        let mut hist = vec![];
        let mut out = [Vec3::zeros()];
        for n in 0..steps {
            let vn = vel(n);
            hist.push(vn);
            t.prepare();
            t.past(&mut out);
            let ours = t.current_weight() * vn + out[0].x;
            let direct = printed_eq6(&hist, h, u);
            approx::assert_relative_eq!(ours, direct, epsilon = 1e-14, max_relative = 1e-12);
            t.push(&[Vec3::new(vn, 0.0, 0.0)], h);
        }
    }

    #[test]
    fn equals_printed_formula_for_several_histories() {
        for &u in &[1usize, 2, 3, 10, 1000] {
            run(|_| 1.0, 40, 1e-2, u);
            run(|n| (n as f64 * 0.3).sin() - 0.2, 40, 3e-3, u);
            run(|n| ((n * 7919) % 13) as f64 - 6.0, 40, 0.05, u);
        }
    }

    #[test]
    fn last_tenth_bracket_is_exact() {
        // For v = 1 the third bracket equals integral_0^{0.1h} s^{-1/2} ds / sqrt(pi).
        let h = 0.01f64;
        let sp = std::f64::consts::PI.sqrt();
        let b = 0.05 * h / sp * (8.0 * 2f64.sqrt() / 3.0 / (0.05 * h).sqrt() - 4.0 / 3.0 / (0.1 * h).sqrt());
        let exact = 2.0 * (0.1 * h).sqrt() / sp;
        assert!((b - exact).abs() < 1e-15);
    }

    #[test]
    fn off_before_first_push_and_memory() {
        let mut t = Truncated::new(3, 2);
        t.prepare();
        assert_eq!(t.current_weight(), 0.0);
        assert_eq!(t.bytes_per_particle(), 3 * 24);
    }
}
