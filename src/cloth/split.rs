//! Self-collision's split of a substep: a substep in which a free vertex would move farther than
//! self-collision's step limit ([`SELF_COLLISION_STEP_LIMIT`] of the thickness) is taken in
//! 2, 4, ... equal pieces instead, each within the limit, so that a long fixed substep (a host's
//! `fc_cloth_step` at frame rate) keeps its motion instead of having it slowed.
//!
//! **How.** Before a substep the pieces are predicted from the free vertices' speeds
//! (`|v| h` over the limit; at most [`SPLIT_AIM`] of it a piece). A piece whose proposed state
//! still moves a vertex too far is refused, nothing committed ([`Advanced::TooFar`]), and the
//! rest of the substep is taken in as many more pieces as its overshoot says. Pieces are
//! always `h / 2^level`, so those taken stay on the grid of the finer ones.
//!
//! **Stable pieces.** At a host's fixed step (not the automatic step's own calls) a split
//! substep's pieces are also no longer than the automatic step's stable substep
//! (`Cloth::stable_level`): an explicit integrator's fixed step too long to be stable, split
//! for the limit, is then split into stable pieces instead of jittering at the limit's scale.
//! A substep the limit does not split is taken as the host asked.
//!
//! **Proved whole.** A piece over the limit is taken as it is when the proof of
//! `collide/unfolded.rs` shows that no pair comes within self-collision's reach at any instant
//! of it (`Cloth::limit_needless`; only a piece stable by itself): an unfolded cloth at a long
//! fixed step keeps its one substep. So a substep its speeds would split is first tried whole
//! when the last look found the cloth out of its own reach, unless a try failed lately
//! ([`WHOLE_BACKOFF`]).
//!
//! **Where it stops.** At [`MAX_SPLIT_LEVEL`] (32 pieces; 32 times the stable pieces at a
//! host's fixed step) a vertex still too fast is slowed to
//! the limit, as before the split existed ([`StepLimit::Slow`]); that is the only slowing.
//!
//! **What a slow cloth pays.** Nothing but the prediction's pass over the speeds. A substep
//! whose vertices are predicted well within the limit ([`REFUSE_FROM`]) is not *watched*: self-
//! collision's memory is not copied before it. Such a substep is still refused when a vertex
//! is flung past the limit within it (the first step from rest, whose speeds predict nothing);
//! its retry then starts from whatever look the refused attempt made at the same start
//! positions (pairs found there, by a reach the longer attempt may have made wider), so its
//! bits may differ from asking for that many substeps, not its validity. A call of one
//! first-order substep copies the memory anyway (it has no other rollback) and keeps its bits.
//!
//! Without self-collision a substep is one piece and nothing here runs.
//!
//! [`SELF_COLLISION_STEP_LIMIT`]: super::collisions::SELF_COLLISION_STEP_LIMIT

use super::collisions::SELF_COLLISION_STEP_LIMIT;
use super::plan::{Stage, StepLimit, StepPlan};
use super::step::Advanced;
use super::{Cloth, Rollback};
use crate::error::Error;

/// A piece aims at moving its fastest vertex at most this fraction of the step limit.
pub const SPLIT_AIM: f64 = 0.8;

/// At most `2^MAX_SPLIT_LEVEL` pieces a substep (32) for the limit; at a host's fixed step,
/// that many times the stable pieces (`Cloth::stable_level`, itself at most this level).
pub const MAX_SPLIT_LEVEL: u32 = 5;

/// At most this many substeps split at once, after a failed try to take one whole, before the
/// next try (`Cloth::take_substep`).
pub const WHOLE_BACKOFF: u32 = 16;

/// A substep whose fastest free vertex is predicted to move less than this fraction of the
/// limit is taken whole and not watched (self-collision's memory is not copied before it): it
/// would have to speed up this many times over within one substep to need a split. If it
/// does, it is refused and split all the same.
pub const REFUSE_FROM: f64 = 0.25;

