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

use crate::math::Vec3;
use crate::model::Model;

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
    m.water.normal_water() || m.water.entrained_mass != 0.0
}

impl Inertia {
    /// The inertia of a particle of mass `mass` (kg) and area `area` (m^2) with unit normal
    /// `normal`, whose patch faces that normal with `projected` times its rest area
    /// (`patch_normals`; 1 at rest), in the water of model `m`.
    #[inline]
    pub fn of(m: &Model, mass: f64, area: f64, normal: Vec3, projected: f64) -> Inertia {
        Self::carrying(m, mass, area, normal, carried(projected * projected))
    }

    /// [`Inertia::of`] with the patch's [`carried`] water given (`f(p^2)`).
    #[inline(always)]
    fn carrying(m: &Model, mass: f64, area: f64, normal: Vec3, carried: f64) -> Inertia {
        Inertia {
            mass,
            entrained: m.water.entrained_mass * area,
            normal_mass: m.water.added_mass * area * carried,
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

/// The squared projected-area ratio `q = p^2` up to which the water a patch carries grows with
/// it ([`carried`]).
pub const CARRIED_FULL: f64 = 1.5;

/// How much more than [`CARRIED_FULL`] the water a stretched patch carries can reach
/// ([`carried`]).
pub const CARRIED_SPAN: f64 = 0.5;

/// The water a patch carries normal to itself, in its rest patch's: `f(q)` of its squared
/// projected-area ratio `q = p^2` ([`patch_normals`]). `q` itself up to [`CARRIED_FULL`]: a
/// patch that folds carries less, down to none. Past it the growth saturates,
/// `f = F + S r / sqrt(1 + r^2)`, `r = (q - F) / S` (`F` [`CARRIED_FULL`], `S`
/// [`CARRIED_SPAN`]): the same value, slope and curvature at `F` (with the bound at 1, where
/// the cloth sits, a kink in the curvature made the free cloth's energy drift by a fifth more
/// with symplectic Euler), never above `F + S`. Without the bound the water's kinetic
/// energy grew without limit as a patch stretched, so a cloth dragged through the water fast
/// enough (a pinned edge or a collider at 1.5-2 m/s, a current of 2 m/s face on) was pulled
/// apart by its own carried water faster than its springs hold it: a stretched patch carries
/// more water, and Lagrange's equations push towards more kinetic energy at a given speed.
#[inline(always)]
pub fn carried(q: f64) -> f64 {
    if q > CARRIED_FULL {
        carried_saturating(q)
    } else {
        q
    }
}

/// [`carried`] past [`CARRIED_FULL`]: out of line, so that the common path stays a compare.
#[cold]
#[inline(never)]
fn carried_saturating(q: f64) -> f64 {
    saturating(q).0
}

/// [`carried`]'s `f(q)` past [`CARRIED_FULL`] and its slope `f'(q)`.
#[inline(always)]
fn saturating(q: f64) -> (f64, f64) {
    let r = (q - CARRIED_FULL) / CARRIED_SPAN;
    let d = 1.0 + r * r;
    let s = d.sqrt();
    (CARRIED_FULL + CARRIED_SPAN * r / s, 1.0 / (d * s))
}

/// `h = f(q) / q` and `dh/dq` for [`carried`]'s `f`, past [`CARRIED_FULL`] (where `h` < 1).
#[inline(always)]
pub(super) fn carried_past(q: f64) -> (f64, f64) {
    let (f, slope) = saturating(q);
    (f / q, (slope * q - f) / (q * q))
}

/// Writes the effective forces of a tile into `out` (component arrays):
/// [`Inertia::effective_force`] of each particle. `projected`: each patch's projected-area
/// ratio ([`patch_normals`]), empty when the model has no normal added mass.
pub fn effective_forces(
    m: &Model,
    masses: &[f64],
    areas: &[f64],
    normals: &[Vec3],
    projected: &[f64],
    force: [&[f64]; 3],
    out: &mut [[f64; crate::parallel::TILE]; 3],
) {
    let len = force[0].len();
    // [`carried`] is `p^2` below its bound, where nearly every patch is: the loop takes that
    // (`min` keeps it a vector loop), and the patches past the bound are done again after.
    for k in 0..len {
        let f = Vec3::new(force[0][k], force[1][k], force[2][k]);
        let p = projected.get(k).copied().unwrap_or(1.0);
        let below = (p * p).min(CARRIED_FULL);
        let g = Inertia::carrying(m, masses[k], areas[k], normals[k], below).effective_force(f);
        (out[0][k], out[1][k], out[2][k]) = (g.x, g.y, g.z);
    }
    for (k, &p) in projected.iter().enumerate().take(len) {
        if p * p > CARRIED_FULL {
            let f = Vec3::new(force[0][k], force[1][k], force[2][k]);
            let g = Inertia::of(m, masses[k], areas[k], normals[k], p).effective_force(f);
            (out[0][k], out[1][k], out[2][k]) = (g.x, g.y, g.z);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inertia() -> Inertia {
        let mut model = Model::fractional();
        model.water.added_mass = 40.0;
        model.water.entrained_mass = 3.0;
        Inertia::of(&model, 1e-3, 1e-4, Vec3::new(0.3, -0.4, 0.866).normalize(), 1.0)
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
