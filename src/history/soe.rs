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
//! the modes per step both folds in the last accepted step and sums what the current step
//! needs, inside the step's own pass over the particles (see [`SumOfExponentials`]).

use std::sync::Arc;

use super::soe_kernel::SoeKernel;
use super::HalfDerivative;
use crate::math::Vec3;
use crate::parallel;

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
pub(crate) const LANES: usize = 16;

/// SOE history of `n` particles.
///
/// Layout: particles are stored in blocks of `LANES`; within a block the modes are ordered
/// mode, component, particle (`[K][3][LANES]`), so the update of one mode is the same
/// arithmetic on `3 * LANES` contiguous numbers and the compiler vectorises it across particles.
///
/// Work per step, deferred: an accepted step only records its velocities `v_n`
/// (`Self::record`, a buffer swap). The next step's pass over the particles (`Self::begin`,
/// then `SoePass::past_range` tile by tile) folds that panel into every mode and, in the same
/// walk over the modes, sums the past `H = w_prev v_n + sum_l w_l e^{-s_l h} G_l` that step
/// needs, while the step's other per-particle work has the tile in cache: the modes are read
/// and written once per step and no other array of the history is streamed. The fold depends
/// on accepted steps only, so a step that fails after it leaves the history as it logically
/// was (folded, nothing recorded); a retry sums the stored modes without folding them again.
/// Every particle's sum is taken in ascending mode order and blocks are independent, so
/// chunks of them run in parallel with identical results.
#[derive(Debug)]
pub struct SumOfExponentials {
    n: usize,
    /// Shared and immutable: cloning the history (substep snapshots) does not copy it.
    kernel: Arc<SoeKernel>,
    /// Block-major: block b holds `[K][3][LANES]` numbers (see the type's docs); the lanes
    /// past `n` in the last block stay zero. Each is a shifted mode `M_l` (module docs).
    modes: crate::aligned::AlignedF64,
    /// The newest sample folded into the modes.
    prev: Vec<Vec3>,
    /// The sample recorded by the last accepted step, waiting to be folded while `clock.recorded`
    /// is set; spare room otherwise.
    newest: Vec<Vec3>,
    clock: Clock,
    w0: f64,
    w_prev: f64,
    /// Cut-off exponent of [`active_modes`].
    cut: f64,
    /// Per-mode coefficients of the pass, reused between steps.
    coef: ModeCoefficients,
    /// What the pass begun last does (read by [`Self::end`]).
    plan: Plan,
}

/// Where the history stands in time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Clock {
    /// Whether a sample has been folded into the modes (`prev` is one).
    has_prev: bool,
    /// Whether the modes hold the first sample only, whose past sum is zero.
    first: bool,
    /// The step that followed `prev`: the gap from it to the next sample.
    gap: f64,
    /// The size of the step that followed `newest`, while it waits to be folded.
    recorded: Option<f64>,
}

impl Clock {
    /// The gap of the step about to be taken (from the newest sample, folded or not).
    fn step_gap(&self) -> Option<f64> {
        self.recorded.or(self.has_prev.then_some(self.gap))
    }
}

/// Per-mode coefficients: `M <- decay M + a v_{n-1} + b v_n` and the sum's `next`.
#[derive(Clone, Debug, Default)]
struct ModeCoefficients {
    decay: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    next: Vec<f64>,
    alpha: Vec<f64>,
}

impl ModeCoefficients {
    fn new(k: usize) -> Self {
        Self {
            decay: vec![0.0; k],
            a: vec![0.0; k],
            b: vec![0.0; k],
            next: vec![0.0; k],
            alpha: vec![0.0; k],
        }
    }
}

/// What one pass does.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Plan {
    /// Fold the recorded sample (which followed a step of this size) before summing.
    fold: Option<f64>,
    /// Modes folded and summed: a prefix, the others being negligible over the step.
    k: usize,
    /// `sum_l w_l g phi_o(s_l g)`: the shift's share of the sum (module docs).
    shift: f64,
    /// Whether a mode restarts from the newest panel (its `a` is not zero).
    restart: bool,
    /// Whether the past sum is zero: the modes hold no sample, or only the first.
    zero: bool,
}