/// What self-collision's step limit did since a cloth was made (steps a refused call undid
/// included).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepLimitStats {
    /// Substeps taken in pieces.
    pub split_substeps: u64,
    /// The pieces those substeps were taken in.
    pub pieces: u64,
    /// Steps in which a free vertex moved farther than the limit, taken all the same because
    /// the proof of `collide/unfolded.rs` showed no pair could come within self-collision's
    /// reach at any instant of them (an unfolded cloth at a long fixed step).
    pub proved_whole: u64,
    /// Free vertices slowed to the limit, summed over steps: the last resort, in a substep
    /// already split as far as it goes (32 pieces; at a host's fixed step 32 times the
    /// pieces it needs to be stable). Not 0 means some motion was held back: a step too long for the
    /// cloth's speed (an unstable fixed step, say) that no host asked to refuse.
    pub slowed: u64,
}

/// The splitter's state: what it did, and when it next tries whole a substep the speeds would
/// split.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Splitter {
    pub stats: StepLimitStats,
    /// Substeps to wait before the next try, and the wait after the next failure.
    whole_wait: u32,
    whole_backoff: u32,
}

impl Splitter {
    /// A substep tried whole was refused: wait twice as long as last time (up to
    /// `WHOLE_BACKOFF` substeps) before the next try.
    fn whole_failed(&mut self) {
        self.whole_backoff = (2 * self.whole_backoff).clamp(1, WHOLE_BACKOFF);
        self.whole_wait = self.whole_backoff;
    }
}

impl Cloth {
    /// What self-collision's step limit did since the cloth was made ([`StepLimitStats`]).
    pub fn step_limit_stats(&self) -> StepLimitStats {
        self.splitter.stats
    }

    /// One substep of size `h` whose pins and mesh colliders go from fraction `f0` of the
    /// call's travel to `f1` (None: the call's end), split as self-collision's step limit needs
    /// (module docs); `auto` when the automatic step chose it. Returns the pieces taken. Not
    /// atomic: on an error the caller restores `snap` when `saved` says it holds the call's
    /// start; a call of one first-order step has none until a split needs it (made here,
    /// before the first piece commits anything).
    pub(super) fn take_substep(
        &mut self,
        h: f64,
        (f0, f1): (f64, Option<f64>),
        auto: bool,
        snap: &mut Rollback,
        saved: &mut bool,
    ) -> Result<u32, Error> {
        let on = self.config.model.self_collision_on();
        let limit_m = SELF_COLLISION_STEP_LIMIT * self.config.model.self_collision_thickness;
        let (watched, mut level) = if on {
            self.predicted_split(h, limit_m)
        } else {
            (false, 0)
        };
        // The level a split substep's pieces are at least at, to be stable (found once, when
        // the substep first splits).
        let mut stable: Option<u32> = None;
        // The limit splits up to `MAX_SPLIT_LEVEL` levels beyond those.
        let top = |stable: Option<u32>| MAX_SPLIT_LEVEL + stable.unwrap_or(0);
        let mut whole = false;
        if level > 0 {
            (level, whole) = self.first_level(h, auto, level, &mut stable);
        }
        let end = f1.unwrap_or(1.0);
        let (mut done, mut taken) = (0u32, 0u32);
        let mut memory = std::mem::take(&mut self.scratch.piece_memory);
        let result = loop {
            let pieces = 1u32 << level;
            if done == pieces {
                if whole {
                    // Taken whole: try again at the next one.
                    self.splitter.whole_backoff = 0;
                }
                if taken > 1 {
                    let stats = &mut self.splitter.stats;
                    stats.split_substeps += 1;
                    stats.pieces += u64::from(taken);
                }
                break Ok(taken);
            }
            if level > 0 && !*saved {
                // The call's only step, split: nothing is committed yet, so this is its start.
                if let Err(e) = snap.save(self) {
                    break Err(e);
                }
                *saved = true;
            }
            let limit = match level < top(stable) {
                true => StepLimit::Refuse,
                false => StepLimit::Slow,
            };
            // What self-collision remembers, for a refused piece of a watched substep or a
            // failed unsaved call. (A retry from the same state would look at the same pairs,
            // so for a refused piece this is defence: `a_refused_piece_leaves_no_trace` passes
            // without it; an unwatched substep goes without, module docs.)
            let keep = on && (watched || !*saved);
            if keep {
                self.self_collision.save_memory(&mut memory);
            }
            let at = |j: u32| f0 + (end - f0) * f64::from(j) / f64::from(pieces);
            let (a, b) = (at(done), (done + 1 < pieces).then(|| at(done + 1)).or(f1));
            let mut plan = StepPlan::new(self.config.integrator, h / f64::from(pieces), a, b, Stage::Whole);
            (plan.limit, plan.auto, plan.piece) = (limit, auto, Some((h, level)));
            match self.take_piece(plan) {
                Ok(Advanced::Taken) => {
                    done += 1;
                    taken += 1;
                }
                Ok(Advanced::TooFar(ratio)) => {
                    if keep {
                        self.self_collision.swap_memory(&mut memory);
                    }
                    if std::mem::take(&mut whole) {
                        self.splitter.whole_failed();
                    }
                    let floor = *stable.get_or_insert_with(|| self.stable_level(h, auto));
                    let next = (level + more_levels(ratio)).max(floor).min(top(stable));
                    done <<= next - level;
                    level = next;
                }
                Err(mut e) => {
                    if keep && !*saved {
                        self.self_collision.swap_memory(&mut memory);
                    }
                    if level > 0 {
                        // The message names the piece's dt: say whose piece it is.
                        e.message = format!(
                            "piece {} of {pieces} of a {h} s substep that self-collision's step limit split: {}",
                            done + 1,
                            e.message
                        );
                    }
                    break Err(e);
                }
            }
        };
        self.scratch.piece_memory = memory;
        result
    }

