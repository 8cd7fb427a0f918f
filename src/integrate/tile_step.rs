//! What an explicit integrator's step on a tile reads ([`StepInput`]), the loop every such step
//! runs ([`step_soa_with`]), and the one soundness test of a step ([`sound`]).

use crate::math::Vec3;

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
pub(super) fn step_soa_with(
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
