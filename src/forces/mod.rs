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
mod tiles;

pub use assemble::add_spring_values;
pub use body::{body_acceleration, body_force};
pub use contact::{apply_friction, Capsule, Collider, Plane, Sphere};
pub use jacobian::{linearise, Linearisation};
pub use normals::vertex_normals;

use crate::model::Model;
use crate::parallel;
use crate::soa::Soa3;
use crate::topology::Topology;
use crate::Vec3;
use assemble::TILE;

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
    springs: Soa3,
    spring_inputs: springs::SpringScratch,
    windows: Vec<f64>,
}

impl ForceScratch {
    /// Vertex normals of the last evaluation (empty when no term needed them).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
}

/// Writes the total force on every particle into `f` (N).
///
/// Per particle: its springs (in the order of [`assemble::add_spring_forces`]), then net
/// weight, drags and contacts are added to that sum. Springs and face normals are evaluated
/// once each into scratch buffers, then every particle gathers, tile by tile; chunks of
/// particles run on rayon's pool when the cloth is large ([`parallel::worth_it`]) and the
/// result does not depend on the thread count.
pub fn accumulate(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    let m = input.model;
    let t = input.topology;
    let n = input.x.len();
    let par = parallel::worth_it(n);
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
    let normals = &scratch.normals;
    let gravity = body_acceleration(m);
    let half = (!input.half_derivative.is_empty()).then_some(input.half_derivative);
    // Everything but the springs, added to their sum `s` for particle p.
    let others = |p: usize, s: [f64; 3]| {
        let mut total = Vec3::new(s[0], s[1], s[2]) + t.masses[p] * gravity;
        let d = half.map_or(&ZERO, |h| &h[p]);
        drag::add(m, &input.v[p], d, with_normals.then(|| &normals[p]), &mut total);
        if !input.colliders.is_empty() {
            contact::add(m, input.colliders, &input.x[p], &input.v[p], &mut total);
        }
        total
    };
    let params = springs::params(input, par, &mut scratch.spring_inputs);
    if let Some(w) = tiles::window(t) {
        scratch.windows.resize(3 * w * n.div_ceil(parallel::CHUNK), 0.0);
        parallel::chunks2(
            par,
            (&mut scratch.windows, 3 * w),
            (f, parallel::CHUNK),
            1,
            |chunk, window, out| {
                let c0 = chunk * parallel::CHUNK;
                tiles::spring_forces(&params, t, c0, out.len(), window, |p0, [x, y, z]| {
                    for (k, fi) in out[p0 - c0..p0 - c0 + x.len()].iter_mut().enumerate() {
                        *fi = others(p0 + k, [x[k], y[k], z[k]]);
                    }
                });
            },
        );
    } else {
        springs::compute(&params, &t.spring_runs, par, &mut scratch.springs);
        let spring_force = scratch.springs.slices();
        parallel::chunks(par, f, parallel::CHUNK, |first, chunk| {
            let mut acc = [[0.0; TILE]; 3];
            for (tile, out) in chunk.chunks_mut(TILE).enumerate() {
                let p0 = first + tile * TILE;
                assemble::add_spring_forces(t, p0, out.len(), spring_force, &mut acc);
                for (k, fi) in out.iter_mut().enumerate() {
                    *fi = others(p0 + k, [acc[0][k], acc[1][k], acc[2][k]]);
                }
            }
        });
    }
}
