//! The per-particle force terms, each written once, on a tile's component arrays.
//!
//! Every step route hands the same [`Tile`] to the same list, [`TERMS`]: the spring sums of a
//! tile arrive as component arrays and each term that is on adds its force to them, in the
//! order of the list (the order is part of the result's bits). A term declares what it reads
//! ([`Reads`]) so that the step keeps exactly that (a term that is off costs nothing), and gives
//! its block of the Jacobian for the implicit integrator.
//!
//! Adding a per-particle term: write its `add` (and `linearise` if it depends on velocity or
//! position), put a [`Term`] in [`TERMS`], and wire its coefficient (model field, description
//! field, header, bindings).

use nalgebra::Matrix3;

use super::body::add_weight_widest;
use super::contact;
use super::drag;
pub use super::drag::per_particle;
use super::Collider;
use crate::math::Vec3;
use crate::model::Model;

/// A tile of consecutive particles `p0 ..` as the terms read it: component arrays of one
/// length, `[x, y, z]`.
pub struct Tile<'b> {
    /// Positions, m.
    pub x: [&'b [f64]; 3],
    /// Velocities of the step, m/s.
    pub v: [&'b [f64]; 3],
    /// D^{1/2}x of the displacement relative to the water, m s^{-1/2}, when a term reads it.
    pub half: Option<[&'b [f64]; 3]>,
    /// Unit vertex normals of the tile's particles, when a term reads them.
    pub normals: Option<&'b [Vec3]>,
    /// Masses, kg.
    pub masses: &'b [f64],
    /// Lumped areas, m^2 (what per-unit-area coefficients multiply).
    pub areas: &'b [f64],
    /// The running mean of the relative velocity the unsteady skin drag acts against, m/s
    /// (None when the model has none).
    pub skin_mean: Option<&'b [Vec3]>,
}

/// What the terms read at one step besides a tile.
pub struct Context<'a> {
    pub model: &'a Model,
    /// Net weight in water per kilogram, m/s^2.
    pub gravity: Vec3,
    pub colliders: &'a [Collider],
}

/// What a term reads besides positions and masses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Reads {
    pub velocity: bool,
    pub half_derivative: bool,
    pub normals: bool,
}

impl Reads {
    const NONE: Reads = Reads {
        velocity: false,
        half_derivative: false,
        normals: false,
    };
    const VELOCITY: Reads = Reads {
        velocity: true,
        half_derivative: false,
        normals: false,
    };
    const NORMALS: Reads = Reads {
        velocity: true,
        half_derivative: false,
        normals: true,
    };

    fn or(self, o: Reads) -> Reads {
        Reads {
            velocity: self.velocity || o.velocity,
            half_derivative: self.half_derivative || o.half_derivative,
            normals: self.normals || o.normals,
        }
    }
}

/// One particle as the Jacobian blocks read it.
pub struct Particle<'a> {
    pub x: &'a Vec3,
    pub v: &'a Vec3,
    /// Unit normal (zero when no term reads normals).
    pub normal: &'a Vec3,
    /// Current-velocity weight of D^{1/2} over the step.
    pub w0: f64,
    /// Lumped area, m^2.
    pub area: f64,
}

/// Blocks of `-df/dv` (damping) and `-df/dx` (stiffness) of one particle.
pub struct Blocks {
    pub damping: Matrix3<f64>,
    pub stiffness: Matrix3<f64>,
}

