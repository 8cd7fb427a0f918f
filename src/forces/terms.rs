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
use super::Collider;
use crate::model::Model;
use crate::Vec3;

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
    /// What it is, for people reading the list.
    #[allow(dead_code)]
    pub name: &'static str,
    /// Whether the term is on for this model (with or without colliders present).
    pub on: fn(&Model, bool) -> bool,
    pub reads: Reads,
    /// Adds the term's forces (N) on the tile's particles to `f`.
    pub add: fn(&Context<'_>, &Tile<'_>, [&mut [f64]; 3]),
    /// Adds its blocks for the implicit integrator (None: it depends on neither x nor v).
    pub linearise: Option<fn(&Context<'_>, &Particle<'_>, &mut Blocks)>,
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
};

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
};

/// Form drag on the velocity normal to the cloth relative to the water, quadratic:
/// `-1/2 rho_w C_d A |v_n| v_n n` (it dominates at a swung towel's Reynolds numbers, 1e3-1e4).
const FORM_DRAG: Term = Term {
    name: "form drag",
    on: |m, _| m.water.form_drag != 0.0,
    reads: Reads::NORMALS,
    add: |c, t, f| {
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
};

/// Skin drag on the velocity along the cloth relative to the water, linear.
const SKIN_DRAG: Term = Term {
    name: "skin drag",
    on: |m, _| m.water.skin_drag != 0.0,
    reads: Reads::NORMALS,
    add: |c, t, f| {
        if let Some(n) = t.normals {
            drag::add_skin(c.model, t.v, n, t.areas, f);
        }
    },
    linearise: Some(|c, p, b| {
        let k = c.model.water.skin_drag * p.area;
        b.damping += k * (Matrix3::identity() - p.normal * p.normal.transpose());
    }),
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
