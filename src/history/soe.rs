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

mod kernels;
mod plan;
#[cfg(test)]
mod tests;

use kernels::{light_sums_widest, pass_blocks, pass_blocks_widest, Coefficients};
#[cfg(test)]
use plan::active_modes;
use plan::{ahead_coefficients, plan, Clock, ModeCoefficients, Plan};

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

/// Bytes of modes from which a cloth's SOE history defers every other fold
/// ([`SumOfExponentials::with_deferred_fold`]): where the modes no longer fit the caches and
/// the step streams them from memory. Measured with `step_cycles fractional` (docs/benchmarks.md).
pub const DEFER_FROM_BYTES: usize = 16 << 20;

/// Environment variable that turns the deferred fold on (`1`) or off (`0`) at every size (read
/// once), for measurement; the choice by size ([`DEFER_FROM_BYTES`]) when unset or not 0/1.
pub const DEFER_VARIABLE: &str = "FRACCLOTH_SOE_DEFER";

/// Whether a cloth's SOE history of `n` particles and `modes` modes defers every other fold.
pub fn defers_folds(n: usize, modes: usize) -> bool {
    static SET: std::sync::OnceLock<Option<bool>> = std::sync::OnceLock::new();
    let set = *SET.get_or_init(|| match std::env::var(DEFER_VARIABLE).ok()?.trim() {
        "1" => Some(true),
        "0" => Some(false),
        _ => None,
    });
    set.unwrap_or(
        n.saturating_mul(modes)
            .saturating_mul(std::mem::size_of::<Vec3>())
            >= DEFER_FROM_BYTES,
    )
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
    /// Whether folds are deferred every other step ([`Self::with_deferred_fold`]).
    defer: bool,
    /// Deferring: the sample of a step whose fold waits for the next pass that folds (with
    /// the newest one after it); spare room otherwise. Empty when not deferring.
    pending_v: Vec<Vec3>,
    /// Deferring: per particle, `sum_l w_l e^{-2 s_l g} M_l` over the stored modes and the
    /// gap `g = clock.gap`, the part of the next step's sum that needs the modes when that
    /// step is of the same size (see [`Self::with_deferred_fold`]). Empty when not deferring.
    ahead: Vec<Vec3>,
    /// The first panel's coefficients of a pass that folds two.
    coef_first: ModeCoefficients,
    /// `w_l e^{-2 s_l g}` of the pass that fills `ahead`.
    ahead_coef: Vec<f64>,
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
            defer: self.defer,
            pending_v: self.pending_v.clone(),
            ahead: self.ahead.clone(),
            coef_first: self.coef_first.clone(),
            ahead_coef: self.ahead_coef.clone(),
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
        self.defer = source.defer;
        self.pending_v.clone_from(&source.pending_v);
        self.ahead.clone_from(&source.ahead);
        // Scratch: contents need not be copied, only room kept.
        let k = source.kernel.len();
        for mine in [
            &mut self.coef.decay,
            &mut self.coef.a,
            &mut self.coef.b,
            &mut self.coef.next,
            &mut self.coef.alpha,
            &mut self.coef_first.decay,
            &mut self.coef_first.a,
            &mut self.coef_first.b,
            &mut self.coef_first.next,
            &mut self.coef_first.alpha,
            &mut self.ahead_coef,
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
            defer: false,
            pending_v: Vec::new(),
            ahead: Vec::new(),
            coef_first: ModeCoefficients::new(k),
            ahead_coef: vec![0.0; k],
        }
    }

    /// Defers every other fold (`on`), or folds every step (the default).
    ///
    /// A step's pass reads and writes every mode (`16 x 3` numbers a particle with the default
    /// kernel): past the caches that is most of the bytes a fractional step streams. Deferring,
    /// a pass that folds also sums, for each particle, `S = sum_l w_l e^{-2 s_l h} M_l` (`h`
    /// the step just folded), the part of the next step's sum that needs the modes when that
    /// step is of the same size `h`; the next pass then takes the sum as
    /// `S + (sum_l next_l b_l) v_n` without reading the modes, and leaves `v_n` pending; the
    /// pass after folds both samples, one after the other, with the same fused multiply-adds
    /// as two passes would. So the modes are read and written every other step, and hold the
    /// same bits as without deferring; the sums of the steps that do not read the modes differ
    /// from the direct sum by rounding (the same terms, grouped otherwise). Steps of another
    /// size, a refused step's retry, or a mode that restarts take a full pass.
    pub fn with_deferred_fold(mut self, on: bool) -> Self {
        self.defer = on;
        let n = if on { self.n } else { 0 };
        self.pending_v = vec![Vec3::zeros(); n];
        self.ahead = vec![Vec3::zeros(); n];
        self.clock.pending = None;
        // A history that already holds samples gets its `ahead` now.
        self.recompute_ahead();
        self
    }

    /// Whether folds are deferred every other step.
    pub fn defers_folds(&self) -> bool {
        self.defer
    }

    /// Whether the next pass may take its sum from `ahead`: deferring, nothing pending, and a
    /// recorded sample after a step of the size the last fold's `ahead` was summed for. While
    /// deferring, `ahead` always holds the sum for the stored modes once they hold a sample:
    /// every pass that folds fills it, and so do reading a state and turning deferring on.
    fn light_eligible(&self) -> bool {
        self.defer
            && self.clock.has_prev
            && self.clock.pending.is_none()
            && self.clock.recorded == Some(self.clock.gap)
    }

    /// Whether a snapshot folds the recorded sample into its copy of the state (the bytes are
    /// then those a refused step's pass would have left); not when the next pass would take
    /// its sum from `ahead`, which the loaded state sums again from the same modes.
    pub(crate) fn snapshot_folds(&self) -> bool {
        self.clock.recorded.is_some() && !self.light_eligible()
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
        self.begin_pass(true)
    }

    /// [`Self::begin`]; `allow_light`: whether the pass may leave the recorded sample
    /// pending (else it folds whatever waits).
    fn begin_pass(&mut self, allow_light: bool) -> SoePass<'_> {
        self.set_weights();
        let light = allow_light && self.light_eligible();
        let (kernel, cut) = (&self.kernel, self.cut);
        let mut first = None;
        if let Some(hp) = self.clock.pending {
            // Two panels: the pending sample's (its plan is the one the pass that left it
            // pending had), then the newest's, from the clock the first leaves.
            let one = Clock {
                recorded: Some(hp),
                pending: None,
                ..self.clock
            };
            let p1 = plan(kernel, cut, &one, &mut self.coef_first);
            // Left pending only when its modes were those kept (`light_eligible`).
            debug_assert!(!p1.restart && !p1.zero && p1.fold == Some(hp));
            first = Some(p1.k);
            let two = Clock {
                has_prev: true,
                first: false,
                gap: hp,
                recorded: self.clock.recorded,
                pending: None,
            };
            self.plan = plan(kernel, cut, &two, &mut self.coef);
        } else {
            self.plan = plan(kernel, cut, &self.clock, &mut self.coef);
        }
        self.plan.light = None;
        let mut fills_ahead = false;
        if light {
            // `S + (sum_l next_l b_l) v_n`: the fold's sum without its modes.
            let c = &self.coef;
            let k = self.plan.k;
            self.plan.light = Some((0..k).fold(0.0, |s, l| c.next[l].mul_add(c.b[l], s)));
        } else if let (true, Some(h)) = (self.defer, self.plan.fold) {
            fills_ahead = true;
            let k = ahead_coefficients(&self.kernel, self.cut, h, &mut self.ahead_coef);
            debug_assert_eq!(k, self.plan.k);
        }
        let block = self.block();
        let (mut c, v) = Coefficients::of(&self.coef, self.plan, self.w_prev, &self.prev, &self.newest);
        c.first = first.map(|k| (&self.coef_first.decay[..k], &self.coef_first.b[..k]));
        if fills_ahead {
            c.ahead = &self.ahead_coef[..self.plan.k];
        }
        c.light = self.plan.light;
        SoePass {
            c,
            w0: self.w0,
            n: self.n,
            block,
            // The panel before the newest: the pending one when two are folded.
            prev: if first.is_some() {
                &self.pending_v
            } else {
                &self.prev
            },
            v,
            modes: parallel::Disjoint::new(&mut self.modes),
            ahead: parallel::Disjoint::new(&mut self.ahead),
        }
    }

    /// Ends the pass begun by `Self::begin`, which covered every particle: the recorded
    /// sample (and a pending one) is now folded in, unless the pass left it pending.
    pub(crate) fn end(&mut self) {
        if self.plan.light.take().is_some() {
            // Nothing moved: `record` leaves the sample pending when the step is accepted.
            return;
        }
        if let Some(h) = self.plan.fold.take() {
            std::mem::swap(&mut self.prev, &mut self.newest);
            self.clock = Clock {
                first: !self.clock.has_prev,
                has_prev: true,
                gap: h,
                recorded: None,
                pending: None,
            };
        }
    }

    /// Records the velocities `v` (one per particle) of the accepted step of size `h`, for the
    /// next pass to fold, by swapping buffers: `v` receives spare room of the same length.
    pub(crate) fn record(&mut self, v: &mut Vec<Vec3>, h: f64) {
        if self.light_eligible() {
            // The sample the step's pass left for later waits for the next pass that folds.
            std::mem::swap(&mut self.pending_v, &mut self.newest);
            self.clock.pending = self.clock.recorded;
        } else {
            self.flush();
        }
        debug_assert_eq!(v.len(), self.n);
        std::mem::swap(&mut self.newest, v);
        self.clock.recorded = Some(h);
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
            let pass = self.begin_pass(false);
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
        // A pending sample is folded into the copy written (`History::write_state`); only
        // the count of bytes may be taken from a state that holds one (the same count).
        debug_assert!(self.clock.pending.is_none() || w.is_counting());
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
            pending: None,
        };
        self.plan = Plan::default();
        self.recompute_ahead();
        Ok(())
    }

    /// Sums `ahead` again from the stored modes (deferring, after a state is read or deferring
    /// is turned on; nothing before the first sample): the same fused multiply-adds in the
    /// same order as the pass that filled it, so the same bits (at the CPU's widest vectors,
    /// as the pass), on the pool for a large cloth.
    fn recompute_ahead(&mut self) {
        if !(self.defer && self.clock.has_prev) {
            return;
        }
        let k = ahead_coefficients(&self.kernel, self.cut, self.clock.gap, &mut self.ahead_coef);
        let coef = &self.ahead_coef[..k];
        // A summing pass: `next` is not used but must cover the same modes.
        let c = Coefficients {
            decay: coef,
            a: coef,
            b: coef,
            next: coef,
            shift: 0.0,
            restart: false,
            fold: false,
            zero: false,
            w_prev: 0.0,
            first: None,
            ahead: coef,
            light: None,
        };
        let (block, n, prev) = (self.block(), self.n, &self.prev[..]);
        // Block by block (each on its own: the same bits on any thread), a chunk of blocks a
        // task: a million particles' modes are 384 MB.
        let per = parallel::CHUNK / LANES;
        let run = |(k, (modes, ahead)): (usize, (&mut [f64], &mut [Vec3]))| {
            let mut sums = [Vec3::zeros(); LANES];
            for (j, (m, a)) in modes.chunks_mut(block).zip(ahead.chunks_mut(LANES)).enumerate() {
                let p0 = (k * per + j) * LANES;
                let p = p0..p0 + a.len();
                pass_blocks_widest(&c, &prev[p.clone()], &prev[p], m, &mut sums[..a.len()], a);
            }
        };
        let (modes, ahead) = (&mut self.modes[..], &mut self.ahead[..n]);
        if parallel::worth_it(n) {
            use rayon::prelude::*;
            let modes = modes.par_chunks_mut(per * block);
            modes
                .zip(ahead.par_chunks_mut(per * LANES))
                .enumerate()
                .for_each(run);
        } else {
            modes
                .chunks_mut(per * block)
                .zip(ahead.chunks_mut(per * LANES))
                .enumerate()
                .for_each(run);
        }
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
    /// Deferring: `S` per particle, read by a pass that leaves its fold for later, written by
    /// one that fills it; empty otherwise.
    ahead: parallel::Disjoint<'a, Vec3>,
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
        if let Some(light) = self.c.light {
            // SAFETY: this range's particles belong to no other live range (as above).
            let ahead = unsafe { self.ahead.range(first..end) };
            light_sums_widest(&self.c, light, &self.v[first..end], ahead, out);
            return;
        }
        let blocks = first / LANES..end.div_ceil(LANES);
        // SAFETY: the blocks of this range belong to no other live range (the contract above).
        let modes = unsafe {
            self.modes
                .range(blocks.start * self.block..blocks.end * self.block)
        };
        let ahead: &mut [Vec3] = if self.c.ahead.is_empty() {
            &mut []
        } else {
            // SAFETY: as the modes.
            unsafe { self.ahead.range(first..end) }
        };
        pass_blocks_widest(
            &self.c,
            &self.prev[first..end],
            &self.v[first..end],
            modes,
            out,
            ahead,
        );
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
        // path (which uses `begin`), so it may allocate. Deferring, this is the direct sum,
        // which a pass that takes it from `ahead` gives within rounding.
        if self.clock.pending.is_some() {
            // Two samples wait: fold both in a copy of the whole history.
            let mut copy = self.clone();
            copy.flush();
            return copy.past_range(first, out);
        }
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
                &mut [],
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
        // Deferring keeps two more samples a particle: the pending one and `ahead`.
        (self.kernel.len() + 2 + 2 * usize::from(self.defer)) * std::mem::size_of::<Vec3>()
    }

    fn reset(&mut self) {
        self.modes.fill(0.0);
        self.prev.fill(Vec3::zeros());
        self.newest.fill(Vec3::zeros());
        self.pending_v.fill(Vec3::zeros());
        self.ahead.fill(Vec3::zeros());
        self.clock = Clock::default();
        self.plan = Plan::default();
    }
}
