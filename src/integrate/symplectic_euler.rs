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
            for k in 0..x_new.len() {
                let i = first + k;
                v_new[k] = v[i] + (h / masses[i]) * force[i];
                x_new[k] = x[i] + h * v_new[k];
            }
        },
    );
}
