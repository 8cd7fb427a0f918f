//! Spring forces, Eq. 5, for the three spring families.
//!
//! On particle i from the spring to j, with `l = x_i - x_j`, rest length r:
//! `F = -k_s (|l| - r) l_hat - k_d [(q_i - q_j) . l_hat] l_hat`,
//! where q is D^{1/2}x for fractional springs (Eq. 5) and v for regular damped springs.
//! Particle j receives the opposite force.
//!
//! Two passes: [`compute`] evaluates each spring once into a per-spring buffer (springs are
//! independent, so chunks of them run in parallel), then every chunk of particles adds the
//! springs that touch it ([`super::assemble`]).
//!
//! The per-spring pass walks the topology's [`SpringRun`]s: the end points of a run are two
//! contiguous slices of the position array, so the loop has no index loads and vectorises.
//! It is compiled again for AVX2 and AVX-512 and the widest the CPU has is chosen at run
//! time ([`crate::simd`]); IEEE square root, division, multiplication and addition round
//! identically at every width, so the results are the same bits on every x86-64 CPU.

use super::ForceInput;
use crate::model::SpringDamping;
use crate::parallel;
use crate::soa::Soa3;
use crate::topology::{for_each_piece, Choice, SpringKind, SpringRun};

/// What the spring pass reads besides the springs.
#[derive(Clone, Copy)]
pub(super) struct Params<'a> {
    pub stiffness: [f64; 3],
    /// Damping constant of each family (stretch, shear, bend); 0 when the springs are undamped.
    pub kd: [f64; 3],
    /// Positions, one array per component.
    pub x: [&'a [f64]; 3],
    /// Rate the damping acts on (v or D^{1/2}x); `x` when undamped (then never read).
    pub q: [&'a [f64]; 3],
    /// The particle at index 0 of `x` and `q`: 0 for whole-cloth arrays, the window's first
    /// particle for a tile walk's window ([`super::inputs`]).
    pub base: usize,
    /// Rest length of each spring (or slot of a padded run); a run's family is its own
    /// (`SpringRun::kind`).
    pub rest: &'a [f64],
}

/// Copies of the positions and of the damping rate in component arrays, reused between steps.
#[derive(Clone, Debug, Default)]
pub(super) struct SpringScratch {
    pub x: Soa3,
    pub q: Soa3,
}

/// What the spring damping acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringRate {
    /// Undamped springs.
    None,
    /// The velocity.
    Velocity,
    /// D^{1/2}x (fractional springs, Eq. 5).
    HalfDerivative,
}

/// What the spring damping of `m` acts on.
pub fn spring_rate(m: &crate::model::Model) -> SpringRate {
    match m.spring_damping_mode {
        _ if m.spring_damping == 0.0 => SpringRate::None,
        SpringDamping::None => SpringRate::None,
        SpringDamping::Velocity => SpringRate::Velocity,
        SpringDamping::Fractional => SpringRate::HalfDerivative,
        // Its own pass (`strain.rs`): the springs' kernel leaves it out.
        SpringDamping::FractionalStrain => SpringRate::None,
    }
}

/// What the spring pass reads; copies the positions and the damping rate into `scratch`
/// (component arrays) when `fill` says so (unless the caller did, or a tile walk reads them
/// from windows of its own, [`super::inputs`]).
pub(super) fn params<'a>(
    input: &ForceInput<'a>,
    parallel: bool,
    scratch: &'a mut SpringScratch,
    fill: bool,
) -> Params<'a> {
    let m = input.model;
    let rate: Option<&[crate::math::Vec3]> = match spring_rate(m) {
        SpringRate::None => None,
        SpringRate::Velocity => Some(input.v),
        SpringRate::HalfDerivative => Some(input.half_derivative),
    };
    let t = input.topology;
    if fill {
        scratch.x.fill_from(parallel, input.x);
        if let Some(q) = rate {
            scratch.q.fill_from(parallel, q);
        }
    }
    Params {
        stiffness: [
            m.stiffness(SpringKind::Stretch, t.spacing),
            m.stiffness(SpringKind::Shear, t.spacing),
            m.stiffness(SpringKind::Bend, t.spacing),
        ],
        kd: if rate.is_some() {
            [
                m.spring_damping_of(SpringKind::Stretch),
                m.spring_damping_of(SpringKind::Shear),
                m.spring_damping_of(SpringKind::Bend),
            ]
        } else {
            [0.0; 3]
        },
        x: scratch.x.slices(),
        q: if rate.is_some() {
            scratch.q.slices()
        } else {
            scratch.x.slices()
        },
        base: 0,
        rest: &t.spring_rest,
    }
}

