//! The cloth's mesh colliders and self-collision: the host's calls, and the step's collision
//! pass, which turns both into [`Contact`] elements (their forces join the force pass, their
//! Jacobian blocks the implicit system, their friction the friction pass).

use super::plan::{StepLimit, StepPlan};
use super::Cloth;
use crate::bytes::{ByteReader, ByteWriter};
use crate::collide::impact_zones::{keep_from_passing, ZoneInput, ZoneTotals};
use crate::collide::mesh::{candidate_room, CANDIDATES_PER_VERTEX};
use crate::collide::room::Full;
use crate::collide::self_collision::Pair;
use crate::collide::{contact, Contact, MeshCollider};
use crate::error::Error;
use crate::math::Vec3;

/// How far (in collision margins) a mesh collider's candidates reach beyond the margin before
/// a cloth vertex looks again (`collide/mesh.rs`).
const MESH_SKIN_MARGINS: f64 = 0.5;
/// Deepest penetration a mesh contact pushes with, in margins: a vertex found deep inside a
/// closed mesh is pushed out at a bounded rate instead of being launched.
const MESH_MAX_DEPTH_MARGINS: f64 = 3.0;
/// Self-collision's step limit: no free vertex moves more than this fraction of the thickness
/// in one step (a faster one is slowed to it; `Cloth::limit_collision_step`).
pub const SELF_COLLISION_STEP_LIMIT: f64 = 0.5;
/// How near (in thicknesses) a vertex and a triangle, or two edges, must come at a coplanar
/// instant of a step for self-collision's continuous check to call it a passage.
pub const PASSAGE_TOLERANCE: f64 = 1e-3;
/// At most this many rounds of the mesh colliders' continuous check in a step.
pub const MESH_PASSAGE_ROUNDS: usize = 4;

impl Cloth {
    /// Adds a triangle-mesh collider (vertices in m, triangles as vertex indices, velocities
    /// in m/s or `None`: then from its motion between calls) and returns its id, shared with
    /// the other colliders (`set_collider_friction` and `remove_collider` take it).
    pub fn add_mesh_collider(
        &mut self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        velocities: Option<&[Vec3]>,
    ) -> Result<u32, Error> {
        let mesh = MeshCollider::new(positions, triangles, velocities)?;
        let id = self.free_collider_id();
        if id >= self.mesh_slots.len() {
            self.mesh_slots.resize_with(id + 1, || None);
        }
        self.mesh_slots[id] = Some(mesh);
        Ok(id as u32)
    }

    /// Moves (or deforms) mesh collider `id`: new positions of the same vertices, where it is
    /// at the end of the next step call (it travels there in a straight line over the call).
    pub fn set_mesh_collider(
        &mut self,
        id: u32,
        positions: &[Vec3],
        velocities: Option<&[Vec3]>,
    ) -> Result<(), Error> {
        match self.mesh_slots.get_mut(id as usize) {
            Some(Some(mesh)) => mesh.set(positions, velocities),
            _ => Err(Error::out_of_range(format!("no mesh collider with id {id}"))),
        }
    }

    /// Mesh collider `id`.
    pub fn mesh_collider(&self, id: u32) -> Option<&MeshCollider> {
        self.mesh_slots.get(id as usize).and_then(Option::as_ref)
    }

    /// The contacts of the last step's collision pass (mesh colliders and self-collision).
    pub fn contacts(&self) -> &[Contact] {
        &self.scratch.contacts
    }

    /// Self-collision's remembered pairs (vertex-triangle, edge-edge; each `(a, b, side)`).
    pub fn self_collision_pairs(&self) -> (&[Pair], &[Pair]) {
        self.self_collision.pairs()
    }

    /// What self-collision's impact zones did since the cloth was made (the step's fail-safe:
    /// `collide::impact_zones`), steps a refused call undid included.
    pub fn self_collision_zones(&self) -> ZoneTotals {
        self.self_collision.zones
    }

