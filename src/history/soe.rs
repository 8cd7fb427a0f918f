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
//!
//! Stored, for speed, is not `G_l` but `M_l = G_l + alpha_l v_{n-1}` with
//! `alpha_l = e^{z} g phi_o(z)` for the gap g that follows `v_{n-1}` (known when `v_{n-1}` is
//! pushed: it is the step just taken). Then the update needs no `v_{n-1}`:
//! `M_l <- e^{-z} M_l + (g phi_n(z) + alpha'_l) v_n` (alpha' for the next gap), one multiply and
//! one fused multiply-add per number instead of one and two, and the sum for D is
//! `sum_l w_l e^{-s_l g'} M_l - (sum_l w_l g' phi_o(s_l g')) v_n`: the shift comes back as one
//! per-particle term, whose coefficients `w_l g' phi_o` are of the size of the sum's own terms,
//! so nothing large cancels there. For a fast mode `M_l` can exceed `G_l` by orders of
//! magnitude (`e^z / z^2`, z up to the cut-off of [`SumOfExponentials::active_modes`], at most
//! 50), and `G_l`'s low bits are lost; but that rounding error enters D multiplied by
//! `w_l e^{-z}`, so it is ~1e-16 of the mode's own term `w_l g phi_o v`: negligible.
//! Steps may change size freely (every mode is updated every step, so a later, smaller
//! step finds every mode correct). The kernel is accurate on `[min_dt, horizon]`; past the
//! horizon the oldest memory fades faster than t^{-1/2}. Modes with `s_l g > 50` cannot
//! contribute to D (their factor is below e^{-50}) and are left out of its sum. One pass over
//! the modes per step both updates them and sums what the next step needs.

use std::sync::Arc;

use super::soe_kernel::SoeKernel;
use super::HalfDerivative;
use crate::parallel;
use crate::Vec3;

/// Largest cut-off exponent of [`SumOfExponentials::active_modes`].
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

/// Particles per block of the mode store: two AVX-512 registers of f64, four of AVX2 (16 was
/// faster than 8, 32 or 256 on the 61 x 41 throughput cloth: `examples/step_cycles.rs`).
const LANES: usize = 16;

/// SOE history of `n` particles.
///
/// Layout and work per step: particles are stored in blocks of [`LANES`]; within a block the
/// modes are ordered mode, component, particle (`[K][3][LANES]`), so the update of one mode
/// is the same arithmetic on `3 * LANES` contiguous numbers and the compiler vectorises it
/// across particles. One pass over the modes both folds the newest panel into every mode and
/// sums what the next step needs, `P_p = sum_l w_l e^{-s_l h} G_{l,p}` (h: the step just
/// taken, which is the next step's gap), each particle's sum in ascending mode order.
/// `past` then only adds `w_prev v_{n-1}`: one pass over the modes per step, not two.
/// Blocks are independent, so chunks of them run in parallel with identical results.
#[derive(Debug)]
pub struct SumOfExponentials {
    n: usize,
    /// Shared and immutable: cloning the history (substep snapshots) does not copy it.
    kernel: Arc<SoeKernel>,
    /// Block-major: block b holds `[K][3][LANES]` numbers (see the type's docs); the lanes
    /// past `n` in the last block stay zero. Each is a shifted mode `M_l` (module docs).
    modes: Vec<f64>,
    prev: Vec<Vec3>,
    /// `sum_l w_l e^{-s_l gap} G_l` per particle, computed by the last push.
    pending: Vec<Vec3>,
    has_prev: bool,
    /// Width of the exact window: time from the last sample to now.
    gap: f64,
    w0: f64,
    w_prev: f64,
    /// Cut-off exponent of [`Self::active_modes`].
    cut: f64,
    /// Per-mode coefficients of the fold, reused between steps.
    decay: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    next: Vec<f64>,
    /// `alpha_l` of the last push, for the gap that followed it (module docs).
    alpha: Vec<f64>,
}

