//! Symplectic (semi-implicit) Euler: `v += h a(x_n, v_n)`, then `x += h v_{n+1}`.
//!
//! The same cost as explicit Euler, but the position update uses the new velocity, which
//! makes the undamped part stable up to `h < 2/omega` instead of never; damping is still
//! explicit.

use super::{step_soa_with, SoaStepInput, StepInput};
use crate::Vec3;

crate::simd_dispatch! { pub fn symplectic_euler_range(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) => symplectic_euler_kernel }

/// One step for the particles of `s` (a tile, or a chunk of [`super::step_all`]). Pinned
/// particles are overwritten by the caller.
#[inline(always)]
fn symplectic_euler_kernel(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) {
    let n = x_new.len();
    let h = s.h;
    let (x, v, force, masses, v_new) = (
        &s.x[..n],
        &s.v[..n],
        &s.force[..n],
        &s.masses[..n],
        &mut v_new[..n],
    );
    for k in 0..n {
        v_new[k] = v[k] + (h / masses[k]) * force[k];
        x_new[k] = x[k] + h * v_new[k];
    }
}

crate::simd_dispatch! { pub fn symplectic_euler_soa(s: &SoaStepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool => symplectic_euler_soa_kernel }

/// [`symplectic_euler_range`] on component arrays, checking each result.
#[inline(always)]
fn symplectic_euler_soa_kernel(s: &SoaStepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool {
    let h = s.h;
    // v += (h / m) f, then x += h v_new: as in the `Vec3` kernel above.
    step_soa_with(s, x_new, v_new, |x, v, f, hm| {
        let vn: [f64; 3] = std::array::from_fn(|c| v[c] + hm * f[c]);
        (std::array::from_fn(|c| x[c] + h * vn[c]), vn)
    })
}