    /// The level a substep the speeds would split (at `level`) starts at, and whether it is
    /// tried whole: first, when the last look found the cloth out of its own reach (the proof
    /// may then show it so throughout the substep, and the limit is not needed:
    /// `Cloth::limit_needless`), unless a try failed lately (after a failure 1, 2, 4, ... up
    /// to `WHOLE_BACKOFF` substeps are split at once before the next try). `stable` gets the
    /// level its pieces must be at to be stable.
    fn first_level(&mut self, h: f64, auto: bool, level: u32, stable: &mut Option<u32>) -> (u32, bool) {
        let floor = *stable.get_or_insert_with(|| self.stable_level(h, auto));
        if floor == 0 && self.self_collision.last_look_proved() && self.splitter.whole_wait == 0 {
            (0, true)
        } else {
            self.splitter.whole_wait = self.splitter.whole_wait.saturating_sub(1);
            (level.max(floor), false)
        }
    }

    /// One piece as `plan` says, by the integrator's own step.
    fn take_piece(&mut self, plan: StepPlan) -> Result<Advanced, Error> {
        if self.config.integrator.is_extrapolated() {
            self.extrapolated_advance(plan)
        } else {
            self.advance(plan)
        }
    }

    /// The fewest levels of pieces that bring a substep of `h` within the automatic step's
    /// stable substep (`Cloth::auto_substep`): a split substep's pieces are no longer, so that
    /// a host's fixed step too long to be stable, split for the limit, is split into stable
    /// pieces instead of jittering at the limit's scale. 0 for implicit Euler (no stability
    /// bound) and in the automatic step's own calls (`auto`: its substeps are stable already).
    pub(super) fn stable_level(&self, h: f64, auto: bool) -> u32 {
        if auto || self.config.integrator.is_implicit() {
            return 0;
        }
        let stable = self.auto_substep(h);
        if stable.is_nan() || stable <= 0.0 || stable >= h {
            return 0;
        }
        ((h / stable).log2().ceil() as u32).min(MAX_SPLIT_LEVEL)
    }

    /// Whether a substep of `h` is watched for the step limit `limit` (m), and the level of
    /// pieces its free vertices' speeds ask for (0: whole).
    fn predicted_split(&self, h: f64, limit: f64) -> (bool, u32) {
        let fastest2 = self
            .state
            .v
            .iter()
            .zip(&self.pins.pinned)
            .filter(|(_, &pinned)| !pinned)
            .map(|(v, _)| v.norm_squared())
            .fold(0.0, f64::max);
        let ratio = fastest2.sqrt() * h / limit;
        // A NaN speed is left to the step's check.
        if ratio.is_nan() || ratio < REFUSE_FROM {
            return (false, 0);
        }
        (
            true,
            if ratio > 1.0 {
                more_levels(ratio).min(MAX_SPLIT_LEVEL)
            } else {
                0
            },
        )
    }
}

