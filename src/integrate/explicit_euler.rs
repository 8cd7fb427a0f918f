//! Explicit (forward) Euler, exactly the paper's Eq. 7:
//! `x(t+h) = x(t) + h v(t)`, `v(t+h) = v(t) + h a(t)`, with a(t) from all forces at t.
//!
//! Chosen as the paper's reference; it is only conditionally stable (the damping
//! must be large enough for the stiffest mode: h ω² < c), see `docs/`.

use crate::parallel;
use crate::Vec3;

/// One explicit Euler step for free particles. `force` holds F(t_n); pinned particles
/// are overwritten by the caller.
pub fn explicit_euler(
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
            explicit_euler_range(
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

crate::simd_dispatch! { pub fn explicit_euler_range(h: f64, x: &[Vec3], v: &[Vec3], force: &[Vec3], masses: &[f64], x_new: &mut [Vec3], v_new: &mut [Vec3]) => explicit_euler_kernel }

/// The same for particles whose state, forces and masses are the given slices (all of one
/// length): a tile, for a caller that integrates forces as they are computed.
#[inline(always)]
fn explicit_euler_kernel(
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
        x_new[k] = x[k] + h * v[k];
        v_new[k] = v[k] + (h / masses[k]) * force[k];
    }
}
