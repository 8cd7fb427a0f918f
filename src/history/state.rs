//! [`History`]: the state of the chosen scheme for one cloth, and what a step's pass over the
//! particles reads of it ([`StepPast`]).

use super::{soe, Full, HalfDerivative, Scheme, SoeKernel, SumOfExponentials, Truncated, MAX_HISTORY_BYTES};
use crate::error::Error;
use crate::math::Vec3;

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
            } => {
                let kernel = SoeKernel::build(tolerance, min_dt, horizon)?;
                let defer = soe::defers_folds(n, kernel.len());
                History::SumOfExponentials(Box::new(
                    SumOfExponentials::new(kernel, n).with_deferred_fold(defer),
                ))
            }
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
            History::SumOfExponentials(s) if s.snapshot_folds() && !w.is_counting() => {
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
// One lives on the stack for the length of a pass; boxing the larger variant would allocate
// every step.
#[allow(clippy::large_enum_variant)]
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
