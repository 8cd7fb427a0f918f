//! Collision avoidance: a repulsive penalty force pushing particles out of colliders
//! (the paper's "standard collision avoidance repulsive force").
//!
//! With d the signed distance from the collider surface and margin δ, a particle with
//! d < δ receives `k_c (δ - d) n + c_c max(0, -(v - v_c) . n) n`, n the outward normal:
//! a spring pushing it out plus damping of the approach velocity only.

use crate::model::Model;
use crate::Vec3;

/// A sphere collider, moved by the host between steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre, m.
    pub center: Vec3,
    /// Radius, m (> 0).
    pub radius: f64,
    /// Velocity of the sphere, m/s (used by the contact damping).
    pub velocity: Vec3,
}

/// Any collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collider {
    Sphere(Sphere),
}

impl Collider {
    /// Signed distance from the surface (negative inside), outward normal, surface velocity.
    pub fn probe(&self, p: &Vec3) -> (f64, Vec3, Vec3) {
        match self {
            Collider::Sphere(s) => {
                let r = p - s.center;
                let len = r.norm();
                let n = if len > 0.0 { r / len } else { Vec3::y() };
                (len - s.radius, n, s.velocity)
            }
        }
    }
}

/// Adds the contact forces of every collider on a particle at `x` with velocity `v` to `f`.
#[inline]
pub(super) fn add(m: &Model, colliders: &[Collider], x: &Vec3, v: &Vec3, f: &mut Vec3) {
    let (k, c, margin) = (m.collision_stiffness, m.collision_damping, m.collision_margin);
    for collider in colliders {
        let (d, n, vc) = collider.probe(x);
        if d < margin {
            let approach = (v - vc).dot(&n).min(0.0);
            *f += (k * (margin - d) - c * approach) * n;
        }
    }
}
