//! Time integrators, one file each.
//!
//! An integrator reads the state at t_n and writes the state at t_n + h into
//! `x_new`/`v_new`; the cloth checks the result and commits it only if it is sound,
//! so every step is atomic.

mod explicit_euler;

pub use explicit_euler::explicit_euler;

/// Which integrator advances the cloth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Integrator {
    /// The paper's Eq. 7: `x += h v; v += h a`, both from the state at t_n.
    #[default]
    ExplicitEuler,
}

impl Integrator {
    /// Human name, used in messages.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit Euler",
        }
    }
}
