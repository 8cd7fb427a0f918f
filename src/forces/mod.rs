//! Forces on the particles, one file per family (paper, section 4.1).
//!
//! [`accumulate`] sums every enabled term into a force buffer. A term whose
//! coefficient is zero is skipped entirely, so a scene pays only for what it uses.

mod assemble;
mod body;
mod contact;
mod drag;
mod jacobian;
mod normals;
mod springs;

pub use assemble::add_spring_values;
pub use body::body_force;
pub use contact::{apply_friction, Capsule, Collider, Plane, Sphere};
pub use jacobian::{linearise, Linearisation};
pub use normals::vertex_normals;

use crate::model::Model;
use crate::parallel;
use crate::topology::Topology;
use crate::Vec3;

/// Stands in for D^{1/2}x when a cloth keeps no history (no term reads it then).
static ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);

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
    faces: Vec<Vec3>,
    springs: Vec<Vec3>,
}

impl ForceScratch {
    /// Vertex normals of the last evaluation (empty when no term needed them).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
}

/// Writes the total force on every particle into `f` (N).
///
/// Per particle, in this order: net weight, drags, its springs (in ascending spring order,
/// see [`add_spring_values`]), contacts. Springs and face normals are evaluated once each into scratch buffers, then
/// every particle gathers; chunks of particles run on rayon's pool when the cloth is large
/// ([`parallel::worth_it`]) and the result does not depend on the thread count.
pub fn accumulate(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    let m = input.model;
    let t = input.topology;
    let n = input.x.len();
    let par = parallel::worth_it(n);
    scratch.springs.resize(t.springs.len(), Vec3::zeros());
    springs::compute(input, par, &mut scratch.springs);
    let with_normals = m.normal_drag != 0.0;
    if with_normals {
        scratch.normals.resize(n, Vec3::zeros());
        scratch.faces.resize(t.triangles.len(), Vec3::zeros());
        normals::vertex_normals_with(
            input.x,
            &t.triangles,
            &t.vertex_triangles,
            par,
            &mut scratch.faces,
            &mut scratch.normals,
        );
    }
    let (spring_force, normals) = (&scratch.springs, &scratch.normals);
    parallel::chunks(par, f, parallel::CHUNK, |first, chunk| {
        for (k, fi) in chunk.iter_mut().enumerate() {
            let p = first + k;
            *fi = body_force(m, t.masses[p]);
            let d = input.half_derivative.get(p).unwrap_or(&ZERO);
            drag::add(m, &input.v[p], d, with_normals.then(|| &normals[p]), fi);
        }
        add_spring_values(t, first, spring_force, -1.0, chunk);
        if !input.colliders.is_empty() {
            for (k, fi) in chunk.iter_mut().enumerate() {
                let p = first + k;
                contact::add(m, input.colliders, &input.x[p], &input.v[p], fi);
            }
        }
    });
}