    /// Cloth vertices the mesh colliders carried since the cloth was made (each vertex counted
    /// once a step it was carried in): the continuous check's fail-safe against passing
    /// through a moving mesh. Steps a refused call undid are counted too.
    pub fn mesh_carried(&self) -> u64 {
        self.mesh_carried
    }

    /// How many times self-collision looked its pairs up again since the cloth was made.
    pub fn self_collision_looks(&self) -> u64 {
        self.self_collision.looks
    }

    /// How many of those looks tested no pair: the proof that the unfolded sheet keeps its
    /// distances covered every pair (`collide/unfolded.rs`).
    pub fn self_collision_proved_looks(&self) -> u64 {
        self.self_collision.certified_looks
    }

    /// The error of mesh collider `id` whose candidate lists were refused (`why`) at margin
    /// `margin` against a cloth of `vertices`.
    fn too_many_candidates(id: usize, mesh: &MeshCollider, margin: f64, vertices: usize, why: Full) -> Error {
        let (mean_edge, entries) = (mesh.mean_edge(), candidate_room(vertices));
        match why {
            Full::Memory => Error::out_of_memory(format!(
                "mesh collider {id}: the lists of its triangles near the cloth cannot be allocated; state left unchanged"
            )),
            Full::Entries => Error::invalid(format!(
                "mesh collider {id}: its margin of {margin} m reaches so many of its triangles from the cloth ({entries} entries, \
                 more than {CANDIDATES_PER_VERTEX} a cloth vertex) that the step would fill memory; its triangles' edges are \
                 {:.4} m long on average: give it a margin of a few of them at most (fc_cloth_set_collider_margin), or a coarser mesh; \
                 state left unchanged",
                mean_edge
            )),
        }
    }

    /// A mesh collider's margin (its own or the model's) and the skin its candidates reach
    /// beyond it.
    fn mesh_reach(model_margin: f64, mesh: &MeshCollider) -> (f64, f64) {
        let margin = mesh.margin.unwrap_or(model_margin);
        (margin, MESH_SKIN_MARGINS * margin)
    }

    /// Each vertex's contact weight for the automatic step, in units of `collision_stiffness`
    /// (and `collision_damping`), into `scratch.contact_weight` (left empty when nothing
    /// touches): Gershgorin's bound on the contacts' row of the stiffness matrix,
    /// `sum_e |c_j| sum_l |c_l|`, for the mesh colliders' contacts where the cloth and the meshes
    /// are as the call begins (a function of the state, so a resumed snapshot steps alike). A
    /// contact that begins within the call is not foreseen, nor are self-collision's (a
    /// crumpled cloth's many pairs would make the bound far smaller than the step it needs,
    /// measured): a frame they make unstable is retried with more substeps.
    pub(super) fn measure_contact_weights(&mut self) -> Result<(), Error> {
        let s = &mut self.scratch;
        s.contact_weight.clear();
        s.start_contacts.clear();
        let model_margin = self.config.model.collision_margin;
        for (id, slot) in self.mesh_slots.iter_mut().enumerate() {
            let Some(mesh) = slot else { continue };
            let (margin, skin) = Self::mesh_reach(model_margin, mesh);
            mesh.refresh(margin + skin)?;
            mesh.contacts(
                &self.state.x,
                &self.topology.triangles,
                0.0,
                margin,
                skin,
                MESH_MAX_DEPTH_MARGINS * margin,
                &mut s.start_contacts,
            )
            .map_err(|why| Self::too_many_candidates(id, mesh, margin, self.state.x.len(), why))?;
        }
        if s.start_contacts.is_empty() {
            return Ok(());
        }
        s.contact_weight.resize(self.state.x.len(), 0.0);
        for e in &s.start_contacts {
            let sum: f64 = e.terms().map(|(_, c)| c.abs()).sum();
            for (j, c) in e.terms() {
                if let Some(w) = s.contact_weight.get_mut(j) {
                    *w += c.abs() * sum;
                }
            }
        }
        Ok(())
    }

