//! A rotation-invariant fractional spring: damping on the half-derivative of each spring's
//! elongation, beside the paper's Eq. 5.
//!
//! Eq. 5 damps `[(D^{1/2}x_i - D^{1/2}x_j) . l_hat] l_hat`: the half-derivative of the
//! particles' displacements, projected on the spring's direction *now*. D^{1/2} remembers
//! the past, so a spring that has only turned (a rigid rotation, length unchanged) still
//! feels a force along itself: the remembered displacement of its ends, projected on its new
//! direction, does not vanish. The velocity form `(v_i - v_j) . l_hat` is exactly the rate of
//! change of length and has no such term. This element takes the half-derivative of the
//! elongation `e = |x_i - x_j| - r` itself (Caputo, from the rates `de/dt = (v_i - v_j) . l_hat`):
//!
//! `F_i = -k_d D^{1/2}e l_hat`, `F_j = -F_i`, with `D^{1/2}e_n = w0 de/dt_n + H_n`,
//!
//! which is zero for any rigid motion of the cloth, at any history. `H_n` comes from a
//! history of scalars, one per spring, kept by the same scheme as the particles' (packed
//! three springs to a `Vec3` entry: every scheme is linear and acts component by component).
//! The implicit integrator treats `k_d w0` as the spring's damping, as for Eq. 5.

use crate::math::Vec3;
use crate::model::Model;
use crate::topology::Topology;

/// History entries (`Vec3`) for `springs` springs.
pub fn entries(springs: usize) -> usize {
    springs.div_ceil(3)
}

/// Writes each spring's rate of elongation `(v_i - v_j) . l_hat` (m/s) into `out`, packed
/// three springs to an entry; a zero-length spring has rate 0.
pub fn elongation_rates(topology: &Topology, x: &[Vec3], v: &[Vec3], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(entries(topology.springs.len()), Vec3::zeros());
    for (k, s) in topology.springs.iter().enumerate() {
        let (i, j) = (s.i as usize, s.j as usize);
        let l = x[i] - x[j];
        let len = l.norm();
        out[k / 3][k % 3] = if len > 0.0 {
            (v[i] - v[j]).dot(&l) / len
        } else {
            0.0
        };
    }
}

/// Adds the force of every spring's fractional damping on each particle into `out`:
/// `-k_d (w0 rate + past) l_hat` on `i`, the opposite on `j`. `rates` and `past` are packed
/// as by [`elongation_rates`].
pub fn add_forces(
    model: &Model,
    topology: &Topology,
    x: &[Vec3],
    w0: f64,
    rates: &[Vec3],
    past: &[Vec3],
    out: &mut [Vec3],
) {
    for (k, s) in topology.springs.iter().enumerate() {
        let (i, j) = (s.i as usize, s.j as usize);
        let l = x[i] - x[j];
        let len = l.norm();
        if len == 0.0 {
            continue;
        }
        let half = w0 * rates[k / 3][k % 3] + past[k / 3][k % 3];
        let f = (-model.spring_damping_of(s.kind) * half / len) * l;
        out[i] += f;
        out[j] -= f;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::GridSpec;

    fn cloth() -> (Topology, Vec<Vec3>) {
        let t = GridSpec {
            width: 4,
            height: 3,
            spacing: 0.1,
            total_mass: 0.1,
        }
        .build()
        .unwrap();
        let x = t.rest_positions.clone();
        (t, x)
    }

    #[test]
    fn a_rigid_rotation_has_no_elongation_rate() {
        let (t, x) = cloth();
        // Spinning about the z axis through the origin at 3 rad/s: v = w x r.
        let w = Vec3::new(0.0, 0.0, 3.0);
        let v: Vec<Vec3> = x.iter().map(|p| w.cross(p)).collect();
        let mut rates = vec![];
        elongation_rates(&t, &x, &v, &mut rates);
        assert_eq!(rates.len(), t.springs.len().div_ceil(3));
        assert!(rates.iter().all(|r| r.amax() < 1e-12), "{rates:?}");
    }

    #[test]
    fn a_stretch_has_the_rate_of_the_length_and_forces_that_sum_to_zero() {
        let (t, x) = cloth();
        // Uniform stretch along x at rate 0.5 1/s: a spring along x of length L grows at 0.5 L.
        let v: Vec<Vec3> = x.iter().map(|p| Vec3::new(0.5 * p.x, 0.0, 0.0)).collect();
        let mut rates = vec![];
        elongation_rates(&t, &x, &v, &mut rates);
        for (k, s) in t.springs.iter().enumerate() {
            let l = x[s.i as usize] - x[s.j as usize];
            let want = 0.5 * l.x * l.x / l.norm();
            assert!((rates[k / 3][k % 3] - want).abs() < 1e-12);
        }
        let model = Model {
            spring_damping: 2.0,
            ..Model::fractional()
        };
        let past = vec![Vec3::new(0.01, 0.02, 0.03); rates.len()];
        let mut f = vec![Vec3::zeros(); x.len()];
        add_forces(&model, &t, &x, 0.3, &rates, &past, &mut f);
        let total: Vec3 = f.iter().sum();
        assert!(total.norm() < 1e-12);
        // One spring alone: -k_d (w0 rate + past) l_hat on its first end.
        let s = t.springs[0];
        let l = x[s.i as usize] - x[s.j as usize];
        let half = 0.3 * rates[0][0] + 0.01;
        let mut single = t.clone();
        single.springs.truncate(1);
        f.fill(Vec3::zeros());
        add_forces(&model, &single, &x, 0.3, &rates, &past, &mut f);
        let want = -model.spring_damping_of(s.kind) * half * l / l.norm();
        assert!((f[s.i as usize] - want).norm() < 1e-15);
    }
}
