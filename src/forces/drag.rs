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

/// A per-particle coefficient plus a per-area one times the particle's area. The sum is `k`
/// exactly when the per-area one is zero, so models without it keep their bits.
#[inline(always)]
pub fn per_particle(k: f64, k_area: f64, area: f64) -> f64 {
    if k_area == 0.0 {
        k
    } else {
        k + k_area * area
    }
}

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
        let k = per_particle(k, ka, areas[t]);
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

/// Adds `g(t, rel, n, area)` to every particle's force, particle by particle, with `t` its
/// place in the tile, `rel` the velocity relative to the water and `n` the unit normal.
#[inline(always)]
fn add_with_normals(
    m: &Model,
    v: [&[f64]; 3],
    n: &[Vec3],
    areas: &[f64],
    f: [&mut [f64]; 3],
    g: impl Fn(usize, Vec3, &Vec3, f64) -> Vec3,
) {
    let [fx, fy, fz] = f;
    for (t, nt) in n.iter().enumerate().take(fx.len()) {
        let rel = Vec3::new(v[0][t], v[1][t], v[2][t]) - m.current;
        let total = Vec3::new(fx[t], fy[t], fz[t]) + g(t, rel, nt, areas[t]);
        (fx[t], fy[t], fz[t]) = (total.x, total.y, total.z);
    }
}

/// Normal drag with unit normals `n`: `-k (v_rel . n) n`.
pub(super) fn add_normal(m: &Model, v: [&[f64]; 3], n: &[Vec3], areas: &[f64], f: [&mut [f64]; 3]) {
    let (k, ka) = (m.normal_drag, m.water.normal_drag);
    add_with_normals(m, v, n, areas, f, |_, rel, nt, a| {
        -(per_particle(k, ka, a) * rel.dot(nt) * nt)
    });
}

/// Form drag: `-1/2 rho_w C_d A |v_n| v_n n`, quadratic in the normal velocity.
pub(super) fn add_form(m: &Model, v: [&[f64]; 3], n: &[Vec3], areas: &[f64], f: [&mut [f64]; 3]) {
    let c = 0.5 * m.water_density * m.water.form_drag;
    add_with_normals(m, v, n, areas, f, |_, rel, nt, a| {
        let vn = rel.dot(nt);
        -(c * a * vn.abs() * vn) * nt
    });
}

/// Skin drag: `-k_s A (v_rel - (v_rel . n) n)`, on the tangential velocity; with an unsteady
/// part (`mean` the running mean of `v_rel`, one per particle of the tile),
/// `-A P_t ((k_s + k_u) v_rel - k_u mean)`: the steady `k_s` on a flow the mean has caught up
/// with, `k_s + k_u` on motion faster than the memory.
pub(super) fn add_skin(
    m: &Model,
    v: [&[f64]; 3],
    n: &[Vec3],
    areas: &[f64],
    mean: Option<&[Vec3]>,
    f: [&mut [f64]; 3],
) {
    let (k, ku) = (m.water.skin_drag, m.water.skin_drag_unsteady);
    match mean {
        Some(mean) if ku != 0.0 => add_with_normals(m, v, n, areas, f, |t, rel, nt, a| {
            let w = (k + ku) * rel - ku * mean[t];
            -(a * (w - w.dot(nt) * nt))
        }),
        _ => add_with_normals(m, v, n, areas, f, |_, rel, nt, a| {
            -(k * a) * (rel - rel.dot(nt) * nt)
        }),
    }
}

