//! The contact element: a penalty between a point of the cloth (one vertex, or a weighted
//! combination of up to four: a point of a triangle, of an edge, or the difference of two such
//! points) and what it must keep away from, written once and used by every collision kind.
//!
//! With `u = sum_j c_j x_j` the element's combination, `n` its unit direction and `depth` how
//! far inside the thickness it is, the element's force on vertex j is `c_j F n` with
//! `F = k depth + c max(0, -(sum_j c_j v_j - v_s) . n)`: a spring pushing out plus damping of the
//! approach only, `v_s` the velocity of what it touches (a collider's surface; 0 against the
//! cloth itself). `k` and `c` are the model's `collision_stiffness` and `collision_damping`,
//! the same as the sphere, plane and capsule contacts. Self-collision's contacts multiply `F`
//! by [`Contact::scale`] (see [`inertia_scale`]): the water a cloth carries along its normal
//! would otherwise make them up to `1 + m_a / m` times softer; every other contact has scale 1.
//!
//! Jacobian (for the implicit solver): `df_j/dx_l = -s k c_j c_l n n^T` and, while approaching,
//! `df_j/dv_l = -s c c_j c_l n n^T` (`s` the scale) (the change of `n` with position is left out, as for the
//! analytic colliders). Friction is a velocity correction after the step, as for the others.

use crate::math::Vec3;

/// Most vertices in one element.
pub const MAX_VERTICES: usize = 4;

/// One contact; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Cloth vertices (the first `len`).
    pub idx: [u32; MAX_VERTICES],
    /// Their coefficients `c_j`.
    pub coef: [f64; MAX_VERTICES],
    pub len: u8,
    /// Unit direction the combination is pushed.
    pub dir: Vec3,
    /// How far inside the thickness, m (> 0).
    pub depth: f64,
    /// Velocity of what the combination touches, m/s.
    pub surface_velocity: Vec3,
    /// Coulomb friction coefficient.
    pub friction: f64,
    /// What the penalty is multiplied by (1: as written): `w_dry / w_wet`, so that the
    /// combination accelerates along `dir` as it would without the water it carries
    /// ([`inertia_scale`]).
    pub scale: f64,
}

impl Contact {
    /// The element's vertices and coefficients.
    pub fn terms(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.idx[..self.len as usize]
            .iter()
            .zip(&self.coef[..self.len as usize])
            .map(|(&i, &c)| (i as usize, c))
    }

    /// `sum_j c_j a_j`.
    pub fn combine(&self, a: &[Vec3]) -> Vec3 {
        self.terms().fold(Vec3::zeros(), |s, (i, c)| s + c * a[i])
    }

    /// Normal speed of approach (> 0 approaching) of the combination with velocities `v`.
    pub fn approach(&self, v: &[Vec3]) -> f64 {
        (-(self.combine(v) - self.surface_velocity).dot(&self.dir)).max(0.0)
    }

    /// The penalty's magnitude `F` with velocities `v`, stiffness `k`, damping `c`.
    pub fn magnitude(&self, k: f64, c: f64, v: &[Vec3]) -> f64 {
        self.scale * (k * self.depth + c * self.approach(v))
    }

    /// `sum_j c_j^2`.
    pub fn coef2(&self) -> f64 {
        self.coef[..self.len as usize].iter().map(|c| c * c).sum()
    }
}

/// Sets every contact's [`Contact::scale`] to `w_dry / w_wet`: `w_wet = sum_j c_j^2 n.M_j^{-1} n`
/// over the free vertices, `inverse(j, n)` giving `M_j^{-1} n` with the water the particle
/// carries along its normal, and `w_dry` the same with `dry(j)`, the inverse of its mass
/// without that water. The combination then accelerates along `n` as a cloth without the
/// normal added mass would: the water's inertia neither softens a contact (a cloth carrying
/// 8 kg/m^2 of water along its normal against its own 1 kg/m^2 was pressed through a moving
/// pin row or collider nine times deeper for the same penalty) nor, since the scale is the
/// inertia's own ratio, makes it launch anything faster than a dry cloth. 1 where no vertex is
/// free, and exactly 1 (the same bits) without normal added mass.
pub fn inertia_scale(
    contacts: &mut [Contact],
    pinned: &[bool],
    inverse: impl Fn(usize, Vec3) -> Vec3,
    dry: impl Fn(usize) -> f64,
) {
    for e in contacts {
        let (mut wet, mut plain) = (0.0, 0.0);
        for (i, c) in e.terms().filter(|&(i, _)| !pinned[i]) {
            wet += c * c * e.dir.dot(&inverse(i, e.dir));
            plain += c * c * dry(i);
        }
        e.scale = if wet > 0.0 && plain > 0.0 {
            plain / wet
        } else {
            1.0
        };
    }
}

/// Adds every contact's force to `f` (velocities `v`, stiffness `k`, damping `c`).
pub fn add_forces(contacts: &[Contact], k: f64, c: f64, v: &[Vec3], f: &mut [Vec3]) {
    for e in contacts {
        let push = e.magnitude(k, c, v) * e.dir;
        for (i, cj) in e.terms() {
            f[i] += cj * push;
        }
    }
}

