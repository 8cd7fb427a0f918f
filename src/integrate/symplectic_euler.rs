//! Symplectic (semi-implicit) Euler: `v += h a(x_n, v_n)`, then `x += h v_{n+1}`.
//!
//! The same cost as explicit Euler, but the position update uses the new velocity, which
//! makes the undamped part stable up to `h < 2/omega` instead of never; damping is still
//! explicit.

use crate::parallel;
use crate::Vec3;

/// One symplectic Euler step for free particles; pinned particles are overwritten by the caller.
pub fn symplectic_euler(
    h: f64,
    x: &[Vec3],
    v: &[Vec3],
    force: &[Vec3],
    masses: &[f64],
    x_new: &mut [Vec3],
    v_new: &mut [Vec3],
) {
    parallel::chunks2(
        parallel::worth_it(x.len()),
        (x_new, 1),
        (v_new, 1),
        parallel::CHUNK,
        |first, x_new, v_new| {
            let r = first..first + x_new.len();
            symplectic_euler_range(
                h,
                &x[r.clone()],
                &v[r.clone()],
                &force[r.clone()],
                &masses[r],
                x_new,
                v_new,
            );
        },
    );
}

crate::simd_dispatch! { pub fn symplectic_euler_range(h: f64, x: &[Vec3], v: &[Vec3], force: &[Vec3], masses: &[f64], x_new: &mut [Vec3], v_new: &mut [Vec3]) => symplectic_euler_kernel }

/// The same for particles whose state, forces and masses are the given slices (all of one
/// length): a tile, for a caller that integrates forces as they are computed.
#[inline(always)]
fn symplectic_euler_kernel(
    h: f64,
    x: &[Vec3],
    v: &[Vec3],
    force: &[Vec3],
    masses: &[f64],
    x_new: &mut [Vec3],
    v_new: &mut [Vec3],
) {
    let n = x_new.len();
    let (x, v, force, masses, v_new) = (&x[..n], &v[..n], &force[..n], &masses[..n], &mut v_new[..n]);
    for k in 0..n {
        v_new[k] = v[k] + (h / masses[k]) * force[k];
        x_new[k] = x[k] + h * v_new[k];
    }
}
