//! Symplectic (semi-implicit) Euler: `v += h a(x_n, v_n)`, then `x += h v_{n+1}`.
//!
//! The same cost as explicit Euler, but the position update uses the new velocity, which
//! makes the undamped part stable up to `h < 2/omega` instead of never; damping is still
//! explicit.

use super::tile_step::{step_soa_with, StepInput};
use crate::math::Vec3;

crate::simd_dispatch! { pub fn symplectic_euler_soa(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool => symplectic_euler_soa_kernel }

/// One step for the particles of a tile, checking each result: `v += (h / m) f`, then `x += h v`.
#[inline(always)]
fn symplectic_euler_soa_kernel(s: &StepInput<'_>, x_new: &mut [Vec3], v_new: &mut [Vec3]) -> bool {
    let h = s.h;
    // v += (h / m) f, then x += h v_new.
    step_soa_with(s, x_new, v_new, |x, v, f, hm| {
        let vn: [f64; 3] = std::array::from_fn(|c| v[c] + hm * f[c]);
        (std::array::from_fn(|c| x[c] + h * vn[c]), vn)
    })
}
