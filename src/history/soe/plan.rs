//! What one SOE pass does, decided from the step sizes alone: the clock of the steps, the
//! modes' coefficients for a step size, and the pass's plan (whether and how it folds, how many
//! modes it keeps).

use super::*;

/// Where the history stands in time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Clock {
    /// Whether a sample has been folded into the modes (`prev` is one).
    pub(super) has_prev: bool,
    /// Whether the modes hold the first sample only, whose past sum is zero.
    pub(super) first: bool,
    /// The step that followed `prev`: the gap from it to the next sample.
    pub(super) gap: f64,
    /// The size of the step that followed `newest`, while it waits to be folded.
    pub(super) recorded: Option<f64>,
    /// Deferring: the size of the step that followed `pending_v`, which waits to be folded
    /// before `newest` (set only while `recorded` is).
    pub(super) pending: Option<f64>,
}

impl Clock {
    /// The gap of the step about to be taken (from the newest sample, folded or not).
    pub(super) fn step_gap(&self) -> Option<f64> {
        self.recorded.or(self.has_prev.then_some(self.gap))
    }
}

/// Per-mode coefficients: `M <- decay M + a v_{n-1} + b v_n` and the sum's `next`.
#[derive(Clone, Debug, Default)]
pub(super) struct ModeCoefficients {
    pub(super) decay: Vec<f64>,
    pub(super) a: Vec<f64>,
    pub(super) b: Vec<f64>,
    pub(super) next: Vec<f64>,
    pub(super) alpha: Vec<f64>,
}

impl ModeCoefficients {
    pub(super) fn new(k: usize) -> Self {
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
pub(super) struct Plan {
    /// Fold the recorded sample (which followed a step of this size) before summing.
    pub(super) fold: Option<f64>,
    /// Deferring: the sum is `ahead + light v_n` (the modes are not read), `light` being
    /// `sum_l next_l b_l` of the fold this pass leaves for later.
    pub(super) light: Option<f64>,
    /// Modes folded and summed: a prefix, the others being negligible over the step.
    pub(super) k: usize,
    /// `sum_l w_l g phi_o(s_l g)`: the shift's share of the sum (module docs).
    pub(super) shift: f64,
    /// Whether a mode restarts from the newest panel (its `a` is not zero).
    pub(super) restart: bool,
    /// Whether the past sum is zero: the modes hold no sample, or only the first.
    pub(super) zero: bool,
}

/// Modes that matter over a gap `g`: those with `s_l g <= cut`, the cut-off being where a
/// mode's factor `e^{-s_l g}` falls below 1/1000 of the sum's own measured error (about 14.1 at
/// the default tolerance). A mode past it adds less than that to D^{1/2}x, so it is neither
/// summed nor folded; at 1/24 s steps that leaves out the four fastest of 16.
pub(super) fn active_modes(kernel: &SoeKernel, cut: f64, g: f64) -> usize {
    kernel.rates.partition_point(|&s| s * g <= cut)
}

/// Fills `out` with `S`'s coefficients `w_l e^{-2 s_l g}` for the modes that matter over a
/// gap `g` (deferring; [`SumOfExponentials::with_deferred_fold`]) and returns their count.
pub(super) fn ahead_coefficients(kernel: &SoeKernel, cut: f64, g: f64, out: &mut [f64]) -> usize {
    let k = active_modes(kernel, cut, g);
    for l in 0..k {
        let e = (-kernel.rates[l] * g).exp();
        out[l] = kernel.weights[l] * e * e;
    }
    k
}

/// Plans the pass of the step about to be taken and fills `c` for its modes.
pub(super) fn plan(kernel: &SoeKernel, cut: f64, clock: &Clock, c: &mut ModeCoefficients) -> Plan {
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
