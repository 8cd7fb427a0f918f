//! `Full`: the exact convolution over the whole history, second order (the reference).
//!
//! The velocity is taken piecewise linear between samples and integrated exactly
//! against the kernel ([`super::kernel::panel_weights`]), so the rule is exact when x is
//! linear or quadratic in t and second order otherwise. Sample times are stored, so
//! steps of different sizes are handled exactly. Cost and memory are O(n) per
//! particle after n steps: use it as the reference, not for long bakes.

use super::kernel::panel_weights;
use super::HalfDerivative;
use crate::math::Vec3;

/// Every past velocity of every particle, with its time.
#[derive(Debug)]
pub struct Full {
    n: usize,
    /// Step-major: velocities of step k are `samples[k*n .. (k+1)*n]`.
    samples: Vec<Vec3>,
    times: Vec<f64>,
    /// weights[k] multiplies the velocity of step k; w0 is separate.
    weights: Vec<f64>,
    w0: f64,
    /// Current time: the last sample's time plus the step taken since.
    now: f64,
}

/// Field-wise, so that `clone_from` reuses the buffers (the substep snapshot must not allocate).
impl Clone for Full {
    fn clone(&self) -> Self {
        Self {
            n: self.n,
            samples: self.samples.clone(),
            times: self.times.clone(),
            weights: self.weights.clone(),
            w0: self.w0,
            now: self.now,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.n = source.n;
        self.samples.clone_from(&source.samples);
        self.times.clone_from(&source.times);
        self.weights.clone_from(&source.weights);
        self.w0 = source.w0;
        self.now = source.now;
    }
}

impl Full {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            samples: Vec::new(),
            times: Vec::new(),
            weights: Vec::new(),
            w0: 0.0,
            now: 0.0,
        }
    }

    /// Steps stored so far.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Makes room for one more step, or says why there is none: the history may not exceed
    /// [`super::MAX_HISTORY_BYTES`], and a failed allocation is an error, not an abort.
    pub(crate) fn reserve_step(&mut self) -> Result<(), crate::Error> {
        self.reserve_within(super::MAX_HISTORY_BYTES)
    }

    fn reserve_within(&mut self, limit: u64) -> Result<(), crate::Error> {
        let bytes = (self.times.len() as u64 + 1)
            .saturating_mul(self.n as u64)
            .saturating_mul(std::mem::size_of::<Vec3>() as u64);
        if bytes > limit {
            return Err(crate::Error::invalid(format!(
                "the full history would exceed {limit} bytes after {} steps; use the SOE history for long runs",
                self.times.len()
            )));
        }
        let room = |e| crate::Error::out_of_memory(format!("out of memory for the full history: {e}"));
        self.samples.try_reserve(self.n).map_err(room)?;
        self.times.try_reserve(1).map_err(room)?;
        Ok(())
    }

    /// Writes the state a later step depends on (weights are recomputed by `prepare`).
    pub(crate) fn write_state(&self, w: &mut crate::bytes::ByteWriter) {
        w.f64s(&self.times);
        w.vec3s(&self.samples);
        w.f64(self.now);
    }

    /// Checks a state read from a snapshot: times finite, increasing, not after `now_cloth`;
    /// every sample finite.
    pub(crate) fn check_state(&self, now_cloth: f64) -> Result<(), crate::Error> {
        let bad = |m: String| Err(crate::Error::invalid(format!("snapshot: full history {m}")));
        let slack = 1e-9 * now_cloth.abs().max(1.0);
        if let Some(k) = self
            .times
            .iter()
            .position(|t| !t.is_finite() || *t < 0.0 || *t > now_cloth + slack)
        {
            return bad(format!(
                "time {k} ({}) is not within [0, {now_cloth}]",
                self.times[k]
            ));
        }
        if let Some(k) = self.times.windows(2).position(|w| w[1] <= w[0]) {
            return bad(format!("times {k} and {} are not increasing", k + 1));
        }
        // Now lies within the span the cloth has lived, and not before its last sample.
        let first = self.times.last().copied().unwrap_or(0.0).max(0.0);
        if !(self.now.is_finite() && self.now >= first - slack && self.now <= now_cloth + slack) {
            return bad(format!(
                "time now {} is not within [{first}, {now_cloth}] (its last sample and the cloth's time)",
                self.now
            ));
        }
        if let Some(p) = self.samples.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
            return bad(format!("sample {p} is not finite"));
        }
        Ok(())
    }

    /// Reads what `write_state` wrote, for the same particle count.
    pub(crate) fn read_state(&mut self, r: &mut crate::bytes::ByteReader<'_>) -> Result<(), crate::Error> {
        r.f64s_into(None, &mut self.times)?;
        r.vec3s_into(Some(self.times.len() * self.n), &mut self.samples)?;
        self.now = r.f64()?;
        self.weights.clear();
        self.w0 = 0.0;
        Ok(())
    }
}

impl HalfDerivative for Full {
    fn prepare(&mut self) {
        let m = self.times.len();
        self.weights.clear();
        self.weights.resize(m, 0.0);
        self.w0 = 0.0;
        if m == 0 {
            return; // t = 0: the integral is empty
        }
        let t_now = self.now;
        // Panel between sample k (far) and k+1 (near); the last panel ends at "now".
        for k in 0..m {
            let far = t_now - self.times[k];
            let near = if k + 1 < m { t_now - self.times[k + 1] } else { 0.0 };
            let (w_near, w_far) = panel_weights(near, far);
            self.weights[k] += w_far;
            if k + 1 < m {
                self.weights[k + 1] += w_near;
            } else {
                self.w0 = w_near;
            }
        }
    }

    fn current_weight(&self) -> f64 {
        self.w0
    }

    fn past_range(&self, first: usize, out: &mut [Vec3]) {
        out.fill(Vec3::zeros());
        for (k, &w) in self.weights.iter().enumerate() {
            let step = &self.samples[k * self.n + first..(k + 1) * self.n];
            for (o, v) in out.iter_mut().zip(step) {
                *o += w * v;
            }
        }
    }

    fn push(&mut self, v: &[Vec3], h: f64) {
        self.samples.extend_from_slice(&v[..self.n]);
        self.times.push(self.now);
        self.now += h;
    }

    fn bytes_per_particle(&self) -> usize {
        self.times.len() * std::mem::size_of::<Vec3>()
    }

    fn reset(&mut self) {
        self.samples.clear();
        self.times.clear();
        self.weights.clear();
        self.w0 = 0.0;
        self.now = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_stops_at_the_byte_limit_with_an_error() {
        let mut f = Full::new(10);
        let v = vec![Vec3::zeros(); 10];
        let limit = 3 * 10 * 24;
        for _ in 0..3 {
            f.reserve_within(limit).unwrap();
            f.push(&v, 1e-3);
        }
        let e = f.reserve_within(limit).unwrap_err();
        assert!(e.message.contains("SOE"), "{}", e.message);
        assert_eq!(f.len(), 3);
    }
}
