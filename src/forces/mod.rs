//! Forces on the particles, one file per family (paper, section 4.1).
//!
//! [`accumulate`] sums every enabled term into a force buffer. A term whose
//! coefficient is zero is skipped entirely, so a scene pays only for what it uses.

mod assemble;
mod body;
mod contact;
mod drag;
mod inputs;
mod jacobian;
mod normals;
mod springs;
mod tiles;

pub use assemble::add_spring_values;
pub use body::{body_acceleration, body_force};
pub use contact::{apply_friction, friction_active, Capsule, Collider, Plane, Sphere};
pub use jacobian::{linearise, Linearisation, SpringBlock};
pub use normals::vertex_normals;
pub use springs::{spring_rate, SpringRate};

use crate::model::Model;
use crate::parallel;
use crate::soa::Soa3;
use crate::topology::Topology;
use crate::Vec3;
use assemble::TILE;

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
    windows: crate::aligned::AlignedF64,
}

impl ForceScratch {
    /// The component arrays the spring pass reads, positions and damping rate (see
    /// [`spring_rate`]), sized for `n` particles: for a caller that fills them in a pass of
    /// its own and then calls [`accumulate_filled`]. Needed only when [`tiled`] is false.
    pub fn spring_arrays(&mut self, n: usize) -> (&mut Soa3, &mut Soa3) {
        let s = &mut self.spring_inputs;
        s.x.resize(n);
        s.q.resize(n);
        (&mut s.x, &mut s.q)
    }

    /// Vertex normals of the last evaluation (empty when no term needed them).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
}

/// Whether the spring pass of `t` walks tiles ([`tiles`]), reading its positions and rates
/// from windows of its own: then it never reads [`ForceScratch::spring_arrays`].
pub fn tiled(t: &Topology) -> bool {
    tiles::Layout::of(t).is_some()
}

/// Writes the total force on every particle into `f` (N).
///
/// Per particle: its springs (in the order of [`assemble::add_spring_forces`]), then net
/// weight, drags and contacts are added to that sum. Springs and face normals are evaluated
/// once each into scratch buffers, then every particle gathers, tile by tile; chunks of
/// particles run on rayon's pool when the cloth is large ([`parallel::worth_it`]) and the
/// result does not depend on the thread count.
pub fn accumulate(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    accumulate_with(input, scratch, f, false)
}

/// As [`accumulate`], with the spring pass's component arrays already filled by the caller
/// ([`ForceScratch::spring_arrays`]: positions `input.x`, and the damping rate `input.v` or
/// `input.half_derivative` as [`spring_rate`] says).
pub fn accumulate_filled(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    accumulate_with(input, scratch, f, true)
}

fn accumulate_with(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3], filled: bool) {
    let out = parallel::Disjoint::new(f);
    for_each_tile(input, scratch, filled, |p0, forces| {
        // SAFETY: tiles are disjoint, each is handed to this closure once.
        unsafe { out.range(p0..p0 + forces.len()) }.copy_from_slice(forces);
    });
}

/// Evaluates the total force on every particle, tile by tile, and calls `sink(p0, forces)`
/// once per tile with the forces (N) on particles `p0 .. p0 + forces.len()` (at most 256 of
/// them, all in one [`parallel::CHUNK`]) while they are still in L1 cache: a
/// caller can use them there (an explicit integrator does) instead of reading a force array
/// back from memory. The spring pass's component arrays must be filled, as for
/// [`accumulate_filled`]. Tiles of different chunks may be handed over on different threads,
/// in any order; the forces do not depend on the thread count.
pub fn accumulate_tiles<S>(input: &ForceInput<'_>, scratch: &mut ForceScratch, sink: S)
where
    S: Fn(usize, &mut [Vec3]) + Sync,
{
    for_each_tile(input, scratch, true, sink)
}

fn for_each_tile<S>(input: &ForceInput<'_>, scratch: &mut ForceScratch, filled: bool, sink: S)
where
    S: Fn(usize, &mut [Vec3]) + Sync,
{
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
    let normals = with_normals.then_some(&scratch.normals[..]);
    let gravity = body_acceleration(m);
    let half = (!input.half_derivative.is_empty()).then_some(input.half_derivative);
    // Everything but the springs, added to the springs' sums `s` of the tile starting at p0;
    // then the tile goes to the sink.
    let finish = |p0: usize, s: [&[f64]; 3], out: &mut [Vec3]| {
        let len = out.len();
        body::add_weight_to_springs_widest(s, &t.masses[p0..p0 + len], gravity, out);
        let range = p0..p0 + len;
        drag::add_tile(
            m,
            &input.v[range.clone()],
            half.map(|h| &h[range.clone()]),
            normals.map(|nr| &nr[range.clone()]),
            out,
        );
        if !input.colliders.is_empty() {
            for (k, fi) in out.iter_mut().enumerate() {
                let p = p0 + k;
                contact::add(m, input.colliders, &input.x[p], &input.v[p], fi);
            }
        }
        sink(p0, out);
    };
    let layout = tiles::Layout::of(t);
    let params = springs::params(
        input,
        par,
        &mut scratch.spring_inputs,
        !filled && layout.is_none(),
    );
    if let Some(layout) = layout {
        // One window per task; task k walks groups k, k + tasks, ... (which task walks a group
        // does not change its sums).
        let groups = n.div_ceil(layout.group);
        let tasks = if par {
            groups.min(2 * rayon::current_num_threads())
        } else {
            1
        };
        let w = layout.scratch();
        scratch.windows.resize(w * tasks);
        parallel::chunks(par, &mut scratch.windows[..w * tasks], w, |first, window| {
            let mut buf = [Vec3::zeros(); TILE];
            let (sums, inputs) = window.split_at_mut(layout.sums_scratch());
            let rate = springs::rate(input);
            for g in (first / w..groups).step_by(tasks) {
                let c0 = g * layout.group;
                let len = layout.group.min(n - c0);
                let finish = |p0: usize, sums: [&[f64]; 3]| finish(p0, sums, &mut buf[..sums[0].len()]);
                let start = c0.saturating_sub(t.tile_runs.max_offset);
                let mut inputs = inputs::InputWindow::new(input.x, rate, inputs, start);
                if layout.gather_runs > 0 {
                    tiles::spring_forces_gathered(&params, t, &layout, c0, len, sums, &mut inputs, finish);
                } else {
                    tiles::spring_forces(&params, t, c0, len, sums, &mut inputs, finish);
                }
            }
        });
    } else {
        springs::compute(&params, &t.spring_runs, par, &mut scratch.springs);
        let spring_force = scratch.springs.slices();
        parallel::for_chunks(par, n, parallel::CHUNK, |first, len| {
            let mut acc = [[0.0; TILE]; 3];
            let mut buf = [Vec3::zeros(); TILE];
            for p0 in (first..first + len).step_by(TILE) {
                let m = TILE.min(first + len - p0);
                assemble::add_spring_forces(t, p0, m, spring_force, &mut acc);
                finish(p0, [&acc[0], &acc[1], &acc[2]], &mut buf[..m]);
            }
        });
    }
}
