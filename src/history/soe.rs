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
    /// Deferring: the size of the step that followed `pending_v`, which waits to be folded
    /// before `newest` (set only while `recorded` is).
    pending: Option<f64>,
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
    /// Deferring: the sum is `ahead + light v_n` (the modes are not read), `light` being
    /// `sum_l next_l b_l` of the fold this pass leaves for later.
    light: Option<f64>,
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

/// Fills `out` with `S`'s coefficients `w_l e^{-2 s_l g}` for the modes that matter over a
/// gap `g` (deferring; [`SumOfExponentials::with_deferred_fold`]) and returns their count.
fn ahead_coefficients(kernel: &SoeKernel, cut: f64, g: f64, out: &mut [f64]) -> usize {
    let k = active_modes(kernel, cut, g);
    for l in 0..k {
        let e = (-kernel.rates[l] * g).exp();
        out[l] = kernel.weights[l] * e * e;
    }
    k
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
            ..Plan::default()
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
        ..Plan::default()
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
    /// A first panel folded before the newest (deferring): its `decay` and `b` per mode; its
    /// sample is `prev` (no mode restarts in it).
    first: Option<(&'a [f64], &'a [f64])>,
    /// Deferring: the coefficients of `ahead` (empty when the pass does not fill it).
    ahead: &'a [f64],
    /// Deferring: the sum is `ahead + light v_n`, the modes not read.
    light: Option<f64>,
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
            first: None,
            ahead: &[],
            light: None,
        };
        (c, if p.fold.is_some() { newest } else { prev })
    }
}

crate::simd_dispatch! { fn pass_blocks_widest(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3], ahead: &mut [Vec3]) => pass_blocks }

/// [`pass_block`] for consecutive blocks: `prev` and `v` hold their particles (the last block
/// may be partial), `modes` and `out` their modes and sums, `ahead` their `S` when the pass
/// fills it (else it is empty).
#[inline(always)]
fn pass_blocks(
    c: &Coefficients<'_>,
    prev: &[Vec3],
    v: &[Vec3],
    modes: &mut [f64],
    out: &mut [Vec3],
    ahead: &mut [Vec3],
) {
    let with_ahead = !c.ahead.is_empty();
    // A pass that folds two panels always fills `ahead` (`SumOfExponentials::begin_pass`).
    debug_assert!(c.first.is_none() || (with_ahead && c.fold));
    // Chosen once for all the blocks, so that each block's loop has no branch on them.
    let s = (prev, v, modes, out, ahead);
    match (c.fold, c.restart, with_ahead, c.first.is_some()) {
        (true, true, false, _) => blocks::<true, true, false, false>(c, s),
        (true, false, false, _) => blocks::<true, false, false, false>(c, s),
        (true, true, true, false) => blocks::<true, true, true, false>(c, s),
        (true, false, true, false) => blocks::<true, false, true, false>(c, s),
        (true, true, true, true) => blocks::<true, true, true, true>(c, s),
        (true, false, true, true) => blocks::<true, false, true, true>(c, s),
        (false, _, false, _) => blocks::<false, false, false, false>(c, s),
        (false, _, true, _) => blocks::<false, false, true, false>(c, s),
    }
}

/// The slices of [`pass_blocks`]: `prev`, `v`, `modes`, `out`, `ahead`.
type BlockSlices<'a> = (
    &'a [Vec3],
    &'a [Vec3],
    &'a mut [f64],
    &'a mut [Vec3],
    &'a mut [Vec3],
);

/// [`pass_blocks`] for one choice of what the pass does: `FIRST`, fold a pending panel first
/// (deferring; only with `AHEAD`, as every pass that folds two fills `ahead`).
#[inline(always)]
fn blocks<const FOLD: bool, const WITH_PREV: bool, const AHEAD: bool, const FIRST: bool>(
    c: &Coefficients<'_>,
    (prev, v, modes, out, ahead): BlockSlices<'_>,
) {
    // A block holds every mode of the kernel; `c` may cover only the first few (the rest are
    // negligible over this step and are left alone).
    let block = modes.len() / out.len().div_ceil(LANES);
    debug_assert!(block >= c.next.len() * 3 * LANES);
    debug_assert!(!FIRST || AHEAD);
    for (b, (m, o)) in modes
        .chunks_exact_mut(block)
        .zip(out.chunks_mut(LANES))
        .enumerate()
    {
        let p0 = b * LANES;
        let p1 = (p0 + LANES).min(v.len());
        let (prev, v) = (&prev[p0..p1], &v[p0..p1]);
        if FIRST {
            if let Some((decay, b)) = c.first {
                fold_first(decay, b, prev, m);
            }
        }
        let s: &mut [Vec3] = if AHEAD { &mut ahead[p0..p1] } else { &mut [] };
        pass_block::<FOLD, WITH_PREV, AHEAD>(c, (prev, v, m, o, s));
    }
}

