//! The buffers a step reuses: grown once, then kept from step to step, so that no step
//! allocates (`tests/no_alloc.rs`).

use super::pins::PinPaths;
use crate::forces::{self, ElementScratch, ForceScratch};
use crate::integrate::ImplicitScratch;
use crate::math::Vec3;

/// Buffers a step reuses (no allocation in a step once they have grown).
#[derive(Clone, Debug, Default)]
pub(super) struct StepScratch {
    /// The step's velocity of every particle (pins' from their goals), m/s.
    pub v_step: crate::aligned::AlignedVec3,
    /// Velocity relative to the water, m/s.
    pub v_rel: Vec<Vec3>,
    /// D^{1/2}x of the displacement relative to the water, m s^{-1/2}.
    pub half: crate::aligned::AlignedVec3,
    /// Total forces as one array (the implicit route only), N.
    pub force_array: Vec<Vec3>,
    /// The velocities where an automatic call with implicit Euler began (`motion.rs`).
    pub motion_v: Vec<Vec3>,
    /// The state the step proposes; committed only if sound.
    pub x_new: crate::aligned::AlignedVec3,
    pub v_new: crate::aligned::AlignedVec3,
    /// The pins' goals and paths (`pins.rs`).
    pub pins: PinPaths,
    /// Where a step over self-collision's limit would end, pins included (`collisions.rs`).
    pub step_end: Vec<Vec3>,
    /// The pair elements' own passes: the rates their memories record (`forces::elements`).
    pub elements: ElementScratch,
    /// Forces of the whole-cloth passes before the force pass (pair elements with a pass of
    /// their own, the carried water's turning forces), one per particle; empty without them.
    pub prior_forces: Vec<Vec3>,
    /// The collision pass's contact elements (mesh colliders, self-collision).
    pub contacts: Vec<crate::collide::Contact>,
    /// Self-collision's memory before a piece of a split substep (`split.rs`).
    pub piece_memory: crate::collide::self_collision::SavedMemory,
    /// The free vertices self-collision's impact zones moved this step.
    pub zone_moved: Vec<u32>,
    /// The cloth's passages through the mesh colliders this step, the free vertices they
    /// carried (ascending) and, when some were, the vertices the impact zones may not move
    /// (pinned or carried).
    pub mesh_passages: Vec<crate::collide::mesh::MeshPassage>,
    pub carried: Vec<u32>,
    pub kinematic: Vec<bool>,
    /// The passages they stopped (`collide::impact_zones`).
    pub zone_stopped: Vec<crate::collide::impact_zones::Passage>,
    /// The impact zones' own buffers (their union-find, the passages of a round).
    pub zones: crate::collide::impact_zones::ZoneScratch,
    /// The mesh colliders' contacts where a call begins, and each vertex's weight from them
    /// (`Cloth::measure_contact_weights`; empty without contacts).
    pub start_contacts: Vec<crate::collide::Contact>,
    pub contact_weight: Vec<f64>,
    pub turning: forces::TurningScratch,
    /// The coarse level of the carried water (`forces::coarse_water`), when the model has one.
    pub coarse: Option<forces::coarse_water::CoarseWater>,
    /// The wide form drag's buffers and rest weights.
    pub wide_drag: forces::WideDragScratch,
    /// Each patch's projected-area ratio ([`forces::patch_normals`]), with normal added mass
    /// only (else empty).
    pub projected: Vec<f64>,
    pub force_pass: ForceScratch,
    pub implicit: ImplicitScratch,
    /// The automatic step's sums over each particle's springs (`auto_step.rs`).
    pub spring_sums: super::auto_step::SpringSums,
    /// The XPBD route's constraints (`constrained.rs`).
    pub constraints: super::constrained::ConstraintScratch,
}