    /// A step call of `dt` seconds begins: each mesh collider's velocities and swept boxes.
    pub(super) fn begin_collider_motion(&mut self, dt: f64) -> Result<(), Error> {
        let model_margin = self.config.model.collision_margin;
        for mesh in self.mesh_slots.iter_mut().flatten() {
            let (margin, skin) = Self::mesh_reach(model_margin, mesh);
            mesh.begin_call(dt, margin + skin)?;
        }
        Ok(())
    }

    /// The call succeeded: every mesh collider is where the host put it.
    pub(super) fn colliders_arrive(&mut self) {
        for mesh in self.mesh_slots.iter_mut().flatten() {
            mesh.arrive();
        }
    }

    /// The collision pass: contact elements with the mesh colliders (at `fraction` of the call,
    /// the end of this step) and of the cloth with itself, their forces added to the forces
    /// before the force pass. Nothing without meshes or self-collision.
    pub(super) fn collisions(&mut self, fraction: Option<f64>) -> Result<(), Error> {
        let s = &mut self.scratch;
        s.contacts.clear();
        let m = &self.config.model;
        let f = fraction.unwrap_or(1.0);
        for (id, slot) in self.mesh_slots.iter_mut().enumerate() {
            let Some(mesh) = slot else { continue };
            let (margin, skin) = Self::mesh_reach(m.collision_margin, mesh);
            // A step outside a call (a snapshot's trial step) finds the boxes made here.
            mesh.refresh(margin + skin)?;
            mesh.contacts(
                &self.state.x,
                &self.topology.triangles,
                f,
                margin,
                skin,
                MESH_MAX_DEPTH_MARGINS * margin,
                &mut s.contacts,
            )
            .map_err(|why| Self::too_many_candidates(id, mesh, margin, self.state.x.len(), why))?;
        }
        let mesh_contacts = s.contacts.len();
        if m.self_collision_on() {
            self.self_collision.contacts(
                &self.state.x,
                &self.topology.rest_positions,
                &self.topology.triangles,
                m.self_collision_thickness,
                m.self_collision_friction,
                &mut s.contacts,
            )?;
        }
        if s.contacts.is_empty() {
            return Ok(());
        }
        if !s.projected.is_empty() {
            // Normal added mass: `Cloth::water_turning` wrote the normals and projected areas
            // of the inertia this step takes.
            let t = &self.topology;
            let (normals, projected) = (s.force_pass.normals(), &s.projected);
            let inertia =
                |i: usize| crate::forces::Inertia::of(m, t.masses[i], t.areas[i], normals[i], projected[i]);
            contact::inertia_scale(
                &mut s.contacts[mesh_contacts..],
                &self.pins.pinned,
                |i, n| inertia(i).effective_force(n) / t.masses[i],
                |i| 1.0 / inertia(i).isotropic(),
            );
        }
        if s.prior_forces.is_empty() {
            s.prior_forces.resize(self.state.x.len(), Vec3::zeros());
        }
        contact::add_forces(
            &s.contacts,
            m.collision_stiffness,
            m.collision_damping,
            &s.v_step,
            &mut s.prior_forces,
        );
        Ok(())
    }

    /// Friction of the contact elements after the step; says whether any applied.
    pub(super) fn contact_friction(&mut self, h: f64) -> bool {
        let s = &mut self.scratch;
        let m = &self.config.model;
        contact::apply_friction(
            &s.contacts,
            m.collision_stiffness,
            m.collision_damping,
            h,
            &s.v_step,
            &self.topology.masses,
            &self.pins.pinned,
            &mut s.v_new,
        )
    }

