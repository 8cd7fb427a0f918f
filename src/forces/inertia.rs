//! The inertia of a particle: its own mass and the water it carries, in one type.
//!
//! A particle of mass m and area A in water drags water along. Two parts, each per unit area
//! of cloth ([`crate::model::Water`]):
//! - water carried in every direction, `m_e = entrained_mass * A`: the mass matrix gains `m_e I`;
//! - water carried by motion normal to the cloth, `m_a = added_mass * A`: it gains
//!   `m_a n n^T`, n the unit vertex normal (motion along the cloth carries almost none).
//!
//! So `M = (m + m_e) I + m_a n n^T`. Everything that needs the mass matrix asks an
//! [`Inertia`]: the explicit integrators its inverse ([`Inertia::effective_force`], exact by
//! Sherman-Morrison), the implicit solver its product and block ([`Inertia::apply`],
//! [`Inertia::matrix`]), and the energy its kinetic energy ([`Inertia::kinetic_energy`]).
//! Changing how the water's inertia is modelled is a change to this file.
//!
//! The mass matrix is taken at the start of each step (the normal of the state the forces are
//! evaluated at). It depends on the configuration through the normals, so the equations of
//! motion are Lagrange's for `T = 1/2 sum v_i^T M_i(x) v_i`:
//! `M a = f + dT/dx - (dM/dt) v`. The last two terms, the forces of the carried water as the
//! cloth turns ([`turning_forces`]), are what make the water's energy the cloth's: without
//! them a cloth whose normals turn gains kinetic energy from nothing (the water's momentum
//! along the old normal becomes the cloth's along the new tangent). `tests/underwater.rs`
//! checks that a free cloth with strongly anisotropic added mass does not gain energy.

use nalgebra::Matrix3;

use crate::model::Model;
use crate::Vec3;

/// The inertia of one particle: `M = (mass + entrained) I + normal_mass n n^T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    /// The particle's own mass, kg.
    pub mass: f64,
    /// Water carried in every direction, kg.
    pub entrained: f64,
    /// Water carried by motion along `normal`, kg.
    pub normal_mass: f64,
    /// Unit normal the added mass acts along (any vector when `normal_mass` is 0).
    pub normal: Vec3,
}

/// Whether the model carries any water (so that the mass matrix differs from `m I`).
pub fn carries_water(m: &Model) -> bool {
    m.water.added_mass != 0.0 || m.water.entrained_mass != 0.0
}

impl Inertia {
    /// The inertia of a particle of mass `mass` (kg) and area `area` (m^2) with unit normal
    /// `normal`, in the water of model `m`.
    #[inline]
    pub fn of(m: &Model, mass: f64, area: f64, normal: Vec3) -> Inertia {
        Inertia {
            mass,
            entrained: m.water.entrained_mass * area,
            normal_mass: m.water.added_mass * area,
            normal,
        }
    }

    /// The isotropic part of the mass matrix, `mass + entrained`, kg.
    #[inline]
    pub fn isotropic(&self) -> f64 {
        self.mass + self.entrained
    }

    /// The force that, divided by the particle's own mass, gives the acceleration:
    /// `m M^{-1} f = m / (m + m_e) (f - beta (n . f) n)`, `beta = m_a / (m + m_e + m_a)`
    /// (Sherman-Morrison). An explicit integrator steps with it unchanged otherwise.
    #[inline]
    pub fn effective_force(&self, f: Vec3) -> Vec3 {
        let iso = self.isotropic();
        let beta = self.normal_mass / (iso + self.normal_mass);
        let n = self.normal;
        (self.mass / iso) * (f - (beta * n.dot(&f)) * n)
    }

    /// What the water adds to `M u`: `m_e u + m_a (n . u) n` (the particle's own `m u` is
    /// the caller's, so that a model without water keeps its bits).
    #[inline]
    pub fn water_times(&self, u: &Vec3) -> Vec3 {
        self.entrained * u + (self.normal_mass * self.normal.dot(u)) * self.normal
    }

    /// `M u`.
    #[inline]
    pub fn apply(&self, u: &Vec3) -> Vec3 {
        self.mass * u + self.water_times(u)
    }

    /// What the water adds to the mass matrix: `m_e I + m_a n n^T`.
    #[inline]
    pub fn water_matrix(&self) -> Matrix3<f64> {
        self.entrained * Matrix3::identity() + self.normal_mass * (self.normal * self.normal.transpose())
    }

    /// The mass matrix `M`.
    pub fn matrix(&self) -> Matrix3<f64> {
        self.mass * Matrix3::identity() + self.water_matrix()
    }

    /// Twice the kinetic energy at velocity `v` with this inertia's normal: `v^T M v`, J.
    #[inline]
    pub fn twice_kinetic(&self, v: &Vec3) -> f64 {
        self.twice_kinetic_along(v, &self.normal)
    }

    /// Twice the kinetic energy at velocity `v` were the normal `n` instead: the energy a turn
    /// of the normal would give the same velocity.
    #[inline]
    pub fn twice_kinetic_along(&self, v: &Vec3, n: &Vec3) -> f64 {
        self.isotropic() * v.norm_squared() + self.normal_mass * v.dot(n).powi(2)
    }

