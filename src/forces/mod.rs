//! Forces on the particles, one file per family (paper, section 4.1).
//!
//! [`accumulate`] sums every enabled term into a force buffer. A term whose
//! coefficient is zero is skipped entirely, so a scene pays only for what it uses.

mod body;
mod contact;
mod drag;
mod jacobian;
mod normals;
mod springs;

pub use body::body_force;
pub use contact::{Collider, Sphere};
pub use jacobian::{linearise, Linearisation};
pub use normals::vertex_normals;

use crate::model::Model;
use crate::topology::Topology;
use crate::Vec3;

/// Everything the forces read at one instant.
pub struct ForceInput<'a> {
    pub model: &'a Model,
    pub topology: &'a Topology,
    /// Positions, m.
    pub x: &'a [Vec3],
    /// Velocities, m/s.
    pub v: &'a [Vec3],
    /// D^{1/2}x of every particle (of the displacement relative to the water), m s^{-1/2};
    /// ignored when the model uses no fractional term.
    pub half_derivative: &'a [Vec3],
    /// Colliders present this step.
    pub colliders: &'a [Collider],
}

/// Scratch buffers the force evaluation reuses (no allocation in a step).
#[derive(Clone, Debug, Default)]
pub struct ForceScratch {
    normals: Vec<Vec3>,
}

impl ForceScratch {
    /// Vertex normals of the last evaluation (empty when no term needed them).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
}

/// Writes the total force on every particle into `f` (N).
pub fn accumulate(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    let m = input.model;
    body::add(input, f);
    drag::add_viscous(input, f);
    drag::add_history(input, f);
    if m.normal_drag != 0.0 {
        scratch.normals.resize(input.x.len(), Vec3::zeros());
        vertex_normals(input.x, &input.topology.triangles, &mut scratch.normals);
        drag::add_normal(input, &scratch.normals, f);
    }
    springs::add(input, f);
    contact::add(input, f);
}