/// Modes that matter over a gap `g`: those with `s_l g <= cut`, the cut-off being where a
/// mode's factor `e^{-s_l g}` falls below 1/1000 of the sum's own measured error (about 14.1 at
/// the default tolerance). A mode past it adds less than that to D^{1/2}x, so it is neither
/// summed nor folded; at 1/24 s steps that leaves out the four fastest of 16.
fn active_modes(kernel: &SoeKernel, cut: f64, g: f64) -> usize {
    kernel.rates.partition_point(|&s| s * g <= cut)
}

/// Plans the pass of the step about to be taken and fills `c` for its modes.
fn plan(kernel: &SoeKernel, cut: f64, clock: &Clock, c: &mut ModeCoefficients) -> Plan {
    // The sum's coefficients over the step's gap h, and the shift alpha for it:
    // alpha = e^{s h} h phi_o(s h), adding w e^{-s h} alpha = w h phi_o(s h) to the sum for D.
    let sum_over = |c: &mut ModeCoefficients, h: f64| {
        let needed = active_modes(kernel, cut, h);
        let mut shift = 0.0;
        for l in 0..needed {
            let s = kernel.rates[l];
            let zh = s * h;
            let po_h = phi(zh).0;
            c.alpha[l] = zh.exp() * (h * po_h);
            // Finite: a mode in use has s h <= cut-off <= SKIP_EXPONENT.
            debug_assert!(c.alpha[l].is_finite(), "mode {l}: s h = {zh}");
            shift += kernel.weights[l] * (h * po_h);
            c.next[l] = kernel.weights[l] * (-s * h).exp();
        }
        (needed, shift)
    };
    let Some(h) = clock.recorded else {
        if !clock.has_prev {
            return Plan {
                zero: true,
                ..Plan::default()
            };
        }
        // Nothing recorded since the last fold: sum what it left, over its step.
        let (k, shift) = sum_over(c, clock.gap);
        return Plan {
            fold: None,
            k,
            shift,
            restart: false,
            zero: clock.first,
        };
    };
    let (needed, shift) = sum_over(c, h);
    // Modes kept at the previous fold (needed over the gap g); none before the first.
    let (g, kept) = if clock.has_prev {
        (clock.gap, active_modes(kernel, cut, clock.gap))
    } else {
        (0.0, 0)
    };
    for l in 0..needed {
        let z = kernel.rates[l] * g;
        if l < kept {
            // M holds G + alpha(g) v_{n-1}: e^{-z} M = e^{-z} G + g phi_o v_{n-1}.
            c.decay[l] = (-z).exp();
            c.a[l] = 0.0;
            c.b[l] = g * phi(z).1 + c.alpha[l];
        } else if clock.has_prev {
            // A mode not kept last time restarts from the newest panel: what it held is
            // weighted by e^{-s g} < e^{-cut-off} (see `active_modes`).
            let (po, pn) = phi(z);
            c.decay[l] = 0.0;
            c.a[l] = g * po;
            c.b[l] = g * pn + c.alpha[l];
        } else {
            // The first sample: G = 0, M = alpha v_0.
            c.decay[l] = 0.0;
            c.a[l] = 0.0;
            c.b[l] = c.alpha[l];
        }
    }
    Plan {
        fold: Some(h),
        k: needed,
        shift,
        restart: clock.has_prev && needed > kept,
        // No history before the first sample: its sum is zero up to rounding, and taken as 0.
        zero: !clock.has_prev,
    }
}

/// Field-wise, so that `clone_from` reuses the buffers (the substep snapshot must not allocate).
impl Clone for SumOfExponentials {
    fn clone(&self) -> Self {
        Self {
            n: self.n,
            kernel: self.kernel.clone(),
            modes: self.modes.clone(),
            prev: self.prev.clone(),
            newest: self.newest.clone(),
            clock: self.clock,
            w0: self.w0,
            w_prev: self.w_prev,
            cut: self.cut,
            coef: self.coef.clone(),
            plan: self.plan,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.n = source.n;
        self.kernel.clone_from(&source.kernel);
        self.modes.clone_from(&source.modes);
        self.prev.clone_from(&source.prev);
        self.newest.clone_from(&source.newest);
        self.clock = source.clock;
        self.w0 = source.w0;
        self.w_prev = source.w_prev;
        self.cut = source.cut;
        self.plan = source.plan;
        // Scratch: contents need not be copied, only room kept.
        let k = source.kernel.len();
        for mine in [
            &mut self.coef.decay,
            &mut self.coef.a,
            &mut self.coef.b,
            &mut self.coef.next,
            &mut self.coef.alpha,
        ] {
            mine.resize(k, 0.0);
        }
    }
}

impl SumOfExponentials {
    #[cfg(test)]
    fn active_modes(&self, g: f64) -> usize {
        active_modes(&self.kernel, self.cut, g)
    }