    /// The mesh colliders' continuous check, after the step with the pins placed
    /// (`MeshCollider::passages`): a cloth vertex, triangle or edge that would pass through a
    /// mesh collider in this step is carried by the mesh instead (its free vertices moved by
    /// the mesh's displacement there, their velocities that over the step), so a collider
    /// too fast for the penalty to stop the cloth within its margin still cannot go through.
    /// Looked at again (the carried vertices may meet another face) up to
    /// [`MESH_PASSAGE_ROUNDS`] times. Returns how many vertices were carried.
    pub(super) fn carry_through_meshes(&mut self, h: f64, from: f64, fraction: Option<f64>) -> usize {
        let s = &mut self.scratch;
        s.carried.clear();
        if self.mesh_slots.iter().all(Option::is_none) {
            return 0;
        }
        let (f0, f1) = (from, fraction.unwrap_or(1.0));
        let tolerance = PASSAGE_TOLERANCE * self.config.model.collision_margin;
        for _ in 0..MESH_PASSAGE_ROUNDS {
            s.mesh_passages.clear();
            for mesh in self.mesh_slots.iter().flatten() {
                mesh.passages(
                    &self.state.x,
                    &s.x_new,
                    &self.topology.triangles,
                    f0,
                    f1,
                    tolerance,
                    &mut s.mesh_passages,
                );
            }
            if s.mesh_passages.is_empty() {
                break;
            }
            for p in &s.mesh_passages {
                for &i in &p.cloth {
                    let i = i as usize;
                    if !self.pins.pinned[i] {
                        s.x_new[i] = self.state.x[i] + p.carry;
                        s.v_new[i] = p.carry / h;
                        s.carried.push(i as u32);
                    }
                }
            }
        }
        s.carried.sort_unstable();
        s.carried.dedup();
        s.carried.len()
    }

    /// Self-collision's impact zones, after the step with the pins placed
    /// (`collide::impact_zones`): a free vertex that would pass through a triangle of the
    /// cloth, or an edge through an edge, in this step moves as one with the others of its
    /// zone (with a pinned row that presses it, or at their shared momentum), its velocity its
    /// new displacement over the step. Returns how many vertices were moved, or an
    /// out-of-memory error (the state left unchanged) when the zones' union-find, one number
    /// a vertex, cannot be allocated the first time a step needs it.
    pub(super) fn impact_zones(&mut self, h: f64) -> Result<usize, Error> {
        if !self.config.model.self_collision_on() {
            return Ok(0);
        }
        let thickness = self.config.model.self_collision_thickness;
        let tolerance = PASSAGE_TOLERANCE * thickness;
        self.self_collision.watch_guard(
            &self.state.x,
            &self.scratch.x_new,
            &self.topology.triangles,
            tolerance,
        );
        let sc = &self.self_collision;
        let (guard, guard_vertices) = sc.guarded();
        if guard.is_empty()
            && guard_vertices.is_empty()
            && sc.vertex_triangle.is_empty()
            && sc.edge_edge.is_empty()
        {
            return Ok(0);
        }
        let super::scratch::StepScratch {
            carried,
            kinematic,
            x_new,
            v_new,
            zone_moved,
            zone_stopped,
            zones,
            ..
        } = &mut self.scratch;
        // Vertices a mesh carried this step are held like pins.
        let kinematic = if carried.is_empty() {
            &self.pins.pinned
        } else {
            kinematic.clone_from(&self.pins.pinned);
            for &i in carried.iter() {
                kinematic[i as usize] = true;
            }
            &*kinematic
        };
        let input = ZoneInput {
            x0: &self.state.x,
            masses: &self.topology.masses,
            kinematic,
            triangles: &self.topology.triangles,
            vertex_triangles: sc.vertex_triangles(),
            neighbours: sc.excluded_rows(),
            edges: sc.edges(),
            vertex_triangle: &sc.vertex_triangle,
            edge_edge: &sc.edge_edge,
            tolerance,
            guard,
            guard_vertices,
        };
        let n = input.x0.len();
        let report = keep_from_passing(&input, x_new, zone_moved, zone_stopped, zones).map_err(|_| {
            Error::out_of_memory(format!(
                "self-collision's impact zones: their union-find of {n} vertices cannot be allocated; state left unchanged"
            ))
        })?;
        for &i in zone_moved.iter() {
            let i = i as usize;
            v_new[i] = (x_new[i] - self.state.x[i]) / h;
        }
        self.self_collision.zones.add(&report);
        Ok(report.moved)
    }

