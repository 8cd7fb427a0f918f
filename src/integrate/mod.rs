//! Time integrators, one file each.
//!
//! An integrator reads the state at t_n and writes the state at t_n + h into
//! `x_new`/`v_new`; the cloth checks the result and commits it only if it is sound,
//! so every step is atomic. See `docs/stability.md` for where each one fails.

mod cg;
mod explicit_euler;
mod implicit_euler;
mod symplectic_euler;

use crate::math::Vec3;

pub use cg::{SolverSettings, SolverStats};
pub use explicit_euler::explicit_euler_soa;
pub use implicit_euler::{implicit_euler, ImplicitInput, ImplicitScratch};
pub use symplectic_euler::symplectic_euler_soa;

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
}

impl Integrator {
    pub const ALL: [Integrator; 5] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::ImplicitEuler,
        Integrator::ExtrapolatedSymplectic,
        Integrator::ExtrapolatedImplicit,
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
        }
    }

    /// The per-tile step of an explicit integrator (None for the implicit one), checking its
    /// results as it writes them.
    pub fn explicit_step_soa(&self) -> Option<StepSoa> {
        match self.base() {
            Integrator::ExplicitEuler => Some(explicit_euler_soa),
            Integrator::SymplecticEuler => Some(symplectic_euler_soa),
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
        }
    }
}

/// What an explicit step reads: the step size and, per particle of a tile, positions,
/// velocities, forces (component arrays `[x, y, z]`, each of one length, as the force pass has
/// them in cache: `forces::for_each_tile`) and masses.
#[derive(Clone, Copy)]
pub struct StepInput<'a> {
    pub h: f64,
    pub x: [&'a [f64]; 3],
    pub v: [&'a [f64]; 3],
    pub force: [&'a [f64]; 3],
    pub masses: &'a [f64],
    /// Largest speed squared a sound result may have, (m/s)^2.
    pub max_speed2: f64,
}

/// An explicit integrator's step for the particles of a [`StepInput`], into `x_new` and
/// `v_new` (as `Vec3`s), returning whether every result is sound as [`sound_particle`] says.
pub type StepSoa = fn(&StepInput<'_>, &mut [Vec3], &mut [Vec3]) -> bool;

/// The loop of a [`StepSoa`]: `update(x, v, f, h / m)` gives a particle's new position and
/// velocity from its position, velocity and force (components); each result is stored and
/// checked as [`sound`] checks it.
#[inline(always)]
fn step_soa_with(
    s: &StepInput<'_>,
    x_new: &mut [Vec3],
    v_new: &mut [Vec3],
    update: impl Fn([f64; 3], [f64; 3], [f64; 3], f64) -> ([f64; 3], [f64; 3]),
) -> bool {
    let n = x_new.len();
    let v_new = &mut v_new[..n];
    let (x, v, f, masses) = (
        s.x.map(|a| &a[..n]),
        s.v.map(|a| &a[..n]),
        s.force.map(|a| &a[..n]),
        &s.masses[..n],
    );
    let mut ok = true;
    for k in 0..n {
        let at = |a: [&[f64]; 3]| -> [f64; 3] { std::array::from_fn(|c| a[c][k]) };
        let (xn, vn) = update(at(x), at(v), at(f), s.h / masses[k]);
        x_new[k] = Vec3::new(xn[0], xn[1], xn[2]);
        v_new[k] = Vec3::new(vn[0], vn[1], vn[2]);
        ok &= sound_particle(xn, vn, s.max_speed2);
    }
    ok
}

crate::simd_dispatch! { pub fn sound(x: &[Vec3], v: &[Vec3], max_speed2: f64) -> bool => sound_kernel }

/// Whether every position and velocity is finite and no speed exceeds `sqrt(max_speed2)`.
/// Branch-free and with no floating-point sum across particles, so it vectorises: `c * 0` is
/// NaN exactly when c is not finite, NaN and infinity propagate into the squared speed, and
/// NaN fails every comparison.
#[inline(always)]
fn sound_kernel(x: &[Vec3], v: &[Vec3], max_speed2: f64) -> bool {
    let mut ok = true;
    for (a, b) in x.iter().zip(v) {
        ok &= sound_particle([a.x, a.y, a.z], [b.x, b.y, b.z], max_speed2);
    }
    ok
}

/// Whether one particle's position and velocity are finite and its speed at most
/// `sqrt(max_speed2)`: the one soundness test of a step (branch-free, see [`sound`]).
#[inline(always)]
pub fn sound_particle(x: [f64; 3], v: [f64; 3], max_speed2: f64) -> bool {
    let position = (x[0] * 0.0 + x[1] * 0.0) + x[2] * 0.0;
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + position <= max_speed2
}