    /// Where component `d` of mode `l` of particle `p` lives in `modes`.
    fn mode_index(&self, p: usize, l: usize, d: usize) -> usize {
        let k = self.kernel.len();
        (p / LANES) * k * 3 * LANES + (l * 3 + d) * LANES + p % LANES
    }

    /// Numbers of one block of the mode store.
    fn block(&self) -> usize {
        self.kernel.len() * 3 * LANES
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
            modes: crate::aligned::AlignedF64::zeros(n.div_ceil(LANES) * k * 3 * LANES),
            prev: vec![Vec3::zeros(); n],
            newest: vec![Vec3::zeros(); n],
            clock: Clock::default(),
            w0: 0.0,
            w_prev: 0.0,
            coef: ModeCoefficients::new(k),
            plan: Plan::default(),
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

    /// Weights of the current and previous velocity over the step about to be taken.
    fn set_weights(&mut self) {
        let Some(g) = self.clock.step_gap() else {
            self.w0 = 0.0;
            self.w_prev = 0.0;
            return;
        };
        let c = (g / std::f64::consts::PI).sqrt();
        self.w0 = 4.0 / 3.0 * c;
        self.w_prev = 2.0 / 3.0 * c;
    }

    /// Begins a step's pass: readies its weights and plans the fold of what the last accepted
    /// step recorded. The caller then fills `H_n` of every particle exactly once through the
    /// returned pass (in ranges that start on a block of `LANES`) and calls [`Self::end`].
    pub(crate) fn begin(&mut self) -> SoePass<'_> {
        self.set_weights();
        self.plan = plan(&self.kernel, self.cut, &self.clock, &mut self.coef);
        let block = self.block();
        let (c, v) = Coefficients::of(&self.coef, self.plan, self.w_prev, &self.prev, &self.newest);
        SoePass {
            c,
            w0: self.w0,
            n: self.n,
            block,
            prev: &self.prev,
            v,
            modes: parallel::Disjoint::new(&mut self.modes),
        }
    }

    /// Ends the pass begun by `Self::begin`, which covered every particle: the recorded
    /// sample is now folded in.
    pub(crate) fn end(&mut self) {
        if let Some(h) = self.plan.fold.take() {
            std::mem::swap(&mut self.prev, &mut self.newest);
            self.clock = Clock {
                first: !self.clock.has_prev,
                has_prev: true,
                gap: h,
                recorded: None,
            };
        }
    }

    /// Records the velocities `v` (one per particle) of the accepted step of size `h`, for the
    /// next pass to fold, by swapping buffers: `v` receives spare room of the same length.
    pub(crate) fn record(&mut self, v: &mut Vec<Vec3>, h: f64) {
        self.flush();
        debug_assert_eq!(v.len(), self.n);
        std::mem::swap(&mut self.newest, v);
        self.clock.recorded = Some(h);
    }

    /// True when a recorded sample waits to be folded by the next step's pass.
    pub(crate) fn has_pending_fold(&self) -> bool {
        self.clock.recorded.is_some()
    }

    /// Particles.
    pub(crate) fn particle_count(&self) -> usize {
        self.n
    }

    /// Folds a recorded sample now, as the next step's pass would (the same bits).
    pub(crate) fn fold_pending(&mut self) {
        self.flush();
    }