    /// After a step the impact zones changed, once it is accepted: a pair kept from passing
    /// stays on the side it started on, and that is its side now (a remembered side it was not
    /// on would have the contacts push it through at the next step).
    pub(super) fn learn_stopped_sides(&mut self) {
        self.self_collision.relearn_sides(&self.scratch.zone_stopped);
    }

    /// Whether the proposed step is proved to bring no pair of self-collision's within its
    /// reach at any instant (`Unfolded::out_of_reach_throughout`), and stable by itself.
    fn limit_needless(&mut self, plan: &StepPlan) -> bool {
        let Some((h, level)) = plan.piece else {
            return false;
        };
        if level < self.stable_level(h, plan.auto) {
            return false;
        }
        let mut end = std::mem::take(&mut self.scratch.step_end);
        self.step_end_into(&mut end);
        let thickness = self.config.model.self_collision_thickness;
        let proved = self.self_collision.out_of_reach_throughout(
            &self.state.x,
            &end,
            &self.topology.triangles,
            thickness,
        );
        self.scratch.step_end = end;
        proved
    }

    /// Self-collision's step limit ([`SELF_COLLISION_STEP_LIMIT`]) on the proposed step: a
    /// free vertex that would move farther (a cloth pinched between two colliders, or flung
    /// faster than its thickness a step, would pass through itself) either refuses the step,
    /// saying by how much it is over ([`StepLimit::Refuse`]: the driver splits the step), or
    /// is moved only that far, its velocity scaled alike ([`StepLimit::Slow`]).
    pub(super) fn limit_collision_step(&mut self, plan: &StepPlan) -> Limited {
        if !self.config.model.self_collision_on() {
            return Limited::Slowed(0);
        }
        let thickness = self.config.model.self_collision_thickness;
        let limit = SELF_COLLISION_STEP_LIMIT * thickness;
        let s = &mut self.scratch;
        // Most steps move no vertex that far: one pass without branches says so (its bound a
        // little under the limit, so that its sum's rounding never passes over a vertex the
        // loop below would limit).
        if !any_past_widest(
            bytemuck::cast_slice(&s.x_new),
            bytemuck::cast_slice(&self.state.x),
            &self.pins.pinned,
            limit * limit * (1.0 - 1e-12),
        ) {
            return Limited::Slowed(0);
        }
        // A cloth proved out of its own reach throughout the step needs no limit (a step the
        // driver may take whole: `split.rs`). Only where the step is stable as it is: an
        // explicit integrator's fixed step too long to be stable is still split into stable
        // pieces, not refused.
        if self.limit_needless(plan) {
            self.splitter.stats.proved_whole += 1;
            return Limited::Slowed(0);
        }
        let s = &mut self.scratch;
        // How far free vertex `i` would move, when over the limit (squared first: the square
        // root only for a vertex over it; a NaN displacement is left to the step's check).
        let over = |x_new: &[Vec3], i: usize| {
            let len2 = (x_new[i] - self.state.x[i]).norm_squared();
            (!self.pins.pinned[i] && len2 > limit * limit && !len2.is_nan())
                .then(|| len2.sqrt())
                .filter(|&len| len > limit)
        };
        if plan.limit == StepLimit::Refuse {
            let farthest = (0..self.state.x.len())
                .filter_map(|i| over(&s.x_new, i))
                .fold(0.0, f64::max);
            return match farthest > limit {
                true => Limited::Over(farthest / limit),
                false => Limited::Slowed(0),
            };
        }
        let mut limited = 0;
        for i in 0..self.state.x.len() {
            let Some(len) = over(&s.x_new, i) else { continue };
            let scale = limit / len;
            s.x_new[i] = self.state.x[i] + scale * (s.x_new[i] - self.state.x[i]);
            s.v_new[i] *= scale;
            limited += 1;
        }
        Limited::Slowed(limited)
    }
}

