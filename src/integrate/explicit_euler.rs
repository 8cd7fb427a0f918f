//! Explicit (forward) Euler, exactly the paper's Eq. 7:
//! `x(t+h) = x(t) + h v(t)`, `v(t+h) = v(t) + h a(t)`, with a(t) from all forces at t.
//!
//! Chosen as the paper's reference; it is only conditionally stable (the damping
//! must be large enough for the stiffest mode: h ω² < c), see `docs/`.

use super::{step_soa_with, SoaStepInput, StepInput};
use crate::Vec3;

crate::simd_dispatch! { pub fn explicit_euler_range(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) => explicit_euler_kernel }

/// One step for the particles of `s` (a tile, or a chunk of [`super::step_all`]). Pinned
/// particles are overwritten by the caller.
#[inline(always)]
fn explicit_euler_kernel(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) {
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
        x_new[k] = x[k] + h * v[k];
        v_new[k] = v[k] + (h / masses[k]) * force[k];
    }
}

crate::simd_dispatch! { pub fn explicit_euler_soa(s: &SoaStepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool => explicit_euler_soa_kernel }

/// [`explicit_euler_range`] on component arrays, checking each result.
#[inline(always)]
fn explicit_euler_soa_kernel(s: &SoaStepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool {
    let h = s.h;
    // x += h v and v += (h / m) f, both from the old state: as in the `Vec3` kernel above.
    step_soa_with(s, x_new, v_new, |x, v, f, hm| {
        (
            std::array::from_fn(|c| x[c] + h * v[c]),
            std::array::from_fn(|c| v[c] + hm * f[c]),
        )
    })
}
