//! Collision avoidance: a repulsive penalty force pushing particles out of colliders
//! (the paper's "standard collision avoidance repulsive force").
//!
//! With d the signed distance from the collider surface and margin δ, a particle with
//! d < δ receives `k_c (δ - d) n + c_c max(0, -(v - v_c) . n) n`, n the outward normal:
//! a spring pushing it out plus damping of the approach velocity only. v_c is the collider
//! surface's velocity (colliders move rigidly, without spin).
//!
//! Friction is not a force here: [`apply_friction`] corrects velocities after the step
//! (Coulomb, as an impulse: the tangential velocity relative to the collider shrinks by at
//! most μ times the normal velocity change the contact gave, and never reverses), which is
//! stable at any step size.

use crate::math::Vec3;
use crate::model::Model;

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

/// An infinite plane; the cloth is kept on the side the normal points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane, m.
    pub point: Vec3,
    /// Unit normal (normalised when the plane is set).
    pub normal: Vec3,
    /// Velocity of the plane, m/s.
    pub velocity: Vec3,
}

/// A capsule: the points within `radius` of the segment from `a` to `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// Segment ends, m.
    pub a: Vec3,
    pub b: Vec3,
    /// Radius, m (> 0).
    pub radius: f64,
    /// Velocity of the capsule, m/s.
    pub velocity: Vec3,
}

/// Any collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collider {
    Sphere(Sphere),
    Plane(Plane),
    Capsule(Capsule),
}

fn radial(r: Vec3) -> (f64, Vec3) {
    let len = r.norm();
    let n = if len > 0.0 { r / len } else { Vec3::y() };
    (len, n)
}

impl Collider {
    /// The same collider with its surface moved out by `delta` m (in by a negative one): a
    /// contact within margin `m` of it is a contact within `m + delta` of this one, with the
    /// same force. How a collider's own margin is made from the cloth's.
    pub fn grown(&self, delta: f64) -> Collider {
        match *self {
            Collider::Sphere(s) => Collider::Sphere(Sphere {
                radius: s.radius + delta,
                ..s
            }),
            Collider::Plane(p) => Collider::Plane(Plane {
                point: p.point + delta * p.normal,
                ..p
            }),
            Collider::Capsule(c) => Collider::Capsule(Capsule {
                radius: c.radius + delta,
                ..c
            }),
        }
    }

    /// Signed distance from the surface (negative inside), outward normal, surface velocity.
    pub fn probe(&self, p: &Vec3) -> (f64, Vec3, Vec3) {
        match self {
            Collider::Sphere(s) => {
                let (len, n) = radial(p - s.center);
                (len - s.radius, n, s.velocity)
            }
            Collider::Plane(pl) => ((p - pl.point).dot(&pl.normal), pl.normal, pl.velocity),
            Collider::Capsule(c) => {
                let ab = c.b - c.a;
                let len2 = ab.norm_squared();
                let t = if len2 > 0.0 {
                    ((p - c.a).dot(&ab) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (len, n) = radial(p - (c.a + t * ab));
                (len - c.radius, n, c.velocity)
            }
        }
    }
}

/// Adds the contact forces on a tile's particles (component arrays) to `f`, particle by
/// particle.
pub(super) fn add_tile(
    m: &Model,
    colliders: &[Collider],
    x: [&[f64]; 3],
    v: [&[f64]; 3],
    f: [&mut [f64]; 3],
) {
    let [fx, fy, fz] = f;
    let at = |a: [&[f64]; 3], k: usize| Vec3::new(a[0][k], a[1][k], a[2][k]);
    for k in 0..fx.len() {
        let mut g = Vec3::new(fx[k], fy[k], fz[k]);
        add(m, colliders, &at(x, k), &at(v, k), &mut g);
        (fx[k], fy[k], fz[k]) = (g.x, g.y, g.z);
    }
}

/// Adds the contact forces of every collider on a particle at `x` with velocity `v` to `f`.
#[inline]
fn add(m: &Model, colliders: &[Collider], x: &Vec3, v: &Vec3, f: &mut Vec3) {
    let (k, c, margin) = (m.collision_stiffness, m.collision_damping, m.collision_margin);
    for collider in colliders {
        let (d, n, vc) = collider.probe(x);
        if d < margin {
            let approach = (v - vc).dot(&n).min(0.0);
            *f += (k * (margin - d) - c * approach) * n;
        }
    }
}

/// Whether any collider has friction (else [`apply_friction`] changes nothing).
pub fn friction_active(colliders: &[Collider], friction: &[f64]) -> bool {
    colliders.iter().zip(friction).any(|(_, &mu)| mu != 0.0)
}

/// Coulomb friction as a velocity correction after a step of size `h`: for every particle in
/// contact with a collider of friction coefficient μ > 0 (at the start-of-step position `x`),
/// the tangential part of `v_new - v_c` shrinks by `min(|v_t|, μ h F_n / m)`, F_n the normal
/// penalty force. Free particles only (`pinned` false).
#[allow(clippy::too_many_arguments)] // one pass over the step's arrays; a struct would only rename them
pub fn apply_friction(
    m: &Model,
    colliders: &[Collider],
    friction: &[f64],
    h: f64,
    x: &[Vec3],
    masses: &[f64],
    pinned: &[bool],
    v_new: &mut [Vec3],
) {
    if !friction_active(colliders, friction) {
        return;
    }
    let (k, margin) = (m.collision_stiffness, m.collision_margin);
    crate::parallel::chunks(
        crate::parallel::worth_it(x.len()),
        v_new,
        crate::parallel::CHUNK,
        |first, chunk| {
            for (q, v) in chunk.iter_mut().enumerate() {
                let p = first + q;
                if pinned[p] {
                    continue;
                }
                for (collider, &mu) in colliders.iter().zip(friction) {
                    let (d, n, vc) = collider.probe(&x[p]);
                    if mu == 0.0 || d >= margin {
                        continue;
                    }
                    let rel = *v - vc;
                    let vt = rel - rel.dot(&n) * n;
                    let speed = vt.norm();
                    if speed > 0.0 {
                        let dv = (mu * h * k * (margin - d) / masses[p]).min(speed);
                        *v -= (dv / speed) * vt;
                    }
                }
            }
        },
    );
}