/// What self-collision's step limit did with a proposed step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Limited {
    /// This many free vertices were slowed to the limit (0: none was over it).
    Slowed(usize),
    /// Refused: the farthest free vertex would move this many times the limit.
    Over(f64),
}

crate::simd_dispatch! { fn any_past_widest(x_new: &[f64], x: &[f64], pinned: &[bool], limit2: f64) -> bool => any_past }

/// Whether a vertex not `pinned` moves more than `sqrt(limit2)` from `x` to `x_new` (both
/// three coordinates a vertex); a NaN displacement is not past.
#[inline(always)]
fn any_past(x_new: &[f64], x: &[f64], pinned: &[bool], limit2: f64) -> bool {
    let mut past = false;
    for ((a, b), &held) in x_new.chunks_exact(3).zip(x.chunks_exact(3)).zip(pinned) {
        let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        past |= (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > limit2) & !held;
    }
    past
}

/// What collisions keep across a snapshot: the mesh colliders by id and self-collision's
/// remembered pairs.
#[derive(Default)]
pub(super) struct CollisionState {
    pub meshes: Vec<Option<MeshCollider>>,
    pub vertex_triangle: Vec<Pair>,
    pub edge_edge: Vec<Pair>,
}

impl Cloth {
    /// Writes the collision state (snapshot format 5, after the histories).
    pub(super) fn write_collision_state(&self, w: &mut ByteWriter) {
        w.u64(self.mesh_slots.len() as u64);
        for slot in &self.mesh_slots {
            let Some(mesh) = slot else {
                w.u8(0);
                continue;
            };
            w.u8(1);
            w.u64(mesh.vertex_count() as u64);
            w.u64(mesh.triangles().len() as u64);
            for t in mesh.triangles() {
                t.iter().for_each(|&i| w.u32(i));
            }
            w.vec3s(mesh.start_positions());
            w.vec3s(mesh.positions());
            match mesh.given_velocities() {
                None => w.u8(0),
                Some(v) => {
                    w.u8(1);
                    w.vec3s(v);
                }
            }
            w.f64(mesh.friction);
            w.f64(mesh.margin.unwrap_or(-1.0));
        }
        let (vt, ee) = self.self_collision.pairs();
        for pairs in [vt, ee] {
            w.u64(pairs.len() as u64);
            for &(a, b, s) in pairs {
                w.u32(a);
                w.u32(b);
                w.u8(s as u8);
            }
        }
    }

