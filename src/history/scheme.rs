//! Which scheme evaluates D^{1/2}x: the configuration, its checks and its defaults.

use super::soe_kernel;
use crate::error::Error;

/// Which scheme evaluates D^{1/2}x (configuration; see [`super::History`] for the state).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scheme {
    /// No fractional terms; keeps no history.
    Off,
    /// The paper's Eq. 6 with the history truncated to the last `u` velocities (`u >= 1`).
    Truncated { u: u32 },
    /// Exact convolution over the whole history, second order; O(n) per step. The reference.
    Full,
    /// Kernel approximated by a sum of exponentials with relative error `tolerance` on
    /// `[min_dt, horizon]` seconds; O(K) per step, K ~ log(horizon / min_dt).
    SumOfExponentials {
        tolerance: f64,
        horizon: f64,
        min_dt: f64,
    },
}

impl Scheme {
    /// The paper's configuration (u = 3).
    pub const PAPER: Scheme = Scheme::Truncated { u: 3 };
    /// The default: SOE with 1e-3 relative kernel error (well below what the eye sees in
    /// cloth motion, see `docs/accuracy.md`) for steps down to 0.1 ms and shots up to 1 h (16 modes).
    pub const DEFAULT: Scheme = Scheme::SumOfExponentials {
        tolerance: DEFAULT_SOE_TOLERANCE,
        horizon: DEFAULT_SOE_HORIZON,
        min_dt: DEFAULT_SOE_MIN_DT,
    };

    /// Checks the parameters without building anything heavy.
    pub fn validate(&self) -> Result<(), Error> {
        match *self {
            Scheme::Truncated { u: 0 } => Err(Error::invalid("truncated history needs u >= 1")),
            Scheme::Truncated { u } if u > MAX_TRUNCATED_U => Err(Error::invalid(format!(
                "truncated history u = {u} exceeds {MAX_TRUNCATED_U}; use Full or SumOfExponentials for long memory"
            ))),
            Scheme::SumOfExponentials {
                tolerance,
                horizon,
                min_dt,
            } => soe_kernel::check_parameters(tolerance, min_dt, horizon),
            _ => Ok(()),
        }
    }

    /// Short human name.
    pub fn name(&self) -> String {
        match *self {
            Scheme::Off => "off".into(),
            Scheme::Truncated { u } => format!("truncated u={u}"),
            Scheme::Full => "full".into(),
            Scheme::SumOfExponentials { tolerance, .. } => format!("soe tol={tolerance:e}"),
        }
    }
}

/// Largest `u` accepted for [`Scheme::Truncated`].
pub const MAX_TRUNCATED_U: u32 = 100_000;

/// Largest history (bytes, all particles) a cloth may ask for up front.
pub const MAX_HISTORY_BYTES: u64 = 1 << 34;

/// Default SOE relative kernel tolerance.
pub const DEFAULT_SOE_TOLERANCE: f64 = 1e-3;
/// Default SOE horizon, s (one hour).
pub const DEFAULT_SOE_HORIZON: f64 = 3600.0;
/// Default SOE smallest step, s.
pub const DEFAULT_SOE_MIN_DT: f64 = 1e-4;
