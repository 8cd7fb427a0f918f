//! [`Integrator`]: which integrator advances the cloth, and what each one is made of.

use super::{explicit_euler_soa, symplectic_euler_soa, StepSoa};

/// Which integrator advances the cloth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Integrator {
    /// The paper's Eq. 7: `x += h v; v += h a`, both from the state at t_n.
    #[default]
    ExplicitEuler,
    /// `v += h a(t_n)`, then `x += h v_{n+1}`.
    SymplecticEuler,
    /// Backward Euler, linearised (Baraff & Witkin), solved by preconditioned CG.
    ImplicitEuler,
    /// Second order, explicit: each step is symplectic Euler over the whole step and over two
    /// half steps, combined as `2 x_half - x_whole` (local Richardson extrapolation, which
    /// cancels the first-order error of every term, the half-derivative's included). Three
    /// force evaluations per step. See [`crate::Cloth::step`] and `docs/accuracy.md`.
    ExtrapolatedSymplectic,
    /// Second order, stable at frame-rate steps: implicit Euler extrapolated in the same way
    /// (its amplification `2/(1 - z/2)^2 - 1/(1 - z)` is below 1 on the whole left half-plane
    /// and tends to 0 for stiff modes). Three linear solves per step.
    ExtrapolatedImplicit,
    /// Symplectic Euler on every force but the stiff in-plane springs, which are compliant
    /// distance constraints (XPBD: Macklin, Mueller & Chentanez 2016; "Small steps in physics
    /// simulation", Macklin et al. 2019): a spring of stiffness k and damping c is the
    /// constraint `|x_i - x_j| - r` of compliance `1/k` with Rayleigh damping c, projected once
    /// a substep (`integrate/xpbd.rs`). The stretch and shear springs no longer bound the step,
    /// so a frame takes a few substeps where symplectic Euler takes a dozen; first order. One
    /// pass holds a chain of springs about `1 + (omega h)^2` softer than its stiffness
    /// (`omega^2 = k / m`): a tall cloth hangs longer. Velocity spring damping rides on the
    /// constraints; fractional damping stays a force. See `docs/realtime.md`.
    Xpbd,
}

impl Integrator {
    pub const ALL: [Integrator; 6] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::ImplicitEuler,
        Integrator::ExtrapolatedSymplectic,
        Integrator::ExtrapolatedImplicit,
        Integrator::Xpbd,
    ];

    /// The first-order integrator a step is made of: itself, or the one an extrapolated
    /// integrator extrapolates.
    pub fn base(&self) -> Integrator {
        match self {
            Integrator::ExtrapolatedSymplectic => Integrator::SymplecticEuler,
            Integrator::ExtrapolatedImplicit => Integrator::ImplicitEuler,
            other => *other,
        }
    }

    /// Whether each step is extrapolated from a whole step and two half steps (second order).
    pub fn is_extrapolated(&self) -> bool {
        self.base() != *self
    }

    /// Order of accuracy in time (1 or 2).
    pub fn order(&self) -> u32 {
        if self.is_extrapolated() {
            2
        } else {
            1
        }
    }

    /// Whether its stiff in-plane springs are constraints projected after the explicit step
    /// ([`Integrator::Xpbd`]).
    pub fn is_constrained(&self) -> bool {
        *self == Integrator::Xpbd
    }

    /// Whether it is stable at frame-rate steps (implicit).
    pub fn is_implicit(&self) -> bool {
        self.base() == Integrator::ImplicitEuler
    }

    /// Human name, used in messages.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit Euler",
            Integrator::SymplecticEuler => "symplectic Euler",
            Integrator::ImplicitEuler => "implicit Euler",
            Integrator::ExtrapolatedSymplectic => "extrapolated symplectic Euler (2nd order)",
            Integrator::ExtrapolatedImplicit => "extrapolated implicit Euler (2nd order)",
            Integrator::Xpbd => "XPBD (compliant in-plane springs)",
        }
    }

    /// The per-tile step of an explicit integrator (None for the implicit one), checking its
    /// results as it writes them.
    pub fn explicit_step_soa(&self) -> Option<StepSoa> {
        match self.base() {
            Integrator::ExplicitEuler => Some(explicit_euler_soa),
            Integrator::SymplecticEuler | Integrator::Xpbd => Some(symplectic_euler_soa),
            _ => None,
        }
    }

    /// Short name for files and command lines.
    pub fn key(&self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit",
            Integrator::SymplecticEuler => "symplectic",
            Integrator::ImplicitEuler => "implicit",
            Integrator::ExtrapolatedSymplectic => "symplectic2",
            Integrator::ExtrapolatedImplicit => "implicit2",
            Integrator::Xpbd => "xpbd",
        }
    }
}