    /// Checks a state read from a snapshot: every number finite, step sizes positive.
    pub(crate) fn check_state(&self) -> Result<(), crate::Error> {
        let k = self.kernel.len();
        for p in 0..self.n {
            for l in 0..k {
                for d in 0..3 {
                    let v = self.modes[self.mode_index(p, l, d)];
                    if !v.is_finite() {
                        return Err(crate::Error::invalid(format!(
                            "snapshot: SOE history mode {l} of particle {p} is not finite ({v})"
                        )));
                    }
                }
            }
        }
        for (what, vs) in [("previous", &self.prev), ("recorded", &self.newest)] {
            if let Some(p) = vs.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
                return Err(crate::Error::invalid(format!(
                    "snapshot: SOE history {what} velocity of particle {p} is not finite"
                )));
            }
        }
        let c = &self.clock;
        if c.has_prev && (c.gap.is_nan() || c.gap <= 0.0) {
            return Err(crate::Error::invalid(format!(
                "snapshot: SOE history step size {} is not > 0",
                c.gap
            )));
        }
        if let Some(h) = c.recorded {
            if h.is_nan() || h <= 0.0 {
                return Err(crate::Error::invalid(format!(
                    "snapshot: SOE recorded step size {h} is not > 0"
                )));
            }
        }
        Ok(())
    }

    /// Folds a recorded sample now (as a step's pass would).
    fn flush(&mut self) {
        if self.clock.recorded.is_none() {
            return;
        }
        let n = self.n;
        {
            let pass = self.begin();
            parallel::for_chunks(parallel::worth_it(n), n, parallel::CHUNK, |first, len| {
                // Whole blocks per tile, so every tile but a chunk's last starts on a block.
                let mut out = [Vec3::zeros(); 16 * LANES];
                for t in (first..first + len).step_by(out.len()) {
                    let m = (first + len - t).min(out.len());
                    // SAFETY: each task covers its own chunk, tile by tile; chunks and tiles
                    // start on a block.
                    unsafe { pass.past_range(t, &mut out[..m]) };
                }
            });
        }
        self.end();
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
        w.vec3s(&self.newest);
        let c = &self.clock;
        w.u8(u8::from(c.has_prev) | u8::from(c.first) << 1 | u8::from(c.recorded.is_some()) << 2);
        w.f64(c.gap);
        w.f64(c.recorded.unwrap_or(0.0));
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
        r.vec3s_into(Some(self.n), &mut self.newest)?;
        let flags = r.u8()?;
        if flags > 7 {
            return Err(crate::Error::invalid(format!(
                "SOE history flags {flags} are not valid"
            )));
        }
        let gap = r.f64()?;
        let recorded = r.f64()?;
        let step_ok = |h: f64| h.is_finite() && h >= 0.0;
        if !(step_ok(gap) && step_ok(recorded)) {
            return Err(crate::Error::invalid("SOE history step sizes are not valid"));
        }
        self.clock = Clock {
            has_prev: flags & 1 != 0,
            first: flags & 2 != 0,
            gap,
            recorded: (flags & 4 != 0).then_some(recorded),
        };
        self.plan = Plan::default();
        Ok(())
    }
}

/// One step's pass over the SOE history, begun by [`SumOfExponentials::begin`].
pub(crate) struct SoePass<'a> {
    c: Coefficients<'a>,
    w0: f64,
    n: usize,
    block: usize,
    prev: &'a [Vec3],
    /// The newest sample: the recorded one when folding, else the newest folded one.
    v: &'a [Vec3],
    modes: parallel::Disjoint<'a, f64>,
}

impl SoePass<'_> {
    /// Weight w0 of the current velocity over this step.
    pub(crate) fn current_weight(&self) -> f64 {
        self.w0
    }

    /// Folds the recorded sample into the modes of particles `first .. first + out.len()` (when
    /// there is one) and writes their `H_n` into `out`.
    ///
    /// # Safety
    /// Ranges passed by calls that overlap in time must not share a block of `LANES`
    /// particles: `first` must be a multiple of `LANES`, and the range must end on one or at
    /// the last particle. Each particle must be covered exactly once per pass (a fold is not
    /// idempotent). Panics when the range is not aligned so.
    pub(crate) unsafe fn past_range(&self, first: usize, out: &mut [Vec3]) {
        let end = first + out.len();
        assert!(
            first % LANES == 0 && (end % LANES == 0 || end == self.n) && end <= self.n,
            "SOE pass range {first}..{end} is not aligned to blocks"
        );
        let blocks = first / LANES..end.div_ceil(LANES);
        // SAFETY: the blocks of this range belong to no other live range (the contract above).
        let modes = unsafe {
            self.modes
                .range(blocks.start * self.block..blocks.end * self.block)
        };
        pass_blocks_widest(&self.c, &self.prev[first..end], &self.v[first..end], modes, out);
    }
}