    /// Reads and checks what [`Self::write_collision_state`] wrote.
    pub(super) fn read_collision_state(
        &self,
        r: &mut ByteReader,
        version: u32,
    ) -> Result<CollisionState, Error> {
        let bad = |what: &str| Error::invalid(format!("snapshot: bad {what}"));
        let slots = r.len(None, 1)?;
        let mut meshes = Vec::new();
        for _ in 0..slots {
            meshes.push(match r.u8()? {
                0 => None,
                1 => {
                    let nv = r.len(None, 48)?;
                    let nt = r.len(None, 12)?;
                    let mut tris = Vec::with_capacity(nt);
                    for _ in 0..nt {
                        tris.push([r.u32()?, r.u32()?, r.u32()?]);
                    }
                    let (mut start, mut target, mut vel) = (Vec::new(), Vec::new(), Vec::new());
                    r.vec3s_into(Some(nv), &mut start)?;
                    r.vec3s_into(Some(nv), &mut target)?;
                    let given = match r.u8()? {
                        0 => None,
                        1 => {
                            r.vec3s_into(Some(nv), &mut vel)?;
                            Some(&vel[..])
                        }
                        _ => return Err(bad("mesh collider velocity tag")),
                    };
                    let friction = r.f64()?;
                    if !(friction.is_finite() && friction >= 0.0) {
                        return Err(bad("mesh collider friction"));
                    }
                    let margin = if version >= 6 { read_margin(r)? } else { None };
                    // A mesh the snapshot holds that does not make a collider is corrupted
                    // data (an invalid argument), whatever the error a host's call would get.
                    let corrupt = |e: Error| bad(&format!("mesh collider ({})", e.message));
                    let mut mesh = MeshCollider::new(&start, &tris, None).map_err(corrupt)?;
                    mesh.set(&target, given).map_err(corrupt)?;
                    mesh.friction = friction;
                    mesh.margin = margin;
                    Some(mesh)
                }
                _ => return Err(bad("mesh collider slot tag")),
            });
        }
        let (n, tris, edges) = (
            self.vertex_count(),
            self.topology.triangles.len(),
            self.self_collision.edge_count(),
        );
        let mut read_pairs = |first: usize, second: usize, what: &str| -> Result<Vec<Pair>, Error> {
            let count = r.len(None, 9)?;
            let mut out: Vec<Pair> = Vec::with_capacity(count);
            for _ in 0..count {
                let (a, b, s) = (r.u32()?, r.u32()?, r.u8()? as i8);
                let sorted = out.last().is_none_or(|l| (l.0, l.1) < (a, b));
                if a as usize >= first || b as usize >= second || !(-1..=1).contains(&s) || !sorted {
                    return Err(bad(what));
                }
                out.push((a, b, s));
            }
            Ok(out)
        };
        let vertex_triangle = read_pairs(n, tris, "self-collision vertex-triangle pair")?;
        let edge_edge = read_pairs(edges, edges, "self-collision edge-edge pair")?;
        Ok(CollisionState {
            meshes,
            vertex_triangle,
            edge_edge,
        })
    }
}

