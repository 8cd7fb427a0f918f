//! The pair elements: forces between two particles, declared once, beside the per-particle
//! terms of `terms.rs`.
//!
//! Each element says whether a model uses it, what it remembers (if anything), how its forces
//! are summed, and its damping in the implicit system's spring block. The step, the Jacobian,
//! the memories a cloth keeps and the snapshot read this list; none of them names an element.
//!
//! | element | forces | memory | block |
//! |---|---|---|---|
//! | [`SPRING`] | Hooke plus velocity or Eq. 5 damping, summed by the tile walks (`tiles.rs`) | D^{1/2} of each particle's displacement with Eq. 5 | `k_s`, `c_s = k_d` or `k_d w0` |
//! | [`STRAIN_SPRING`] | the rotation-invariant fractional damping (`strain.rs`), a pass of its own before the force pass | D^{1/2} of each spring's elongation | `c_s = k_d w0'` |
//!
//! Contacts (mesh colliders, self-collision) are pair elements too, whose pairs are found each
//! step: they live in `crate::collide::contact` with their own Jacobian blocks.
//!
//! Adding a spring with a memory is one entry here (its kernel and its damping) plus its
//! switch in [`crate::model::Model`] and the ABI's description.

use super::springs::{spring_rate, SpringRate};
use super::strain;
use crate::math::Vec3;
use crate::model::{Model, SpringDamping};
use crate::topology::Topology;

/// A displacement whose half-derivative an element remembers; each is one history.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Memory {
    /// Every particle's displacement relative to the water (one `Vec3` per particle).
    Particles,
    /// Every spring's elongation (one scalar per spring, packed three to a `Vec3`).
    Springs,
}

impl Memory {
    /// Every memory, in the order the step and the snapshot keep them.
    pub(crate) const ALL: [Memory; 2] = [Memory::Particles, Memory::Springs];

    /// History entries (`Vec3`) this memory needs on `topology`.
    pub fn entries(self, topology: &Topology) -> usize {
        match self {
            Memory::Particles => topology.vertex_count(),
            Memory::Springs => strain::entries(topology.springs.len()),
        }
    }

    /// Its index in `Memory::ALL`.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The current-rate weight `w0` of each memory's D^{1/2} this step (0 for a memory not kept):
/// what the implicit integrator treats as damping.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Weights(pub [f64; 2]);

impl Weights {
    /// The weight of `memory`.
    pub fn of(&self, memory: Memory) -> f64 {
        self.0[memory.index()]
    }
}

/// How an element's forces are summed.
#[derive(Clone, Copy)]
pub enum Kernel {
    /// In the force pass's spring walk (`tiles.rs`), damping on [`spring_rate`].
    SpringWalk,
    /// A whole-cloth pass before the force pass, from the rates its memory records: `rates`
    /// writes them from the state, `forces` adds the element's forces given the memory's
    /// weight `w0` and past part (`D^{1/2} = w0 rate + past`).
    Prior {
        rates: fn(&Topology, &[Vec3], &[Vec3], &mut Vec<Vec3>),
        forces: ForcesFn,
    },
}

/// `forces(model, topology, x, w0, rates, past, out)`: adds an element's forces into `out`.
pub type ForcesFn = fn(&Model, &Topology, &[Vec3], f64, &[Vec3], &[Vec3], &mut [Vec3]);

/// One kind of pair element.
pub struct PairElement {
    /// What the element is, for people (tests and messages name it).
    #[cfg_attr(not(test), allow(dead_code))]
    pub name: &'static str,
    /// Whether model `m` uses it (off costs nothing).
    pub on: fn(&Model) -> bool,
    /// What it remembers under model `m`, if anything.
    pub memory: fn(&Model) -> Option<Memory>,
    pub kernel: Kernel,
    /// Its damping coefficient `c_s` for a spring of unit damping scale (the block is
    /// `c_s l_hat l_hat^T`), given the memories' weights this step.
    pub damping: fn(&Model, &Weights) -> f64,
}

/// Hooke's springs with the paper's damping: none, `k_d (v_i - v_j) . l_hat` or Eq. 5's
/// `k_d (D^{1/2}x_i - D^{1/2}x_j) . l_hat`.
pub const SPRING: PairElement = PairElement {
    name: "spring",
    on: |_| true,
    memory: |m| (spring_rate(m) == SpringRate::HalfDerivative).then_some(Memory::Particles),
    kernel: Kernel::SpringWalk,
    damping: |m, w| match spring_rate(m) {
        SpringRate::None => 0.0,
        SpringRate::Velocity => m.spring_damping,
        SpringRate::HalfDerivative => m.spring_damping * w.of(Memory::Particles),
    },
};

/// The rotation-invariant fractional damping: `-k_d D^{1/2}(|l| - r) l_hat` (`strain.rs`).
pub const STRAIN_SPRING: PairElement = PairElement {
    name: "strain spring",
    on: strain_on,
    memory: |m| strain_on(m).then_some(Memory::Springs),
    kernel: Kernel::Prior {
        rates: strain::elongation_rates,
        forces: strain::add_forces,
    },
    damping: |m, w| {
        if strain_on(m) {
            m.spring_damping * w.of(Memory::Springs)
        } else {
            0.0
        }
    },
};

fn strain_on(m: &Model) -> bool {
    m.spring_damping_mode == SpringDamping::FractionalStrain && m.spring_damping != 0.0
}

/// Every pair element, in the order their forces are summed.
pub const PAIR_ELEMENTS: &[PairElement] = &[SPRING, STRAIN_SPRING];

/// The spring damping `c_s` of model `m` (before each family's scale), summed over the
/// elements.
pub fn spring_damping(m: &Model, w: &Weights) -> f64 {
    PAIR_ELEMENTS.iter().map(|e| (e.damping)(m, w)).sum()
}

/// What model `m`'s springs damp: nothing, their ends' velocities, or a half-derivative (its
/// current-rate weight `w0` then scales the damping: what the automatic step's bound reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DampingRate {
    None,
    Velocity,
    HalfDerivative,
}

