//! Second order by local Richardson extrapolation ([`Integrator::ExtrapolatedSymplectic`],
//! [`Integrator::ExtrapolatedImplicit`]).
//!
//! A first-order step from the state at t has a local error `e h^2 + O(h^3)`; two half steps
//! have `e h^2 / 2 + O(h^3)`. So `2 y_half - y_whole` has a local error O(h^3) and the method is
//! second order, whatever the forces are: springs, every drag, added mass, contacts, pins, and
//! the half-derivative, whose history records the two half steps' velocities (the product
//! integration of every history scheme is consistent to second order with them; tested against
//! the fractional oscillator's 30-digit reference in `tests/second_order.rs`).
//!
//! For implicit Euler the amplification of a linear mode `z = h lambda` becomes
//! `R(z) = 2 / (1 - z/2)^2 - 1 / (1 - z)`: `|R| < 1` on the whole left half-plane and `R -> 0`
//! as `|z| -> infinity`, so the extrapolated step keeps implicit Euler's stability at frame
//! rate and damps stiff modes. For symplectic Euler the stability bound is about the base's
//! (`docs/stability.md`).
//!
//! [`Integrator::ExtrapolatedSymplectic`]: crate::Integrator::ExtrapolatedSymplectic
//! [`Integrator::ExtrapolatedImplicit`]: crate::Integrator::ExtrapolatedImplicit

use super::plan::{Stage, StepLimit, StepPlan};
use super::step::Advanced;
use super::Cloth;
use crate::error::Error;
use crate::integrate;

impl Cloth {
    /// One extrapolated step as `plan` says (its size, where its pins start and end, its
    /// limit: the whole step's plan). Not atomic by itself: the caller restores its rollback
    /// on an error. Self-collision's step limit acts on the whole step and on each half step
    /// as the plan's limit says: refused (nothing committed: for a refused second half the
    /// step's start, kept aside while a refusal is possible, is put back) or slowed (the last
    /// resort).
    pub(super) fn extrapolated_advance(&mut self, plan: StepPlan) -> Result<Advanced, Error> {
        let mut probe = std::mem::take(&mut self.probe);
        let mut start = std::mem::take(&mut self.probe_start);
        let done = self.extrapolate_with(&mut probe, &mut start, plan);
        self.probe = probe;
        self.probe_start = start;
        done
    }

    fn extrapolate_with(
        &mut self,
        probe: &mut super::Rollback,
        start: &mut super::Rollback,
        plan: StepPlan,
    ) -> Result<Advanced, Error> {
        let (h, f0, f1) = (plan.h, plan.from, plan.fraction);
        let steps = self.state.steps;
        probe.save(self)?;
        // A refused second half needs the start back: one more copy of the state, with
        // self-collision only (61 x 41 symplectic2 at a fixed 1/30 s, self-collision 4 mm, 32
        // pieces a frame: 9.0-9.4 s a 12 s bake against 8.9 s without the copy, `water_sweep`).
        let refusable = self.config.model.self_collision_on();
        let limit = match refusable {
            true => plan.limit,
            false => StepLimit::Slow,
        };
        if limit == StepLimit::Refuse {
            start.save(self)?;
        }
        let integrator = self.config.integrator;
        // The whole step, kept aside in `probe` (restoring swaps it there). A whole step too
        // far for self-collision's limit is refused before anything is committed.
        // Each of the three steps is the call's (automatic or not, the piece of a split
        // substep), at its own stage.
        let staged = |h, from, fraction, stage| StepPlan {
            auto: plan.auto,
            piece: plan.piece,
            ..StepPlan::new(integrator, h, from, fraction, stage).limited(limit)
        };
        let whole = staged(h, f0, f1, Stage::Whole);
        if let Advanced::TooFar(ratio) = self.advance(whole)? {
            return Ok(Advanced::TooFar(ratio));
        }
        probe.restore(self);
        // Two half steps, the first with the pins aimed at their mid goals (`pins.rs`). A
        // refused first half committed nothing; a refused second half puts the start back.
        let fmid = self.plan_mid_goals(h, f0, f1);
        let first = staged(0.5 * h, f0, Some(fmid), Stage::FirstHalf);
        if let Advanced::TooFar(ratio) = self.advance(first)? {
            return Ok(Advanced::TooFar(ratio));
        }
        let second = staged(0.5 * h, fmid, f1, Stage::SecondHalf);
        if let Advanced::TooFar(ratio) = self.advance(second)? {
            start.restore(self);
            return Ok(Advanced::TooFar(ratio));
        }
        // Saved above: a missing copy would be a bug, refused rather than stepped wrong.
        let whole = probe
            .state
            .as_ref()
            .ok_or_else(|| Error::invalid("internal: the whole step's state was not kept"))?;
        self.state.extrapolate(whole);
        if !integrator.is_implicit() {
            self.keep_pin_secants(&whole.v);
        }
        self.state.steps = steps + 1;
        let max2 = self.config.max_speed * self.config.max_speed;
        let far = self
            .state
            .x
            .iter()
            .position(|x| x.amax() >= super::MAX_COORDINATE);
        if !integrate::sound(&self.state.x, &self.state.v, max2) || far.is_some() {
            let i = (0..self.state.x.len())
                .find(|&i| {
                    let (x, v) = (self.state.x[i], self.state.v[i]);
                    !integrate::sound_particle([x.x, x.y, x.z], [v.x, v.y, v.z], max2)
                        || x.amax() >= super::MAX_COORDINATE
                })
                .unwrap_or(0);
            return Err(Error::unstable(format!(
                "{} with dt = {h} s is unstable at step {steps}: vertex {i} would reach speed {:.3e} m/s (limit {} m/s) or leave the float range; state left unchanged, retry with a smaller dt (max_substep = FC_MAX_SUBSTEP_AUTO lets the library choose the substeps; or set max_substep, or call fc_cloth_step_substeps)",
                self.config.integrator.name(),
                self.state.v[i].norm(),
                self.config.max_speed
            )));
        }
        Ok(Advanced::Taken)
    }
}