/// A per-particle force term.
pub struct Term {
    /// What it is, for people reading the list (and the tests' messages).
    #[cfg_attr(not(test), allow(dead_code))]
    pub name: &'static str,
    /// Whether the term is on for this model (with or without colliders present). What it
    /// reads is then kept for it: [`Reads::half_derivative`] alone decides whether the cloth
    /// keeps a history (`memories.rs`).
    pub on: fn(&Model, bool) -> bool,
    pub reads: Reads,
    /// Adds the term's forces (N) on the tile's particles to `f`.
    pub add: fn(&Context<'_>, &Tile<'_>, [&mut [f64]; 3]),
    /// Adds its blocks for the implicit integrator (None: it depends on neither x nor v).
    pub linearise: Option<fn(&Context<'_>, &Particle<'_>, &mut Blocks)>,
    /// The largest damping rate (N s/m) it gives a particle of `area` (m^2) moving at `speed`
    /// (m/s) relative to the water, `w0` the half-derivative's current weight: what it asks of
    /// an explicit step (`cloth/auto_step.rs`). Contacts say 0: the automatic step weighs them
    /// by where the colliders touch.
    pub rate: fn(m: &Model, area: f64, speed: f64, w0: f64) -> f64,
    /// Whether it acts along the normal alone (so on the water carried there too, which the
    /// XPBD route's bound reads).
    pub along_normal: bool,
}

/// Every per-particle term, in the order it is added.
pub const TERMS: [Term; 7] = [
    WEIGHT,
    VISCOUS_DRAG,
    HISTORY_DRAG,
    NORMAL_DRAG,
    FORM_DRAG,
    SKIN_DRAG,
    CONTACTS,
];

/// Net weight in water, Eq. 2.
const WEIGHT: Term = Term {
    name: "weight and buoyancy",
    on: |_, _| true,
    reads: Reads::NONE,
    add: |c, t, f| add_weight_widest(f, t.masses, c.gravity),
    linearise: None,
    rate: |_, _, _, _| 0.0,
    along_normal: false,
};

/// Viscous drag on the velocity relative to the water, Eq. 3.
const VISCOUS_DRAG: Term = Term {
    name: "viscous drag",
    on: |m, _| m.viscous_drag != 0.0 || m.water.viscous_drag != 0.0,
    reads: Reads::VELOCITY,
    add: |c, t, f| drag::add_viscous(c.model, t.v, t.areas, f),
    linearise: Some(|c, p, b| {
        let m = c.model;
        b.damping += per_particle(m.viscous_drag, m.water.viscous_drag, p.area) * Matrix3::identity()
    }),
    rate: |m, area, _, _| per_particle(m.viscous_drag, m.water.viscous_drag, area),
    along_normal: false,
};

/// History (Basset) drag, Eq. 4.
const HISTORY_DRAG: Term = Term {
    name: "history drag",
    on: |m, _| m.history_drag != 0.0 || m.water.history_drag != 0.0,
    reads: Reads {
        velocity: true,
        half_derivative: true,
        normals: false,
    },
    add: |c, t, f| {
        if let Some(d) = t.half {
            drag::add_history(c.model, t.v, d, t.areas, f);
        }
    },
    linearise: Some(|c, p, b| {
        let m = c.model;
        let rel = p.v - m.current;
        let speed = rel.norm();
        if speed > 0.0 {
            let u = rel / speed;
            let k = per_particle(m.history_drag, m.water.history_drag, p.area);
            b.damping += k * p.w0 * (u * u.transpose());
        }
    }),
    rate: |m, area, _, w0| w0 * per_particle(m.history_drag, m.water.history_drag, area),
    along_normal: false,
};

/// Drag on the normal velocity (the paper's regular models, Fig. 7).
const NORMAL_DRAG: Term = Term {
    name: "normal drag",
    on: |m, _| m.normal_drag != 0.0 || m.water.normal_drag != 0.0,
    reads: Reads::NORMALS,
    add: |c, t, f| {
        if let Some(n) = t.normals {
            drag::add_normal(c.model, t.v, n, t.areas, f);
        }
    },
    linearise: Some(|c, p, b| {
        let m = c.model;
        b.damping +=
            per_particle(m.normal_drag, m.water.normal_drag, p.area) * (p.normal * p.normal.transpose())
    }),
    rate: |m, area, _, _| per_particle(m.normal_drag, m.water.normal_drag, area),
    along_normal: true,
};

