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
mod soe;
mod soe_kernel;
mod truncated;

pub use full::Full;
pub use kernel::panel_weights;
pub use soe::SumOfExponentials;
/// Particles per block of the SOE mode store (a step's pass hands the history whole blocks).
pub(crate) use soe::LANES as SOE_BLOCK;
pub use soe_kernel::SoeKernel;
pub use truncated::{eq6_weights, Truncated};

use crate::error::Error;
use crate::math::Vec3;

/// Which scheme evaluates D^{1/2}x (configuration; see [`History`] for the state).
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

/// State of the chosen scheme for one cloth.
#[derive(Debug)]
pub enum History {
    Off,
    Truncated(Truncated),
    Full(Full),
    /// Boxed: the largest state by far.
    SumOfExponentials(Box<SumOfExponentials>),
}

/// `clone_from` reuses the buffers when both sides hold the same scheme.
impl Clone for History {
    fn clone(&self) -> Self {
        match self {
            History::Off => History::Off,
            History::Truncated(s) => History::Truncated(s.clone()),
            History::Full(s) => History::Full(s.clone()),
            History::SumOfExponentials(s) => History::SumOfExponentials(s.clone()),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        match (self, source) {
            (History::Truncated(a), History::Truncated(b)) => a.clone_from(b),
            (History::Full(a), History::Full(b)) => a.clone_from(b),
            (History::SumOfExponentials(a), History::SumOfExponentials(b)) => a.clone_from(b),
            (me, other) => *me = other.clone(),
        }
    }
}

impl History {
    /// Builds the state for `n` particles. `Off` allocates nothing.
    pub fn new(scheme: Scheme, n: usize) -> Result<Self, Error> {
        scheme.validate()?;
        let per_particle = match scheme {
            Scheme::Truncated { u } => u64::from(u),
            _ => 0,
        };
        let bytes = per_particle
            .saturating_mul(n as u64)
            .saturating_mul(std::mem::size_of::<Vec3>() as u64);
        if bytes > MAX_HISTORY_BYTES {
            return Err(Error::invalid(format!(
                "the history would need {bytes} bytes (limit {MAX_HISTORY_BYTES})"
            )));
        }
        Ok(match scheme {
            Scheme::Off => History::Off,
            Scheme::Truncated { u } => History::Truncated(Truncated::new(u as usize, n)),
            Scheme::Full => History::Full(Full::new(n)),
            Scheme::SumOfExponentials {
                tolerance,
                horizon,
                min_dt,
            } => History::SumOfExponentials(Box::new(SumOfExponentials::new(
                SoeKernel::build(tolerance, min_dt, horizon)?,
                n,
            ))),
        })
    }

    fn inner(&self) -> Option<&dyn HalfDerivative> {
        match self {
            History::Off => None,
            History::Truncated(s) => Some(s),
            History::Full(s) => Some(s),
            History::SumOfExponentials(s) => Some(s.as_ref()),
        }
    }

    fn inner_mut(&mut self) -> Option<&mut dyn HalfDerivative> {
        match self {
            History::Off => None,
            History::Truncated(s) => Some(s),
            History::Full(s) => Some(s),
            History::SumOfExponentials(s) => Some(s.as_mut()),
        }
    }

    /// True when no history is kept.
    pub fn is_off(&self) -> bool {
        matches!(self, History::Off)
    }

    /// Tag of the scheme held (0 off, 1 truncated, 2 full, 3 SOE), for snapshots.
    pub(crate) fn tag(&self) -> u8 {
        match self {
            History::Off => 0,
            History::Truncated(_) => 1,
            History::Full(_) => 2,
            History::SumOfExponentials(_) => 3,
        }
    }

    /// Makes room for the next step's history (only `Full` grows); an error when it may not.
    pub(crate) fn reserve_step(&mut self) -> Result<(), Error> {
        match self {
            History::Full(s) => s.reserve_step(),
            _ => Ok(()),
        }
    }

    /// Writes the state (see each scheme's `write_state`). The bytes are canonical: a
    /// recorded sample that the next step would fold into the SOE modes is folded into the
    /// written state (in a copy), so the bytes do not depend on whether a refused step
    /// already folded it. Folding early or in the step gives the same bits.
    pub(crate) fn write_state(&self, w: &mut crate::bytes::ByteWriter) -> Result<(), Error> {
        match self {
            History::Off => {}
            History::Truncated(s) => s.write_state(w),
            History::Full(s) => s.write_state(w),
            History::SumOfExponentials(s) if s.has_pending_fold() && !w.is_counting() => {
                crate::memory::ensure_available(
                    s.bytes_per_particle() as u64 * s.particle_count() as u64,
                    "a snapshot of the SOE history",
                )?;
                let mut copy = s.clone();
                copy.fold_pending();
                copy.write_state(w);
            }
            History::SumOfExponentials(s) => s.write_state(w),
        }
        Ok(())
    }