/// How `m`'s springs are damped, from the elements that damp them: an element with a memory
/// damps on a half-derivative.
pub fn damping_rate(m: &Model) -> DampingRate {
    let unit = Weights([1.0; 2]);
    PAIR_ELEMENTS
        .iter()
        .find(|e| (e.on)(m) && (e.damping)(m, &unit) > 0.0)
        .map_or(DampingRate::None, |e| {
            if (e.memory)(m).is_some() {
                DampingRate::HalfDerivative
            } else {
                DampingRate::Velocity
            }
        })
}

/// Whether any element of model `m` remembers `memory`.
pub fn remembers(m: &Model, memory: Memory) -> bool {
    PAIR_ELEMENTS
        .iter()
        .any(|e| (e.on)(m) && (e.memory)(m) == Some(memory))
}

/// Scratch of the elements' own passes.
#[derive(Clone, Debug, Default)]
pub struct ElementScratch {
    /// The rates each memory records this step (the particles' are the step's velocities
    /// relative to the water, kept by the step; this holds the others).
    pub rates: Vec<Vec3>,
    pub past: Vec<Vec3>,
}

/// The forces of every element with a [`Kernel::Prior`] pass into `out`: emptied, then sized
/// to the particles and summed into when any runs; says whether any ran. `memory_past` gives a
/// memory's weight and writes its past part into the buffer (the caller owns the histories).
/// Whether the model has a pair element with a pass of its own before the force pass
/// ([`prior_forces`], which reads the step's velocities).
pub fn prior_elements_on(model: &Model) -> bool {
    PAIR_ELEMENTS
        .iter()
        .any(|e| (e.on)(model) && matches!(e.kernel, Kernel::Prior { .. }))
}

pub fn prior_forces(
    model: &Model,
    topology: &Topology,
    x: &[Vec3],
    v: &[Vec3],
    scratch: &mut ElementScratch,
    mut memory_past: impl FnMut(Memory, &mut [Vec3]) -> f64,
    out: &mut Vec<Vec3>,
) -> bool {
    out.clear();
    let mut any = false;
    for e in PAIR_ELEMENTS.iter().filter(|e| (e.on)(model)) {
        let Kernel::Prior { rates, forces } = e.kernel else {
            continue;
        };
        if !any {
            out.resize(x.len(), Vec3::zeros());
            any = true;
        }
        rates(topology, x, v, &mut scratch.rates);
        scratch.past.clear();
        scratch.past.resize(scratch.rates.len(), Vec3::zeros());
        let w0 = match (e.memory)(model) {
            Some(memory) => memory_past(memory, &mut scratch.past),
            None => 0.0,
        };
        forces(model, topology, x, w0, &scratch.rates, &scratch.past, out);
    }
    any
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::RegularDrag;

    #[test]
    fn each_damping_mode_has_one_element_that_damps() {
        let w = Weights([0.25, 0.5]);
        let mut m = Model::regular(RegularDrag::Normal);
        m.spring_damping = 2.0;
        for (mode, want) in [
            (SpringDamping::None, 0.0),
            (SpringDamping::Velocity, 2.0),
            (SpringDamping::Fractional, 0.5),
            (SpringDamping::FractionalStrain, 1.0),
        ] {
            m.spring_damping_mode = mode;
            assert_eq!(spring_damping(&m, &w), want, "{mode:?}");
            let damping: Vec<_> = PAIR_ELEMENTS
                .iter()
                .filter(|e| (e.damping)(&m, &w) != 0.0)
                .map(|e| e.name)
                .collect();
            assert!(damping.len() <= 1, "{mode:?}: {damping:?}");
        }
    }

    #[test]
    fn the_damping_rate_is_the_damping_elements() {
        let mut m = Model::regular(RegularDrag::Normal);
        m.spring_damping = 1.0;
        for (mode, want) in [
            (SpringDamping::None, DampingRate::None),
            (SpringDamping::Velocity, DampingRate::Velocity),
            (SpringDamping::Fractional, DampingRate::HalfDerivative),
            (SpringDamping::FractionalStrain, DampingRate::HalfDerivative),
        ] {
            m.spring_damping_mode = mode;
            assert_eq!(damping_rate(&m), want, "{mode:?}");
        }
        m.spring_damping = 0.0;
        m.spring_damping_mode = SpringDamping::Velocity;
        assert_eq!(damping_rate(&m), DampingRate::None);
    }

    #[test]
    fn memories_are_the_elements_own() {
        let mut m = Model::regular(RegularDrag::Normal);
        m.spring_damping = 1.0;
        m.spring_damping_mode = SpringDamping::Fractional;
        assert!(remembers(&m, Memory::Particles) && !remembers(&m, Memory::Springs));
        m.spring_damping_mode = SpringDamping::FractionalStrain;
        assert!(!remembers(&m, Memory::Particles) && remembers(&m, Memory::Springs));
        m.spring_damping = 0.0;
        assert!(!remembers(&m, Memory::Particles) && !remembers(&m, Memory::Springs));
    }
}
