//! Half-derivative D^{1/2}x of particle displacement, from a stored velocity history.
//!
//! Caputo form: `D^{1/2}x(t) = 1/sqrt(pi) * integral_0^t (t - s)^{-1/2} v(s) ds`.
//! Every scheme computes, at step n, `D^{1/2}x_n = w0 * v_n + H_n`: `w0` weighs the
//! current velocity and `H_n` depends only on velocities already pushed. The split is
//! what lets an implicit integrator treat `w0` as damping and `H_n` as a known force.
//!
//! How a step uses it (`src/cloth/step.rs`):
//! 1. `History::begin_step` readies the step's weights (each scheme keeps its own clock) and
//!    returns a `StepPast` that fills `H_n` range by range inside the step's pass over the
//!    particles; the SOE history folds the last accepted step into its modes during that same
//!    walk; then `History::end_step`;
//! 2. after the step is accepted, `History::record` takes the velocities the step started
//!    from (relative to the water) and the step size.
//!
//! [`HalfDerivative`] (`prepare`, `current_weight`, `past`, `push`) is the same protocol one
//! scheme at a time, for tests and the reference computations.
//!
//! Schemes, one file each: [`Truncated`] (the paper's Eq. 6), [`Full`] (exact product
//! integration over all history, the reference), [`SumOfExponentials`] (full memory at
//! O(K) cost). See `docs/accuracy.md` for their measured orders and errors.

mod full;
mod kernel;
mod protocol;
mod scheme;
mod soe;
mod soe_kernel;
mod state;
mod truncated;

pub use full::Full;
pub use kernel::panel_weights;
pub use protocol::HalfDerivative;
pub use scheme::{
    Scheme, DEFAULT_SOE_HORIZON, DEFAULT_SOE_MIN_DT, DEFAULT_SOE_TOLERANCE, MAX_HISTORY_BYTES,
    MAX_TRUNCATED_U,
};
/// Particles per block of the SOE mode store (a step's pass hands the history whole blocks).
pub(crate) use soe::LANES as SOE_BLOCK;
pub use soe::{defers_folds, SumOfExponentials, DEFER_FROM_BYTES, DEFER_VARIABLE};
pub use soe_kernel::SoeKernel;
pub use state::History;
pub(crate) use state::StepPast;
pub use truncated::{eq6_weights, Truncated};
