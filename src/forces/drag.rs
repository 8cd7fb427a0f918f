//! External drags, acting on the velocity relative to the water (`v - current`).
//!
//! - viscous drag, Eq. 3: `-k_vd v`;
//! - history (Basset) drag, Eq. 4: `-k_hd (D^{1/2}x . v_hat) v_hat`, zero when v = 0;
//! - normal drag (regular models of Fig. 7): `-k_nd (v . n_hat) n_hat`.
//!
//! Coefficients are per particle, N s/m (viscous, normal) and N s^{1/2}/m (history). Each adds
//! to a tile's forces as component arrays ([`super::terms`] decides when), in a loop over the
//! tile that the compiler vectorises.

use crate::math::Vec3;
use crate::model::Model;

crate::simd_dispatch! { pub(super) fn add_viscous(m: &Model, v: [&[f64]; 3], areas: &[f64], f: [&mut [f64]; 3]) => add_viscous_kernel }

#[inline(always)]
fn add_viscous_kernel(m: &Model, v: [&[f64]; 3], areas: &[f64], f: [&mut [f64]; 3]) {
    let (k, ka, c) = (m.viscous_drag, m.water.viscous_drag, m.current);
    for (fc, (vc, cc)) in f.into_iter().zip(v.into_iter().zip([c.x, c.y, c.z])) {
        let vc = &vc[..fc.len()];
        if ka == 0.0 {
            for (fk, vk) in fc.iter_mut().zip(vc) {
                *fk -= k * (vk - cc);
            }
        } else {
            let a = &areas[..fc.len()];
            for ((fk, vk), ak) in fc.iter_mut().zip(vc).zip(a) {
                *fk -= (k + ka * ak) * (vk - cc);
            }
        }
    }
}

crate::simd_dispatch! { pub(super) fn add_history(m: &Model, v: [&[f64]; 3], d: [&[f64]; 3], areas: &[f64], f: [&mut [f64]; 3]) => add_history_kernel }

#[inline(always)]
fn add_history_kernel(m: &Model, v: [&[f64]; 3], d: [&[f64]; 3], areas: &[f64], f: [&mut [f64]; 3]) {
    let [fx, fy, fz] = f;
    let len = fx.len();
    let (fy, fz) = (&mut fy[..len], &mut fz[..len]);
    let (vx, vy, vz) = (&v[0][..len], &v[1][..len], &v[2][..len]);
    let (dx, dy, dz) = (&d[0][..len], &d[1][..len], &d[2][..len]);
    let (k, ka, c) = (m.history_drag, m.water.history_drag, m.current);
    let areas = &areas[..len];
    for t in 0..len {
        let k = super::terms::per_particle(k, ka, areas[t]);
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

/// Adds `g(k, rel, n, area)` to every particle's force, particle by particle, with `rel` the
/// velocity relative to the water and `n` the unit normal.
#[inline(always)]
fn add_with_normals(
    m: &Model,
    v: [&[f64]; 3],
    n: &[Vec3],
    areas: &[f64],
    f: [&mut [f64]; 3],
    g: impl Fn(Vec3, &Vec3, f64) -> Vec3,
) {
    let [fx, fy, fz] = f;
    for (t, nt) in n.iter().enumerate().take(fx.len()) {
        let rel = Vec3::new(v[0][t], v[1][t], v[2][t]) - m.current;
        let total = Vec3::new(fx[t], fy[t], fz[t]) + g(rel, nt, areas[t]);
        (fx[t], fy[t], fz[t]) = (total.x, total.y, total.z);
    }
}

/// Normal drag with unit normals `n`: `-k (v_rel . n) n`.
pub(super) fn add_normal(m: &Model, v: [&[f64]; 3], n: &[Vec3], areas: &[f64], f: [&mut [f64]; 3]) {
    let (k, ka) = (m.normal_drag, m.water.normal_drag);
    add_with_normals(m, v, n, areas, f, |rel, nt, a| {
        -(super::terms::per_particle(k, ka, a) * rel.dot(nt) * nt)
    });
}

/// Form drag: `-1/2 rho_w C_d A |v_n| v_n n`, quadratic in the normal velocity.
pub(super) fn add_form(m: &Model, v: [&[f64]; 3], n: &[Vec3], areas: &[f64], f: [&mut [f64]; 3]) {
    let c = 0.5 * m.water_density * m.water.form_drag;
    add_with_normals(m, v, n, areas, f, |rel, nt, a| {
        let vn = rel.dot(nt);
        -(c * a * vn.abs() * vn) * nt
    });
}

/// Skin drag: `-k_s A (v_rel - (v_rel . n) n)`, on the tangential velocity.
pub(super) fn add_skin(m: &Model, v: [&[f64]; 3], n: &[Vec3], areas: &[f64], f: [&mut [f64]; 3]) {
    let k = m.water.skin_drag;
    add_with_normals(m, v, n, areas, f, |rel, nt, a| {
        -(k * a) * (rel - rel.dot(nt) * nt)
    });
}