impl HalfDerivative for SumOfExponentials {
    fn prepare(&mut self) {
        self.set_weights();
    }

    fn current_weight(&self) -> f64 {
        self.w0
    }

    fn past_range(&self, first: usize, out: &mut [Vec3]) {
        // Read only: a recorded sample is folded into copies of the modes. Not on a step's
        // path (which uses `begin`), so it may allocate.
        let mut coef = ModeCoefficients::new(self.kernel.len());
        let p = plan(&self.kernel, self.cut, &self.clock, &mut coef);
        let (c, v) = Coefficients::of(&coef, p, self.w_prev, &self.prev, &self.newest);
        let end = first + out.len();
        let block = self.block();
        let mut modes = vec![0.0; block];
        let mut sums = [Vec3::zeros(); LANES];
        for b in first / LANES..end.div_ceil(LANES) {
            let (p0, p1) = (b * LANES, ((b + 1) * LANES).min(self.n));
            modes.copy_from_slice(&self.modes[b * block..(b + 1) * block]);
            pass_blocks(
                &c,
                &self.prev[p0..p1],
                &v[p0..p1],
                &mut modes,
                &mut sums[..p1 - p0],
            );
            // The part of the block inside the range.
            let (a, z) = (p0.max(first), p1.min(end));
            out[a - first..z - first].copy_from_slice(&sums[a - p0..z - p0]);
        }
    }

    /// Records `v` and folds it in at once.
    fn push(&mut self, v: &[Vec3], h: f64) {
        self.flush();
        self.newest.copy_from_slice(&v[..self.n]);
        self.clock.recorded = Some(h);
        self.flush();
    }

    fn bytes_per_particle(&self) -> usize {
        (self.kernel.len() + 2) * std::mem::size_of::<Vec3>()
    }

    fn reset(&mut self) {
        self.modes.fill(0.0);
        self.prev.fill(Vec3::zeros());
        self.newest.fill(Vec3::zeros());
        self.clock = Clock::default();
        self.plan = Plan::default();
    }
}

/// Coefficients of one pass: per mode `M <- decay M + a v_{n-1} + b v_n` (when folding), then
/// per particle `H = w_prev v_n + (sum_l next_l M_l - shift v_n)`.
struct Coefficients<'a> {
    decay: &'a [f64],
    a: &'a [f64],
    b: &'a [f64],
    next: &'a [f64],
    shift: f64,
    /// Whether some `a` is not zero (a mode restarts); else the `v_{n-1}` term is skipped.
    restart: bool,
    /// Whether the modes are folded (else only summed).
    fold: bool,
    /// Whether the sum is taken as zero (the first sample).
    zero: bool,
    w_prev: f64,
}

impl<'a> Coefficients<'a> {
    /// The coefficients of plan `p` (filled into `coef` by [`plan`]), and the newest sample the
    /// pass works from: the recorded one `newest` when it folds, else the folded `prev`.
    fn of(
        coef: &'a ModeCoefficients,
        p: Plan,
        w_prev: f64,
        prev: &'a [Vec3],
        newest: &'a [Vec3],
    ) -> (Self, &'a [Vec3]) {
        let k = p.k;
        let c = Coefficients {
            decay: &coef.decay[..k],
            a: &coef.a[..k],
            b: &coef.b[..k],
            next: &coef.next[..k],
            shift: p.shift,
            restart: p.restart,
            fold: p.fold.is_some(),
            zero: p.zero,
            w_prev,
        };
        (c, if p.fold.is_some() { newest } else { prev })
    }
}

crate::simd_dispatch! { fn pass_blocks_widest(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3]) => pass_blocks }

/// [`pass_block`] for consecutive blocks: `prev` and `v` hold their particles (the last block
/// may be partial), `modes` and `out` their modes and sums.
#[inline(always)]
fn pass_blocks(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3]) {
    // A block holds every mode of the kernel; `c` may cover only the first few (the rest are
    // negligible over this step and are left alone).
    let block = modes.len() / out.len().div_ceil(LANES);
    debug_assert!(block >= c.next.len() * 3 * LANES);
    for (b, (m, o)) in modes
        .chunks_exact_mut(block)
        .zip(out.chunks_mut(LANES))
        .enumerate()
    {
        let p0 = b * LANES;
        let p1 = (p0 + LANES).min(v.len());
        let (prev, v) = (&prev[p0..p1], &v[p0..p1]);
        match (c.fold, c.restart) {
            (true, true) => pass_block::<true, true>(c, prev, v, m, o),
            (true, false) => pass_block::<true, false>(c, prev, v, m, o),
            (false, _) => pass_block::<false, false>(c, prev, v, m, o),
        }
    }
}

