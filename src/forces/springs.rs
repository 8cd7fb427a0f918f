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
use crate::topology::{SpringKind, SpringRun};
use crate::Vec3;

/// What the spring pass reads besides the springs.
struct Params<'a> {
    stiffness: [f64; 3],
    /// Damping coefficient, 0 when the springs are undamped.
    kd: f64,
    x: &'a [Vec3],
    /// Rate the damping acts on (v or D^{1/2}x); `x` when undamped (then never read).
    q: &'a [Vec3],
    rest: &'a [f64],
    kinds: &'a [u8],
}

/// Writes the force each spring exerts on its `i` end into `out` (one entry per spring).
pub(super) fn compute(input: &ForceInput<'_>, parallel: bool, out: &mut [Vec3]) {
    let m = input.model;
    let rate: Option<&[Vec3]> = match m.spring_damping_mode {
        _ if m.spring_damping == 0.0 => None,
        SpringDamping::None => None,
        SpringDamping::Velocity => Some(input.v),
        SpringDamping::Fractional => Some(input.half_derivative),
    };
    let t = input.topology;
    let p = Params {
        stiffness: [
            m.stiffness(SpringKind::Stretch),
            m.stiffness(SpringKind::Shear),
            m.stiffness(SpringKind::Bend),
        ],
        kd: if rate.is_some() { m.spring_damping } else { 0.0 },
        x: input.x,
        q: rate.unwrap_or(input.x),
        rest: &t.spring_rest,
        kinds: &t.spring_kinds,
    };
    let runs = &t.spring_runs;
    parallel::chunks(parallel, out, parallel::CHUNK, |first, chunk| {
        let end = first + chunk.len();
        let mut r = runs.partition_point(|r| (r.first_spring + r.len) as usize <= first);
        while let Some(run) = runs.get(r) {
            let (a, b) = (run.first_spring as usize, (run.first_spring + run.len) as usize);
            if a >= end {
                break;
            }
            let (lo, hi) = (a.max(first), b.min(end));
            run_widest(&p, run, lo, &mut chunk[lo - first..hi - first]);
            r += 1;
        }
    });
}

crate::simd_dispatch! { fn run_widest(p: &Params<'_>, run: &SpringRun, first_spring: usize, out: &mut [Vec3]) => run_kernel }

/// Springs `first_spring ..` of `run`, as many as `out` holds.
#[inline(always)]
fn run_kernel(p: &Params<'_>, run: &SpringRun, first_spring: usize, out: &mut [Vec3]) {
    let n = out.len();
    let i0 = run.first_vertex as usize + (first_spring - run.first_spring as usize);
    let j0 = i0 + run.offset as usize;
    let ks = p.stiffness[p.kinds[first_spring] as usize];
    let (xi, xj) = (&p.x[i0..i0 + n], &p.x[j0..j0 + n]);
    let (qi, qj) = (&p.q[i0..i0 + n], &p.q[j0..j0 + n]);
    let rest = &p.rest[first_spring..first_spring + n];
    let kd = p.kd;
    // Out-of-range squared lengths (see `inverse_length`) fall back to the exact kernel.
    let mut outside = false;
    for t in 0..n {
        let l = xi[t] - xj[t];
        let dq = qi[t] - qj[t];
        let l2 = l.x * l.x + l.y * l.y + l.z * l.z;
        outside |= !(SEED_MIN..=SEED_MAX).contains(&l2);
        let inv = inverse_length(l2);
        let len = l2 * inv;
        // F = (mag / |l|) l with mag = -k_s (|l| - r) - k_d (dq . l) / |l|.
        let mag = if kd == 0.0 {
            -ks * (len - rest[t])
        } else {
            let dql = dq.x * l.x + dq.y * l.y + dq.z * l.z;
            -ks * (len - rest[t]) - kd * dql * inv
        };
        let s = mag * inv;
        out[t] = Vec3::new(s * l.x, s * l.y, s * l.z);
    }
    if outside {
        exact_kernel(ks, kd, xi, xj, qi, qj, rest, out);
    }
}

/// Squared lengths inside which the f32 seed of [`inverse_length`] is a normal f32 number.
const SEED_MIN: f64 = 1e-30;
const SEED_MAX: f64 = 1e30;

/// `1 / sqrt(l2)` for `l2` in `[SEED_MIN, SEED_MAX]`, to about 1e-14 relative, without an f64
/// square root or division (the divider is what bounds the spring pass): an f32 seed (square
/// root and division in f32, correctly rounded, ~1e-7), then one Newton step in f64
/// (`y (3 - l2 y^2) / 2` squares the error). Every operation is IEEE and correctly rounded,
/// so the result is the same bits at every vector width.
#[inline(always)]
fn inverse_length(l2: f64) -> f64 {
    let a = l2.clamp(SEED_MIN, SEED_MAX) as f32;
    let y = f64::from(1.0 / a.sqrt());
    y * (1.5 - 0.5 * l2 * (y * y))
}

/// The spring pass with f64 square root and division, for slices with a squared length outside
/// `[SEED_MIN, SEED_MAX]` (collapsed or absurdly long springs). A zero-length spring has no
/// direction: no force rather than NaN.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn exact_kernel(
    ks: f64,
    kd: f64,
    xi: &[Vec3],
    xj: &[Vec3],
    qi: &[Vec3],
    qj: &[Vec3],
    rest: &[f64],
    out: &mut [Vec3],
) {
    for t in 0..out.len() {
        let l = xi[t] - xj[t];
        let dq = qi[t] - qj[t];
        let len = (l.x * l.x + l.y * l.y + l.z * l.z).sqrt();
        let dql = dq.x * l.x + dq.y * l.y + dq.z * l.z;
        let inv = 1.0 / len;
        let mag = if kd == 0.0 {
            -ks * (len - rest[t])
        } else {
            -ks * (len - rest[t]) - kd * dql * inv
        };
        let s = if len > 0.0 { mag * inv } else { 0.0 };
        out[t] = Vec3::new(s * l.x, s * l.y, s * l.z);
    }
}
