//! Pins: the host's calls that pin and move vertices, where each pin is at the end of a step
//! (its goal), the velocity a hard pin gives the history, and the pass that puts pins on their
//! goals.
//!
//! A multi-substep call moves every pin in a straight line from where the call found it
//! (`PinPaths::start`) to the host's target, a fraction of the way per substep; an extrapolated
//! step's first half aims hard pins at a point on a parabola instead (`Cloth::plan_mid_goals`).

use super::plan::{Stage, StepPlan};
use super::Cloth;
use crate::error::{check_finite_vec, Error};
use crate::math::Vec3;

/// The pins as the host set them: what a snapshot carries of them.
#[derive(Clone, Debug)]
pub(super) struct Pins {
    /// Fully pinned (weight 1): the solver treats these as prescribed.
    pub pinned: Vec<bool>,
    /// Pin weight of every vertex in [0, 1]; 0 = free.
    pub weight: Vec<f64>,
    /// Vertices with a weight > 0, in the order they were pinned.
    pub list: Vec<u32>,
    /// Where each pinned vertex is to be at the end of the next call, m.
    pub target: Vec<Vec3>,
}

/// The pins' buffers a step reuses.
#[derive(Clone, Debug, Default)]
pub(super) struct PinPaths {
    /// Where every pin is at the end of the step (entries of free vertices unused).
    pub goal: Vec<Vec3>,
    /// Pin positions at the start of a multi-substep call, in `pin_list` order.
    pub start: Vec<Vec3>,
    /// Goals of the pins (in `pin_list` order) for the first half of an extrapolated step.
    pub mid: Vec<Vec3>,
    /// Fully pinned particles, ascending (to find those of a tile by bisection).
    pub hard: Vec<u32>,
}

pub(super) fn check_weight(i: usize, w: f64) -> Result<(), Error> {
    if (0.0..=1.0).contains(&w) {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "pin weight of vertex {i} must be in [0, 1], got {w}"
        )))
    }
}

impl Cloth {
    /// Pinned vertex indices, in the order they were given.
    pub fn pinned(&self) -> &[u32] {
        &self.pins.list
    }

    /// Replaces the pinned set: the listed vertices are fully pinned (weight 1), every other
    /// vertex is free. Pins hold their current positions until moved.
    pub fn set_pinned(&mut self, indices: &[u32]) -> Result<(), Error> {
        for &i in indices {
            self.check_index(i)?;
        }
        self.clear_pins();
        for &i in indices {
            self.pin(i as usize, 1.0);
        }
        Ok(())
    }

    /// Replaces every vertex's pin weight (one per vertex, each in [0, 1]; 0 = free,
    /// 1 = fully pinned). A vertex of weight w in (0, 1) is pulled the fraction w of the way
    /// onto its target (and its velocity the fraction w onto the target's) at the end of
    /// every step: a soft pin, as a DCC's pin weight or goal strength.
    pub fn set_pin_weights(&mut self, weights: &[f64]) -> Result<(), Error> {
        if weights.len() != self.vertex_count() {
            return Err(Error::invalid(format!(
                "expected {} pin weights, got {}",
                self.vertex_count(),
                weights.len()
            )));
        }
        for (i, &w) in weights.iter().enumerate() {
            check_weight(i, w)?;
        }
        self.clear_pins();
        for (i, &w) in weights.iter().enumerate() {
            self.pin(i, w);
        }
        Ok(())
    }

    /// Sets the pin weight of a group of vertices (e.g. a DCC vertex group) to `weight` in
    /// [0, 1], leaving every other vertex as it is; 0 frees them.
    pub fn pin_group(&mut self, indices: &[u32], weight: f64) -> Result<(), Error> {
        for &i in indices {
            check_weight(self.check_index(i)?, weight)?;
        }
        for &i in indices {
            let i = i as usize;
            if self.pins.weight[i] > 0.0 {
                self.pins.weight[i] = 0.0;
                self.pins.pinned[i] = false;
                self.pins.list.retain(|&p| p as usize != i);
            }
            self.pin(i, weight);
        }
        Ok(())
    }

    /// Pin weight of every vertex.
    pub fn pin_weights(&self) -> &[f64] {
        &self.pins.weight
    }

    fn clear_pins(&mut self) {
        self.pins.pinned.fill(false);
        self.pins.weight.fill(0.0);
        self.pins.list.clear();
    }

    /// Pins free vertex `i` with weight `w` (nothing for w = 0) at its current position.
    fn pin(&mut self, i: usize, w: f64) {
        if w > 0.0 && self.pins.weight[i] == 0.0 {
            self.pins.weight[i] = w;
            self.pins.pinned[i] = w == 1.0;
            self.pins.list.push(i as u32);
            self.pins.target[i] = self.state.x[i];
        }
    }