/// Form drag on the velocity normal to the cloth relative to the water, quadratic:
/// `-1/2 rho_w C_d A |v_n| v_n n` (it dominates at a swung towel's Reynolds numbers, 1e3-1e4).
const FORM_DRAG: Term = Term {
    name: "form drag",
    on: |m, _| m.water.form_drag != 0.0,
    reads: Reads::NORMALS,
    add: |c, t, f| {
        // With a length the drag is the whole-cloth pass's (`wide_drag.rs`); this block of the
        // Jacobian stays, the local drag's, an upper bound of the smoothed one's.
        if super::wide_drag::wide(c.model) {
            return;
        }
        if let Some(n) = t.normals {
            drag::add_form(c.model, t.v, n, t.areas, f);
        }
    },
    linearise: Some(|c, p, b| {
        // d/dv of -1/2 rho C A |v_n| v_n n is -rho C A |v_n| n n^T.
        let m = c.model;
        let vn = (p.v - m.current).dot(p.normal);
        let k = m.water_density * m.water.form_drag * p.area * vn.abs();
        b.damping += k * (p.normal * p.normal.transpose());
    }),
    rate: |m, area, speed, _| m.water_density * m.water.form_drag * area * speed,
    along_normal: true,
};

/// Skin drag on the velocity along the cloth relative to the water, linear.
const SKIN_DRAG: Term = Term {
    name: "skin drag",
    on: |m, _| m.water.skin_drag != 0.0 || m.water.skin_drag_unsteady != 0.0,
    reads: Reads::NORMALS,
    add: |c, t, f| {
        if let Some(n) = t.normals {
            drag::add_skin(c.model, t.v, n, t.areas, t.skin_mean, f);
        }
    },
    linearise: Some(|c, p, b| {
        // The running mean is held over the step: the velocity's own coefficient.
        let w = &c.model.water;
        let k = (w.skin_drag + w.skin_drag_unsteady) * p.area;
        b.damping += k * (Matrix3::identity() - p.normal * p.normal.transpose());
    }),
    rate: |m, area, _, _| (m.water.skin_drag + m.water.skin_drag_unsteady) * area,
    along_normal: false,
};

/// Penalty contacts with the colliders.
const CONTACTS: Term = Term {
    name: "contacts",
    on: |_, colliders| colliders,
    reads: Reads::VELOCITY,
    add: |c, t, f| contact::add_tile(c.model, c.colliders, t.x, t.v, f),
    linearise: Some(|c, p, b| {
        let m = c.model;
        for collider in c.colliders {
            let (dist, nrm, vc) = Collider::probe(collider, p.x);
            if dist < m.collision_margin {
                b.stiffness += m.collision_stiffness * (nrm * nrm.transpose());
                if (p.v - vc).dot(&nrm) < 0.0 {
                    b.damping += m.collision_damping * (nrm * nrm.transpose());
                }
            }
        }
    }),
    rate: |_, _, _, _| 0.0,
    along_normal: false,
};

/// What the terms that are on read, together (the added mass, an inertia rather than a
/// force, reads the normals too).
pub fn reads(m: &Model, colliders: bool) -> Reads {
    let mass = Reads {
        normals: super::carries_water(m),
        ..Reads::NONE
    };
    TERMS
        .iter()
        .filter(|t| (t.on)(m, colliders))
        .fold(mass, |r, t| r.or(t.reads))
}

/// Adds every term that is on to a tile's spring sums `f`.
#[inline]
pub fn add_all(c: &Context<'_>, tile: &Tile<'_>, f: [&mut [f64]; 3]) {
    let [fx, fy, fz] = f;
    let has_colliders = !c.colliders.is_empty();
    for term in &TERMS {
        if (term.on)(c.model, has_colliders) {
            (term.add)(c, tile, [&mut *fx, &mut *fy, &mut *fz]);
        }
    }
}

/// Every term's blocks for one particle, summed in the order of [`TERMS`].
pub fn linearise_all(c: &Context<'_>, p: &Particle<'_>) -> Blocks {
    let mut b = Blocks {
        damping: Matrix3::zeros(),
        stiffness: Matrix3::zeros(),
    };
    let has_colliders = !c.colliders.is_empty();
    for term in &TERMS {
        if let (Some(lin), true) = (term.linearise, (term.on)(c.model, has_colliders)) {
            lin(c, p, &mut b);
        }
    }
    b
}