    /// Kinetic energy at velocity `v`, `1/2 v^T M v`, J.
    #[inline]
    pub fn kinetic_energy(&self, v: &Vec3) -> f64 {
        0.5 * self.twice_kinetic(v)
    }
}

/// Writes the effective forces of a tile into `out` (component arrays):
/// [`Inertia::effective_force`] of each particle.
pub fn effective_forces(
    m: &Model,
    masses: &[f64],
    areas: &[f64],
    normals: &[Vec3],
    force: [&[f64]; 3],
    out: &mut [[f64; crate::parallel::TILE]; 3],
) {
    let len = force[0].len();
    for k in 0..len {
        let f = Vec3::new(force[0][k], force[1][k], force[2][k]);
        let g = Inertia::of(m, masses[k], areas[k], normals[k]).effective_force(f);
        (out[0][k], out[1][k], out[2][k]) = (g.x, g.y, g.z);
    }
}

/// Scratch of [`turning_forces`]: per face its normal times twice its area and that
/// normal's rate, then per face the sum of its vertices' weights; per vertex the weight.
#[derive(Clone, Debug, Default)]
pub struct TurningScratch {
    faces: Vec<Vec3>,
    rates: Vec<Vec3>,
    weights: Vec<Vec3>,
}

/// Adds the forces of the carried water as the normals turn, `dT/dx - (dM/dt) v`, to `out`
/// (one per particle), for the normal added mass of `m` at positions `x` and velocities
/// relative to the water `v`. Nothing without normal added mass.
///
/// With `N_i` the sum of vertex i's face normals (each twice its face's area, as
/// [`super::vertex_normals`]), `n_i = N_i / |N_i|` and `P_i = I - n_i n_i^T`:
/// - `(dM_i/dt) v_i = m_a,i (ndot_i (n_i . v_i) + n_i (ndot_i . v_i))`, with
///   `ndot_i = P_i Ndot_i / |N_i|` and `Ndot_i` the sum of its faces' normals' rates;
/// - `dT/dx_j = sum_i (dN_i/dx_j)^T w_i`, `w_i = m_a,i (n_i . v_i) P_i v_i / |N_i|`: per face
///   `c = e1 x e2` (`e1 = x_b - x_a`, `e2 = x_c - x_a`) and `W` the sum of its vertices' w,
///   the gradient of `W . c` is `e2 x W` at b, `W x e1` at c and minus their sum at a.
///
/// Both are quadratic in the velocity (no stiffness): they enter every integrator as known
/// forces of the step's start.
#[allow(clippy::too_many_arguments)] // the state, the mesh and the output of one pass
pub fn turning_forces(
    m: &Model,
    x: &[Vec3],
    v: &[Vec3],
    areas: &[f64],
    triangles: &[[u32; 3]],
    vertex_triangles: &crate::topology::Adjacency,
    scratch: &mut TurningScratch,
    out: &mut [Vec3],
) {
    let ma = m.water.added_mass;
    if ma == 0.0 {
        return;
    }
    let TurningScratch {
        faces,
        rates,
        weights,
    } = scratch;
    faces.clear();
    rates.clear();
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let (e1, e2) = (x[b] - x[a], x[c] - x[a]);
        faces.push(e1.cross(&e2));
        rates.push((v[b] - v[a]).cross(&e2) + e1.cross(&(v[c] - v[a])));
    }
    weights.clear();
    for (i, o) in out.iter_mut().enumerate() {
        let (mut big_n, mut big_ndot) = (Vec3::zeros(), Vec3::zeros());
        for &t in vertex_triangles.row(i) {
            big_n += faces[t as usize];
            big_ndot += rates[t as usize];
        }
        let len = big_n.norm();
        if len == 0.0 {
            weights.push(Vec3::zeros());
            continue;
        }
        let n = big_n / len;
        let mass = ma * areas[i];
        let vn = n.dot(&v[i]);
        let ndot = (big_ndot - n.dot(&big_ndot) * n) / len;
        *o -= mass * (vn * ndot + ndot.dot(&v[i]) * n);
        weights.push((mass * vn / len) * (v[i] - vn * n));
    }
    // W of every face, then each vertex gathers its faces' gradients (no scatter).
    for (f, t) in faces.iter_mut().zip(triangles) {
        *f = t.iter().map(|&i| weights[i as usize]).sum();
    }
    for (i, o) in out.iter_mut().enumerate() {
        for &t in vertex_triangles.row(i) {
            let [a, b, c] = triangles[t as usize];
            let w = faces[t as usize];
            let (e1, e2) = (x[b as usize] - x[a as usize], x[c as usize] - x[a as usize]);
            let (gb, gc) = (e2.cross(&w), w.cross(&e1));
            *o += if i == b as usize {
                gb
            } else if i == c as usize {
                gc
            } else {
                -(gb + gc)
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::{GridSpec, Topology};

    /// A crumpled, moving patch: positions, velocities, and a model with normal added mass.
    fn patch() -> (Topology, Vec<Vec3>, Vec<Vec3>, Model) {
        let t = GridSpec {
            width: 4,
            height: 3,
            spacing: 0.1,
            total_mass: 0.2,
        }
        .build()
        .expect("a valid grid");
        let mut r = crate::testing::numbers(3);
        let x = t
            .rest_positions
            .iter()
            .map(|p| p + 0.03 * Vec3::new(r(), r(), r()))
            .collect();
        let v = (0..t.vertex_count()).map(|_| Vec3::new(r(), r(), r())).collect();
        let mut m = Model::fractional();
        m.water.added_mass = 30.0;
        (t, x, v, m)
    }

    fn normals(t: &Topology, x: &[Vec3]) -> Vec<Vec3> {
        let mut n = vec![Vec3::zeros(); x.len()];
        super::super::vertex_normals(x, &t.triangles, &mut n);
        n
    }

    /// The water's kinetic energy `1/2 sum m_a (v . n)^2`.
    fn water_energy(t: &Topology, m: &Model, x: &[Vec3], v: &[Vec3]) -> f64 {
        let n = normals(t, x);
        (0..x.len())
            .map(|i| 0.5 * m.water.added_mass * t.areas[i] * v[i].dot(&n[i]).powi(2))
            .sum()
    }

    #[test]
    fn turning_forces_are_lagranges_terms() {
        let (t, x, v, m) = patch();
        let mut got = vec![Vec3::zeros(); x.len()];
        let mut s = TurningScratch::default();
        turning_forces(
            &m,
            &x,
            &v,
            &t.areas,
            &t.triangles,
            &t.vertex_triangles,
            &mut s,
            &mut got,
        );
        // dT/dx by central differences of T at fixed v; (dM/dt) v by central differences
        // of M(x + s v) v in s.
        let eps = 1e-6;
        let ma: Vec<f64> = t.areas.iter().map(|a| m.water.added_mass * a).collect();
        for j in 0..x.len() {
            let mut grad = Vec3::zeros();
            for a in 0..3 {
                let shifted = |s: f64| {
                    let mut y = x.clone();
                    y[j][a] += s * eps;
                    water_energy(&t, &m, &y, &v)
                };
                grad[a] = (shifted(1.0) - shifted(-1.0)) / (2.0 * eps);
            }
            let m_v = |s: f64| {
                let y: Vec<Vec3> = x.iter().zip(&v).map(|(x, v)| x + s * eps * v).collect();
                let n = normals(&t, &y)[j];
                ma[j] * n.dot(&v[j]) * n
            };
            let mdot_v = (m_v(1.0) - m_v(-1.0)) / (2.0 * eps);
            let want = grad - mdot_v;
            assert!(
                (got[j] - want).norm() < 1e-6 * (1.0 + want.norm()),
                "particle {j}: {} against {}",
                got[j],
                want
            );
        }
        // Nothing without normal added mass.
        let mut none = vec![Vec3::zeros(); x.len()];
        let plain = Model::fractional();
        turning_forces(
            &plain,
            &x,
            &v,
            &t.areas,
            &t.triangles,
            &t.vertex_triangles,
            &mut s,
            &mut none,
        );
        assert!(none.iter().all(|f| *f == Vec3::zeros()));
    }

    fn inertia() -> Inertia {
        let mut model = Model::fractional();
        model.water.added_mass = 40.0;
        model.water.entrained_mass = 3.0;
        Inertia::of(&model, 1e-3, 1e-4, Vec3::new(0.3, -0.4, 0.866).normalize())
    }

    #[test]
    fn the_effective_force_is_the_exact_inverse_mass_matrix() {
        let i = inertia();
        let f = Vec3::new(0.2, 0.7, -0.1);
        // M a = f with a = effective / m.
        let a = i.effective_force(f) / i.mass;
        let back = i.apply(&a);
        assert!((back - f).norm() < 1e-12 * f.norm(), "{back} {f}");
        assert!((i.matrix() * a - f).norm() < 1e-12 * f.norm());
        // Along the cloth only the entrained water; along the normal the whole added mass.
        let n = i.normal;
        let t = n.cross(&Vec3::x()).normalize();
        let iso = i.mass + i.entrained;
        assert!((i.effective_force(t) - i.mass / iso * t).norm() < 1e-15);
        let along = i.mass / (iso + i.normal_mass);
        assert!((i.effective_force(n) - along * n).norm() < 1e-15);
    }

    #[test]
    fn kinetic_energy_is_half_v_m_v() {
        let i = inertia();
        let v = Vec3::new(-0.3, 0.1, 0.25);
        let want = 0.5 * v.dot(&(i.matrix() * v));
        assert!((i.kinetic_energy(&v) - want).abs() < 1e-15 * want.abs().max(1e-30));
        let other = Vec3::x();
        let turned = Inertia { normal: other, ..i };
        assert_eq!(i.twice_kinetic_along(&v, &other), turned.twice_kinetic(&v));
    }
}
