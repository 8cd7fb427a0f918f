//! Which half-derivative memories a model keeps, derived from what its terms read.
//!
//! A history is kept exactly when something reads it: a per-particle term whose [`Reads`]
//! says `half_derivative` (the list in [`super::terms`]), or a pair element whose memory it is
//! (the list in [`super::elements`]: springs damped on D^{1/2}x by Eq. 5, springs damped on
//! the half-derivative of their elongation). There is no second list to keep in step: a
//! D^{1/2} term or element added to either list gets its history by what it declares.
//!
//! [`Reads`]: super::terms::Reads

use super::elements::{remembers, Memory};
use super::terms;
use crate::model::Model;

/// The memories a model keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Memories {
    /// D^{1/2} of every particle's displacement relative to the water.
    pub particles: bool,
    /// D^{1/2} of every spring's elongation (rotation-invariant fractional springs).
    pub springs: bool,
}

impl Memories {
    /// Whether `memory` is kept.
    pub fn keeps(&self, memory: Memory) -> bool {
        match memory {
            Memory::Particles => self.particles,
            Memory::Springs => self.springs,
        }
    }
}

/// What `m` reads of the past. Colliders read none, so the answer does not depend on them.
pub fn memories(m: &Model) -> Memories {
    Memories {
        particles: terms::reads(m, true).half_derivative || remembers(m, Memory::Particles),
        springs: remembers(m, Memory::Springs),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{RegularDrag, SpringDamping};

    #[test]
    fn a_history_is_kept_exactly_when_a_term_reads_it() {
        assert!(memories(&Model::fractional()).particles);
        assert!(!memories(&Model::regular(RegularDrag::Normal)).particles);
        assert!(!memories(&Model::underwater()).particles);
        // The history drag alone, per particle or per area, needs it; so does Eq. 5 alone.
        let only = |f: fn(&mut Model)| {
            let mut m = Model::regular(RegularDrag::Normal);
            m.spring_damping = 0.0;
            f(&mut m);
            memories(&m)
        };
        assert!(only(|m| m.history_drag = 1e-3).particles);
        assert!(only(|m| m.water.history_drag = 1.0).particles);
        let eq5 = only(|m| {
            m.spring_damping = 0.1;
            m.spring_damping_mode = SpringDamping::Fractional;
        });
        assert!(eq5.particles && !eq5.springs);
        let strain = only(|m| {
            m.spring_damping = 0.1;
            m.spring_damping_mode = SpringDamping::FractionalStrain;
        });
        assert!(!strain.particles && strain.springs);
        assert_eq!(
            only(|_| ()),
            Memories {
                particles: false,
                springs: false
            }
        );
    }

    #[test]
    fn every_term_that_reads_the_half_derivative_gets_a_history() {
        // Switch each term on alone (every coefficient set), and check the rule agrees with
        // the term's own declaration.
        let mut m = Model::regular(RegularDrag::Normal);
        m.history_drag = 1e-3;
        m.viscous_drag = 1e-3;
        m.water.form_drag = 1.0;
        m.water.skin_drag = 1.0;
        for t in terms::TERMS.iter().filter(|t| (t.on)(&m, true)) {
            if t.reads.half_derivative {
                assert!(memories(&m).particles, "{}", t.name);
            }
        }
    }
}
