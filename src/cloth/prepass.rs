//! The loops of the pass before the forces (see `Cloth::advance`), compiled for the widest
//! vector unit the CPU has ([`crate::simd`]): they move every particle's numbers between
//! `Vec3` arrays and component arrays, which vectorises only with wide shuffles.

use super::plan::PinSampling;
use crate::forces::{SpringRate, TILE};
use crate::history::StepPast;
use crate::math::Vec3;
use crate::parallel::Disjoint;

/// The step's first pass over the particles, range by range: the step's velocities `v_step`
/// (pins' from their goals), the velocity relative to the water `v_rel`, D^{1/2}x = w0 v_rel + H
/// of it (`half`; the history folds the last accepted step in here), and the component arrays
/// of positions `sx` and of the springs' damping rate `sq` (empty unless an untiled topology's
/// spring pass reads them). Run over every particle once a step, in ranges that may be run
/// on different threads ([`FirstPass::run`]).
pub(super) struct FirstPass<'a> {
    pub x: &'a [Vec3],
    pub v: &'a [Vec3],
    /// The pins' goals at the end of the step, and the fully pinned particles, ascending.
    pub goal: &'a [Vec3],
    pub hard_pins: &'a [u32],
    pub h: f64,
    pub sampling: PinSampling,
    /// The water's velocity, m/s.
    pub current: Vec3,
    pub rate: SpringRate,
    /// The particles' history this step, when they keep one.
    pub past: Option<&'a StepPast<'a>>,
    pub v_step: Disjoint<'a, Vec3>,
    pub v_rel: Disjoint<'a, Vec3>,
    pub half: Disjoint<'a, Vec3>,
    pub sx: [Disjoint<'a, f64>; 3],
    pub sq: [Disjoint<'a, f64>; 3],
}

impl<'a> FirstPass<'a> {
    /// The weight w0 of the current rate in D^{1/2}x this step (0 without a history).
    pub fn w0(&self) -> f64 {
        self.past.map_or(0.0, StepPast::current_weight)
    }

    /// The pass over particles `r`, tile by tile (so that its loops find a tile's numbers in
    /// L1).
    ///
    /// # Safety
    /// Every particle is covered once a step; ranges that may run at the same time do not
    /// overlap, and start on multiples of `TILE` and end on one or at the last particle (the
    /// history's blocks of 16, [`StepPast::past_range`]); nothing reads a range while it runs.
    pub unsafe fn run(&self, r: std::ops::Range<usize>) {
        // SAFETY: this range only (the caller's contract).
        let (v_step, half) = unsafe { (self.v_step.range(r.clone()), self.half.range(r.clone())) };
        // SAFETY: the caller's contract.
        unsafe { self.run_with(r, v_step, half, false) };
    }

    /// [`Self::run`], writing the step's velocities and D^{1/2}x of particles `r` into
    /// `v_step` and `half` (as long as `r`) instead of this pass's arrays: for a force pass
    /// that keeps them only while it reads them (`forces::Ahead`). The same operations, so
    /// the same bits. The fully pinned particles' step velocities also go to this pass's
    /// `v_step` (the pins' pass after the step reads them there).
    ///
    /// # Safety
    /// As [`Self::run`].
    pub unsafe fn run_into(&self, r: std::ops::Range<usize>, v_step: &mut [Vec3], half: &mut [Vec3]) {
        // SAFETY: the caller's contract.
        unsafe { self.run_with(r, v_step, half, true) };
    }

    /// The pass over `r` into `v_step` and `half`; `keep_pins`: the fully pinned particles'
    /// step velocities also into this pass's `v_step` (which `v_step` is not part of).
    ///
    /// # Safety
    /// As [`Self::run`].
    unsafe fn run_with(
        &self,
        r: std::ops::Range<usize>,
        v_step: &mut [Vec3],
        half: &mut [Vec3],
        keep_pins: bool,
    ) {
        let first = r.start;
        let len = r.len();
        debug_assert!(v_step.len() == len && half.len() == len);
        let with_history = self.past.is_some();
        // SAFETY: this range only (the caller's contract).
        let v_rel = unsafe { self.v_rel.range(r.clone()) };
        let arrays = !self.sx[0].is_empty();
        // This range's part of a component array, or nothing when the arrays are not kept.
        let part = |a: &Disjoint<'a, f64>| -> &'a mut [f64] {
            if a.is_empty() {
                return &mut [];
            }
            // SAFETY: this range only (the caller's contract).
            unsafe { a.range(r.clone()) }
        };
        let [sx, sy, sz] = self.sx.each_ref().map(part);
        let [qx, qy, qz] = self.sq.each_ref().map(part);
        let (x, v, goal, hard_pins) = (&self.x[r.clone()], &self.v[r.clone()], self.goal, self.hard_pins);
        for t0 in (0..len).step_by(TILE) {
            let t = t0..(t0 + TILE).min(len);
            // The tile in the component arrays: nothing when they are not kept.
            let ts = if arrays { t.clone() } else { 0..0 };
            velocities_and_positions(
                &x[t.clone()],
                &v[t.clone()],
                self.current,
                &mut v_step[t.clone()],
                &mut v_rel[t.clone()],
                [&mut sx[ts.clone()], &mut sy[ts.clone()], &mut sz[ts.clone()]],
            );
            // Fully pinned particles move to their goals: that is their velocity.
            let (lo, hi) = (first + t.start, first + t.end);
            let pins = &hard_pins[hard_pins.partition_point(|&i| (i as usize) < lo)..];
            for &i in pins.iter().take_while(|&&i| (i as usize) < hi) {
                let (p, k) = (i as usize, i as usize - first);
                v_step[k] = (goal[p] - x[k]) / self.h;
                v_rel[k] = self.sampling.rate(v[k], v_step[k]) - self.current;
                if keep_pins {
                    // SAFETY: particle `p` is in `r`, which this run alone writes (the
                    // caller's contract), and `v_step` is not this pass's array here.
                    let kept = unsafe { self.v_step.range(p..p + 1) };
                    kept[0] = v_step[k];
                }
            }
            if let Some(past) = self.past {
                // SAFETY: every particle once; tiles start on multiples of TILE and end on
                // one or at the last particle, so on blocks of 16 (the caller's contract).
                unsafe { past.past_range(lo, &mut half[t.clone()]) };
            }
            // The damping rate's component arrays: none for undamped springs.
            let (rate, q): (Option<&[Vec3]>, [&mut [f64]; 3]) = match self.rate {
                SpringRate::None if !with_history => continue,
                SpringRate::None => (None, [&mut [], &mut [], &mut []]),
                SpringRate::HalfDerivative => (
                    None,
                    [&mut qx[ts.clone()], &mut qy[ts.clone()], &mut qz[ts.clone()]],
                ),
                SpringRate::Velocity => (
                    Some(&v_step[t.clone()]),
                    [&mut qx[ts.clone()], &mut qy[ts.clone()], &mut qz[ts.clone()]],
                ),
            };
            add_current_and_split(
                with_history.then_some(self.w0()),
                &v_rel[t.clone()],
                &mut half[t.clone()],
                rate,
                q,
            );
        }
    }
}

crate::simd_dispatch! { pub(super) fn velocities_and_positions(x: &[Vec3], v: &[Vec3], current: Vec3, v_step: &mut [Vec3], v_rel: &mut [Vec3], sx: [&mut [f64]; 3]) => velocities_and_positions_kernel }

/// `v_step = v`, `v_rel = v - current`, and the positions `x` into component arrays `sx`
/// (unless they are empty); all other slices of one length.
#[inline(always)]
fn velocities_and_positions_kernel(
    x: &[Vec3],
    v: &[Vec3],
    current: Vec3,
    v_step: &mut [Vec3],
    v_rel: &mut [Vec3],
    sx: [&mut [f64]; 3],
) {
    let n = v_step.len();
    let (x, v, v_rel) = (&x[..n], &v[..n], &mut v_rel[..n]);
    let [px, py, pz] = sx;
    if px.is_empty() {
        for k in 0..n {
            v_step[k] = v[k];
            v_rel[k] = v[k] - current;
        }
        return;
    }
    let (px, py, pz) = (&mut px[..n], &mut py[..n], &mut pz[..n]);
    for k in 0..n {
        v_step[k] = v[k];
        v_rel[k] = v[k] - current;
        (px[k], py[k], pz[k]) = (x[k].x, x[k].y, x[k].z);
    }
}

crate::simd_dispatch! { pub(super) fn add_current_and_split(w0: Option<f64>, v_rel: &[Vec3], half: &mut [Vec3], rate: Option<&[Vec3]>, q: [&mut [f64]; 3]) => add_current_and_split_kernel }

/// `half += w0 v_rel` (when there is a history, `w0` not None), then the
/// damping rate (`rate`, or `half` itself when None) into component arrays `q` (unless they
/// are empty: undamped springs); all other slices of one length.
#[inline(always)]
fn add_current_and_split_kernel(
    w0: Option<f64>,
    v_rel: &[Vec3],
    half: &mut [Vec3],
    rate: Option<&[Vec3]>,
    q: [&mut [f64]; 3],
) {
    let n = half.len();
    if let Some(w0) = w0 {
        let v_rel = &v_rel[..n];
        for k in 0..n {
            half[k] += w0 * v_rel[k];
        }
    }
    let [qx, qy, qz] = q;
    if qx.is_empty() {
        return;
    }
    let r: &[Vec3] = rate.unwrap_or(half);
    let r = &r[..n];
    let (qx, qy, qz) = (&mut qx[..n], &mut qy[..n], &mut qz[..n]);
    for k in 0..n {
        (qx[k], qy[k], qz[k]) = (r[k].x, r[k].y, r[k].z);
    }
}
