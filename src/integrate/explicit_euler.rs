//! Explicit (forward) Euler, exactly the paper's Eq. 7:
//! `x(t+h) = x(t) + h v(t)`, `v(t+h) = v(t) + h a(t)`, with a(t) from all forces at t.
//!
//! Chosen as the paper's reference; it is only conditionally stable (the damping
//! must be large enough for the stiffest mode: h ω² < c), see `docs/`.

use super::tile_step::{step_soa_with, StepInput};
use crate::math::Vec3;

crate::simd_dispatch! { pub fn explicit_euler_soa(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool => explicit_euler_soa_kernel }

/// One step for the particles of a tile, checking each result: `x += h v`, `v += (h / m) f`.
#[inline(always)]
fn explicit_euler_soa_kernel(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool {
    let h = s.h;
    // x += h v and v += (h / m) f, both from the old state.
    step_soa_with(s, x_new, v_new, |x, v, f, hm| {
        (
            std::array::from_fn(|c| x[c] + h * v[c]),
            std::array::from_fn(|c| v[c] + hm * f[c]),
        )
    })
}
