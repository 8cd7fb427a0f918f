//! What the driver decides for one step ([`StepPlan`]), built once by it (`Cloth::step_substeps`,
//! `split.rs`, `extrapolate.rs`, the snapshot's trial step) and read by the passes, instead of
//! locals and flags on the cloth: the role of Box2D's `b2StepContext` and rapier's
//! `IntegrationParameters`. Every per-call fact a pass needs is here: the step's size, where
//! pins and mesh colliders start and end it, which part of the integrator's step it is, the
//! pins' sampling, what self-collision's step limit does, whether the call is the automatic
//! step's and the substep a split piece belongs to.

use crate::integrate::Integrator;
use crate::math::Vec3;

/// One step, as its passes read it.
#[derive(Clone, Copy, Debug)]
pub(super) struct StepPlan {
    /// Step size, s.
    pub h: f64,
    /// Where pins and mesh colliders are at the start of the step: this fraction of the way
    /// through the call.
    pub from: f64,
    /// Where pins and mesh colliders are at the end of the step: this fraction of the way
    /// through the call, or None for where the host put them.
    pub fraction: Option<f64>,
    /// Which part of the integrator's step this is.
    pub stage: Stage,
    /// Which velocity a hard pin gives the history.
    pub sampling: PinSampling,
    /// What self-collision's step limit does to a vertex that would move too far.
    pub limit: StepLimit,
    /// Whether the call is the automatic step's (its substeps are stable already).
    pub auto: bool,
    /// The substep this step is a piece of and its level of pieces, while `split.rs` takes
    /// it: the step limit's proof is trusted only for a piece stable by itself.
    pub piece: Option<(f64, u32)>,
}

/// What self-collision's step limit (`collisions::SELF_COLLISION_STEP_LIMIT`) does with a
/// step in which a free vertex would move farther than it allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum StepLimit {
    /// Slows the vertex to the limit (the last resort: the step is already as short as the
    /// driver splits it, or nothing can split it).
    Slow,
    /// Refuses the step, nothing committed (`Advanced::TooFar`), so that the driver takes it
    /// in shorter pieces (`Cloth::take_substep`).
    Refuse,
}

/// Which part of an integrator's step a step is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stage {
    /// A whole step (a first-order integrator's, or an extrapolated step's whole run).
    Whole,
    /// The first of an extrapolated step's two half steps: hard pins aim at their mid goals.
    FirstHalf,
    /// The second half step.
    SecondHalf,
}

impl StepPlan {
    /// A step of `integrator` of size `h` from fraction `from` of the call to `fraction`, as
    /// stage `stage`; its limit slows (`limited` sets another), outside the automatic step and
    /// any split.
    pub(super) fn new(
        integrator: Integrator,
        h: f64,
        from: f64,
        fraction: Option<f64>,
        stage: Stage,
    ) -> Self {
        StepPlan {
            h,
            from,
            fraction,
            stage,
            sampling: PinSampling::of(integrator, stage),
            limit: StepLimit::Slow,
            auto: false,
            piece: None,
        }
    }

    /// The same plan, its step limit `limit`.
    pub(super) fn limited(self, limit: StepLimit) -> Self {
        StepPlan { limit, ..self }
    }
}

/// Which velocity a hard pin gives the history (and this step's D^{1/2}), from its stored
/// velocity `v` and its step velocity, the secant to its goal, `v_step`.
///
/// A hard pin's step velocity is its goal's secant, the velocity half a step ahead. The
/// second-order integrators give the history the slope of the pin's path at the start of the
/// (half) step instead: the history keeps every sample, so a first-order error in them would
/// never be extrapolated away. Its stored velocity is read as the last secant, half a step
/// back (what extrapolated symplectic Euler leaves it; extrapolated implicit Euler
/// extrapolates it and measured best so), giving the mean of it and this secant; in the first
/// half step, whose secant reaches only a quarter step ahead, `(S_prev + 2 S_1) / 3`. The
/// first-order integrators keep the secant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PinSampling {
    Secant,
    Central,
    StartSlope,
}

impl PinSampling {
    pub(super) fn of(integrator: Integrator, stage: Stage) -> PinSampling {
        if !integrator.is_extrapolated() {
            PinSampling::Secant
        } else if !integrator.is_implicit() && stage == Stage::FirstHalf {
            PinSampling::StartSlope
        } else {
            PinSampling::Central
        }
    }

    #[inline]
    pub(super) fn rate(self, v: Vec3, v_step: Vec3) -> Vec3 {
        match self {
            PinSampling::Secant => v_step,
            PinSampling::Central => 0.5 * (v + v_step),
            // The slope at the start from the last whole secant (a step back) and this half
            // step's: p'(0) = S_prev / 3 + 2 S_1 / 3 on a parabola.
            PinSampling::StartSlope => (v + 2.0 * v_step) / 3.0,
        }
    }
}