/// Field-wise, so that `clone_from` reuses the buffers (the substep snapshot must not allocate).
impl Clone for SumOfExponentials {
    fn clone(&self) -> Self {
        Self {
            n: self.n,
            kernel: self.kernel.clone(),
            modes: self.modes.clone(),
            prev: self.prev.clone(),
            pending: self.pending.clone(),
            has_prev: self.has_prev,
            gap: self.gap,
            w0: self.w0,
            w_prev: self.w_prev,
            cut: self.cut,
            decay: self.decay.clone(),
            a: self.a.clone(),
            b: self.b.clone(),
            next: self.next.clone(),
            alpha: self.alpha.clone(),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.n = source.n;
        self.kernel.clone_from(&source.kernel);
        self.modes.clone_from(&source.modes);
        self.prev.clone_from(&source.prev);
        self.pending.clone_from(&source.pending);
        self.has_prev = source.has_prev;
        self.gap = source.gap;
        self.w0 = source.w0;
        self.w_prev = source.w_prev;
        self.cut = source.cut;
        // Scratch: contents need not be copied, only room kept.
        for (mine, theirs) in [
            (&mut self.decay, &source.decay),
            (&mut self.a, &source.a),
            (&mut self.b, &source.b),
            (&mut self.next, &source.next),
            (&mut self.alpha, &source.alpha),
        ] {
            mine.resize(theirs.len(), 0.0);
        }
    }
}

impl SumOfExponentials {
    /// Modes that matter over a gap `g`: those with `s_l g <= cut-off`, the cut-off being where
    /// a mode's factor `e^{-s_l g}` falls below 1/1000 of the sum's own measured error (about
    /// 14.1 at the default tolerance). A mode past it adds less than that to D^{1/2}x, so it is
    /// neither summed nor folded; at 1/24 s steps that leaves out the four fastest of 16.
    fn active_modes(&self, g: f64) -> usize {
        self.kernel.rates.partition_point(|&s| s * g <= self.cut)
    }

    /// Where component `d` of mode `l` of particle `p` lives in `modes`.
    fn mode_index(&self, p: usize, l: usize, d: usize) -> usize {
        let k = self.kernel.len();
        (p / LANES) * k * 3 * LANES + (l * 3 + d) * LANES + p % LANES
    }

