//! The cloth's memories as one collection: one half-derivative history per [`Memory`] (the
//! particles' displacements, the springs' elongations), each `Off` unless a term or pair
//! element of the model reads it ([`forces::memories`]).
//!
//! The step, the rollback of a refused call, the snapshot and its trial step handle them with
//! one loop each, so a new memory is one more [`Memory`] and its rates, not a new field
//! threaded through every site.

use crate::error::Error;
use crate::forces::{self, Memory};
use crate::history::{HalfDerivative, History, Scheme};
use crate::model::Model;
use crate::topology::Topology;

/// One history per [`Memory`], in the order of [`Memory::ALL`].
#[derive(Debug)]
pub(crate) struct Histories([History; 2]);

impl Clone for Histories {
    fn clone(&self) -> Self {
        Histories(self.0.clone())
    }

    /// Reuses each history's buffers (`History::clone_from`).
    fn clone_from(&mut self, source: &Self) {
        for (a, b) in self.0.iter_mut().zip(&source.0) {
            a.clone_from(b);
        }
    }
}

impl Histories {
    /// The histories model `m` reads, each by `scheme`, sized for `topology`.
    pub(crate) fn new(m: &Model, scheme: Scheme, topology: &Topology) -> Result<Self, Error> {
        let keeps = forces::memories(m);
        let make = |memory: Memory| {
            let on = if keeps.keeps(memory) { scheme } else { Scheme::Off };
            History::new(on, memory.entries(topology))
        };
        Ok(Histories([make(Memory::Particles)?, make(Memory::Springs)?]))
    }

    pub(crate) fn get(&self, memory: Memory) -> &History {
        &self.0[memory.index()]
    }

    pub(crate) fn get_mut(&mut self, memory: Memory) -> &mut History {
        &mut self.0[memory.index()]
    }

    /// Lets every history make room for a step (only the full history grows).
    pub(crate) fn reserve_step(&mut self) -> Result<(), Error> {
        self.0.iter_mut().try_for_each(History::reserve_step)
    }

    /// Bytes the histories hold on `topology`.
    pub(crate) fn bytes(&self, topology: &Topology) -> u64 {
        Memory::ALL
            .iter()
            .map(|&m| self.get(m).bytes_per_particle() as u64 * m.entries(topology) as u64)
            .sum()
    }

    /// The memories kept beyond the particles', for a snapshot's fingerprint (a history per
    /// spring changes the state's layout): one bit per memory after the first.
    pub(crate) fn layout(&self) -> u32 {
        self.0
            .iter()
            .enumerate()
            .skip(1)
            .filter(|(_, h)| !h.is_off())
            .map(|(k, _)| 1 << (k - 1))
            .sum()
    }

    pub(crate) fn write_state(&self, w: &mut crate::bytes::ByteWriter) -> Result<(), Error> {
        self.0.iter().try_for_each(|h| h.write_state(w))
    }

    pub(crate) fn read_state(&mut self, r: &mut crate::bytes::ByteReader<'_>) -> Result<(), Error> {
        self.0.iter_mut().try_for_each(|h| h.read_state(r))
    }

    /// Checks every history read from a snapshot (see `History::check_state`).
    pub(crate) fn check_state(&self, now: f64) -> Result<(), Error> {
        self.0.iter().try_for_each(|h| h.check_state(now))
    }
}
