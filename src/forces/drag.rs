//! External drags, acting on the velocity relative to the water.
//!
//! - viscous drag, Eq. 3: `-k_vd v`;
//! - history (Basset) drag, Eq. 4: `-k_hd (D^{1/2}x . v_hat) v_hat`, zero when v = 0;
//! - normal drag (regular models of Fig. 7): `-k_nd (v . n_hat) n_hat`.
//!
//! A term whose coefficient is zero is skipped. The drags are added tile by tile (a few hundred
//! particles), in a loop over the tile that the compiler vectorises.

use crate::model::Model;
use crate::Vec3;

crate::simd_dispatch! { pub(super) fn add_tile(m: &Model, v: &[Vec3], d: Option<&[Vec3]>, n: Option<&[Vec3]>, f: &mut [Vec3]) => add_tile_kernel }

/// Adds the drags on particles `0 .. f.len()` of a tile to `f`: velocities `v`,
/// half-derivatives `d` (read when history drag is on) and unit normals `n` (read when normal
/// drag is on), all of the same length.
#[inline(always)]
fn add_tile_kernel(m: &Model, v: &[Vec3], d: Option<&[Vec3]>, n: Option<&[Vec3]>, f: &mut [Vec3]) {
    let len = f.len();
    let (v, c) = (&v[..len], m.current);
    let history = d.filter(|_| m.history_drag != 0.0);
    match (m.viscous_drag, history) {
        (0.0, None) => {}
        (k, None) => {
            for (fi, vi) in f.iter_mut().zip(v) {
                *fi -= k * (vi - c);
            }
        }
        (kv, Some(d)) => {
            // One loop for both (same operations in the same order as two loops).
            let (d, k) = (&d[..len], m.history_drag);
            for t in 0..len {
                if kv != 0.0 {
                    f[t] -= kv * (v[t] - c);
                }
                let (rx, ry, rz) = (v[t].x - c.x, v[t].y - c.y, v[t].z - c.z);
                let speed2 = rx * rx + ry * ry + rz * rz;
                let dr = d[t].x * rx + d[t].y * ry + d[t].z * rz;
                // (d . v_hat) v_hat = (d . rel) rel / |rel|^2; no direction (and no drag) at rest.
                let s = if speed2 > 0.0 { k * dr / speed2 } else { 0.0 };
                f[t] -= Vec3::new(s * rx, s * ry, s * rz);
            }
        }
    }
    if let (Some(n), true) = (n, m.normal_drag != 0.0) {
        let (n, k) = (&n[..len], m.normal_drag);
        for t in 0..len {
            f[t] -= k * (v[t] - c).dot(&n[t]) * n[t];
        }
    }
}

crate::simd_dispatch! { pub(super) fn add_tile_soa(m: &Model, v: [&[f64]; 3], d: Option<[&[f64]; 3]>, f: [&mut [f64]; 3]) => add_tile_soa_kernel }

/// [`add_tile`] on component arrays, without the normal drag: the same numbers, operation for
/// operation, several times faster (no shuffling of `Vec3`s into lanes).
#[inline(always)]
fn add_tile_soa_kernel(m: &Model, v: [&[f64]; 3], d: Option<[&[f64]; 3]>, f: [&mut [f64]; 3]) {
    let [fx, fy, fz] = f;
    let len = fx.len();
    let (fy, fz) = (&mut fy[..len], &mut fz[..len]);
    let (vx, vy, vz) = (&v[0][..len], &v[1][..len], &v[2][..len]);
    let c = m.current;
    let history = d.filter(|_| m.history_drag != 0.0);
    match (m.viscous_drag, history) {
        (0.0, None) => {}
        (k, None) => {
            for t in 0..len {
                fx[t] -= k * (vx[t] - c.x);
                fy[t] -= k * (vy[t] - c.y);
                fz[t] -= k * (vz[t] - c.z);
            }
        }
        (kv, Some(d)) => {
            let (dx, dy, dz) = (&d[0][..len], &d[1][..len], &d[2][..len]);
            let k = m.history_drag;
            for t in 0..len {
                let (rx, ry, rz) = (vx[t] - c.x, vy[t] - c.y, vz[t] - c.z);
                if kv != 0.0 {
                    fx[t] -= kv * rx;
                    fy[t] -= kv * ry;
                    fz[t] -= kv * rz;
                }
                let speed2 = rx * rx + ry * ry + rz * rz;
                let dr = dx[t] * rx + dy[t] * ry + dz[t] * rz;
                let s = if speed2 > 0.0 { k * dr / speed2 } else { 0.0 };
                fx[t] -= s * rx;
                fy[t] -= s * ry;
                fz[t] -= s * rz;
            }
        }
    }
}
