//! The protocol every scheme speaks, one scheme at a time (tests and reference computations).

use crate::math::Vec3;

/// One way of evaluating the half-derivative for every particle of a cloth.
pub trait HalfDerivative {
    /// Readies the weights for the current step.
    fn prepare(&mut self);
    /// Weight w0 of the current velocity v_n.
    fn current_weight(&self) -> f64;
    /// Writes H_n (the part from the past) for particles `first .. first + out.len()` into
    /// `out`. Reads only, so disjoint ranges may be filled by different threads.
    fn past_range(&self, first: usize, out: &mut [Vec3]);
    /// Writes H_n for every particle into `out`.
    fn past(&self, out: &mut [Vec3]) {
        self.past_range(0, out)
    }
    /// Records the velocities v_n the accepted step of size `h` (s) started from.
    fn push(&mut self, v: &[Vec3], h: f64);
    /// Bytes of history held per particle now.
    fn bytes_per_particle(&self) -> usize;
    /// Forgets the past (as at t = 0).
    fn reset(&mut self);
}
