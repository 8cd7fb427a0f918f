//! What evolves with a cloth's steps, in one place: positions, velocities, time, steps and the
//! memories (the half-derivative histories, the unsteady skin drag's running mean, the motion's
//! averages).
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

impl State {
    /// At rest at positions `x`, its memories `histories` and `skin_mean`.
    pub(crate) fn at_rest(x: &[Vec3], histories: Histories, skin_mean: Vec<Vec3>) -> Self {
        State {
            x: AlignedVec3::from_slice(x),
            v: AlignedVec3::zeros(x.len()),
            time: 0.0,
            steps: 0,
            histories,
            skin_mean,
            motion: MotionRate::default(),
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
