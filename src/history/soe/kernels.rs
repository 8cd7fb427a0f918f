//! The SOE history's per-particle kernels: one pass folds the newest sample into every mode and
//! sums the half-derivative, block by block in vectors (`pass_blocks`), or takes its sum from
//! the deferred `S` (`light_sums`).

use super::*;

/// Coefficients of one pass: per mode `M <- decay M + a v_{n-1} + b v_n` (when folding), then
/// per particle `H = w_prev v_n + (sum_l next_l M_l - shift v_n)`.
pub(super) struct Coefficients<'a> {
    pub(super) decay: &'a [f64],
    pub(super) a: &'a [f64],
    pub(super) b: &'a [f64],
    pub(super) next: &'a [f64],
    pub(super) shift: f64,
    /// Whether some `a` is not zero (a mode restarts); else the `v_{n-1}` term is skipped.
    pub(super) restart: bool,
    /// Whether the modes are folded (else only summed).
    pub(super) fold: bool,
    /// Whether the sum is taken as zero (the first sample).
    pub(super) zero: bool,
    pub(super) w_prev: f64,
    /// A first panel folded before the newest (deferring): its `decay` and `b` per mode; its
    /// sample is `prev` (no mode restarts in it).
    pub(super) first: Option<(&'a [f64], &'a [f64])>,
    /// Deferring: the coefficients of `ahead` (empty when the pass does not fill it).
    pub(super) ahead: &'a [f64],
    /// Deferring: the sum is `ahead + light v_n`, the modes not read.
    pub(super) light: Option<f64>,
}

impl<'a> Coefficients<'a> {
    /// The coefficients of plan `p` (filled into `coef` by [`plan`]), and the newest sample the
    /// pass works from: the recorded one `newest` when it folds, else the folded `prev`.
    pub(super) fn of(
        coef: &'a ModeCoefficients,
        p: Plan,
        w_prev: f64,
        prev: &'a [Vec3],
        newest: &'a [Vec3],
    ) -> (Self, &'a [Vec3]) {
        let k = p.k;
        let c = Coefficients {
            decay: &coef.decay[..k],
            a: &coef.a[..k],
            b: &coef.b[..k],
            next: &coef.next[..k],
            shift: p.shift,
            restart: p.restart,
            fold: p.fold.is_some(),
            zero: p.zero,
            w_prev,
            first: None,
            ahead: &[],
            light: None,
        };
        (c, if p.fold.is_some() { newest } else { prev })
    }
}

