//! What evolves with a cloth's steps, in one place: positions, velocities, time, steps and the
//! memories (the half-derivative histories, the unsteady skin drag's running mean, the motion's
//! averages).
//!
//! Which memories a state keeps follows from its model ([`State::memories_for`]): a cloth
//! built, reconfigured or loaded from a snapshot asks the same question, so a memory a term
//! turns on starts (and one it turns off is dropped) the same way everywhere.
//!
//! A refused call puts the whole state back ([`State::copy_into`] before it, a swap after),
//! an extrapolated step combines two states ([`State::extrapolate`]), and a snapshot writes
//! and reads them in its format's order (`snapshot.rs`). Each memory says in [`Evolving`] how
//! it is copied and how it extrapolates, and [`State`] lists the memories once
//! ([`for_each_memory`]), so a new term with a memory adds its type's `Evolving` and one entry
//! to that list. The role of Jolt's `SoftBodyMotionProperties::SaveState` / `RestoreState`.
//!
//! Self-collision's remembered pairs and sides are a memory too, kept with the search that
//! reads them (`collide::self_collision`); a rollback copies them beside the state.

use super::histories::Histories;
use super::motion::MotionRate;
use crate::aligned::AlignedVec3;
use crate::error::Error;
use crate::math::Vec3;
use crate::model::Model;
use crate::topology::Topology;

/// How one memory of the state is copied, put back and extrapolated.
pub(crate) trait Evolving {
    /// Makes `copy` this memory, in `copy`'s buffers where they are large enough.
    fn copy_into(&self, copy: &mut Self);
    /// Local Richardson extrapolation after two half steps: `2 self - whole`, `whole` the same
    /// memory after one whole step from the same start; nothing for a memory that records
    /// the half steps themselves (the histories) or is updated between calls (the averages).
    fn extrapolate(&mut self, whole: &Self);
    /// Bytes it holds on `topology` (what a copy of it needs).
    fn bytes(&self, topology: &Topology) -> u64;
}

impl Evolving for AlignedVec3 {
    fn copy_into(&self, copy: &mut Self) {
        copy.clone_from(self);
    }
    fn extrapolate(&mut self, whole: &Self) {
        for (a, b) in self.iter_mut().zip(whole.iter()) {
            *a = 2.0 * *a - b;
        }
    }
    fn bytes(&self, _: &Topology) -> u64 {
        (self.len() * std::mem::size_of::<Vec3>()) as u64
    }
}

/// The unsteady skin drag's running mean of the velocity relative to the water, m/s (empty
/// when the model has none).
impl Evolving for Vec<Vec3> {
    fn copy_into(&self, copy: &mut Self) {
        copy.clone_from(self);
    }
    fn extrapolate(&mut self, whole: &Self) {
        for (a, b) in self.iter_mut().zip(whole) {
            *a = 2.0 * *a - b;
        }
    }
    fn bytes(&self, _: &Topology) -> u64 {
        (self.len() * std::mem::size_of::<Vec3>()) as u64
    }
}

impl Evolving for Histories {
    fn copy_into(&self, copy: &mut Self) {
        copy.clone_from(self);
    }
    /// The histories record the two half steps' samples: nothing to combine.
    fn extrapolate(&mut self, _: &Self) {}
    fn bytes(&self, topology: &Topology) -> u64 {
        Histories::bytes(self, topology)
    }
}

/// The motion's averages change between calls, never within a step.
impl Evolving for MotionRate {
    fn copy_into(&self, copy: &mut Self) {
        *copy = *self;
    }
    fn extrapolate(&mut self, _: &Self) {}
    fn bytes(&self, _: &Topology) -> u64 {
        0
    }
}

/// Everything of a cloth that its steps change.
#[derive(Clone, Debug)]
pub(crate) struct State {
    /// Positions, m.
    pub x: AlignedVec3,
    /// Velocities, m/s.
    pub v: AlignedVec3,
    /// Simulated time, s.
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// The half-derivative memories the model's terms and pair elements read.
    pub histories: Histories,
    /// The running mean of the velocity relative to the water that the unsteady skin drag
    /// acts against (`Water::skin_drag_unsteady`), m/s; empty when the model has none.
    pub skin_mean: Vec<Vec3>,
    /// The motion's frequency, averaged over calls: implicit Euler's accuracy bound on the
    /// automatic step (`motion.rs`).
    pub motion: MotionRate,
}

/// Calls `$each!(field)` for every evolving part of a [`State`] but time and steps: the one
/// list of what a copy, a restore and an extrapolation carry.
macro_rules! for_each_memory {
    ($each:ident) => {
        $each!(x);
        $each!(v);
        $each!(histories);
        $each!(skin_mean);
        $each!(motion);
    };
}