/// Folds the first of two panels (deferring) into one block's modes: `M <- decay M + b v`,
/// the fused multiply-add of [`pass_block`]'s fold without a restarting mode, so the modes
/// get the bits two passes would give them.
#[inline(always)]
fn fold_first(decay: &[f64], b: &[f64], v: &[Vec3], modes: &mut [f64]) {
    const W: usize = 3 * LANES;
    let mut vn = [0.0; W];
    for (q, x) in v.iter().enumerate() {
        for d in 0..3 {
            vn[d * LANES + q] = x[d];
        }
    }
    for ((mode, &decay), &b) in modes.chunks_exact_mut(W).zip(decay).zip(b) {
        for k in 0..W {
            mode[k] = decay.mul_add(mode[k], b * vn[k]);
        }
    }
}

/// One block of up to `LANES` particles: folds the panel (`prev`, `v`) into its modes when
/// `FOLD`, and writes each particle's `H` into `out`. Same arithmetic, in the same order, for
/// every particle as a scalar loop over its modes; laid out so it vectorises across lanes.
/// `WITH_PREV`: whether the `a v_{n-1}` term is added (some `a` is not zero).
/// `AHEAD`: whether the block's `S` is summed into `ahead` (deferring).
#[inline(always)]
fn pass_block<const FOLD: bool, const WITH_PREV: bool, const AHEAD: bool>(
    c: &Coefficients<'_>,
    (prev, v, modes, out, ahead): BlockSlices<'_>,
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
    let mut acc_ahead = [0.0; W];
    for (l, mode) in modes.chunks_exact_mut(W).take(c.next.len()).enumerate() {
        let next = c.next[l];
        let ahead_l = if AHEAD { c.ahead[l] } else { 0.0 };
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
                if AHEAD {
                    acc_ahead[k] = ahead_l.mul_add(m, acc_ahead[k]);
                }
            }
        } else {
            for k in 0..W {
                acc[k] = next.mul_add(mode[k], acc[k]);
                if AHEAD {
                    acc_ahead[k] = ahead_l.mul_add(mode[k], acc_ahead[k]);
                }
            }
        }
    }
    if AHEAD {
        for (q, s) in ahead.iter_mut().enumerate() {
            *s = Vec3::new(acc_ahead[q], acc_ahead[LANES + q], acc_ahead[2 * LANES + q]);
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

crate::simd_dispatch! { fn light_sums_widest(c: &Coefficients<'_>, light: f64, v: &[Vec3], ahead: &[Vec3], out: &mut [Vec3]) => light_sums }

/// A pass that leaves its fold for later (deferring): each particle's sum is
/// `S + light v_n` instead of the modes' sum, then as in [`pass_block`].
#[inline(always)]
fn light_sums(c: &Coefficients<'_>, light: f64, v: &[Vec3], ahead: &[Vec3], out: &mut [Vec3]) {
    for ((o, &v), &s) in out.iter_mut().zip(v).zip(ahead) {
        let sum = light.mul_add_vec(v, s);
        *o = c.w_prev * v + (-c.shift).mul_add_vec(v, sum);
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
        let pass = soe_pass;
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

    /// A step's pass over every particle, in tiles of one block (the last one partial) as a
    /// step hands them out.
    fn soe_pass(h: &mut SumOfExponentials) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); N];
        let p = h.begin();
        for (b, o) in out.chunks_mut(LANES).enumerate() {
            // SAFETY: disjoint blocks, each once.
            unsafe { p.past_range(b * LANES, o) };
        }
        h.end();
        out
    }

    /// [`soe_pass`] of a history holding SOE.
    fn step_pass(h: &mut crate::history::History) -> Vec<Vec3> {
        match h {
            crate::history::History::SumOfExponentials(s) => soe_pass(s),
            _ => unreachable!("an SOE history"),
        }
    }

    fn deferred(kernel: &SoeKernel) -> crate::history::History {
        crate::history::History::SumOfExponentials(Box::new(
            SumOfExponentials::new(kernel.clone(), N).with_deferred_fold(true),
        ))
    }

    fn soe(h: &crate::history::History) -> &SumOfExponentials {
        match h {
            crate::history::History::SumOfExponentials(s) => s,
            _ => unreachable!("an SOE history"),
        }
    }

    fn sample(k: usize) -> Vec<Vec3> {
        (0..N)
            .map(|p| {
                Vec3::new(
                    (0.3 * k as f64 + p as f64).sin(),
                    0.1 * p as f64 - 0.5,
                    (0.7 * k as f64).cos(),
                )
            })
            .collect()
    }

    /// Steps of one size with a run of coarser ones (four modes left out, then restarting)
    /// and a change back; step 37 is refused once (its pass runs twice).
    fn deferred_step(k: usize) -> f64 {
        match k {
            20..=22 => 1.0 / 24.0,
            41..=45 => 2e-3,
            _ => 1e-3,
        }
    }

    #[test]
    fn deferring_keeps_the_modes_bits_and_the_sums_within_rounding() {
        let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
        let mut every =
            crate::history::History::SumOfExponentials(Box::new(SumOfExponentials::new(kernel.clone(), N)));
        let mut other = deferred(&kernel);
        assert!(soe(&other).defers_folds() && !soe(&every).defers_folds());
        let (mut light, mut worst, mut scale) = (0, 0.0f64, 0.0f64);
        for k in 0..70 {
            for _ in 0..if k == 37 { 2 } else { 1 } {
                let was_pending = soe(&other).clock.recorded.is_some();
                let folded_before = soe(&other).clock.recorded.is_none();
                let (a, b) = (step_pass(&mut every), step_pass(&mut other));
                let s = soe(&other);
                if was_pending && s.clock.recorded.is_some() {
                    light += 1;
                }
                if s.clock.recorded.is_none() && !folded_before || k == 0 {
                    // The deferred history folded everything that waited: the same modes.
                    let (x, y) = (&soe(&every).modes[..], &s.modes[..]);
                    assert!(
                        x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits()),
                        "step {k}"
                    );
                }
                for (a, b) in a.iter().zip(&b) {
                    worst = worst.max((a - b).amax());
                    scale = scale.max(a.amax());
                }
            }
            every.record(&mut sample(k), deferred_step(k));
            other.record(&mut sample(k), deferred_step(k));
        }
        // Every other step of one size left its fold for later (70 steps, 9 of other sizes
        // or after a change, one retry).
        assert!(light >= 30, "{light} passes left their fold for later");
        assert!(scale > 1e-3);
        assert!(worst <= 1e-13 * scale, "{worst:e} of {scale:e}");
        // After a flush both hold the same modes and give the same sum.
        let (mut a, mut b) = (every.clone(), other.clone());
        if let (
            crate::history::History::SumOfExponentials(a),
            crate::history::History::SumOfExponentials(b),
        ) = (&mut a, &mut b)
        {
            a.flush();
            b.flush();
            assert!(a
                .modes
                .iter()
                .zip(b.modes.iter())
                .all(|(x, y)| x.to_bits() == y.to_bits()));
        }
        assert_eq!(step_pass(&mut a), step_pass(&mut b));
    }

    /// `ahead` summed again from the modes (as after a snapshot is read) on the pool, for a
    /// cloth of several chunks, holds the bits the folding pass left in it.
    #[test]
    fn ahead_summed_again_on_the_pool_has_the_passs_bits() {
        let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
        let n = crate::parallel::min_parallel().max(3 * crate::parallel::CHUNK) + 21;
        let mut h = SumOfExponentials::new(kernel, n).with_deferred_fold(true);
        let v = |k: usize| -> Vec<Vec3> {
            (0..n)
                .map(|p| {
                    Vec3::new(
                        (0.3 * k as f64 + p as f64).sin(),
                        1e-4 * p as f64,
                        (0.7 * k as f64).cos(),
                    )
                })
                .collect()
        };
        let mut checked = 0;
        for k in 0..6 {
            let mut out = vec![Vec3::zeros(); n];
            let p = h.begin();
            for (b, o) in out.chunks_mut(LANES).enumerate() {
                // SAFETY: disjoint blocks, each once.
                unsafe { p.past_range(b * LANES, o) };
            }
            h.end();
            if h.clock.pending.is_none() && h.clock.has_prev && h.clock.recorded.is_none() {
                let want = h.ahead.clone();
                h.ahead.fill(Vec3::zeros());
                h.recompute_ahead();
                let bits = |a: &[Vec3]| {
                    a.iter()
                        .flat_map(|p| p.iter().map(|c| c.to_bits()))
                        .collect::<Vec<_>>()
                };
                assert_eq!(bits(&h.ahead), bits(&want), "after {k} steps");
                assert!(want.iter().any(|s| s.x != 0.0));
                checked += 1;
            }
            h.record(&mut v(k), 1e-3);
        }
        assert!(checked > 0);
    }

    #[test]
    fn a_deferred_state_written_and_read_continues_bitwise_and_its_bytes_are_canonical() {
        let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
        let bytes = |h: &crate::history::History| {
            let mut w = crate::bytes::ByteWriter::default();
            h.write_state(&mut w).unwrap();
            w.buf
        };
        // Saved after every record: nothing pending and the next pass light, a sample
        // pending, a size change, the coarse steps.
        let mut phases = std::collections::BTreeSet::new();
        for save in 1..50 {
            let mut a = deferred(&kernel);
            for k in 0..save {
                step_pass(&mut a);
                a.record(&mut sample(k), deferred_step(k));
            }
            let s = soe(&a);
            phases.insert((s.clock.pending.is_some(), s.light_eligible()));
            let written = bytes(&a);
            // A refused step's pass leaves a state with the same bytes.
            let mut refused = a.clone();
            step_pass(&mut refused);
            assert_eq!(bytes(&refused), written, "saved after {save} steps");
            let mut b = deferred(&kernel);
            b.read_state(&mut crate::bytes::ByteReader::new(&written))
                .unwrap();
            for k in save..save + 25 {
                assert_eq!(
                    step_pass(&mut a),
                    step_pass(&mut b),
                    "saved after {save}, step {k}"
                );
                a.record(&mut sample(k), deferred_step(k));
                b.record(&mut sample(k), deferred_step(k));
            }
        }
        // Every phase was saved: pending, light next, neither.
        assert_eq!(phases.len(), 3, "{phases:?}");
    }
}