/// Coulomb friction after a step of size `h`: each contact's tangential relative velocity
/// shrinks by at most `mu h F / m` (m the mass of its first vertex, F its normal force at the
/// start of the step) and never reverses, spread over its vertices in proportion to their
/// coefficients (the combination's change is exactly that). Pinned vertices are not changed.
#[allow(clippy::too_many_arguments)] // one pass over the step's arrays
pub fn apply_friction(
    contacts: &[Contact],
    k: f64,
    c: f64,
    h: f64,
    v_start: &[Vec3],
    masses: &[f64],
    pinned: &[bool],
    v_new: &mut [Vec3],
) -> bool {
    let mut any = false;
    for e in contacts.iter().filter(|e| e.friction > 0.0) {
        let rel = e.combine(v_new) - e.surface_velocity;
        let vt = rel - rel.dot(&e.dir) * e.dir;
        let speed = vt.norm();
        let m = masses[e.idx[0] as usize];
        if !(speed > 0.0 && m > 0.0) {
            continue;
        }
        let dv = (e.friction * h * e.magnitude(k, c, v_start) / m).min(speed);
        let scale = dv / (speed * e.coef2());
        for (i, cj) in e.terms() {
            if !pinned[i] {
                v_new[i] -= (cj * scale) * vt;
            }
        }
        any = true;
    }
    any
}

/// Each contact's weight in the implicit system, `h c_e + h^2 k`, `c_e` the damping while
/// approaching (at velocities `v`), into `out` (once a solve; the product reads it every
/// iteration).
pub fn system_weights(contacts: &[Contact], k: f64, c: f64, h: f64, v: &[Vec3], out: &mut Vec<f64>) {
    out.clear();
    out.extend(contacts.iter().map(|e| {
        let damping = if e.approach(v) > 0.0 { c } else { 0.0 };
        e.scale * (h * damping + h * h * k)
    }));
}

/// The contacts' part of the implicit system `A p`: `w_e c_j (n . sum_l c_l p_l) n` added to
/// `out[j]`, `w_e` from [`system_weights`].
pub fn add_system_product(contacts: &[Contact], weights: &[f64], p: &[Vec3], out: &mut [Vec3]) {
    for (e, &w) in contacts.iter().zip(weights) {
        let s = w * e.dir.dot(&e.combine(p));
        for (i, cj) in e.terms() {
            out[i] += (cj * s) * e.dir;
        }
    }
}

/// The contacts' diagonal blocks `w_e c_j^2 n n^T`, added to `blocks[j]`.
pub fn add_system_diagonal(contacts: &[Contact], weights: &[f64], blocks: &mut [nalgebra::Matrix3<f64>]) {
    for (e, &w) in contacts.iter().zip(weights) {
        let nn = e.dir * e.dir.transpose() * w;
        for (i, cj) in e.terms() {
            blocks[i] += cj * cj * nn;
        }
    }
}