/// How many levels (halvings) bring a piece that moves `ratio` times the limit to
/// [`SPLIT_AIM`] of it or below (at least one).
fn more_levels(ratio: f64) -> u32 {
    let levels = (ratio / SPLIT_AIM).log2().ceil();
    if levels.is_nan() || levels < 1.0 {
        1
    } else {
        levels.min(f64::from(MAX_SPLIT_LEVEL)) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::{ClothConfig, GridSpec, Integrator, Vec3};

    #[test]
    fn a_piece_over_the_limit_is_split_to_the_aim() {
        // 1.5 times the limit: halves (0.75 <= 0.8).
        assert_eq!(more_levels(1.5), 1);
        // 1.7: quarters (0.85 > 0.8 in halves).
        assert_eq!(more_levels(1.7), 2);
        assert_eq!(more_levels(6.0), 3);
        // At least one level, never more than the cap, whatever the ratio.
        assert_eq!(more_levels(1.0 + 1e-12), 1);
        assert_eq!(more_levels(1e300), MAX_SPLIT_LEVEL);
        assert_eq!(more_levels(f64::INFINITY), MAX_SPLIT_LEVEL);
        assert_eq!(more_levels(f64::NAN), 1);
    }

    /// A 21 x 21 towel of the underwater preset with self-collision 4 mm, implicit Euler, its
    /// top row pinned: its lower half folded up in front of the upper half, 6 mm off it (so
    /// that self-collision has pairs in reach and remembers them), moving at `speed` m/s
    /// towards it, and its rows beyond the fold stretched by `stretch` (their springs then pull
    /// them back within a step).
    fn folded(speed: f64, stretch: f64) -> Cloth {
        let t = GridSpec {
            width: 21,
            height: 21,
            spacing: 0.01,
            total_mass: 0.04,
        }
        .build()
        .expect("a grid");
        let model = Model {
            self_collision_thickness: 0.004,
            self_collision_friction: 0.3,
            ..Model::underwater()
        };
        let config = ClothConfig {
            model,
            integrator: Integrator::ImplicitEuler,
            ..ClothConfig::default()
        };
        let mut c = Cloth::new(t, config).expect("a cloth");
        c.set_pinned(&(0..21).collect::<Vec<u32>>()).expect("pins");
        let (mut x, mut v) = (c.positions().to_vec(), vec![Vec3::zeros(); c.vertex_count()]);
        for (i, (x, v)) in x.iter_mut().zip(&mut v).enumerate() {
            let row = (i / 21) as f64;
            if row > 10.0 {
                // Row 10 + k goes to row 10 - k * stretch, in front.
                let k = row - 10.0;
                *x = Vec3::new(x.x, -0.01 * (10.0 - k * stretch), 0.006);
                *v = Vec3::new(0.0, 0.0, -speed);
            }
        }
        c.set_positions(&x).expect("positions");
        c.set_velocities(&v).expect("velocities");
        c
    }

    /// Everything a call leaves: positions, velocities and the snapshot's bytes (histories,
    /// self-collision's memory).
    fn state(c: &Cloth) -> (Vec<Vec3>, Vec<Vec3>, Vec<u8>) {
        let bytes = c.save_snapshot().expect("a snapshot");
        (c.positions().to_vec(), c.velocities().to_vec(), bytes)
    }

    /// A substep its vertices' speeds say is too long (0.3 m/s for 1/30 s: 5 times the 2 mm
    /// limit) is taken in 8 pieces: the same bits as a call asking for 8 substeps, and the
    /// statistics say 8.
    #[test]
    fn a_split_substep_is_the_substeps_it_was_split_into() {
        let (mut split, mut asked) = (folded(0.3, 1.0), folded(0.3, 1.0));
        let limit = SELF_COLLISION_STEP_LIMIT * 0.004;
        assert_eq!(split.predicted_split(1.0 / 30.0, limit), (true, 3));
        for _ in 0..3 {
            split.step_substeps(1.0 / 30.0, 1).expect("the split call");
            asked.step_substeps(1.0 / 30.0, 8).expect("the asked call");
            assert_eq!(split.step_stats().substeps, asked.step_stats().substeps);
        }
        assert!(split.step_stats().substeps >= 8);
        let (pairs, _) = split.self_collision.pairs();
        assert!(!pairs.is_empty(), "self-collision remembers pairs");
        assert!(state(&split) == state(&asked));
        // Three substeps split, into the pieces counted, none slowed; the asked call split none.
        let stats = split.step_limit_stats();
        assert_eq!((stats.split_substeps, stats.slowed), (3, 0));
        assert!(stats.pieces >= 24);
        assert_eq!(asked.step_limit_stats(), StepLimitStats::default());
    }

    /// Symplectic Euler at a host's fixed 1/30 s, far past its stable substep: a substep its
    /// speeds split (4 pieces for the limit) is taken in pieces no longer than the automatic
    /// step's stable one instead (32 here), the same bits as asking for that many substeps;
    /// without the floor its pieces were unstable and the cloth jittered at the limit's scale.
    #[test]
    fn a_split_substep_is_cut_into_stable_pieces_at_a_fixed_step() {
        // The towel of `folded` unfolded, symplectic Euler, its free vertices moving at
        // 0.1 m/s across it (3.3 mm in 1/30 s: 4 pieces for the 2 mm limit).
        let flung = || {
            let mut c = folded(0.0, 1.0);
            let t = c.topology().clone();
            let mut config = c.config.clone();
            config.integrator = Integrator::SymplecticEuler;
            c = Cloth::new(t, config).expect("a cloth");
            c.set_pinned(&(0..21).collect::<Vec<u32>>()).expect("pins");
            let v: Vec<Vec3> = (0..c.vertex_count())
                .map(|i| Vec3::new(0.0, 0.0, if i < 21 { 0.0 } else { 0.1 }))
                .collect();
            c.set_velocities(&v).expect("velocities");
            c
        };
        let (mut split, mut asked) = (flung(), flung());
        let h = 1.0 / 30.0;
        let limit = SELF_COLLISION_STEP_LIMIT * 0.004;
        assert_eq!(split.predicted_split(h, limit), (true, 2));
        let floor = split.stable_level(h, false);
        assert!(
            split.auto_substep(h) * 16.0 < h,
            "1/30 s is far past the stable substep"
        );
        assert_eq!(floor, MAX_SPLIT_LEVEL);
        split.step_substeps(h, 1).expect("the split call");
        assert_eq!(split.step_stats().substeps, 1 << floor);
        asked.step_substeps(h, 1 << floor).expect("the asked call");
        assert!(state(&split) == state(&asked));
        // The automatic step's own calls are stable already: no floor.
        assert_eq!(split.stable_level(h, true), 0);
    }

    /// A piece that fails (here implicit Euler's solve, stopped after one iteration) fails the
    /// call, which leaves the cloth as it was, and the message says the dt it names is a piece
    /// of a substep the limit split (the host asked for 1/30 s, not for 1/240 s).
    #[test]
    fn a_failed_piece_says_whose_piece_it_is() {
        let mut c = folded(0.3, 1.0);
        let settings = crate::integrate::SolverSettings {
            tolerance: 1e-14,
            max_iterations: 1,
        };
        c.set_solver(settings).expect("settings");
        let before = state(&c);
        let e = c
            .step_substeps(1.0 / 30.0, 1)
            .expect_err("an unconverged solve is refused");
        println!("{}", e.message);
        assert!(
            e.message.starts_with("piece 1 of 8 of a 0.0333") && e.message.contains("step limit split"),
            "{}",
            e.message
        );
        assert!(state(&c) == before);
    }

    /// A substep from rest is predicted within the limit and not watched, yet its springs fling
    /// vertices past the limit within it: it is refused and split all the same, nothing slowed
    /// (not slowed). A call of that one substep keeps its bits
    /// (the same as asking for that many substeps); a call of two, whose first substep is
    /// unwatched and goes without a copy of self-collision's memory, splits it too.
    #[test]
    fn a_substep_predicted_slow_but_flung_is_split_not_slowed() {
        let (mut c, mut asked) = (folded(0.0, 1.1), folded(0.0, 1.1));
        let limit = SELF_COLLISION_STEP_LIMIT * 0.004;
        assert_eq!(c.predicted_split(1.0 / 30.0, limit), (false, 0));
        c.step_substeps(1.0 / 30.0, 1).expect("the call");
        let stats = c.step_limit_stats();
        assert_eq!((stats.split_substeps, stats.slowed), (1, 0), "{stats:?}");
        let pieces = c.step_stats().substeps;
        assert!(pieces > 1 && pieces.is_power_of_two(), "{pieces} pieces");
        assert_eq!(stats.pieces, u64::from(pieces));
        asked.step_substeps(1.0 / 30.0, pieces).expect("the asked call");
        assert!(state(&c) == state(&asked));

        let mut two = folded(0.0, 1.1);
        two.step_substeps(2.0 / 30.0, 2).expect("the call of two");
        let stats = two.step_limit_stats();
        assert!(stats.split_substeps >= 1 && stats.slowed == 0, "{stats:?}");
        assert!(two.step_stats().substeps > 2);
    }

    /// An extrapolated integrator's substep too far for the limit is refused before anything is
    /// committed and taken in pieces: the same bits as a call asking for that many substeps,
    /// none slowed (implicit: 8 and 4 pieces; symplectic: 32, its stable pieces). The refused
    /// second half's restore is exercised by `tests/water_scenes.rs`
    /// (`an_extrapolated_fixed_step_with_self_collision_slows_no_half_step`: 7 in its bake,
    /// counted once by a throwaway print).
    #[test]
    fn an_extrapolated_split_substep_is_the_substeps_it_was_split_into() {
        for (integrator, speed, stretch) in [
            (Integrator::ExtrapolatedImplicit, 0.05, 1.05),
            (Integrator::ExtrapolatedImplicit, 0.1, 1.0),
            (Integrator::ExtrapolatedSymplectic, 0.02, 1.1),
        ] {
            let make = || {
                let c = folded(speed, stretch);
                let t = c.topology().clone();
                let (x, v) = (c.positions().to_vec(), c.velocities().to_vec());
                let mut config = c.config.clone();
                config.integrator = integrator;
                let mut c = Cloth::new(t, config).expect("a cloth");
                c.set_pinned(&(0..21).collect::<Vec<u32>>()).expect("pins");
                c.set_positions(&x).expect("positions");
                c.set_velocities(&v).expect("velocities");
                c
            };
            let (mut split, mut asked) = (make(), make());
            let h = 1.0 / 30.0;
            split.step_substeps(h, 1).expect("the split call");
            let pieces = split.step_stats().substeps;
            assert!(
                pieces > 1 && pieces.is_power_of_two(),
                "{integrator:?}: {pieces} pieces"
            );
            assert_eq!(split.step_limit_stats().slowed, 0, "{integrator:?}");
            asked.step_substeps(h, pieces).expect("the asked call");
            assert!(state(&split) == state(&asked), "{integrator:?}");
        }
    }

    /// A substep whose start speeds say it fits, but whose springs fling the cloth too far
    /// within it (3.8 times the limit, read once by a throwaway print: it was split into 8),
    /// is refused before anything is committed and taken in pieces: the same bits as a call
    /// asking for that many substeps (so the refused attempt left no trace in the histories
    /// or self-collision's memory).
    #[test]
    fn a_refused_piece_leaves_no_trace() {
        let (mut split, mut asked) = (folded(0.02, 1.1), folded(0.02, 1.1));
        let limit = SELF_COLLISION_STEP_LIMIT * 0.004;
        assert_eq!(split.predicted_split(1.0 / 30.0, limit), (true, 0));
        split.step_substeps(1.0 / 30.0, 1).expect("the split call");
        let pieces = split.step_stats().substeps;
        assert!(pieces > 1 && pieces.is_power_of_two(), "{pieces} pieces");
        asked.step_substeps(1.0 / 30.0, pieces).expect("the asked call");
        assert!(state(&split) == state(&asked));
    }
}