/// Writes the force each spring exerts on its `i` end into `out` (component arrays, one entry
/// per spring).
pub(super) fn compute(p: &Params<'_>, runs: &[SpringRun], parallel: bool, out: &mut Soa3) {
    out.resize(p.rest.len());
    parallel::chunks3(parallel, out.slices_mut(), parallel::CHUNK, |first, mut chunk| {
        let end = first + chunk[0].len();
        for_each_piece(runs, first, end, |run, lo, hi| {
            let [ox, oy, oz] = &mut chunk;
            let piece = [
                &mut ox[lo - first..hi - first],
                &mut oy[lo - first..hi - first],
                &mut oz[lo - first..hi - first],
            ];
            run_widest(p, run, lo, piece);
        });
    });
}

/// One spring's force on its first end as a multiple `s` of `l` (the force is `s l`), with a
/// bool, `(f64, bool)`, from `l = x_i - x_j`, the
/// expression `$dq` giving `q_i - q_j` (evaluated only when damped), the spring's `(k_s, k_d,
/// rest)` and `$undamped`; the bool says the squared length is outside `[SEED_MIN, SEED_MAX]`
/// (or NaN), where the slice must be done again exactly. A macro, so that it is expanded in
/// the dispatched kernels' bodies (a closure left out of line there is compiled without their
/// vector width and fused multiply-add).
macro_rules! slot_force {
    ($l:expr, $dq:expr, $slot:expr, $undamped:expr) => {{
        let [lx, ly, lz]: [f64; 3] = $l;
        let (ks, kd, r): (f64, f64, f64) = $slot;
        let l2 = lx.mul_add(lx, ly.mul_add(ly, lz * lz));
        let outside = !(SEED_MIN..=SEED_MAX).contains(&l2);
        let inv = inverse_length(l2);
        let len = l2 * inv;
        // F = (mag / |l|) l with mag = -k_s (|l| - r) - k_d (dq . l) / |l|.
        let mag = if $undamped {
            -ks * (len - r)
        } else {
            let [dx, dy, dz]: [f64; 3] = $dq;
            let dql = dx.mul_add(lx, dy.mul_add(ly, dz * lz));
            (-ks).mul_add(len - r, -(kd * inv) * dql)
        };
        (mag * inv, outside)
    }};
}