/// The running mean of the velocity relative to the water that the unsteady skin drag acts
/// against, after an accepted step of `h` s ending at velocities `v`: a first-order low-pass
/// of time constant `memory`, `mean += (1 - e^{-h / memory}) (v_rel - mean)` (exact for a
/// velocity held over the step).
pub fn follow_skin_mean(m: &Model, v: &[Vec3], h: f64, mean: &mut [Vec3]) {
    let a = -(-h / m.water.skin_drag_memory).exp_m1();
    let c = m.current;
    for (mk, vk) in mean.iter_mut().zip(v) {
        *mk += a * (vk - c - *mk);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The skin drag on one particle of area `a`, normal `n`, velocity `v` and running mean
    /// `mean`.
    fn skin(m: &Model, v: Vec3, n: Vec3, a: f64, mean: Option<Vec3>) -> Vec3 {
        let (vs, mut f) = ([[v.x], [v.y], [v.z]], [[0.0], [0.0], [0.0]]);
        let means = mean.map(|m| [m]);
        let [fx, fy, fz] = &mut f;
        add_skin(
            m,
            [&vs[0], &vs[1], &vs[2]],
            &[n],
            &[a],
            means.as_ref().map(|m| &m[..]),
            [fx, fy, fz],
        );
        Vec3::new(f[0][0], f[1][0], f[2][0])
    }

    #[test]
    fn a_steady_flow_meets_the_steady_skin_drag_and_a_sudden_one_both() {
        let mut m = Model::underwater();
        m.current = Vec3::new(0.3, 0.0, 0.1);
        let (ks, ku) = (m.water.skin_drag, m.water.skin_drag_unsteady);
        assert!(ks > 0.0 && ku > 0.0);
        let n = Vec3::new(0.0, 0.0, 1.0);
        let (v, a) = (Vec3::new(-0.1, 0.2, 0.5), 2e-4);
        let rel = v - m.current;
        let along = rel - rel.dot(&n) * n;
        // The mean caught up with the flow: the steady friction alone.
        let steady = skin(&m, v, n, a, Some(rel));
        assert!((steady + ks * a * along).norm() < 1e-15 * along.norm());
        // A flow the mean has not seen (a sudden start, or motion much faster than the
        // memory): both.
        let sudden = skin(&m, v, n, a, Some(Vec3::zeros()));
        assert!((sudden + (ks + ku) * a * along).norm() < 1e-15 * along.norm());
        // Nothing along the normal, whatever the mean.
        let odd = skin(&m, v, n, a, Some(Vec3::new(0.7, -0.2, 3.0)));
        assert_eq!(odd.z, 0.0);
        // Without a mean (the unsteady part off), the steady friction as before.
        m.water.skin_drag_unsteady = 0.0;
        assert_eq!(skin(&m, v, n, a, None), steady);
    }

    #[test]
    fn the_mean_follows_the_flow_with_its_time_constant() {
        let mut m = Model::underwater();
        m.current = Vec3::new(0.0, 0.0, 0.2);
        let memory = m.water.skin_drag_memory;
        // A velocity held from rest: after the memory, 1 - 1/e of the way, in any step size.
        let v = [Vec3::new(0.1, 0.0, 0.0)];
        for steps in [1, 10, 1000] {
            let mut mean = [Vec3::zeros()];
            for _ in 0..steps {
                follow_skin_mean(&m, &v, memory / steps as f64, &mut mean);
            }
            let want = (1.0 - (-1.0f64).exp()) * (v[0] - m.current);
            assert!((mean[0] - want).norm() < 1e-14, "{steps} steps: {:?}", mean[0]);
        }
        // An oscillation much faster than the memory barely moves it.
        let (mut mean, h, omega) = ([Vec3::zeros()], 1e-3, 2.0 * std::f64::consts::PI * 2.0);
        m.current = Vec3::zeros();
        let mut peak: f64 = 0.0;
        for k in 0..4000 {
            let v = [Vec3::new(0.1 * (omega * k as f64 * h).sin(), 0.0, 0.0)];
            follow_skin_mean(&m, &v, h, &mut mean);
            peak = peak.max(mean[0].norm());
        }
        // A first-order low-pass passes 1 / sqrt(1 + (omega T)^2) of the amplitude.
        let pass = 1.0 / (1.0 + (omega * memory).powi(2)).sqrt();
        assert!(peak < 0.1 * 2.0 * pass, "peak {peak}");
    }
}