    pub fn new(kernel: SoeKernel, n: usize) -> Self {
        let k = kernel.len();
        let cut = (1e3 / kernel.max_relative_error.max(1e-300))
            .ln()
            .min(SKIP_EXPONENT);
        Self {
            cut,
            n,
            kernel: Arc::new(kernel),
            modes: vec![0.0; n.div_ceil(LANES) * k * 3 * LANES],
            prev: vec![Vec3::zeros(); n],
            pending: vec![Vec3::zeros(); n],
            has_prev: false,
            gap: 0.0,
            w0: 0.0,
            w_prev: 0.0,
            decay: vec![0.0; k],
            a: vec![0.0; k],
            b: vec![0.0; k],
            next: vec![0.0; k],
            alpha: vec![0.0; k],
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

    /// Writes the state a later step depends on (the step weights are recomputed by `prepare`).
    pub(crate) fn write_state(&self, w: &mut crate::bytes::ByteWriter) {
        // Particle by particle, mode by mode, x y z: independent of the block layout in memory.
        w.u64((self.n * self.kernel.len() * 3) as u64);
        for p in 0..self.n {
            for l in 0..self.kernel.len() {
                for d in 0..3 {
                    w.f64(self.modes[self.mode_index(p, l, d)]);
                }
            }
        }
        w.vec3s(&self.prev);
        w.vec3s(&self.pending);
        w.u8(u8::from(self.has_prev));
        w.f64(self.gap);
    }

    /// Reads what `write_state` wrote, for the same kernel and particle count.
    pub(crate) fn read_state(&mut self, r: &mut crate::bytes::ByteReader<'_>) -> Result<(), crate::Error> {
        let k = self.kernel.len();
        let count = r.len(Some(self.n * k * 3), 8)?;
        debug_assert_eq!(count, self.n * k * 3);
        self.modes.fill(0.0);
        for p in 0..self.n {
            for l in 0..k {
                for d in 0..3 {
                    let at = self.mode_index(p, l, d);
                    self.modes[at] = r.f64()?;
                }
            }
        }
        r.vec3s_into(Some(self.n), &mut self.prev)?;
        r.vec3s_into(Some(self.n), &mut self.pending)?;
        self.has_prev = r.u8()? != 0;
        self.gap = r.f64()?;
        Ok(())
    }
}

impl HalfDerivative for SumOfExponentials {
    fn prepare(&mut self) {
        if !self.has_prev {
            self.w0 = 0.0;
            self.w_prev = 0.0;
            return;
        }
        let c = (self.gap / std::f64::consts::PI).sqrt();
        self.w0 = 4.0 / 3.0 * c;
        self.w_prev = 2.0 / 3.0 * c;
    }

    fn current_weight(&self) -> f64 {
        self.w0
    }

    fn past_range(&self, first: usize, out: &mut [Vec3]) {
        past_widest(self.w_prev, &self.prev[first..], &self.pending[first..], out);
    }

    fn push(&mut self, v: &[Vec3], h: f64) {
        // Modes needed by the next step (those not negligible over its gap h); rates ascend,
        // so they are a prefix.
        let needed = self.active_modes(h);
        // Modes kept at the previous push (needed over the gap g); none before the first.
        let (g, kept) = if self.has_prev {
            (self.gap, self.active_modes(self.gap))
        } else {
            (0.0, 0)
        };
        let mut shift = 0.0;
        for l in 0..needed {
            let s = self.kernel.rates[l];
            let z = s * g;
            // The shift for the next gap h: alpha = e^{s h} h phi_o(s h), and what it adds to
            // the sum for D, w e^{-s h} alpha = w h phi_o(s h).
            let zh = s * h;
            let po_h = phi(zh).0;
            self.alpha[l] = zh.exp() * (h * po_h);
            // Finite: a mode in use has s h <= cut-off <= SKIP_EXPONENT.
            debug_assert!(self.alpha[l].is_finite(), "mode {l}: s h = {zh}");
            shift += self.kernel.weights[l] * (h * po_h);
            if l < kept {
                // M holds G + alpha(g) v_{n-1}: e^{-z} M = e^{-z} G + g phi_o v_{n-1}.
                self.decay[l] = (-z).exp();
                self.a[l] = 0.0;
                self.b[l] = g * phi(z).1 + self.alpha[l];
            } else if self.has_prev {
                // A mode not kept last time restarts from the newest panel: what it held is
                // weighted by e^{-s g} < e^{-cut-off} (see `active_modes`).
                let (po, pn) = phi(z);
                self.decay[l] = 0.0;
                self.a[l] = g * po;
                self.b[l] = g * pn + self.alpha[l];
            } else {
                // The first sample: G = 0, M = alpha v_0.
                self.decay[l] = 0.0;
                self.a[l] = 0.0;
                self.b[l] = self.alpha[l];
            }
            self.next[l] = self.kernel.weights[l] * (-s * h).exp();
        }
        let k = needed;
        let coefficients = Coefficients {
            decay: &self.decay[..k],
            a: &self.a[..k],
            b: &self.b[..k],
            next: &self.next[..k],
            shift,
            restart: self.has_prev && needed > kept,
        };
        let (prev, n) = (&self.prev, self.n);
        let block = self.kernel.len() * 3 * LANES;
        let blocks_per_chunk = parallel::CHUNK / LANES;
        parallel::chunks2(
            parallel::worth_it(n),
            (&mut self.modes, block),
            (&mut self.pending, LANES),
            blocks_per_chunk,
            |first_block, modes, pending| {
                let p0 = first_block * LANES;
                let p1 = (p0 + pending.len()).min(n);
                fold_blocks_widest(&coefficients, &prev[p0..p1], &v[p0..p1], modes, pending);
            },
        );
        if !self.has_prev {
            // No history yet: nothing from the past (the fold's sum is zero up to rounding).
            self.pending.fill(Vec3::zeros());
        }
        self.prev.copy_from_slice(&v[..self.n]);
        self.has_prev = true;
        self.gap = h;
    }

    fn bytes_per_particle(&self) -> usize {
        (self.kernel.len() + 2) * std::mem::size_of::<Vec3>()
    }

    fn reset(&mut self) {
        self.modes.fill(0.0);
        self.prev.fill(Vec3::zeros());
        self.pending.fill(Vec3::zeros());
        self.has_prev = false;
        self.gap = 0.0;
    }
}

crate::simd_dispatch! { fn past_widest(w_prev: f64, prev: &[Vec3], pending: &[Vec3], out: &mut [Vec3]) => past_kernel }

/// `out = w_prev prev + pending`, element by element.
#[inline(always)]
fn past_kernel(w_prev: f64, prev: &[Vec3], pending: &[Vec3], out: &mut [Vec3]) {
    let n = out.len();
    let (prev, pending) = (&prev[..n], &pending[..n]);
    for k in 0..n {
        out[k] = w_prev * prev[k] + pending[k];
    }
}

/// Coefficients of one fold: `M <- decay M + a v_{n-1} + b v_n` per mode, and the sum
/// `sum next M - shift v_n` per particle.
struct Coefficients<'a> {
    decay: &'a [f64],
    a: &'a [f64],
    b: &'a [f64],
    next: &'a [f64],
    shift: f64,
    /// Whether some `a` is not zero (a mode restarts); else the `v_{n-1}` term is skipped.
    restart: bool,
}

crate::simd_dispatch! { fn fold_blocks_widest(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3]) => fold_blocks }

/// [`fold_block`] for consecutive blocks: `prev` and `v` hold their particles (the last block
/// may be partial), `modes` and `out` their modes and sums.
#[inline(always)]
fn fold_blocks(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3]) {
    // A block holds every mode of the kernel; `c` may cover only the first few (the rest are
    // negligible over this step and are left alone).
    let block = modes.len() / out.len().div_ceil(LANES);
    debug_assert!(block >= c.decay.len() * 3 * LANES);
    for (b, (m, o)) in modes
        .chunks_exact_mut(block)
        .zip(out.chunks_mut(LANES))
        .enumerate()
    {
        let p0 = b * LANES;
        let p1 = (p0 + LANES).min(prev.len());
        fold_block(c, &prev[p0..p1], &v[p0..p1], m, o);
    }
}