crate::simd_dispatch! { pub(super) fn run_widest(p: &Params<'_>, run: &SpringRun, first_spring: usize, out: [&mut [f64]; 3]) => run_kernel_each }
crate::simd_dispatch! { pub(super) fn run_uniform_widest(p: &Params<'_>, run: &SpringRun, first_spring: usize, rest: f64, out: [&mut [f64]; 3]) => run_kernel_uniform }

#[inline(always)]
fn run_kernel_each(p: &Params<'_>, run: &SpringRun, first_spring: usize, out: [&mut [f64]; 3]) {
    match run.second {
        None => run_kernel::<false, false>(p, run, first_spring, 0.0, out),
        Some(_) => run_kernel::<false, true>(p, run, first_spring, 0.0, out),
    }
}

#[inline(always)]
fn run_kernel_uniform(p: &Params<'_>, run: &SpringRun, first_spring: usize, rest: f64, out: [&mut [f64]; 3]) {
    run_kernel::<true, false>(p, run, first_spring, rest, out)
}

/// Springs `first_spring ..` of `run`, as many as `out` holds. With `UNIFORM`, every spring
/// has the rest length `uniform_rest` and `p.rest` is not read (same arithmetic either way).
/// Padding slots (a NaN rest length) come out as garbage: the caller sets them to no force
/// ([`zero_pads_widest`]). With `TWO` (a run two
/// families share, `SpringRun::second`), a slot whose rest length is negated is of the second
/// family and takes its constants (a select by the sign, no per-slot load more), the rest
/// length its magnitude: the same arithmetic as the family's own run.
#[inline(always)]
fn run_kernel<'a, const UNIFORM: bool, const TWO: bool>(
    p: &Params<'a>,
    run: &SpringRun,
    first_spring: usize,
    uniform_rest: f64,
    out: [&mut [f64]; 3],
) {
    let [fx, fy, fz] = out;
    let n = fx.len();
    let (fy, fz) = (&mut fy[..n], &mut fz[..n]);
    let i0 = run.first_vertex as usize + (first_spring - run.first_spring as usize);
    let j0 = i0 + run.offset as usize;
    let ks = p.stiffness[usize::from(run.kind)];
    let ends = |a: [&'a [f64]; 3], s: usize| [&a[0][s..s + n], &a[1][s..s + n], &a[2][s..s + n]];
    let (i0, j0) = (i0 - p.base, j0 - p.base);
    let ([xi, yi, zi], [xj, yj, zj]) = (ends(p.x, i0), ends(p.x, j0));
    let ([qxi, qyi, qzi], [qxj, qyj, qzj]) = (ends(p.q, i0), ends(p.q, j0));
    let rest: &[f64] = if UNIFORM {
        &[]
    } else {
        &p.rest[first_spring..first_spring + n]
    };
    let kd = p.kd[usize::from(run.kind)];
    let (ks2, kd2) = match run.second {
        Some(b) if TWO => (p.stiffness[usize::from(b)], p.kd[usize::from(b)]),
        _ => (ks, kd),
    };
    // Slot t's stiffness, damping and rest length.
    let slot = |t: usize| -> (f64, f64, f64) {
        if UNIFORM {
            (ks, kd, uniform_rest)
        } else if TWO {
            let r = rest[t];
            // The sign bit, not `r < 0.0`: a second-family spring of rest length 0 holds -0.0.
            let two = r.is_sign_negative();
            (if two { ks2 } else { ks }, if two { kd2 } else { kd }, r.abs())
        } else {
            (ks, kd, rest[t])
        }
    };
    let undamped = kd == 0.0 && (!TWO || kd2 == 0.0);
    // A squared length outside `[SEED_MIN, SEED_MAX]` (see `inverse_length`), or NaN: the slice
    // is done again exactly.
    let mut outside = false;
    // Fused multiply-adds where they save an operation: one rounding each, the same bits on
    // every CPU (see crate::simd).
    for t in 0..n {
        let l = [xi[t] - xj[t], yi[t] - yj[t], zi[t] - zj[t]];
        // The rates' difference, read only when damped (the macro expands it there).
        let (s, out) = slot_force!(
            l,
            [qxi[t] - qxj[t], qyi[t] - qyj[t], qzi[t] - qzj[t]],
            slot(t),
            undamped
        );
        outside |= out;
        fx[t] = s * l[0];
        fy[t] = s * l[1];
        fz[t] = s * l[2];
    }
    if outside {
        exact_kernel(
            undamped,
            [xi, yi, zi],
            [xj, yj, zj],
            [qxi, qyi, qzi],
            [qxj, qyj, qzj],
            slot,
            [&mut *fx, &mut *fy, &mut *fz],
        );
    }
}

crate::simd_dispatch! { pub(super) fn run_choice_widest(p: &Params<'_>, run: &SpringRun, choice: &Choice, select: &[u8], first_slot: usize, out: [&mut [f64]; 3]) => run_kernel_choice }

// Slot t's place of one end: `second` when `on`, else `first`. Both are loaded and one kept
// by a mask on the bits (a select of two loads would be compiled as a gather, slower).
macro_rules! pick {
    ($first:expr, $second:expr, $on:expr, $t:expr) => {{
        let (f, s, t) = ($first, $second, $t);
        let m = 0u64.wrapping_sub(u64::from($on));
        let keep = |a: f64, b: f64| f64::from_bits((a.to_bits() & !m) | (b.to_bits() & m));
        [
            keep(f[0][t], s[0][t]),
            keep(f[1][t], s[1][t]),
            keep(f[2][t], s[2][t]),
        ]
    }};
}

/// Slots `first_slot ..` of the choice run `run` (`crate::topology::Choice`: slot t's ends are at
/// `key + a[select & 1]` and `key + b[(select >> 1) & 1]`, `key = first_vertex + t`), as many as
/// `out` holds; `select` holds those slots' select bytes. Each slot loads both places of each
/// end and keeps one (a select, no gather), then takes the arithmetic of [`run_kernel`]; padding
/// comes out as garbage, as there.
#[inline(always)]
fn run_kernel_choice<'a>(
    p: &Params<'a>,
    run: &SpringRun,
    choice: &Choice,
    select: &[u8],
    first_slot: usize,
    out: [&mut [f64]; 3],
) {
    let [fx, fy, fz] = out;
    let n = fx.len();
    let (fy, fz, select) = (&mut fy[..n], &mut fz[..n], &select[..n]);
    let key = run.first_vertex as usize + (first_slot - run.first_spring as usize) - p.base;
    let ends = |a: [&'a [f64]; 3], s: u32| {
        let s = key + s as usize;
        [&a[0][s..s + n], &a[1][s..s + n], &a[2][s..s + n]]
    };
    let (xa, xb, xc, xd) = (
        ends(p.x, choice.a[0]),
        ends(p.x, choice.a[1]),
        ends(p.x, choice.b[0]),
        ends(p.x, choice.b[1]),
    );
    let (qa, qb, qc, qd) = (
        ends(p.q, choice.a[0]),
        ends(p.q, choice.a[1]),
        ends(p.q, choice.b[0]),
        ends(p.q, choice.b[1]),
    );
    let rest = &p.rest[first_slot..first_slot + n];
    let (ks, kd) = (p.stiffness[usize::from(run.kind)], p.kd[usize::from(run.kind)]);
    let undamped = kd == 0.0;
    let mut outside = false;
    for t in 0..n {
        let (i_at, j_at) = (select[t] & 1 != 0, select[t] & 2 != 0);
        let (xi, xj) = (pick!(xa, xb, i_at, t), pick!(xc, xd, j_at, t));
        let l = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
        // The rates' places, picked and read only when damped (the macro expands them there).
        let (s, out) = slot_force!(
            l,
            {
                let (qi, qj) = (pick!(qa, qb, i_at, t), pick!(qc, qd, j_at, t));
                [qi[0] - qj[0], qi[1] - qj[1], qi[2] - qj[2]]
            },
            (ks, kd, rest[t]),
            undamped
        );
        outside |= out;
        fx[t] = s * l[0];
        fy[t] = s * l[1];
        fz[t] = s * l[2];
    }
    if outside {
        exact_choice(
            undamped,
            (ks, kd, rest),
            select,
            [xa, xb, xc, xd],
            [qa, qb, qc, qd],
            [fx, fy, fz],
        );
    }
}

/// [`run_kernel_choice`]'s exact pass, for a run some slot of which fell outside the fast
/// kernel's range: the selected places of both ends gathered a tile at a time, then
/// [`exact_kernel`] over them.
#[cold]
#[allow(clippy::type_complexity)]
fn exact_choice(
    undamped: bool,
    (ks, kd, rest): (f64, f64, &[f64]),
    select: &[u8],
    [xa, xb, xc, xd]: [[&[f64]; 3]; 4],
    [qa, qb, qc, qd]: [[&[f64]; 3]; 4],
    [fx, fy, fz]: [&mut [f64]; 3],
) {
    let n = fx.len();
    // The selected places, then the exact pass over them.
    let mut places = [[0.0; crate::parallel::TILE]; 12];
    for start in (0..n).step_by(crate::parallel::TILE) {
        let m = (n - start).min(crate::parallel::TILE);
        for t in 0..m {
            let s = start + t;
            let (i_at, j_at) = (select[s] & 1 != 0, select[s] & 2 != 0);
            let v = [
                pick!(xa, xb, i_at, s),
                pick!(xc, xd, j_at, s),
                pick!(qa, qb, i_at, s),
                pick!(qc, qd, j_at, s),
            ];
            for (k, w) in v.iter().enumerate() {
                for c in 0..3 {
                    places[3 * k + c][t] = w[c];
                }
            }
        }
        let [x0, x1, x2, y0, y1, y2, q0, q1, q2, r0, r1, r2] = &places;
        fn part(a: &[f64; crate::parallel::TILE], m: usize) -> &[f64] {
            &a[..m]
        }
        let part = |a| part(a, m);
        exact_kernel(
            undamped,
            [part(x0), part(x1), part(x2)],
            [part(y0), part(y1), part(y2)],
            [part(q0), part(q1), part(q2)],
            [part(r0), part(r1), part(r2)],
            |t| (ks, kd, rest[start + t]),
            [
                &mut fx[start..start + m],
                &mut fy[start..start + m],
                &mut fz[start..start + m],
            ],
        );
    }
}

crate::simd_dispatch! { pub(super) fn zero_pads_widest(rest: &[f64], out: [&mut [f64]; 3]) => zero_pads }

/// Sets the force of every padding slot (rest length NaN, `topology::PAD_REST`) among `rest` to
/// none: a mask over the slice, vectorised, for runs that hold many (an irregular mesh's).
#[inline(always)]
fn zero_pads(rest: &[f64], out: [&mut [f64]; 3]) {
    let [fx, fy, fz] = out;
    let n = rest.len();
    let (fx, fy, fz) = (&mut fx[..n], &mut fy[..n], &mut fz[..n]);
    for t in 0..n {
        if rest[t].is_nan() {
            (fx[t], fy[t], fz[t]) = (0.0, 0.0, 0.0);
        }
    }
}

/// Squared lengths inside which the f32 seed of [`inverse_length`] is a normal f32 number.
const SEED_MIN: f64 = 1e-30;
const SEED_MAX: f64 = 1e30;

/// `1 / sqrt(l2)` for `l2` in `[SEED_MIN, SEED_MAX]`, to about 1e-14 relative, without an f64
/// square root or division (the divider is what bounds the spring pass): an f32 seed (square
/// root and division in f32, correctly rounded, ~1e-7), then one Newton step in f64
/// (`y (3 - l2 y^2) / 2` squares the error). Every operation (the fused multiply-add too) is
/// IEEE and correctly rounded, so the result is the same bits at every vector width.
#[inline(always)]
fn inverse_length(l2: f64) -> f64 {
    let a = l2.clamp(SEED_MIN, SEED_MAX) as f32;
    let y = f64::from(1.0 / a.sqrt());
    y * (-(0.5 * l2) * y).mul_add(y, 1.5)
}

/// The spring pass with f64 square root and division, for slices with a squared length outside
/// `[SEED_MIN, SEED_MAX]` (collapsed or absurdly long springs). A zero-length spring has no
/// direction: no force rather than NaN. `slot(t)`: the stiffness, damping and rest length of
/// spring t; `undamped`: every damping is 0.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn exact_kernel(
    undamped: bool,
    xi: [&[f64]; 3],
    xj: [&[f64]; 3],
    qi: [&[f64]; 3],
    qj: [&[f64]; 3],
    slot: impl Fn(usize) -> (f64, f64, f64),
    out: [&mut [f64]; 3],
) {
    let [fx, fy, fz] = out;
    for t in 0..fx.len() {
        let (ks, kd, rest) = slot(t);
        let l = [xi[0][t] - xj[0][t], xi[1][t] - xj[1][t], xi[2][t] - xj[2][t]];
        let dq = [qi[0][t] - qj[0][t], qi[1][t] - qj[1][t], qi[2][t] - qj[2][t]];
        let len = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        let dql = dq[0] * l[0] + dq[1] * l[1] + dq[2] * l[2];
        let inv = 1.0 / len;
        let mag = if undamped {
            -ks * (len - rest)
        } else {
            -ks * (len - rest) - kd * dql * inv
        };
        let s = if len > 0.0 { mag * inv } else { 0.0 };
        fx[t] = s * l[0];
        fy[t] = s * l[1];
        fz[t] = s * l[2];
    }
}