crate::simd_dispatch! { pub(super) fn pass_blocks_widest(c: &Coefficients<'_>, prev: &[Vec3], v: &[Vec3], modes: &mut [f64], out: &mut [Vec3], ahead: &mut [Vec3]) => pass_blocks }

/// [`pass_block`] for consecutive blocks: `prev` and `v` hold their particles (the last block
/// may be partial), `modes` and `out` their modes and sums, `ahead` their `S` when the pass
/// fills it (else it is empty).
#[inline(always)]
pub(super) fn pass_blocks(
    c: &Coefficients<'_>,
    prev: &[Vec3],
    v: &[Vec3],
    modes: &mut [f64],
    out: &mut [Vec3],
    ahead: &mut [Vec3],
) {
    let with_ahead = !c.ahead.is_empty();
    // A pass that folds two panels always fills `ahead` (`SumOfExponentials::begin_pass`).
    debug_assert!(c.first.is_none() || (with_ahead && c.fold));
    // Chosen once for all the blocks, so that each block's loop has no branch on them.
    let s = (prev, v, modes, out, ahead);
    match (c.fold, c.restart, with_ahead, c.first.is_some()) {
        (true, true, false, _) => blocks::<true, true, false, false>(c, s),
        (true, false, false, _) => blocks::<true, false, false, false>(c, s),
        (true, true, true, false) => blocks::<true, true, true, false>(c, s),
        (true, false, true, false) => blocks::<true, false, true, false>(c, s),
        (true, true, true, true) => blocks::<true, true, true, true>(c, s),
        (true, false, true, true) => blocks::<true, false, true, true>(c, s),
        (false, _, false, _) => blocks::<false, false, false, false>(c, s),
        (false, _, true, _) => blocks::<false, false, true, false>(c, s),
    }
}

/// The slices of [`pass_blocks`]: `prev`, `v`, `modes`, `out`, `ahead`.
type BlockSlices<'a> = (
    &'a [Vec3],
    &'a [Vec3],
    &'a mut [f64],
    &'a mut [Vec3],
    &'a mut [Vec3],
);

/// [`pass_blocks`] for one choice of what the pass does: `FIRST`, fold a pending panel first
/// (deferring; only with `AHEAD`, as every pass that folds two fills `ahead`).
#[inline(always)]
fn blocks<const FOLD: bool, const WITH_PREV: bool, const AHEAD: bool, const FIRST: bool>(
    c: &Coefficients<'_>,
    (prev, v, modes, out, ahead): BlockSlices<'_>,
) {
    // A block holds every mode of the kernel; `c` may cover only the first few (the rest are
    // negligible over this step and are left alone).
    let block = modes.len() / out.len().div_ceil(LANES);
    debug_assert!(block >= c.next.len() * 3 * LANES);
    debug_assert!(!FIRST || AHEAD);
    for (b, (m, o)) in modes
        .chunks_exact_mut(block)
        .zip(out.chunks_mut(LANES))
        .enumerate()
    {
        let p0 = b * LANES;
        let p1 = (p0 + LANES).min(v.len());
        let (prev, v) = (&prev[p0..p1], &v[p0..p1]);
        if FIRST {
            if let Some((decay, b)) = c.first {
                fold_first(decay, b, prev, m);
            }
        }
        let s: &mut [Vec3] = if AHEAD { &mut ahead[p0..p1] } else { &mut [] };
        pass_block::<FOLD, WITH_PREV, AHEAD>(c, (prev, v, m, o, s));
    }
}

/// Folds the first of two panels (deferring) into one block's modes: `M <- decay M + b v`,
/// the fused multiply-add of [`pass_block`]'s fold without a restarting mode, so the modes
/// get the bits two passes would give them.
#[inline(always)]
fn fold_first(decay: &[f64], b: &[f64], v: &[Vec3], modes: &mut [f64]) {
    const W: usize = 3 * LANES;
    let mut vn = [0.0; W];
    for (q, x) in v.iter().enumerate() {
        for d in 0..3 {
            vn[d * LANES + q] = x[d];
        }
    }
    for ((mode, &decay), &b) in modes.chunks_exact_mut(W).zip(decay).zip(b) {
        for k in 0..W {
            mode[k] = decay.mul_add(mode[k], b * vn[k]);
        }
    }
}

/// One block of up to `LANES` particles: folds the panel (`prev`, `v`) into its modes when
/// `FOLD`, and writes each particle's `H` into `out`. Same arithmetic, in the same order, for
/// every particle as a scalar loop over its modes; laid out so it vectorises across lanes.
/// `WITH_PREV`: whether the `a v_{n-1}` term is added (some `a` is not zero).
/// `AHEAD`: whether the block's `S` is summed into `ahead` (deferring).
#[inline(always)]
fn pass_block<const FOLD: bool, const WITH_PREV: bool, const AHEAD: bool>(
    c: &Coefficients<'_>,
    (prev, v, modes, out, ahead): BlockSlices<'_>,
) {
    const W: usize = 3 * LANES;
    // Component-major, as the modes: entry d * LANES + q is component d of lane q.
    let mut pv = [0.0; W];
    let mut vn = [0.0; W];
    for q in 0..v.len() {
        for d in 0..3 {
            if WITH_PREV {
                pv[d * LANES + q] = prev[q][d];
            }
            vn[d * LANES + q] = v[q][d];
        }
    }
    let mut acc = [0.0; W];
    let mut acc_ahead = [0.0; W];
    for (l, mode) in modes.chunks_exact_mut(W).take(c.next.len()).enumerate() {
        let next = c.next[l];
        let ahead_l = if AHEAD { c.ahead[l] } else { 0.0 };
        if FOLD {
            let (decay, a, b) = (c.decay[l], c.a[l], c.b[l]);
            for k in 0..W {
                // Fused multiply-adds: one rounding each, same bits on every CPU (crate::simd).
                let input = if WITH_PREV {
                    a.mul_add(pv[k], b * vn[k])
                } else {
                    b * vn[k]
                };
                let m = decay.mul_add(mode[k], input);
                mode[k] = m;
                acc[k] = next.mul_add(m, acc[k]);
                if AHEAD {
                    acc_ahead[k] = ahead_l.mul_add(m, acc_ahead[k]);
                }
            }
        } else {
            for k in 0..W {
                acc[k] = next.mul_add(mode[k], acc[k]);
                if AHEAD {
                    acc_ahead[k] = ahead_l.mul_add(mode[k], acc_ahead[k]);
                }
            }
        }
    }
    if AHEAD {
        for (q, s) in ahead.iter_mut().enumerate() {
            *s = Vec3::new(acc_ahead[q], acc_ahead[LANES + q], acc_ahead[2 * LANES + q]);
        }
    }
    for (q, o) in out.iter_mut().enumerate().take(v.len()) {
        let pending = if c.zero {
            Vec3::zeros()
        } else {
            let sum = Vec3::new(acc[q], acc[LANES + q], acc[2 * LANES + q]);
            (-c.shift).mul_add_vec(v[q], sum)
        };
        *o = c.w_prev * v[q] + pending;
    }
}

/// `a * x + y` component by component, each a fused multiply-add.
trait MulAddVec {
    fn mul_add_vec(self, x: Vec3, y: Vec3) -> Vec3;
}

impl MulAddVec for f64 {
    #[inline(always)]
    fn mul_add_vec(self, x: Vec3, y: Vec3) -> Vec3 {
        Vec3::new(
            self.mul_add(x.x, y.x),
            self.mul_add(x.y, y.y),
            self.mul_add(x.z, y.z),
        )
    }
}

crate::simd_dispatch! { pub(super) fn light_sums_widest(c: &Coefficients<'_>, light: f64, v: &[Vec3], ahead: &[Vec3], out: &mut [Vec3]) => light_sums }

/// A pass that leaves its fold for later (deferring): each particle's sum is
/// `S + light v_n` instead of the modes' sum, then as in [`pass_block`].
#[inline(always)]
fn light_sums(c: &Coefficients<'_>, light: f64, v: &[Vec3], ahead: &[Vec3], out: &mut [Vec3]) {
    for ((o, &v), &s) in out.iter_mut().zip(v).zip(ahead) {
        let sum = light.mul_add_vec(v, s);
        *o = c.w_prev * v + (-c.shift).mul_add_vec(v, sum);
    }
}