/// Folds the panel (`prev`, `v`) into the modes of one block of up to [`LANES`] particles and
/// writes each particle's next-step sum into `out`. Same arithmetic, in the same order, for
/// every particle as a scalar loop over its modes; laid out so it vectorises across lanes.
#[inline(always)]
fn fold_block(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3]) {
    if c.restart {
        fold_block_with::<true>(c, prev, v, modes, out)
    } else {
        fold_block_with::<false>(c, prev, v, modes, out)
    }
}

/// [`fold_block`]; `WITH_PREV`: whether the `a v_{n-1}` term is added (some `a` is not zero).
#[inline(always)]
fn fold_block_with<const WITH_PREV: bool>(
    c: &Coefficients<'_>,
    prev: &[Vec3],
    v: &[Vec3],
    modes: &mut [f64],
    out: &mut [Vec3],
) {
    const W: usize = 3 * LANES;
    // Component-major, as the modes: entry d * LANES + q is component d of lane q.
    let mut pv = [0.0; W];
    let mut vn = [0.0; W];
    for q in 0..prev.len() {
        for d in 0..3 {
            if WITH_PREV {
                pv[d * LANES + q] = prev[q][d];
            }
            vn[d * LANES + q] = v[q][d];
        }
    }
    let mut acc = [0.0; W];
    for (l, mode) in modes.chunks_exact_mut(W).take(c.decay.len()).enumerate() {
        let (decay, a, b, next) = (c.decay[l], c.a[l], c.b[l], c.next[l]);
        for k in 0..W {
            // Fused multiply-adds: one rounding each, same bits on every CPU (crate::simd).
            let input = if WITH_PREV {
                a.mul_add(pv[k], b * vn[k])
            } else {
                b * vn[k]
            };
            let m = decay.mul_add(mode[k], input);
            mode[k] = m;
            acc[k] = next.mul_add(m, acc[k]);
        }
    }
    for (q, o) in out.iter_mut().enumerate().take(prev.len()) {
        let sum = Vec3::new(acc[q], acc[LANES + q], acc[2 * LANES + q]);
        *o = (-c.shift).mul_add_vec(v[q], sum);
    }
}