/// What a model asks of one memory a state has or lacks.
#[derive(Debug)]
pub(super) enum Change<T> {
    /// Kept as it is.
    Keep,
    /// Started, at this value.
    Start(T),
    /// Dropped: the model does not keep it.
    Drop,
}

/// What a model asks of a state's memories besides the histories (whose layout is fixed when
/// the cloth is made): each memory to keep, to start or to drop.
#[derive(Debug)]
pub(crate) struct MemoryChange {
    skin_mean: Change<Vec<Vec3>>,
}

/// What `model` asks of a skin drag's mean `mean` of a state with velocities `v`: kept, started
/// from the flow when missing, dropped when the model has no unsteady skin drag.
pub(super) fn skin_mean_change(model: &Model, mean: &[Vec3], v: &[Vec3]) -> Result<Change<Vec<Vec3>>, Error> {
    Ok(match (model.water.unsteady_skin(), mean.is_empty()) {
        (false, _) => Change::Drop,
        (true, true) => Change::Start(flow_mean(v, model.current)?),
        (true, false) => Change::Keep,
    })
}

/// The velocities `v` relative to a water of current `current`: where the unsteady skin drag's
/// running mean starts (a flow that has always been there). Out of memory, an error.
fn flow_mean(v: &[Vec3], current: Vec3) -> Result<Vec<Vec3>, Error> {
    let mut mean = Vec::new();
    mean.try_reserve_exact(v.len())
        .map_err(|_| Error::out_of_memory("the skin drag's running mean cannot be allocated"))?;
    mean.extend(v.iter().map(|v| v - current));
    Ok(mean)
}

impl State {
    /// At rest at positions `x` in the water of `model` (at rest in its current: a flow that
    /// has always been there), its histories `histories`.
    pub(crate) fn at_rest(x: &[Vec3], histories: Histories, model: &Model) -> Self {
        State {
            x: AlignedVec3::from_slice(x),
            v: AlignedVec3::zeros(x.len()),
            time: 0.0,
            steps: 0,
            histories,
            skin_mean: match model.water.unsteady_skin() {
                true => vec![-model.current; x.len()],
                false => Vec::new(),
            },
            motion: MotionRate::default(),
        }
    }

    /// What `model` asks of this state's memories (a reconfigured cloth's, or a loaded
    /// snapshot's): a memory it keeps that the state lacks is started from the state as it is
    /// (the skin drag's mean from the flow, no sudden start), its room asked for now; one it
    /// does not keep is dropped. Nothing changes until [`State::change_memories`], so a caller
    /// can refuse after this and leave the state whole.
    pub(crate) fn memories_for(&self, model: &Model) -> Result<MemoryChange, Error> {
        let skin_mean = skin_mean_change(model, &self.skin_mean, &self.v)?;
        Ok(MemoryChange { skin_mean })
    }

    /// Makes the memories what [`State::memories_for`] said.
    pub(crate) fn change_memories(&mut self, change: MemoryChange) {
        match change.skin_mean {
            Change::Keep => {}
            Change::Start(mean) => self.skin_mean = mean,
            Change::Drop => self.skin_mean = Vec::new(),
        }
    }

    /// Bytes of the state on `topology`: what a copy of it needs.
    pub(crate) fn bytes(&self, topology: &Topology) -> u64 {
        let mut sum = 0;
        macro_rules! add {
            ($f:ident) => {
                sum += Evolving::bytes(&self.$f, topology);
            };
        }
        for_each_memory!(add);
        sum
    }

    /// Makes `copy` this state, reusing its buffers (a first copy is a clone). Fails with an
    /// out-of-memory error, nothing copied, when the room it needs beyond what `copy` holds
    /// cannot be had (all of it the first time; then what a full history grew by).
    pub(crate) fn copy_into(&self, copy: &mut Option<State>, topology: &Topology) -> Result<(), Error> {
        let need = self.bytes(topology);
        let have = copy.as_ref().map_or(0, |c| c.bytes(topology));
        if need > have {
            crate::memory::ensure_available(
                2 * (need - have),
                "the copy that makes a multi-substep call atomic",
            )?;
        }
        let Some(copy) = copy else {
            *copy = Some(self.clone());
            return Ok(());
        };
        macro_rules! copy {
            ($f:ident) => {
                Evolving::copy_into(&self.$f, &mut copy.$f);
            };
        }
        for_each_memory!(copy);
        copy.time = self.time;
        copy.steps = self.steps;
        Ok(())
    }

    /// `2 self - whole` for every memory that extrapolates (positions, velocities, the skin
    /// mean), `whole` the state after one whole step from the same start as this one's two
    /// half steps.
    pub(crate) fn extrapolate(&mut self, whole: &State) {
        macro_rules! extrapolate {
            ($f:ident) => {
                Evolving::extrapolate(&mut self.$f, &whole.$f);
            };
        }
        for_each_memory!(extrapolate);
    }
}
