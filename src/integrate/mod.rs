//! Time integrators, one file each.
//!
//! An integrator reads the state at t_n and writes the state at t_n + h into
//! `x_new`/`v_new`; the cloth checks the result and commits it only if it is sound,
//! so every step is atomic. See `docs/stability.md` for where each one fails.

mod cg;
mod explicit_euler;
mod implicit_euler;
mod symplectic_euler;

use crate::Vec3;

pub use cg::{SolverSettings, SolverStats};
pub use explicit_euler::{explicit_euler_range, explicit_euler_soa};
pub use implicit_euler::{implicit_euler, ImplicitInput, ImplicitScratch};
pub use symplectic_euler::{symplectic_euler_range, symplectic_euler_soa};

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
}

impl Integrator {
    pub const ALL: [Integrator; 3] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::ImplicitEuler,
    ];

    /// Human name, used in messages.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit Euler",
            Integrator::SymplecticEuler => "symplectic Euler",
            Integrator::ImplicitEuler => "implicit Euler",
        }
    }

    /// The per-particle step of an explicit integrator (None for the implicit one).
    pub fn explicit_step(&self) -> Option<StepRange> {
        match self {
            Integrator::ExplicitEuler => Some(explicit_euler_range),
            Integrator::SymplecticEuler => Some(symplectic_euler_range),
            Integrator::ImplicitEuler => None,
        }
    }

    /// [`Self::explicit_step`] on component arrays, checking its results as it writes them.
    pub fn explicit_step_soa(&self) -> Option<StepSoa> {
        match self {
            Integrator::ExplicitEuler => Some(explicit_euler_soa),
            Integrator::SymplecticEuler => Some(symplectic_euler_soa),
            Integrator::ImplicitEuler => None,
        }
    }

    /// Short name for files and command lines.
    pub fn key(&self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit",
            Integrator::SymplecticEuler => "symplectic",
            Integrator::ImplicitEuler => "implicit",
        }
    }
}

/// What an explicit step reads: the step size and, per particle, positions, velocities,
/// forces and masses (slices of one length).
#[derive(Clone, Copy)]
pub struct StepInput<'a> {
    pub h: f64,
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    pub force: &'a [Vec3],
    pub masses: &'a [f64],
}

impl<'a> StepInput<'a> {
    /// The particles `r` only.
    pub fn range(&self, r: std::ops::Range<usize>) -> StepInput<'a> {
        StepInput {
            h: self.h,
            x: &self.x[r.clone()],
            v: &self.v[r.clone()],
            force: &self.force[r.clone()],
            masses: &self.masses[r],
        }
    }
}