    /// Moves pinned vertices: at the end of the next step vertex `indices[k]` sits at
    /// `targets[k]`. Every index must be pinned.
    pub fn set_pin_targets(&mut self, indices: &[u32], targets: &[Vec3]) -> Result<(), Error> {
        if indices.len() != targets.len() {
            return Err(Error::invalid(format!(
                "{} indices but {} targets",
                indices.len(),
                targets.len()
            )));
        }
        for (&i, t) in indices.iter().zip(targets) {
            let i = self.check_index(i)?;
            if self.pins.weight[i] == 0.0 {
                return Err(Error::invalid(format!("vertex {i} is not pinned")));
            }
            check_finite_vec("pin target", t)?;
        }
        for (&i, t) in indices.iter().zip(targets) {
            self.pins.target[i as usize] = *t;
        }
        Ok(())
    }

    /// Remembers where every pin is as a multi-substep call starts.
    pub(super) fn start_pin_paths(&mut self) {
        let start = &mut self.scratch.pins.start;
        start.clear();
        start.extend(self.pins.list.iter().map(|&i| self.state.x[i as usize]));
    }

    /// Where every pin is at the end of the step: its target, the plan's fraction of the way
    /// there from where a multi-substep call started, or (an extrapolated step's first half)
    /// its mid goal. Also lists the hard pins for the velocity pass.
    pub(super) fn pin_goals(&mut self, plan: &StepPlan) {
        let p = &mut self.scratch.pins;
        for (k, &i) in self.pins.list.iter().enumerate() {
            let i = i as usize;
            p.goal[i] = match (plan.stage, plan.fraction) {
                (Stage::FirstHalf, _) => p.mid[k],
                (_, Some(f)) => p.start[k] + f * (self.pins.target[i] - p.start[k]),
                (_, None) => self.pins.target[i],
            };
        }
        p.hard.clear();
        p.hard
            .extend(self.pins.list.iter().filter(|&&i| self.pins.pinned[i as usize]));
        p.hard.sort_unstable();
    }

    /// The pins' goals at the middle of an extrapolated step of size `h` whose pins start at
    /// fraction `f0` of the call's travel and end at `f1` (None: at their targets). A soft
    /// pin's is half-way along its straight path; a hard pin's is on the parabola through its
    /// last position (from its velocity, the last step's secant), its position and its goal:
    /// `5/8 x_n + 3/8 x_{n+1} + h/8 v_n`, third-order accurate where the straight line is
    /// second-order, which would leave the half steps' pin velocities with a first-order error
    /// that both runs share and no extrapolation removes. Returns the middle's fraction.
    pub(super) fn plan_mid_goals(&mut self, h: f64, f0: f64, f1: Option<f64>) -> f64 {
        let fmid = 0.5 * (f0 + f1.unwrap_or(1.0));
        let p = &mut self.scratch.pins;
        p.mid.clear();
        for (k, &i) in self.pins.list.iter().enumerate() {
            let i = i as usize;
            let along = |f: f64| p.start[k] + f * (self.pins.target[i] - p.start[k]);
            let end = f1.map_or(self.pins.target[i], along);
            p.mid.push(if self.pins.pinned[i] {
                0.625 * self.state.x[i] + 0.375 * end + (0.125 * h) * self.state.v[i]
            } else {
                along(fmid)
            });
        }
        fmid
    }

    /// After an extrapolated symplectic step: a hard pin keeps the whole step's secant
    /// (`whole_v`), the slope of its path half a step back, which is what the next step's mid
    /// goal and history sample read it as. (Extrapolating it too would feed the last velocity
    /// into the next through the mid goal, a recurrence whose error after a kink in the path
    /// never dies out.)
    pub(super) fn keep_pin_secants(&mut self, whole_v: &[Vec3]) {
        for &i in &self.pins.list {
            let i = i as usize;
            if self.pins.pinned[i] {
                self.state.v[i] = whole_v[i];
            }
        }
    }

    /// The positions the proposed step ends at once [`Cloth::pins`] has run, into `out`.
    pub(super) fn step_end_into(&self, out: &mut Vec<Vec3>) {
        let s = &self.scratch;
        out.clear();
        out.extend_from_slice(&s.x_new);
        for &i in &self.pins.list {
            let i = i as usize;
            let goal = s.pins.goal[i];
            out[i] = match self.pins.pinned[i] {
                true => goal,
                false => s.x_new[i] + self.pins.weight[i] * (goal - s.x_new[i]),
            };
        }
    }

    /// Pinned particles onto their goals (moving with their step velocity); soft pins pulled
    /// the fraction of their weight of the way there.
    pub(super) fn pins(&mut self, h: f64) {
        let s = &mut self.scratch;
        let goal = &s.pins.goal;
        for &i in &self.pins.list {
            let i = i as usize;
            let w = self.pins.weight[i];
            if self.pins.pinned[i] {
                s.x_new[i] = goal[i];
                s.v_new[i] = s.v_step[i];
            } else {
                // Soft pin: the fraction w of the way onto the target and its velocity.
                let v_goal = (goal[i] - self.state.x[i]) / h;
                let (x_free, v_free) = (s.x_new[i], s.v_new[i]);
                s.x_new[i] = x_free + w * (goal[i] - x_free);
                s.v_new[i] = v_free + w * (v_goal - v_free);
            }
        }
    }
}
