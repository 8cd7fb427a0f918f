//! What a refused call puts back ([`Rollback`]): the state saved before a multi-substep call.

use super::state::State;
use super::Cloth;
use crate::error::Error;
use crate::math::Vec3;

/// What a refused call puts back: the [`State`] saved before a multi-substep call (and around
/// the whole step of an extrapolated integrator), with self-collision's remembered pairs.
#[derive(Clone, Debug, Default)]
pub(super) struct Rollback {
    /// The state as saved (none before the first save).
    pub(super) state: Option<State>,
    /// Self-collision's remembered pairs and sides (state: a snapshot carries them).
    pub(super) self_collision: crate::collide::self_collision::SavedMemory,
    /// Room for the pins' targets a snapshot's trial step sets aside (not saved or restored).
    pub(super) targets: Vec<Vec3>,
}

impl Rollback {
    /// Copies the state, or fails with an out-of-memory error when the copy of a history
    /// that grew (the full history) cannot be allocated.
    pub(super) fn save(&mut self, c: &Cloth) -> Result<(), Error> {
        c.state.copy_into(&mut self.state, &c.topology)?;
        c.self_collision.save_memory(&mut self.self_collision);
        Ok(())
    }

    /// Puts the saved state back (the cloth's is kept here in exchange).
    pub(super) fn restore(&mut self, c: &mut Cloth) {
        if let Some(state) = &mut self.state {
            std::mem::swap(&mut c.state, state);
        }
        c.self_collision.swap_memory(&mut self.self_collision);
    }
}