/// An explicit integrator's step for the particles of a [`StepInput`], into `x_new`, `v_new`.
pub type StepRange = fn(&StepInput<'_>, &mut [Vec3], &mut [Vec3]);

/// [`StepInput`] as component arrays (`[x, y, z]`, each of one length), as a tile walk has them
/// in cache ([`crate::forces::accumulate_tiles_soa`]).
#[derive(Clone, Copy)]
pub struct SoaStepInput<'a> {
    pub h: f64,
    pub x: [&'a [f64]; 3],
    pub v: [&'a [f64]; 3],
    pub force: [&'a [f64]; 3],
    pub masses: &'a [f64],
    /// Largest speed squared a sound result may have, (m/s)^2.
    pub max_speed2: f64,
}

/// An explicit integrator's step for the particles of a [`SoaStepInput`], into `x_new` and
/// `v_new` (as `Vec3`s; the same numbers as its [`StepRange`]), returning whether every result
/// is sound as [`sound`] says.
pub type StepSoa = fn(&SoaStepInput<'_>, &mut [Vec3], &mut [Vec3]) -> bool;

/// The loop of a [`StepSoa`]: `update(x, v, f, h / m)` gives a particle's new position and
/// velocity from its position, velocity and force (components); each result is stored and
/// checked as [`sound`] checks it.
#[inline(always)]
fn step_soa_with(
    s: &SoaStepInput<'_>,
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
        let position = (xn[0] * 0.0 + xn[1] * 0.0) + xn[2] * 0.0;
        ok &= (vn[0] * vn[0] + vn[1] * vn[1] + vn[2] * vn[2]) + position <= s.max_speed2;
    }
    ok
}

/// `step` for every particle, chunk by chunk (in parallel for large cloths).
pub fn step_all(step: StepRange, s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) {
    crate::parallel::chunks2(
        crate::parallel::worth_it(s.x.len()),
        (x_new, 1),
        (v_new, 1),
        crate::parallel::CHUNK,
        |first, x_new, v_new| step(&s.range(first..first + x_new.len()), x_new, v_new),
    );
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
        let position = (a.x * 0.0 + a.y * 0.0) + a.z * 0.0;
        let s = (b.x * b.x + b.y * b.y + b.z * b.z) + position;
        ok &= s <= max_speed2;
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn component_array_steps_match_their_vec3_steps_bit_for_bit_and_check_soundness() {
        let n = 37;
        let mut rnd = crate::testing::numbers(7);
        let mut vec3s =
            |scale: f64| -> Vec<Vec3> { (0..n).map(|_| scale * Vec3::new(rnd(), rnd(), rnd())).collect() };
        let (x, v, f) = (vec3s(1.0), vec3s(3.0), vec3s(1e-2));
        let masses: Vec<f64> = (0..n).map(|k| 1e-4 * (1.0 + k as f64)).collect();
        let comps =
            |a: &[Vec3]| -> [Vec<f64>; 3] { std::array::from_fn(|c| a.iter().map(|p| p[c]).collect()) };
        for integrator in [Integrator::ExplicitEuler, Integrator::SymplecticEuler] {
            let (aos, soa) = (
                integrator.explicit_step().unwrap(),
                integrator.explicit_step_soa().unwrap(),
            );
            // Sound; one velocity too fast; one position not finite.
            for (case, max_speed2) in [(0, 1e6), (1, 1.0), (2, 1e6)] {
                let mut f = f.clone();
                if case == 2 {
                    f[11].y = f64::INFINITY;
                }
                let (xc, vc, fc) = (comps(&x), comps(&v), comps(&f));
                let s = StepInput {
                    h: 1e-3,
                    x: &x,
                    v: &v,
                    force: &f,
                    masses: &masses,
                };
                let (mut xa, mut va) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
                aos(&s, &mut xa, &mut va);
                let c = SoaStepInput {
                    h: 1e-3,
                    x: [&xc[0], &xc[1], &xc[2]],
                    v: [&vc[0], &vc[1], &vc[2]],
                    force: [&fc[0], &fc[1], &fc[2]],
                    masses: &masses,
                    max_speed2,
                };
                let (mut xs, mut vs) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
                let ok = soa(&c, &mut xs, &mut vs);
                let bits =
                    |a: &[Vec3]| -> Vec<[u64; 3]> { a.iter().map(|p| p.map(f64::to_bits).into()).collect() };
                assert_eq!(
                    (bits(&xs), bits(&vs)),
                    (bits(&xa), bits(&va)),
                    "{integrator:?} case {case}"
                );
                assert_eq!(ok, sound(&xa, &va, max_speed2), "{integrator:?} case {case}");
                assert_eq!(ok, case == 0, "{integrator:?} case {case}");
            }
        }
    }

    #[test]
    fn sound_refuses_every_non_finite_number_and_excess_speed() {
        let ok = vec![Vec3::new(1e300, -2.0, 3.0); 37];
        let slow = vec![Vec3::new(0.5, -0.5, 0.5); 37];
        assert!(sound(&ok, &slow, 1.0));
        assert!(sound(&[], &[], 1.0));
        for k in [0, 17, 36] {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for c in 0..3 {
                    let mut x = ok.clone();
                    x[k][c] = bad;
                    assert!(!sound(&x, &slow, 1.0), "position {k} {c} = {bad}");
                    let mut v = slow.clone();
                    v[k][c] = bad;
                    assert!(!sound(&ok, &v, 1.0), "velocity {k} {c} = {bad}");
                }
            }
            let mut v = slow.clone();
            v[k] = Vec3::new(0.0, 1.0001, 0.0);
            assert!(!sound(&ok, &v, 1.0), "speed at {k}");
            v[k] = Vec3::new(0.0, 1.0, 0.0);
            assert!(sound(&ok, &v, 1.0), "speed exactly at the limit at {k}");
        }
    }
}