/// One block of up to `LANES` particles: folds the panel (`prev`, `v`) into its modes when
/// `FOLD`, and writes each particle's `H` into `out`. Same arithmetic, in the same order, for
/// every particle as a scalar loop over its modes; laid out so it vectorises across lanes.
/// `WITH_PREV`: whether the `a v_{n-1}` term is added (some `a` is not zero).
#[inline(always)]
fn pass_block<const FOLD: bool, const WITH_PREV: bool>(
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
    for q in 0..v.len() {
        for d in 0..3 {
            if WITH_PREV {
                pv[d * LANES + q] = prev[q][d];
            }
            vn[d * LANES + q] = v[q][d];
        }
    }
    let mut acc = [0.0; W];
    for (l, mode) in modes.chunks_exact_mut(W).take(c.next.len()).enumerate() {
        let next = c.next[l];
        if FOLD {
            let (decay, a, b) = (c.decay[l], c.a[l], c.b[l]);
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
        } else {
            for k in 0..W {
                acc[k] = next.mul_add(mode[k], acc[k]);
            }
        }
    }
    for (q, o) in out.iter_mut().enumerate().take(v.len()) {
        let pending = if c.zero {
            Vec3::zeros()
        } else {
            let sum = Vec3::new(acc[q], acc[LANES + q], acc[2 * LANES + q]);
            (-c.shift).mul_add_vec(v[q], sum)
        };
        *o = c.w_prev * v[q] + pending;
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
        let mut w = crate::bytes::ByteWriter::default();
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
    fn the_pass_the_read_only_past_and_a_retry_give_the_same_bits() {
        let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
        let mut h = SumOfExponentials::new(kernel, N);
        let v = |k: usize| -> Vec<Vec3> {
            (0..N)
                .map(|p| Vec3::new((0.3 * k as f64 + p as f64).sin(), 0.1 * p as f64, -0.2))
                .collect()
        };
        let pass = |h: &mut SumOfExponentials| {
            let mut out = vec![Vec3::zeros(); N];
            let p = h.begin();
            // Tiles of one block, last one partial: as a step's pass hands them out.
            for (b, o) in out.chunks_mut(LANES).enumerate() {
                // SAFETY: disjoint blocks, each once.
                unsafe { p.past_range(b * LANES, o) };
            }
            h.end();
            out
        };
        // Steps of two sizes, so that modes are left out and restart.
        let step = |k: usize| if k % 7 < 3 { 1.0 / 24.0 } else { 1e-3 };
        // Nothing recorded yet: no past at all.
        assert!(pass(&mut h).iter().all(|p| *p == Vec3::zeros()));
        for k in 0..20 {
            let mut rec = v(k);
            h.record(&mut rec, step(k));
            // Before the fold: the read-only past folds copies, over any range.
            h.prepare();
            let mut before = vec![Vec3::zeros(); N];
            h.past(&mut before);
            let mut part = vec![Vec3::zeros(); 7];
            h.past_range(LANES + 5, &mut part);
            assert_eq!(part[..], before[LANES + 5..LANES + 12], "step {k}");
            // The pass folds in place and gives the same bits.
            let folded = pass(&mut h);
            assert_eq!(folded, before, "step {k}");
            // A second pass without a new record (a retry after a failed step) sums the
            // folded modes: the same bits again, and the read-only past agrees.
            assert_eq!(pass(&mut h), folded, "step {k}");
            let mut after = vec![Vec3::zeros(); N];
            h.past(&mut after);
            assert_eq!(after, folded, "step {k}");
            if k == 0 {
                // The first sample alone: only its panel's weight, no sum over the modes.
                let expected: Vec<Vec3> = v(0).iter().map(|x| h.w_prev * x + Vec3::zeros()).collect();
                assert_eq!(folded, expected);
            } else {
                assert!(folded.iter().all(|p| p.norm() > 1e-6), "step {k}");
            }
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