/// The contacts' part of the implicit right-hand side, `-h^2 K v`: `-h^2 k c_j (n . sum c_l v_l) n`.
pub fn add_rhs(contacts: &[Contact], k: f64, h: f64, v: &[Vec3], rhs: &mut [Vec3]) {
    for e in contacts {
        let s = -h * h * k * e.scale * e.dir.dot(&e.combine(v));
        for (i, cj) in e.terms() {
            rhs[i] += (cj * s) * e.dir;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair() -> Contact {
        Contact {
            idx: [0, 1, 2, 3],
            coef: [1.0, -0.2, -0.5, -0.3],
            len: 4,
            dir: Vec3::new(0.0, 0.6, 0.8),
            depth: 0.004,
            surface_velocity: Vec3::zeros(),
            friction: 0.0,
            scale: 1.0,
        }
    }

    /// The element's force is the negative gradient of `k/2 (depth)^2` with
    /// `depth = d0 - n . u(x)`: a central difference of the energy matches `add_forces`, and
    /// the forces sum to zero (momentum) for a pair whose coefficients sum to zero.
    #[test]
    fn force_is_the_gradient_of_the_penalty_and_conserves_momentum() {
        let e = pair();
        let k = 50.0;
        let x: Vec<Vec3> = (0..4)
            .map(|i| Vec3::new(0.1 * i as f64, 0.02, -0.01 * i as f64))
            .collect();
        let v = vec![Vec3::zeros(); 4];
        let u0 = e.combine(&x);
        let energy = |x: &[Vec3]| {
            let depth = e.depth - e.dir.dot(&(e.combine(x) - u0));
            0.5 * k * depth * depth
        };
        let mut f = vec![Vec3::zeros(); 4];
        add_forces(&[e], k, 0.0, &v, &mut f);
        let eps = 1e-7;
        for i in 0..4 {
            for a in 0..3 {
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[i][a] += eps;
                xm[i][a] -= eps;
                let g = -(energy(&xp) - energy(&xm)) / (2.0 * eps);
                assert!((g - f[i][a]).abs() < 1e-6, "{i} {a}: {g} vs {}", f[i][a]);
            }
        }
        let total: Vec3 = f.iter().sum();
        assert!(total.norm() < 1e-14);
    }

    /// The system product is the Jacobian: `A p` of the contacts equals
    /// `-(h^2) d f/dx . p` by a central difference (no damping while separating).
    #[test]
    fn system_product_is_the_stiffness_jacobian() {
        let e = pair();
        let (k, h) = (50.0, 1e-3);
        let v = vec![Vec3::zeros(); 4];
        let p: Vec<Vec3> = (0..4).map(|i| Vec3::new(0.3, -0.1 * i as f64, 0.7)).collect();
        let mut out = vec![Vec3::zeros(); 4];
        let mut weights = Vec::new();
        system_weights(&[e], k, 0.0, h, &v, &mut weights);
        add_system_product(&[e], &weights, &p, &mut out);
        // f(x + eps p) - f(x - eps p): depth changes by -/+ eps n . u(p).
        let force_at = |s: f64| {
            let mut moved = e;
            moved.depth = e.depth - s * e.dir.dot(&e.combine(&p));
            let mut f = vec![Vec3::zeros(); 4];
            add_forces(&[moved], k, 0.0, &v, &mut f);
            f
        };
        let (fp, fm) = (force_at(1e-6), force_at(-1e-6));
        for i in 0..4 {
            let jp = -(h * h) * (fp[i] - fm[i]) / 2e-6;
            assert!((jp - out[i]).norm() < 1e-12, "{i}");
        }
        let mut blocks = vec![nalgebra::Matrix3::zeros(); 4];
        add_system_diagonal(&[e], &weights, &mut blocks);
        let only0: Vec<Vec3> = (0..4)
            .map(|i| if i == 0 { p[0] } else { Vec3::zeros() })
            .collect();
        let mut out0 = vec![Vec3::zeros(); 4];
        add_system_product(&[e], &weights, &only0, &mut out0);
        assert!((blocks[0] * p[0] - out0[0]).norm() < 1e-15);
    }

    /// A contact along a particle's normal, where it carries water of `wet` times its own mass,
    /// pushes `1 + wet` times as hard (the same acceleration as a dry particle); one along the
    /// cloth (no water carried) as written; a pinned vertex takes no part.
    #[test]
    fn the_inertia_scale_gives_the_dry_cloths_acceleration_along_the_contact() {
        let (m, wet) = (2e-3, 8.0);
        let normal = Vec3::new(0.0, 0.6, 0.8);
        let inverse = |_: usize, n: Vec3| (n - (wet / (1.0 + wet)) * normal.dot(&n) * normal) / m;
        let mut along = pair();
        along.dir = normal;
        let mut across = pair();
        across.dir = Vec3::new(1.0, 0.0, 0.0);
        let mut contacts = [along, across];
        inertia_scale(&mut contacts, &[false; 4], inverse, |_| 1.0 / m);
        assert!(
            (contacts[0].scale - (1.0 + wet)).abs() < 1e-12,
            "{}",
            contacts[0].scale
        );
        assert!((contacts[1].scale - 1.0).abs() < 1e-12, "{}", contacts[1].scale);
        // The combination's acceleration along the normal under the scaled force equals the
        // dry one: F scale w_wet = F w_dry.
        let e = contacts[0];
        let w_wet: f64 = e
            .terms()
            .map(|(_, c)| c * c * e.dir.dot(&inverse(0, e.dir)))
            .sum();
        let w_dry: f64 = e.terms().map(|(_, c)| c * c / m).sum();
        assert!((e.scale * w_wet - w_dry).abs() < 1e-9 * w_dry);
        let mut all_pinned = [along];
        inertia_scale(&mut all_pinned, &[true; 4], inverse, |_| 1.0 / m);
        assert_eq!(all_pinned[0].scale, 1.0);
    }

    /// Friction takes the tangential relative speed down by at most mu h F / m, never past 0.
    #[test]
    fn friction_slows_the_tangential_slip_without_reversing_it() {
        let mut e = pair();
        e.friction = 0.5;
        let (k, h) = (50.0, 1e-3);
        let masses = [1e-3; 4];
        let pinned = [false; 4];
        let v0 = vec![Vec3::zeros(); 4];
        let mut v = vec![
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
        ];
        assert!(apply_friction(&[e], k, 0.0, h, &v0, &masses, &pinned, &mut v));
        let slip = e.combine(&v).x;
        let expect = 1.0 - 0.5 * h * k * e.depth / 1e-3;
        assert!((slip - expect).abs() < 1e-12, "{slip} vs {expect}");
        let mut slow = vec![
            Vec3::new(1e-6, 0.0, 0.0),
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
        ];
        apply_friction(&[e], k, 0.0, h, &v0, &masses, &pinned, &mut slow);
        assert!(e.combine(&slow).x.abs() < 1e-18);
    }
}
