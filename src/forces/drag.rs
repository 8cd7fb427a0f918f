//! External drags, acting on the velocity relative to the water (`v - current`).
//!
//! - viscous drag, Eq. 3: `-k_vd v`;
//! - history (Basset) drag, Eq. 4: `-k_hd (D^{1/2}x . v_hat) v_hat`, zero when v = 0;
//! - normal drag (regular models of Fig. 7): `-k_nd (v . n_hat) n_hat`.
//!
//! Coefficients are per particle, N s/m (viscous, normal) and N s^{1/2}/m (history). Each adds
//! to a tile's forces as component arrays ([`super::terms`] decides when), in a loop over the
//! tile that the compiler vectorises.

use crate::model::Model;
use crate::Vec3;

crate::simd_dispatch! { pub(super) fn add_viscous(m: &Model, v: [&[f64]; 3], f: [&mut [f64]; 3]) => add_viscous_kernel }

#[inline(always)]
fn add_viscous_kernel(m: &Model, v: [&[f64]; 3], f: [&mut [f64]; 3]) {
    let (k, c) = (m.viscous_drag, m.current);
    for (fc, (vc, cc)) in f.into_iter().zip(v.into_iter().zip([c.x, c.y, c.z])) {
        let vc = &vc[..fc.len()];
        for (fk, vk) in fc.iter_mut().zip(vc) {
            *fk -= k * (vk - cc);
        }
    }
}

crate::simd_dispatch! { pub(super) fn add_history(m: &Model, v: [&[f64]; 3], d: [&[f64]; 3], f: [&mut [f64]; 3]) => add_history_kernel }

#[inline(always)]
fn add_history_kernel(m: &Model, v: [&[f64]; 3], d: [&[f64]; 3], f: [&mut [f64]; 3]) {
    let [fx, fy, fz] = f;
    let len = fx.len();
    let (fy, fz) = (&mut fy[..len], &mut fz[..len]);
    let (vx, vy, vz) = (&v[0][..len], &v[1][..len], &v[2][..len]);
    let (dx, dy, dz) = (&d[0][..len], &d[1][..len], &d[2][..len]);
    let (k, c) = (m.history_drag, m.current);
    for t in 0..len {
        let (rx, ry, rz) = (vx[t] - c.x, vy[t] - c.y, vz[t] - c.z);
        let speed2 = rx * rx + ry * ry + rz * rz;
        let dr = dx[t] * rx + dy[t] * ry + dz[t] * rz;
        // (d . v_hat) v_hat = (d . rel) rel / |rel|^2; no direction (and no drag) at rest.
        let s = if speed2 > 0.0 { k * dr / speed2 } else { 0.0 };
        fx[t] -= s * rx;
        fy[t] -= s * ry;
        fz[t] -= s * rz;
    }
}

/// Normal drag with unit normals `n`, particle by particle.
pub(super) fn add_normal(m: &Model, v: [&[f64]; 3], n: &[Vec3], f: [&mut [f64]; 3]) {
    let [fx, fy, fz] = f;
    let (k, c) = (m.normal_drag, m.current);
    for (t, nt) in n.iter().enumerate().take(fx.len()) {
        let rel = Vec3::new(v[0][t], v[1][t], v[2][t]) - c;
        let g = Vec3::new(fx[t], fy[t], fz[t]) - k * rel.dot(nt) * nt;
        (fx[t], fy[t], fz[t]) = (g.x, g.y, g.z);
    }
}
