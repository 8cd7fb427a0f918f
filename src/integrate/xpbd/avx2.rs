//! [`super::project`]'s four-link step in AVX2: the particles' positions, start positions and
//! inverse masses gathered straight from their arrays (`vgatherqpd`), the update computed four
//! links at once, the moved positions written back lane by lane. Every operation is the
//! scalar step's, in its order (no fused multiply-add): the same bits as
//! [`super::project_one`].

use std::arch::x86_64::*;

use super::{Compliance, InverseMass, Link};
use crate::math::Vec3;

/// Projects `quads` (a multiple of four links, the four of each group touching distinct
/// particles) on `x`.
///
/// # Safety
/// The CPU has AVX2; every link's particles are below the lengths of `inverse`, `start` and
/// `x` ([`super::Batches::of`] checked them against the particle count the caller checked).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn project_quads(
    quads: &[Link],
    params: &[Compliance; 3],
    inverse: &[InverseMass],
    start: &[Vec3],
    x: &mut [Vec3],
) {
    // Vec3 is three f64 and InverseMass four (`repr(C)`), so component c of particle i sits
    // at 3 i + c, and of its inverse mass at 4 i + c.
    const { assert!(std::mem::size_of::<Vec3>() == 24 && std::mem::size_of::<InverseMass>() == 32) };
    let (xp, sp, ip) = (
        x.as_mut_ptr() as *mut f64,
        start.as_ptr() as *const f64,
        inverse.as_ptr() as *const f64,
    );
    let (zero, one) = (_mm256_setzero_pd(), _mm256_set1_pd(1.0));
    for q in quads.chunks_exact(4) {
        let i = [q[0].i, q[1].i, q[2].i, q[3].i].map(i64::from);
        let j = [q[0].j, q[1].j, q[2].j, q[3].j].map(i64::from);
        let offsets = |p: [i64; 4], scale: i64, c: i64| {
            _mm256_set_epi64x(
                scale * p[3] + c,
                scale * p[2] + c,
                scale * p[1] + c,
                scale * p[0] + c,
            )
        };
        // SAFETY (every gather): the offsets are components of particles below the arrays'
        // lengths (the function's contract).
        let gather = |base: *const f64, p: [i64; 4], scale: i64, c: i64| unsafe {
            _mm256_i64gather_pd::<8>(base, offsets(p, scale, c))
        };
        let xi = [0, 1, 2].map(|c| gather(xp, i, 3, c));
        let xj = [0, 1, 2].map(|c| gather(xp, j, 3, c));
        let si = [0, 1, 2].map(|c| gather(sp, i, 3, c));
        let sj = [0, 1, 2].map(|c| gather(sp, j, 3, c));
        let (wa, wb) = (gather(ip, i, 4, 0), gather(ip, j, 4, 0));
        let ua = [1, 2, 3].map(|c| gather(ip, i, 4, c));
        let ub = [1, 2, 3].map(|c| gather(ip, j, 4, c));
        let lane = |f: fn(&Link, &[Compliance; 3]) -> f64| {
            _mm256_set_pd(
                f(&q[3], params),
                f(&q[2], params),
                f(&q[1], params),
                f(&q[0], params),
            )
        };
        let neg_kappa = lane(|l, p| -p[l.family as usize].kappa);
        let kappa = lane(|l, p| p[l.family as usize].kappa);
        let delta = lane(|l, p| p[l.family as usize].delta);
        let rest = lane(|l, _| l.rest);
        let d = [0, 1, 2].map(|c| _mm256_sub_pd(xi[c], xj[c]));
        let moved =
            [0, 1, 2].map(|c| _mm256_sub_pd(_mm256_sub_pd(xi[c], si[c]), _mm256_sub_pd(xj[c], sj[c])));
        let dot = |a: [__m256d; 3], b: [__m256d; 3]| {
            _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(a[0], b[0]), _mm256_mul_pd(a[1], b[1])),
                _mm256_mul_pd(a[2], b[2]),
            )
        };
        let l2 = dot(d, d);
        let l = _mm256_sqrt_pd(l2);
        let long = _mm256_cmp_pd::<_CMP_GT_OQ>(l2, zero);
        let inv_l = _mm256_and_pd(_mm256_div_pd(one, l), long);
        let g = d.map(|dc| _mm256_mul_pd(dc, inv_l));
        let (ag, bg, along) = (dot(ua, g), dot(ub, g), dot(g, moved));
        let weight = _mm256_add_pd(
            _mm256_sub_pd(wa, _mm256_mul_pd(ag, ag)),
            _mm256_sub_pd(wb, _mm256_mul_pd(bg, bg)),
        );
        let num = _mm256_sub_pd(
            _mm256_mul_pd(neg_kappa, _mm256_sub_pd(l, rest)),
            _mm256_mul_pd(delta, along),
        );
        let den = _mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(kappa, delta), weight), one);
        let moves = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(weight, zero), long);
        let dl = _mm256_and_pd(_mm256_div_pd(num, den), moves);
        let (a, b) = (_mm256_mul_pd(dl, wa), _mm256_mul_pd(dl, wb));
        let (aa, bb) = (_mm256_mul_pd(dl, ag), _mm256_mul_pd(dl, bg));
        let mut ni = [[0.0; 4]; 3];
        let mut nj = [[0.0; 4]; 3];
        for c in 0..3 {
            let vi = _mm256_sub_pd(
                _mm256_add_pd(xi[c], _mm256_mul_pd(a, g[c])),
                _mm256_mul_pd(aa, ua[c]),
            );
            let vj = _mm256_add_pd(
                _mm256_sub_pd(xj[c], _mm256_mul_pd(b, g[c])),
                _mm256_mul_pd(bb, ub[c]),
            );
            // SAFETY: four f64 of room each.
            unsafe {
                _mm256_storeu_pd(ni[c].as_mut_ptr(), vi);
                _mm256_storeu_pd(nj[c].as_mut_ptr(), vj);
            }
        }
        for k in 0..4 {
            x[i[k] as usize] = Vec3::new(ni[0][k], ni[1][k], ni[2][k]);
            x[j[k] as usize] = Vec3::new(nj[0][k], nj[1][k], nj[2][k]);
        }
    }
}
