//! One patch's turning forces: the kernel that both the faces' scatter (`turning.rs`) and the
//! grid's row walk (`turning_grid.rs`) use, with the face gradients they share.

use super::inertia::{carried_past, CARRIED_FULL};
use crate::math::Vec3;

/// At one vertex (`big_n` and `big_ndot` the sums of its faces' area vectors and of their
/// rates, `k = m_a A`): subtracts the force of the patch's turning from `o`, writes the
/// projected-area ratio and the unit normal, and returns the vertex's `w`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn patch_turning(
    big_n: Vec3,
    big_ndot: Vec3,
    scale: f64,
    k: f64,
    v: &Vec3,
    o: &mut Vec3,
    projected: &mut f64,
    normal: &mut Vec3,
) -> Vec3 {
    let len = big_n.norm();
    *normal = if len > 0.0 { big_n / len } else { big_n };
    let (a, adot) = (scale * big_n, scale * big_ndot);
    let q = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    *projected = q.sqrt();
    let av = a.dot(v);
    if q > CARRIED_FULL {
        // T = 1/2 k h(q) (a . v)^2: the terms of h's change too.
        let (h, hq) = carried_past(q);
        let qdot = 2.0 * a.dot(&adot);
        *o -= (k * h) * (av * adot + adot.dot(v) * a);
        *o -= (k * hq * qdot * av) * a;
        return (k * h * av * scale) * v + (k * hq * av * av * scale) * a;
    }
    *o -= k * (av * adot + adot.dot(v) * a);
    (k * av * scale) * v
}

/// What [`patch_range`] writes for its vertices: their forces (subtracted from), projected-area
/// ratios, unit normals and `w`.
pub(super) struct PatchOut<'a> {
    pub o: &'a mut [Vec3],
    pub projected: &'a mut [f64],
    pub normals: &'a mut [Vec3],
    pub w: &'a mut [Vec3],
}

/// Vertices per block of [`patch_range`]: one AVX-512 vector of f64.
pub(super) const PATCH_BLOCK: usize = 8;

/// [`patch_turning`] for every vertex of a range (`areas`, `scale`, `sums`, `rates`, `v` and
/// the outputs all of the range's length; `ma` the normal added mass per area), in blocks of
/// [`PATCH_BLOCK`] vertices whose components are laid out side by side so that the square
/// roots and divisions run a vector at a time. The same operations in the same order as
/// [`patch_turning`] (a unit test compares them bit for bit), so the same bits.
#[inline(always)]
pub(super) fn patch_range(
    ma: f64,
    areas: &[f64],
    scale: &[f64],
    sums: &[Vec3],
    rates: &[Vec3],
    v: &[Vec3],
    out: PatchOut<'_>,
) {
    const B: usize = PATCH_BLOCK;
    let PatchOut {
        o,
        projected,
        normals,
        w,
    } = out;
    let m = o.len();
    let (areas, scale, sums, rates, v) = (&areas[..m], &scale[..m], &sums[..m], &rates[..m], &v[..m]);
    let (projected, normals, w) = (&mut projected[..m], &mut normals[..m], &mut w[..m]);
    let whole = m / B * B;
    for q in (0..whole).step_by(B) {
        let side = |a: &[Vec3], c: usize| -> [f64; B] { std::array::from_fn(|l| a[q + l][c]) };
        let n: [[f64; B]; 3] = std::array::from_fn(|c| side(sums, c));
        let nd: [[f64; B]; 3] = std::array::from_fn(|c| side(rates, c));
        let vv: [[f64; B]; 3] = std::array::from_fn(|c| side(v, c));
        let mut oo: [[f64; B]; 3] = std::array::from_fn(|c| side(o, c));
        let sc: [f64; B] = std::array::from_fn(|l| scale[q + l]);
        let k: [f64; B] = std::array::from_fn(|l| ma * areas[q + l]);
        let (mut nr, mut ww) = ([[0.0; B]; 3], [[0.0; B]; 3]);
        let mut pr = [0.0; B];
        // Patches stretched past the carried water's bound (rare: a patch that stretches a
        // fifth of its area) take `patch_turning`'s path, with its extra terms.
        let mut over = [false; B];
        for l in 0..B {
            let len = (n[0][l] * n[0][l] + n[1][l] * n[1][l] + n[2][l] * n[2][l]).sqrt();
            for c in 0..3 {
                nr[c][l] = if len > 0.0 { n[c][l] / len } else { n[c][l] };
            }
            let a = [sc[l] * n[0][l], sc[l] * n[1][l], sc[l] * n[2][l]];
            let ad = [sc[l] * nd[0][l], sc[l] * nd[1][l], sc[l] * nd[2][l]];
            let q = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
            pr[l] = q.sqrt();
            over[l] = q > CARRIED_FULL;
            let av = a[0] * vv[0][l] + a[1] * vv[1][l] + a[2] * vv[2][l];
            let adv = ad[0] * vv[0][l] + ad[1] * vv[1][l] + ad[2] * vv[2][l];
            let kw = k[l] * av * sc[l];
            for c in 0..3 {
                oo[c][l] -= k[l] * (av * ad[c] + adv * a[c]);
                ww[c][l] = kw * vv[c][l];
            }
        }
        let before = over
            .contains(&true)
            .then(|| std::array::from_fn::<Vec3, B, _>(|l| o[q + l]));
        for l in 0..B {
            let i = q + l;
            o[i] = Vec3::new(oo[0][l], oo[1][l], oo[2][l]);
            normals[i] = Vec3::new(nr[0][l], nr[1][l], nr[2][l]);
            w[i] = Vec3::new(ww[0][l], ww[1][l], ww[2][l]);
            projected[i] = pr[l];
        }
        if let Some(before) = before {
            for l in (0..B).filter(|&l| over[l]) {
                let i = q + l;
                o[i] = before[l];
                w[i] = patch_turning(
                    sums[i],
                    rates[i],
                    scale[i],
                    k[l],
                    &v[i],
                    &mut o[i],
                    &mut projected[i],
                    &mut normals[i],
                );
            }
        }
    }
    for i in whole..m {
        w[i] = patch_turning(
            sums[i],
            rates[i],
            scale[i],
            ma * areas[i],
            &v[i],
            &mut o[i],
            &mut projected[i],
            &mut normals[i],
        );
    }
}

/// The gradients of `W . c` at a face's corners b and c (`W` the sum of its corners' `w`).
#[inline(always)]
pub(super) fn face_gradients(x: &[Vec3], w: &[Vec3], t: &[u32; 3]) -> [Vec3; 2] {
    face_gradients_at(x, w, 0, t)
}

/// As [`face_gradients`], with `w` holding the vertices from `lo` on.
#[inline(always)]
pub(super) fn face_gradients_at(x: &[Vec3], w: &[Vec3], lo: usize, t: &[u32; 3]) -> [Vec3; 2] {
    let sum: Vec3 = t.iter().map(|&i| w[i as usize - lo]).sum();
    let [a, b, c] = t.map(|i| i as usize);
    let (e1, e2) = (x[b] - x[a], x[c] - x[a]);
    [e2.cross(&sum), sum.cross(&e1)]
}

/// Face `tri`'s term at its corner `i`, from its gradients at b and c (`gb`, `gc`; a's is minus
/// their sum).
#[inline(always)]
pub(super) fn corner_term(tri: &[u32; 3], i: usize, gb: Vec3, gc: Vec3) -> Vec3 {
    if i == tri[1] as usize {
        gb
    } else if i == tri[2] as usize {
        gc
    } else {
        -(gb + gc)
    }
}
