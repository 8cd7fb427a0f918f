//! The cloth's mesh colliders and self-collision: the host's calls, and the step's collision
//! pass, which turns both into [`Contact`] elements (their forces join the force pass, their
//! Jacobian blocks the implicit system, their friction the friction pass).

use super::Cloth;
use crate::collide::self_collision::Pair;
use crate::collide::{contact, Contact, MeshCollider};
use crate::error::Error;
use crate::Vec3;

/// How far (in collision margins) a mesh collider's candidates reach beyond the margin before
/// a cloth vertex looks again (`collide/mesh.rs`).
const MESH_SKIN_MARGINS: f64 = 2.0;
/// Deepest penetration a mesh contact pushes with, in margins: a vertex found deep inside a
/// closed mesh is pushed out at a bounded rate instead of being launched.
const MESH_MAX_DEPTH_MARGINS: f64 = 3.0;
/// Self-collision's step limit: no free vertex may move more than this fraction of the
/// thickness in one step (else the step is refused as unstable and the automatic step takes
/// more substeps).
pub const SELF_COLLISION_STEP_LIMIT: f64 = 0.5;

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

    /// How many times self-collision looked its pairs up again since the cloth was made.
    pub fn self_collision_looks(&self) -> u64 {
        self.self_collision.looks
    }

    fn mesh_reach(&self) -> (f64, f64) {
        let margin = self.config.model.collision_margin;
        (margin, MESH_SKIN_MARGINS * margin)
    }

    /// A step call of `dt` seconds begins: each mesh collider's velocities and swept boxes.
    pub(super) fn begin_collider_motion(&mut self, dt: f64) {
        let (margin, skin) = self.mesh_reach();
        for mesh in self.mesh_slots.iter_mut().flatten() {
            mesh.begin_call(dt, margin + skin);
        }
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
    pub(super) fn collisions(&mut self, fraction: Option<f64>) {
        let s = &mut self.scratch;
        s.contacts.clear();
        let m = &self.config.model;
        let (margin, skin) = (m.collision_margin, MESH_SKIN_MARGINS * m.collision_margin);
        let f = fraction.unwrap_or(1.0);
        for mesh in self.mesh_slots.iter_mut().flatten() {
            // A step outside a call (a snapshot's trial step) finds the boxes made here.
            mesh.refresh(margin + skin);
            mesh.contacts(
                &self.x,
                &self.topology.triangles,
                f,
                margin,
                skin,
                MESH_MAX_DEPTH_MARGINS * margin,
                &mut s.contacts,
            );
        }
        if m.self_collision_thickness > 0.0 {
            self.self_collision.contacts(
                &self.x,
                &self.topology.rest_positions,
                &self.topology.triangles,
                m.self_collision_thickness,
                m.self_collision_friction,
                &mut s.contacts,
            );
        }
        if s.contacts.is_empty() {
            return;
        }
        if s.prior_forces.is_empty() {
            s.prior_forces.resize(self.x.len(), Vec3::zeros());
        }
        contact::add_forces(
            &s.contacts,
            m.collision_stiffness,
            m.collision_damping,
            &s.v_step,
            &mut s.prior_forces,
        );
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
            &self.pinned,
            &mut s.v_new,
        )
    }

    /// Self-collision's step limit ([`SELF_COLLISION_STEP_LIMIT`]).
    pub(super) fn check_collision_step(&self, h: f64) -> Result<(), Error> {
        let thickness = self.config.model.self_collision_thickness;
        if thickness <= 0.0 {
            return Ok(());
        }
        let limit = SELF_COLLISION_STEP_LIMIT * thickness;
        let x_new = &self.scratch.x_new;
        let far = (0..self.x.len()).find(|&i| !self.pinned[i] && (x_new[i] - self.x[i]).norm() > limit);
        match far {
            None => Ok(()),
            Some(i) => Err(Error::unstable(format!(
                "{} with dt = {h} s would move vertex {i} by {:.3e} m, more than half the self-collision thickness ({thickness} m), so a fold could pass through itself; state left unchanged, retry with a smaller dt (max_substep = FC_MAX_SUBSTEP_AUTO lets the library choose the substeps; or set max_substep, or call fc_cloth_step_substeps)",
                self.config.integrator.name(),
                (x_new[i] - self.x[i]).norm()
            ))),
        }
    }
}