/// A collider's own margin as a snapshot holds it: -1 for the model's, else the margin (m).
pub(super) fn read_margin(r: &mut ByteReader) -> Result<Option<f64>, Error> {
    let m = r.f64()?;
    if m == -1.0 {
        Ok(None)
    } else if (0.0..1e6).contains(&m) {
        Ok(Some(m))
    } else {
        Err(Error::invalid(format!("snapshot: bad collider margin {m}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The proof that an unfolded sheet keeps its distances (`collide/unfolded.rs`) leaves a
    /// bake's every bit as it was: a 41 x 31 towel of the underwater preset (1 kg/m^2) with
    /// self-collision at 4 mm, its top row swung 4 cm at 0.5 Hz (unfolded: the proof settles
    /// every look, 55 of 55) and 8 cm at 2 Hz (it crumples: thousands of pairs in reach),
    /// stepped at 1 ms with and without the proof, positions compared bit for bit every 50
    /// steps.
    #[test]
    fn the_proof_leaves_a_bake_bit_for_bit_as_it_was() {
        use crate::{ClothConfig, GridSpec, Integrator, Model};
        for (frequency, amplitude, steps) in [(0.5, 0.04, 1500), (2.0, 0.08, 1000)] {
            let bake = |full_looks: bool| {
                let t = GridSpec {
                    width: 41,
                    height: 31,
                    spacing: 0.01,
                    total_mass: 0.4 * 0.3,
                }
                .build()
                .expect("grid");
                let model = Model {
                    self_collision_thickness: 0.004,
                    ..Model::underwater()
                };
                let config = ClothConfig {
                    model,
                    integrator: Integrator::SymplecticEuler,
                    ..ClothConfig::default()
                };
                let mut c = Cloth::new(t, config).expect("cloth");
                c.self_collision.full_looks = full_looks;
                let top: Vec<u32> = (0..41).collect();
                let rest: Vec<Vec3> = top.iter().map(|&i| c.positions()[i as usize]).collect();
                c.set_pinned(&top).expect("pins");
                let (mut frames, mut most_pairs) = (Vec::new(), 0);
                for n in 1..=steps {
                    let time = f64::from(n) * 1e-3;
                    let shift = amplitude * (std::f64::consts::TAU * frequency * time).sin();
                    let goals: Vec<Vec3> = rest.iter().map(|p| p + Vec3::new(0.0, 0.0, shift)).collect();
                    c.set_pin_targets(&top, &goals).expect("targets");
                    c.step(1e-3).expect("step");
                    most_pairs =
                        most_pairs.max(c.self_collision_pairs().0.len() + c.self_collision_pairs().1.len());
                    if n % 50 == 0 {
                        frames.push(
                            c.positions()
                                .iter()
                                .map(|p| p.map(f64::to_bits))
                                .collect::<Vec<_>>(),
                        );
                    }
                }
                (
                    frames,
                    c.self_collision.certified_looks,
                    c.self_collision_looks(),
                    most_pairs,
                )
            };
            let (with, proved, looks, pairs) = bake(false);
            let (without, none, _, pairs_without) = bake(true);
            assert_eq!(none, 0);
            assert_eq!(pairs, pairs_without);
            println!(
                "{frequency} Hz: {proved} of {looks} looks proved whole, at most {pairs} pairs in reach"
            );
            if frequency < 1.0 {
                assert!(proved * 2 > looks, "{proved} of {looks} looks proved whole");
            } else {
                assert!(pairs > 0, "the brisk swing touches itself");
            }
            for (k, (a, b)) in with.iter().zip(&without).enumerate() {
                assert!(a == b, "{frequency} Hz: the bakes part at step {}", 50 * (k + 1));
            }
        }
    }

    /// The step limit's first pass finds a free vertex past the bound exactly when one vertex
    /// by one does (pinned ones and NaN displacements passed over), at every place of a block
    /// and in the tail. It fails with the pinned flag ignored, or with a vertex's third
    /// coordinate left out (both checked).
    #[test]
    fn the_step_limits_first_pass_finds_what_each_vertex_says() {
        let mut r = crate::testing::numbers(17);
        let limit2 = 0.25;
        for n in [1usize, 5, 8, 13, 64] {
            let x: Vec<Vec3> = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
            // Every vertex well within the bound, then one at a time past it (along z only)
            // or NaN, free or pinned.
            for k in 0..n {
                for (d, pinned_k, expect) in [
                    (Vec3::new(0.0, 0.0, 0.6), false, true),
                    (Vec3::new(0.0, 0.0, 0.6), true, false),
                    (Vec3::new(f64::NAN, 0.0, 0.0), false, false),
                    (Vec3::new(0.0, 0.0, 0.4), false, false),
                ] {
                    let mut x_new: Vec<Vec3> = x.iter().map(|p| p + 0.1 * Vec3::new(r(), r(), r())).collect();
                    x_new[k] = x[k] + d;
                    let mut pinned = vec![false; n];
                    pinned[k] = pinned_k;
                    let each = x_new
                        .iter()
                        .zip(&x)
                        .zip(&pinned)
                        .any(|((a, b), &p)| !p && (a - b).norm_squared() > limit2);
                    assert_eq!(each, expect, "{n} vertices, vertex {k}");
                    let fast = any_past_widest(
                        bytemuck::cast_slice(&x_new),
                        bytemuck::cast_slice(&x),
                        &pinned,
                        limit2,
                    );
                    assert_eq!(
                        fast, expect,
                        "{n} vertices, vertex {k} moved by {d:?}, pinned {pinned_k}"
                    );
                }
            }
        }
    }
}