#[cfg(test)]
mod tests {
    //! Each term's Jacobian block against a central difference of its force.
    use super::*;
    use crate::forces::Plane;
    use crate::model::RegularDrag;

    /// One particle as a tile: its force from `add` at position `x`, velocity `v` and
    /// D^{1/2}x = `w0 v + past`.
    fn force(c: &Context<'_>, term: &Term, x: Vec3, v: Vec3, w0: f64, past: Vec3, n: Vec3) -> Vec3 {
        let half = w0 * v + past;
        let (xs, vs, hs) = (
            [[x.x], [x.y], [x.z]],
            [[v.x], [v.y], [v.z]],
            [[half.x], [half.y], [half.z]],
        );
        let normals = [n];
        let tile = Tile {
            x: [&xs[0], &xs[1], &xs[2]],
            v: [&vs[0], &vs[1], &vs[2]],
            half: Some([&hs[0], &hs[1], &hs[2]]),
            normals: Some(&normals),
            masses: &[2e-4],
            areas: &[1.5e-4],
            // The unsteady skin drag's running mean, held over the step.
            skin_mean: Some(&[Vec3::new(0.04, -0.01, 0.02)]),
        };
        let mut f = [[0.0], [0.0], [0.0]];
        let [a, b, d] = &mut f;
        (term.add)(c, &tile, [a, b, d]);
        Vec3::new(f[0][0], f[1][0], f[2][0])
    }

    /// `-df/du` at u = 0 by central differences, `f(u)` the force with the position or the
    /// velocity shifted by u.
    fn minus_jacobian(f: impl Fn(Vec3) -> Vec3) -> Matrix3<f64> {
        let mut j = Matrix3::zeros();
        for a in 0..3 {
            let e = 1e-7 * Vec3::ith(a, 1.0);
            j.set_column(a, &(-(f(e) - f(-e)) / 2e-7));
        }
        j
    }

    /// A model with every drag coefficient on, and a current.
    fn every_coefficient_on() -> Model {
        let mut m = Model::regular(RegularDrag::ViscousAndNormal);
        m.history_drag = 2e-3;
        m.water.viscous_drag = 3.0;
        m.water.history_drag = 4.0;
        m.water.normal_drag = 5.0;
        m.water.form_drag = 1.2;
        m.water.skin_drag = 0.7;
        m.water.skin_drag_unsteady = 0.9;
        m.water.skin_drag_memory = 1.0;
        m.current = Vec3::new(0.05, -0.02, 0.01);
        m
    }

