//! Half-derivative D^{1/2}x of particle displacement, from a stored velocity history.
//!
//! Caputo form: `D^{1/2}x(t) = 1/sqrt(pi) * integral_0^t (t - s)^{-1/2} v(s) ds`.
//! Every scheme computes, at step n, `D^{1/2}x_n = w0 * v_n + H_n`: `w0` weighs the
//! current velocity and `H_n` depends only on velocities already pushed. The
//! split is what lets an implicit integrator treat `w0` as damping and `H_n` as a
//! known force.
//!
//! Protocol, once per step of size h:
//! 1. [`HalfDerivative::prepare`] with h;
//! 2. [`HalfDerivative::current_weight`] and [`HalfDerivative::past`] as often as needed;
//! 3. after the step is accepted, [`HalfDerivative::push`] the velocities v_n the step used.

mod truncated;

pub use truncated::Truncated;

use crate::Vec3;

/// Which scheme evaluates D^{1/2}x (configuration; see [`History`] for the state).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scheme {
    /// No fractional terms; keeps no history.
    Off,
    /// The paper's Eq. 6 with the history truncated to the last `u` velocities (`u >= 1`).
    Truncated { u: u32 },
}

impl Scheme {
    /// The paper's configuration (u = 3).
    pub const PAPER: Scheme = Scheme::Truncated { u: 3 };
}

/// One way of evaluating the half-derivative for every particle of a cloth.
pub trait HalfDerivative {
    /// Readies the weights for a step of size `h` seconds.
    fn prepare(&mut self, h: f64);
    /// Weight w0 of the current velocity v_n.
    fn current_weight(&self) -> f64;
    /// Writes H_n (the part from the past) for every particle into `out`.
    fn past(&self, out: &mut [Vec3]);
    /// Records the velocities v_n used by the step just accepted.
    fn push(&mut self, v: &[Vec3]);
    /// Bytes of history held per particle.
    fn bytes_per_particle(&self) -> usize;
    /// Forgets the past (as at t = 0).
    fn reset(&mut self);
}

/// State of the chosen scheme for one cloth.
#[derive(Clone, Debug)]
pub enum History {
    Off,
    Truncated(Truncated),
}

impl History {
    /// Builds the state for `n` particles. `Off` allocates nothing.
    pub fn new(scheme: Scheme, n: usize) -> Self {
        match scheme {
            Scheme::Off => History::Off,
            Scheme::Truncated { u } => History::Truncated(Truncated::new(u.max(1) as usize, n)),
        }
    }

    fn inner(&self) -> Option<&dyn HalfDerivative> {
        match self {
            History::Off => None,
            History::Truncated(t) => Some(t),
        }
    }

    fn inner_mut(&mut self) -> Option<&mut dyn HalfDerivative> {
        match self {
            History::Off => None,
            History::Truncated(t) => Some(t),
        }
    }

    /// True when no history is kept.
    pub fn is_off(&self) -> bool {
        matches!(self, History::Off)
    }
}

impl HalfDerivative for History {
    fn prepare(&mut self, h: f64) {
        if let Some(s) = self.inner_mut() {
            s.prepare(h)
        }
    }
    fn current_weight(&self) -> f64 {
        self.inner().map_or(0.0, |s| s.current_weight())
    }
    fn past(&self, out: &mut [Vec3]) {
        match self.inner() {
            Some(s) => s.past(out),
            None => out.fill(Vec3::zeros()),
        }
    }
    fn push(&mut self, v: &[Vec3]) {
        if let Some(s) = self.inner_mut() {
            s.push(v)
        }
    }
    fn bytes_per_particle(&self) -> usize {
        self.inner().map_or(0, |s| s.bytes_per_particle())
    }
    fn reset(&mut self) {
        if let Some(s) = self.inner_mut() {
            s.reset()
        }
    }
}
