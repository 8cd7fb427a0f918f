//! The water's added mass for motion normal to the cloth: an inertia, not a force.
//!
//! A particle of mass m and area A accelerating normal to the cloth drags water along; its
//! mass matrix becomes `M = m I + m_a n n^T` with `m_a = added_mass * A` (kg/m^2 times m^2)
//! and n its unit vertex normal, while motion along the cloth carries almost none. An explicit
//! step needs `M^{-1} f`, which Sherman-Morrison gives exactly:
//! `M^{-1} f = (1/m) (f - m_a / (m + m_a) (n . f) n)`. So the explicit integrators step with the
//! effective force `f - beta (n . f) n`, `beta = m_a / (m + m_a)`, unchanged otherwise; the
//! implicit integrator puts `m_a n n^T` into its system matrix and preconditioner
//! ([`super::Linearisation::added_mass`]).
//!
//! The mass matrix is taken at the start of each step (the normal of the state the forces are
//! evaluated at); `tests/underwater.rs` checks that a free cloth with strongly anisotropic
//! added mass does not gain energy.

use crate::model::Model;
use crate::parallel::TILE;
use crate::Vec3;

/// The added mass for normal motion of a particle of area `area`, kg.
#[inline]
pub fn added_mass(m: &Model, area: f64) -> f64 {
    m.water.added_mass * area
}

/// The water entrained in every direction by a particle of area `area`, kg.
#[inline]
pub fn entrained_mass(m: &Model, area: f64) -> f64 {
    m.water.entrained_mass * area
}

/// Whether the model adds any inertia.
pub fn has_added_inertia(m: &Model) -> bool {
    m.water.added_mass != 0.0 || m.water.entrained_mass != 0.0
}

/// Writes the effective forces of a tile into `out` (component arrays): `m M^{-1} f` with
/// `M = (m + m_e) I + m_a n n^T`, that is `m / (m + m_e) (f - beta (n . f) n)`,
/// `beta = m_a / (m + m_e + m_a)`.
pub fn effective_forces(
    m: &Model,
    masses: &[f64],
    areas: &[f64],
    normals: &[Vec3],
    force: [&[f64]; 3],
    out: &mut [[f64; TILE]; 3],
) {
    let len = force[0].len();
    for k in 0..len {
        let (ma, me) = (added_mass(m, areas[k]), entrained_mass(m, areas[k]));
        let iso = masses[k] + me;
        let beta = ma / (iso + ma);
        let n = normals[k];
        let f = Vec3::new(force[0][k], force[1][k], force[2][k]);
        let g = (masses[k] / iso) * (f - (beta * n.dot(&f)) * n);
        (out[0][k], out[1][k], out[2][k]) = (g.x, g.y, g.z);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_effective_force_is_the_exact_inverse_mass_matrix() {
        let mut model = Model::fractional();
        model.water.added_mass = 40.0;
        let (mass, area) = (1e-3, 1e-4);
        let n = Vec3::new(0.3, -0.4, 0.866).normalize();
        let f = Vec3::new(0.2, 0.7, -0.1);
        let mut out = [[0.0; TILE]; 3];
        let comps = [[f.x], [f.y], [f.z]];
        effective_forces(
            &model,
            &[mass],
            &[area],
            &[n],
            [&comps[0], &comps[1], &comps[2]],
            &mut out,
        );
        // M a = f with M = m I + m_a n n^T, a = effective / m.
        let a = Vec3::new(out[0][0], out[1][0], out[2][0]) / mass;
        let ma = 40.0 * area;
        let back = mass * a + ma * n.dot(&a) * n;
        assert!((back - f).norm() < 1e-12 * f.norm(), "{back} {f}");
        // Along the cloth nothing changes; along the normal the acceleration is m / (m + m_a).
        let t = n.cross(&Vec3::x()).normalize();
        let g = |v: Vec3| {
            let c = [[v.x], [v.y], [v.z]];
            let mut o = [[0.0; TILE]; 3];
            effective_forces(&model, &[mass], &[area], &[n], [&c[0], &c[1], &c[2]], &mut o);
            Vec3::new(o[0][0], o[1][0], o[2][0])
        };
        assert!((g(t) - t).norm() < 1e-15);
        assert!((g(n) - mass / (mass + ma) * n).norm() < 1e-15);
    }
}
