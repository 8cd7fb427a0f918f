//! The analytic colliders (spheres, planes, capsules) a host adds, moves and removes, each
//! with its friction and its own margin; the mesh colliders' calls are in `collisions.rs`.

use super::Cloth;
use crate::collide::MeshCollider;
use crate::error::{check_finite_vec, check_non_negative, check_positive, Error};
use crate::forces::{Collider, Plane, Sphere};

/// An analytic collider as the host set it, with its friction and its own margin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ColliderSlot {
    pub shape: Collider,
    pub friction: f64,
    /// Its own margin, m, or the model's (`None`).
    pub margin: Option<f64>,
}

impl Cloth {
    /// Adds a sphere collider and returns its id.
    pub fn add_sphere(&mut self, sphere: Sphere) -> Result<u32, Error> {
        self.add_collider(Collider::Sphere(sphere))
    }

    /// Moves or resizes sphere `id`.
    pub fn set_sphere(&mut self, id: u32, sphere: Sphere) -> Result<(), Error> {
        self.set_collider(id, Collider::Sphere(sphere))
    }

    /// Adds any collider (friction 0) and returns its id, the smallest free one.
    pub fn add_collider(&mut self, collider: Collider) -> Result<u32, Error> {
        let collider = checked_collider(collider)?;
        let id = self.free_collider_id();
        if id >= self.collider_slots.len() {
            self.collider_slots.resize(id + 1, None);
        }
        self.collider_slots[id] = Some(ColliderSlot {
            shape: collider,
            friction: 0.0,
            margin: None,
        });
        self.rebuild_colliders();
        Ok(id as u32)
    }

    /// Replaces collider `id` (its shape may change; its friction and margin are kept).
    pub fn set_collider(&mut self, id: u32, collider: Collider) -> Result<(), Error> {
        let collider = checked_collider(collider)?;
        if let Some(slot) = self.collider_slot(id)? {
            slot.shape = collider;
        }
        self.rebuild_colliders();
        Ok(())
    }

    /// Sets the Coulomb friction coefficient (>= 0) of collider `id` (any kind, meshes too).
    pub fn set_collider_friction(&mut self, id: u32, friction: f64) -> Result<(), Error> {
        check_non_negative("friction", friction)?;
        self.with_collider(
            id,
            |mesh| mesh.friction = friction,
            |slot| slot.friction = friction,
        )
    }

    /// Sets the margin of collider `id` (any kind, meshes too), m (>= 0): the distance from it
    /// at which the cloth is pushed away, instead of the model's `collision_margin` (a collider's
    /// own thickness: a rough rock kept further off than a smooth hull). The contact stiffness
    /// and damping stay the model's.
    pub fn set_collider_margin(&mut self, id: u32, margin: f64) -> Result<(), Error> {
        check_non_negative("collider margin", margin)?;
        if margin.is_nan() || margin >= 1e6 {
            return Err(Error::invalid(format!(
                "collider margin must be below 1e6 m, got {margin}"
            )));
        }
        self.with_collider(
            id,
            |mesh| mesh.margin = Some(margin),
            |slot| slot.margin = Some(margin),
        )
    }

    /// Changes collider `id`: a mesh collider by `mesh`, an analytic one by `slot` (then the
    /// contacts' list is rebuilt).
    pub(super) fn with_collider(
        &mut self,
        id: u32,
        mesh: impl FnOnce(&mut MeshCollider),
        slot: impl FnOnce(&mut ColliderSlot),
    ) -> Result<(), Error> {
        if let Some(Some(m)) = self.mesh_slots.get_mut(id as usize) {
            mesh(m);
            return Ok(());
        }
        if let Some(s) = self.collider_slot(id)? {
            slot(s);
        }
        self.rebuild_colliders();
        Ok(())
    }

    /// The margin collider `id` keeps the cloth at, m: its own, or the model's.
    pub fn collider_margin(&self, id: u32) -> Option<f64> {
        let own = if let Some(Some(mesh)) = self.mesh_slots.get(id as usize) {
            Some(mesh.margin)
        } else {
            self.collider_slots
                .get(id as usize)
                .and_then(Option::as_ref)
                .map(|s| s.margin)
        };
        own.map(|m| m.unwrap_or(self.config.model.collision_margin))
    }

    /// Removes collider `id` (any kind, meshes too); its id may be reused.
    pub fn remove_collider(&mut self, id: u32) -> Result<(), Error> {
        if let Some(slot @ Some(_)) = self.mesh_slots.get_mut(id as usize) {
            *slot = None;
            return Ok(());
        }
        *self.collider_slot(id)? = None;
        self.rebuild_colliders();
        Ok(())
    }

    /// Every analytic collider present, as the contacts see it: grown by the difference of its
    /// own margin and the model's, where it has one ([`Cloth::set_collider_margin`]).
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// The collider with id `id`.
    pub fn collider(&self, id: u32) -> Option<&Collider> {
        self.collider_slots
            .get(id as usize)
            .and_then(Option::as_ref)
            .map(|s| &s.shape)
    }

    /// Friction coefficient of collider `id` (any kind).
    pub fn collider_friction(&self, id: u32) -> Option<f64> {
        if let Some(Some(mesh)) = self.mesh_slots.get(id as usize) {
            return Some(mesh.friction);
        }
        self.collider_slots
            .get(id as usize)
            .and_then(Option::as_ref)
            .map(|s| s.friction)
    }

    /// The smallest id free among the analytic and the mesh colliders.
    pub(super) fn free_collider_id(&self) -> usize {
        let taken = |i: usize| {
            matches!(self.collider_slots.get(i), Some(Some(_)))
                || matches!(self.mesh_slots.get(i), Some(Some(_)))
        };
        (0..).find(|&i| !taken(i)).unwrap_or(0)
    }

    pub(super) fn collider_slot(&mut self, id: u32) -> Result<&mut Option<ColliderSlot>, Error> {
        match self.collider_slots.get_mut(id as usize) {
            Some(slot @ Some(_)) => Ok(slot),
            _ => Err(Error::out_of_range(format!("no collider with id {id}"))),
        }
    }

    pub(super) fn rebuild_colliders(&mut self) {
        self.colliders.clear();
        self.friction.clear();
        let margin = self.config.model.collision_margin;
        for slot in self.collider_slots.iter().flatten() {
            self.colliders.push(match slot.margin {
                Some(own) => slot.shape.grown(own - margin),
                None => slot.shape,
            });
            self.friction.push(slot.friction);
        }
    }
}

/// Checks a collider's numbers; a plane's normal is normalised.
pub(super) fn checked_collider(c: Collider) -> Result<Collider, Error> {
    Ok(match c {
        Collider::Sphere(s) => {
            check_finite_vec("sphere center", &s.center)?;
            check_finite_vec("sphere velocity", &s.velocity)?;
            check_positive("sphere radius", s.radius)?;
            c
        }
        Collider::Plane(p) => {
            check_finite_vec("plane point", &p.point)?;
            check_finite_vec("plane velocity", &p.velocity)?;
            check_finite_vec("plane normal", &p.normal)?;
            let len = p.normal.norm();
            if !(len > 0.0 && len.is_finite()) {
                return Err(Error::invalid("plane normal must not be zero"));
            }
            Collider::Plane(Plane {
                normal: p.normal / len,
                ..p
            })
        }
        Collider::Capsule(k) => {
            check_finite_vec("capsule end a", &k.a)?;
            check_finite_vec("capsule end b", &k.b)?;
            check_finite_vec("capsule velocity", &k.velocity)?;
            check_positive("capsule radius", k.radius)?;
            c
        }
    })
}