/// `a * x + y` component by component, each a fused multiply-add.
trait MulAddVec {
    fn mul_add_vec(self, x: Vec3, y: Vec3) -> Vec3;
}

impl MulAddVec for f64 {
    #[inline(always)]
    fn mul_add_vec(self, x: Vec3, y: Vec3) -> Vec3 {
        Vec3::new(
            self.mul_add(x.x, y.x),
            self.mul_add(x.y, y.y),
            self.mul_add(x.z, y.z),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Particles of the skipping test: several blocks, a partial last one.
    const N: usize = 2 * LANES + 5;

    /// D^{1/2} of every particle after each push of `v_p(t)` at the given steps.
    fn run(mut h: SumOfExponentials, steps: &[f64]) -> Vec<f64> {
        let mut t = 0.0f64;
        let mut out = vec![];
        let mut past = vec![Vec3::zeros(); N];
        let v = |p: usize, t: f64| {
            let w = 1.0 + p as f64 * 0.37;
            Vec3::new((w * t).sin() + 0.3, (2.0 * w * t).cos(), 0.1 * p as f64)
        };
        for &dt in steps {
            let vs: Vec<Vec3> = (0..N).map(|p| v(p, t)).collect();
            h.push(&vs, dt);
            t += dt;
            h.prepare();
            h.past(&mut past);
            for (p, d) in past.iter().enumerate() {
                out.extend((h.current_weight() * v(p, t) + d).iter());
            }
        }
        out
    }

    #[test]
    fn leaving_out_negligible_modes_changes_d_by_less_than_the_cut_off_promises() {
        let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
        let skipping = SumOfExponentials::new(kernel.clone(), N);
        // At 1/24 s four of the 16 modes are negligible; at 0.5 ms none.
        assert_eq!(skipping.active_modes(1.0 / 24.0), kernel.len() - 4);
        assert_eq!(skipping.active_modes(5e-4), kernel.len());
        let mut keeping = skipping.clone();
        // Every mode that can matter in f64 (factor e^{-s g} >= e^{-50}, about 2e-22).
        keeping.cut = SKIP_EXPONENT;
        // Fine steps, coarse ones (modes left out, their state goes stale), fine again (they
        // rejoin), coarse again.
        let steps: Vec<f64> = (0..760)
            .map(|k| {
                if (300..348).contains(&k) || k >= 700 {
                    1.0 / 24.0
                } else {
                    1e-4
                }
            })
            .collect();
        let (a, b) = (run(skipping, &steps), run(keeping, &steps));
        assert!(a.iter().chain(&b).all(|x| x.is_finite()));
        let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        // The cut-off is 1/1000 of the kernel's own error (7.4e-4): 1e-6 of D at most.
        assert!(worst <= 1e-6 * scale, "{worst:e} of {scale:e}");
        assert!(worst > 0.0, "modes were left out, so something must differ");
    }

    #[test]
    fn state_saved_while_modes_are_left_out_continues_bitwise() {
        let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
        let mut a = SumOfExponentials::new(kernel.clone(), N);
        let v = |k: usize| -> Vec<Vec3> {
            (0..N)
                .map(|p| Vec3::new((0.1 * k as f64 + p as f64).sin(), 0.2, p as f64 * 0.01))
                .collect()
        };
        // Coarse steps leave four modes out; save; then finer steps bring them back.
        let steps = |k: usize| if k < 30 { 1.0 / 24.0 } else { 1e-4 };
        for k in 0..30 {
            a.push(&v(k), steps(k));
        }
        let mut w = crate::bytes::ByteWriter { buf: vec![] };
        a.write_state(&mut w);
        let mut b = SumOfExponentials::new(kernel, N);
        b.read_state(&mut crate::bytes::ByteReader::new(&w.buf)).unwrap();
        let (mut pa, mut pb) = (vec![Vec3::zeros(); N], vec![Vec3::zeros(); N]);
        for k in 30..60 {
            a.push(&v(k), steps(k));
            b.push(&v(k), steps(k));
            a.prepare();
            b.prepare();
            a.past(&mut pa);
            b.past(&mut pb);
            assert_eq!(pa, pb, "step {k}");
        }
    }

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