    #[test]
    fn every_terms_blocks_match_a_central_difference_of_its_force() {
        // Every coefficient on, a current, and a plane the particle is inside the margin of.
        let m = every_coefficient_on();
        let plane = Collider::Plane(Plane {
            point: Vec3::new(0.0, -0.004, 0.0),
            normal: Vec3::new(0.1, 1.0, 0.2).normalize(),
            velocity: Vec3::new(0.0, 0.3, 0.0),
        });
        let colliders = [plane];
        let c = Context {
            model: &m,
            gravity: crate::forces::body_acceleration(&m),
            colliders: &colliders,
        };
        let x = Vec3::new(0.001, 0.0, 0.002);
        let v = Vec3::new(0.11, -0.23, 0.31);
        let n = Vec3::new(0.2, -0.3, 0.9).normalize();
        let w0 = 0.37;
        let mut checked = 0;
        for term in TERMS.iter().filter(|t| (t.on)(&m, true)) {
            let mut b = Blocks {
                damping: Matrix3::zeros(),
                stiffness: Matrix3::zeros(),
            };
            if let Some(lin) = term.linearise {
                let p = Particle {
                    x: &x,
                    v: &v,
                    normal: &n,
                    w0,
                    area: 1.5e-4,
                };
                lin(&c, &p, &mut b);
            }
            // The history drag reads D^{1/2}x = w0 v + H. Its block keeps the part along the
            // relative velocity and drops the part across it (which would make the system
            // non-symmetric): exact when the past H is zero and D^{1/2}x lies along the
            // velocity, and checked there along the velocity only.
            let history = term.reads.half_derivative;
            // With the current, D^{1/2}x (of the displacement relative to the water) is
            // w0 v_rel when the past is -w0 times the current.
            let past = if history {
                -w0 * m.current
            } else {
                Vec3::new(0.01, 0.02, -0.03)
            };
            let jv = minus_jacobian(|u| force(&c, term, x, v + u, w0, past, n));
            let jx = minus_jacobian(|u| force(&c, term, x + u, v, w0, past, n));
            let (jv, damping) = if history {
                let u = (v - m.current).normalize();
                let along = |a: &Matrix3<f64>| Matrix3::from_element((u.transpose() * a * u)[0]);
                (along(&jv), along(&b.damping))
            } else {
                (jv, b.damping)
            };
            let scale = jv.norm().max(damping.norm()).max(1e-12);
            assert!(
                (jv - damping).norm() < 1e-6 * scale,
                "{}: -df/dv\n{jv}\nagainst its damping block\n{damping}",
                term.name
            );
            let scale = jx.norm().max(b.stiffness.norm()).max(1e-12);
            assert!(
                (jx - b.stiffness).norm() < 1e-6 * scale,
                "{}: -df/dx\n{jx}\nagainst its stiffness block\n{}",
                term.name,
                b.stiffness
            );
            checked += 1;
        }
        // Weight, viscous, history, normal, form and skin drag and contacts: all on.
        assert_eq!(checked, TERMS.len());
    }

    /// Each term's rate (what the automatic step reads) is the largest eigenvalue of its
    /// damping block where the velocity relative to the water lies along the normal, and
    /// bounds it at any other velocity; contacts say 0 (the automatic step weighs them apart).
    #[test]
    fn every_terms_rate_is_its_damping_blocks_largest() {
        let m = every_coefficient_on();
        let c = Context {
            model: &m,
            gravity: crate::forces::body_acceleration(&m),
            colliders: &[],
        };
        let (x, n, w0, area) = (Vec3::zeros(), Vec3::new(0.2, -0.3, 0.9).normalize(), 0.37, 1.5e-4);
        let largest = |term: &Term, v: Vec3| {
            let mut b = Blocks {
                damping: Matrix3::zeros(),
                stiffness: Matrix3::zeros(),
            };
            let p = Particle {
                x: &x,
                v: &v,
                normal: &n,
                w0,
                area,
            };
            if let Some(lin) = term.linearise {
                lin(&c, &p, &mut b);
            }
            let sym = 0.5 * (b.damping + b.damping.transpose());
            sym.symmetric_eigen().eigenvalues.max()
        };
        let mut checked = 0;
        for term in TERMS.iter().filter(|t| t.name != "contacts") {
            let along = m.current + 0.3 * n;
            let speed = (along - m.current).norm();
            let rate = (term.rate)(&m, area, speed, w0);
            let want = largest(term, along);
            assert!(
                (rate - want).abs() <= 1e-12 * want.abs().max(1e-9),
                "{}: rate {rate} against {want}",
                term.name
            );
            let across = m.current + Vec3::new(0.11, -0.23, 0.31);
            let speed = (across - m.current).norm();
            let bound = (term.rate)(&m, area, speed, w0);
            assert!(
                bound >= largest(term, across) * (1.0 - 1e-12),
                "{}: {bound} below its block",
                term.name
            );
            checked += 1;
        }
        assert_eq!(checked, TERMS.len() - 1);
        let contacts = TERMS
            .iter()
            .find(|t| t.name == "contacts")
            .map(|t| (t.rate)(&m, area, 1.0, w0));
        assert_eq!(contacts, Some(0.0));
    }
}