    /// Checks a state read from a snapshot for meaning: every number finite, step sizes
    /// positive, sample times ordered and not after the cloth's time `now` (s).
    pub(crate) fn check_state(&self, now: f64) -> Result<(), Error> {
        match self {
            History::Off => Ok(()),
            History::Truncated(s) => s.check_state(),
            History::Full(s) => s.check_state(now),
            History::SumOfExponentials(s) => s.check_state(),
        }
    }

    /// Reads a state written by `write_state` of a history of the same scheme and size
    /// (check its meaning with `check_state`).
    pub(crate) fn read_state(&mut self, r: &mut crate::bytes::ByteReader<'_>) -> Result<(), Error> {
        match self {
            History::Off => Ok(()),
            History::Truncated(s) => s.read_state(r),
            History::Full(s) => s.read_state(r),
            History::SumOfExponentials(s) => s.read_state(r),
        }
    }

    /// Begins a step's pass over the particles: readies the step's weights and returns what
    /// gives `H_n` range by range ([`StepPast::past_range`]). After the pass, call
    /// [`Self::end_step`].
    pub(crate) fn begin_step(&mut self) -> StepPast<'_> {
        match self {
            History::SumOfExponentials(s) => StepPast::Soe(s.begin()),
            other => {
                other.prepare();
                StepPast::Read(other)
            }
        }
    }

    /// Ends the pass begun by [`Self::begin_step`], which covered every particle once.
    pub(crate) fn end_step(&mut self) {
        if let History::SumOfExponentials(s) = self {
            s.end();
        }
    }

    /// Records the velocities of the accepted step of size `h` (one per particle). `v` may be
    /// swapped for a buffer of the same length instead of copied (SOE).
    pub(crate) fn record(&mut self, v: &mut Vec<Vec3>, h: f64) {
        match self {
            History::SumOfExponentials(s) => s.record(v, h),
            other => other.push(v, h),
        }
    }

    /// Exponential modes in use (SOE only; 0 otherwise).
    pub fn mode_count(&self) -> usize {
        match self {
            History::SumOfExponentials(s) => s.mode_count(),
            _ => 0,
        }
    }
}

/// What one step's pass over the particles reads of the history, from `History::begin_step`.
pub(crate) enum StepPast<'a> {
    /// Schemes whose past is read only.
    Read(&'a History),
    /// SOE, which folds the last accepted step into its modes during the pass.
    Soe(soe::SoePass<'a>),
}

impl StepPast<'_> {
    /// Weight w0 of the current velocity over this step.
    pub(crate) fn current_weight(&self) -> f64 {
        match self {
            StepPast::Read(h) => h.current_weight(),
            StepPast::Soe(s) => s.current_weight(),
        }
    }

    /// Writes `H_n` of particles `first .. first + out.len()` into `out`.
    ///
    /// # Safety
    /// Every particle is covered exactly once per pass, and ranges whose calls may overlap in
    /// time start and end on blocks of 16 particles (or end at the last particle); see
    /// [`soe::SoePass::past_range`].
    pub(crate) unsafe fn past_range(&self, first: usize, out: &mut [Vec3]) {
        match self {
            StepPast::Read(h) => h.past_range(first, out),
            // SAFETY: the caller's contract is the pass's.
            StepPast::Soe(s) => unsafe { s.past_range(first, out) },
        }
    }
}

impl HalfDerivative for History {
    fn prepare(&mut self) {
        if let Some(s) = self.inner_mut() {
            s.prepare()
        }
    }
    fn current_weight(&self) -> f64 {
        self.inner().map_or(0.0, |s| s.current_weight())
    }
    fn past_range(&self, first: usize, out: &mut [Vec3]) {
        match self.inner() {
            Some(s) => s.past_range(first, out),
            None => out.fill(Vec3::zeros()),
        }
    }
    fn push(&mut self, v: &[Vec3], h: f64) {
        if let Some(s) = self.inner_mut() {
            s.push(v, h)
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
