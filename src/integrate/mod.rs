//! Time integrators, one file each.
//!
//! An integrator reads the state at t_n and writes the state at t_n + h into
//! `x_new`/`v_new`; the cloth checks the result and commits it only if it is sound,
//! so every step is atomic. See `docs/stability.md` for where each one fails.

mod cg;
mod explicit_euler;
mod implicit_euler;
mod integrator;
mod symplectic_euler;
mod tile_step;
pub mod xpbd;

pub use cg::{SolverSettings, SolverStats};
pub use explicit_euler::explicit_euler_soa;
pub use implicit_euler::{implicit_euler, ImplicitInput, ImplicitScratch};
pub use integrator::Integrator;
pub use symplectic_euler::symplectic_euler_soa;
pub use tile_step::{sound, sound_particle, StepInput, StepSoa};
