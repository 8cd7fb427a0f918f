//! The loops of the pass before the forces (see `Cloth::advance`), compiled for the widest
//! vector unit the CPU has ([`crate::simd`]): they move every particle's numbers between
//! `Vec3` arrays and component arrays, which vectorises only with wide shuffles.

use crate::math::Vec3;

crate::simd_dispatch! { pub(super) fn velocities_and_positions(x: &[Vec3], v: &[Vec3], current: Vec3, v_step: &mut [Vec3], v_rel: &mut [Vec3], sx: [&mut [f64]; 3]) => velocities_and_positions_kernel }

/// `v_step = v`, `v_rel = v - current`, and the positions `x` into component arrays `sx`
/// (unless they are empty); all other slices of one length.
#[inline(always)]
fn velocities_and_positions_kernel(
    x: &[Vec3],
    v: &[Vec3],
    current: Vec3,
    v_step: &mut [Vec3],
    v_rel: &mut [Vec3],
    sx: [&mut [f64]; 3],
) {
    let n = v_step.len();
    let (x, v, v_rel) = (&x[..n], &v[..n], &mut v_rel[..n]);
    let [px, py, pz] = sx;
    if px.is_empty() {
        for k in 0..n {
            v_step[k] = v[k];
            v_rel[k] = v[k] - current;
        }
        return;
    }
    let (px, py, pz) = (&mut px[..n], &mut py[..n], &mut pz[..n]);
    for k in 0..n {
        v_step[k] = v[k];
        v_rel[k] = v[k] - current;
        (px[k], py[k], pz[k]) = (x[k].x, x[k].y, x[k].z);
    }
}

crate::simd_dispatch! { pub(super) fn add_current_and_split(w0: Option<f64>, v_rel: &[Vec3], half: &mut [Vec3], rate: Option<&[Vec3]>, q: [&mut [f64]; 3]) => add_current_and_split_kernel }

/// `half += w0 v_rel` (when there is a history, `w0` not None), then the
/// damping rate (`rate`, or `half` itself when None) into component arrays `q` (unless they
/// are empty: undamped springs); all other slices of one length.
#[inline(always)]
fn add_current_and_split_kernel(
    w0: Option<f64>,
    v_rel: &[Vec3],
    half: &mut [Vec3],
    rate: Option<&[Vec3]>,
    q: [&mut [f64]; 3],
) {
    let n = half.len();
    if let Some(w0) = w0 {
        let v_rel = &v_rel[..n];
        for k in 0..n {
            half[k] += w0 * v_rel[k];
        }
    }
    let [qx, qy, qz] = q;
    if qx.is_empty() {
        return;
    }
    let r: &[Vec3] = rate.unwrap_or(half);
    let r = &r[..n];
    let (qx, qy, qz) = (&mut qx[..n], &mut qy[..n], &mut qz[..n]);
    for k in 0..n {
        (qx[k], qy[k], qz[k]) = (r[k].x, r[k].y, r[k].z);
    }
}
