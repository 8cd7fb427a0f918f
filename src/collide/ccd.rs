//! Continuous collision: whether a vertex passes through a triangle, or an edge through an
//! edge, while all their corners move in straight lines over a step (Provot 1997, Bridson et
//! al. 2002). The four points are coplanar where the cubic
//! `g(t) = (x1 - x0) x (x2 - x0) . (x3 - x0)` vanishes; a *passage* is a root of `g` in
//! `[0, 1]` where its sign changes and the points then meet (the vertex on the triangle, the
//! two segments on each other, within `tolerance`). A graze (a double root, the sign kept) is
//! not a passage: the pair ends on the side it began on.

use super::geometry::{closest_on_segments, offset_from_triangle};
use crate::math::Vec3;

/// Four points' start and end positions.
pub type Path = [(Vec3, Vec3); 4];

/// The coefficients `[k0, k1, k2, k3]` of `g(t) = sum k_i t^i` for points moving from `.0`
/// to `.1`.
fn coplanarity(path: &Path) -> [f64; 4] {
    let [(a0, a1), (b0, b1), (c0, c1), (d0, d1)] = *path;
    // Relative to the first point: u = b - a, w = c - a, r = d - a, each linear in t.
    let (u, du) = (b0 - a0, (b1 - a1) - (b0 - a0));
    let (w, dw) = (c0 - a0, (c1 - a1) - (c0 - a0));
    let (r, dr) = (d0 - a0, (d1 - a1) - (d0 - a0));
    // u x w = A + B t + C t^2.
    let a = u.cross(&w);
    let b = u.cross(&dw) + du.cross(&w);
    let c = du.cross(&dw);
    [
        a.dot(&r),
        a.dot(&dr) + b.dot(&r),
        b.dot(&dr) + c.dot(&r),
        c.dot(&dr),
    ]
}

fn eval(k: &[f64; 4], t: f64) -> f64 {
    ((k[3] * t + k[2]) * t + k[1]) * t + k[0]
}

/// Whether the cubic `k` surely keeps one strict sign on `[0, 1]`: its Bernstein coefficients
/// all have it (the curve lies in their convex hull). Most listed pairs, whose points move a
/// little of their distance in a step, are done with here.
fn one_sign(k: &[f64; 4]) -> bool {
    let b = [
        k[0],
        k[0] + k[1] / 3.0,
        k[0] + (2.0 * k[1] + k[2]) / 3.0,
        k[0] + k[1] + k[2] + k[3],
    ];
    b.iter().all(|&v| v > 0.0) || b.iter().all(|&v| v < 0.0)
}

/// The sign-changing roots of the cubic `k` in `[0, 1]`, in ascending order (at most three):
/// the interval is cut at the roots of `g'`, and each piece whose ends differ in sign is
/// bisected to the last bit.
fn sign_changes(k: &[f64; 4]) -> ([f64; 3], usize) {
    if one_sign(k) {
        return ([0.0; 3], 0);
    }
    // Roots of g' = 3 k3 t^2 + 2 k2 t + k1 inside (0, 1).
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    let (qa, qb, qc) = (3.0 * k[3], 2.0 * k[2], k[1]);
    let mut push = |t: f64| {
        if t > 0.0 && t < 1.0 {
            cuts[n] = t;
            n += 1;
        }
    };
    if qa != 0.0 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc > 0.0 {
            let s = disc.sqrt();
            // The stable pair of roots.
            let q = -0.5 * (qb + qb.signum() * s);
            let (r1, r2) = (q / qa, if q != 0.0 { qc / q } else { 0.0 });
            push(r1.min(r2));
            push(r1.max(r2));
        }
    } else if qb != 0.0 {
        push(-qc / qb);
    }
    cuts[n] = 1.0;
    let pieces = &mut cuts[..=n];
    pieces.sort_by(f64::total_cmp);
    let mut roots = [0.0; 3];
    let mut found = 0;
    for piece in pieces.windows(2) {
        let (mut lo, mut hi) = (piece[0], piece[1]);
        let (glo, ghi) = (eval(k, lo), eval(k, hi));
        // A sign change: strictly opposite, or ending on zero from a nonzero start.
        if !((glo < 0.0 && ghi >= 0.0) || (glo > 0.0 && ghi <= 0.0)) {
            continue;
        }
        let rising = glo < 0.0;
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if (eval(k, mid) < 0.0) == rising {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if found < 3 {
            roots[found] = hi;
            found += 1;
        }
    }
    (roots, found)
}

fn at(p: &(Vec3, Vec3), t: f64) -> Vec3 {
    p.0 + t * (p.1 - p.0)
}

/// When, as a fraction of the step, vertex `path[3]` first passes through the triangle
/// `path[0..3]`: a sign change of the coplanarity cubic with the vertex then within
/// `tolerance` of the triangle. `None` if it does not.
pub fn vertex_passes_triangle(path: &Path, tolerance: f64) -> Option<f64> {
    let k = coplanarity(path);
    let (roots, n) = sign_changes(&k);
    roots[..n].iter().copied().find(|&t| {
        let [a, b, c, p] = path.each_ref().map(|q| at(q, t));
        offset_from_triangle(&p, &a, &b, &c).1.norm() <= tolerance
    })
}

/// When edge `path[0] path[1]` first passes through edge `path[2] path[3]`: likewise, the
/// segments then within `tolerance` of each other.
pub fn edge_passes_edge(path: &Path, tolerance: f64) -> Option<f64> {
    let k = coplanarity(path);
    let (roots, n) = sign_changes(&k);
    roots[..n].iter().copied().find(|&t| {
        let [p0, p1, q0, q1] = path.each_ref().map(|q| at(q, t));
        let (s, u) = closest_on_segments(&p0, &p1, &q0, &q1);
        ((p0 + s * (p1 - p0)) - (q0 + u * (q1 - q0))).norm() <= tolerance
    })
}

/// The side `g` has at the start of the step for these paths: `+1` or `-1` (0 counts as
/// `+1`), the sign the side of a vertex over a triangle's face and of two edges' interior
/// closest points is told by (`(b - a) x (c - a) . (p - a)`, `(e1 - e0) x (f1 - f0) . (e0 - f0)`
/// up to the order of the points).
pub fn start_sign(path: &Path) -> i8 {
    if coplanarity(path)[0] < 0.0 {
        -1
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers uniform in [-1, 1) from `seed` (a linear congruential generator).
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    fn still(p: Vec3) -> (Vec3, Vec3) {
        (p, p)
    }

    fn triangle() -> [(Vec3, Vec3); 3] {
        [
            still(Vec3::new(0.0, 0.0, 0.0)),
            still(Vec3::new(1.0, 0.0, 0.0)),
            still(Vec3::new(0.0, 1.0, 0.0)),
        ]
    }

    #[test]
    fn a_vertex_falling_through_a_triangle_passes_it_when_it_reaches_the_plane() {
        let [a, b, c] = triangle();
        let p = (Vec3::new(0.2, 0.2, 0.3), Vec3::new(0.2, 0.2, -0.1));
        let t = vertex_passes_triangle(&[a, b, c, p], 1e-9).expect("a passage");
        assert!((t - 0.75).abs() < 1e-12, "{t}");
        // Beside the triangle: the plane is crossed, the triangle is not.
        let beside = (Vec3::new(0.8, 0.8, 0.3), Vec3::new(0.8, 0.8, -0.1));
        assert_eq!(vertex_passes_triangle(&[a, b, c, beside], 1e-9), None);
        // Stopping short of it.
        let short = (Vec3::new(0.2, 0.2, 0.3), Vec3::new(0.2, 0.2, 0.001));
        assert_eq!(vertex_passes_triangle(&[a, b, c, short], 1e-9), None);
    }

    #[test]
    fn a_triangle_swept_over_a_still_vertex_passes_it() {
        // The triangle moves down through a vertex at rest (a pinned row pressing on a point).
        let drop = |p: Vec3| (p, p - Vec3::new(0.0, 0.0, 1.0));
        let tri = [
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(0.0, 1.0, 0.5),
        ];
        let p = still(Vec3::new(0.25, 0.25, 0.0));
        let t =
            vertex_passes_triangle(&[drop(tri[0]), drop(tri[1]), drop(tri[2]), p], 1e-9).expect("passage");
        assert!((t - 0.5).abs() < 1e-12, "{t}");
    }

    #[test]
    fn a_tilting_triangle_passes_a_vertex_its_plane_sweeps_over() {
        // One corner of the triangle swings down through the plane of the vertex: the vertex
        // stays still and the face comes to it.
        let a = still(Vec3::new(0.0, 0.0, 0.0));
        let b = still(Vec3::new(1.0, 0.0, 0.0));
        let c = (Vec3::new(0.0, 1.0, 0.2), Vec3::new(0.0, 1.0, -0.2));
        let p = still(Vec3::new(0.1, 0.5, 0.0));
        let t = vertex_passes_triangle(&[a, b, c, p], 1e-9).expect("passage");
        // The plane through a, b and c(t) holds p when c's height is 0: t = 0.5.
        assert!((t - 0.5).abs() < 1e-9, "{t}");
    }

    #[test]
    fn one_sign_is_never_claimed_for_a_cubic_with_a_root_in_the_step() {
        let mut rnd = uniform(3);
        let (mut claimed, mut rooted) = (0, 0);
        for _ in 0..20_000 {
            let k = [rnd(), 4.0 * rnd(), 4.0 * rnd(), 4.0 * rnd()];
            let has_root = (0..=1000)
                .map(|i| eval(&k, i as f64 / 1000.0))
                .collect::<Vec<_>>()
                .windows(2)
                .any(|w| w[0].signum() != w[1].signum());
            rooted += usize::from(has_root);
            if one_sign(&k) {
                claimed += 1;
                assert!(!has_root, "{k:?}");
            }
        }
        assert!(claimed > 1000 && rooted > 1000, "{claimed} {rooted}");
    }

    #[test]
    fn crossing_edges_pass_each_other_and_parallel_ones_do_not() {
        let e0 = still(Vec3::new(-1.0, 0.0, 0.0));
        let e1 = still(Vec3::new(1.0, 0.0, 0.0));
        let f0 = (Vec3::new(0.0, -1.0, 0.4), Vec3::new(0.0, -1.0, -0.6));
        let f1 = (Vec3::new(0.0, 1.0, 0.4), Vec3::new(0.0, 1.0, -0.6));
        let t = edge_passes_edge(&[e0, e1, f0, f1], 1e-9).expect("passage");
        assert!((t - 0.4).abs() < 1e-12, "{t}");
        // Shifted past e's end: the lines cross, the segments do not.
        let g0 = (Vec3::new(2.0, -1.0, 0.4), Vec3::new(2.0, -1.0, -0.6));
        let g1 = (Vec3::new(2.0, 1.0, 0.4), Vec3::new(2.0, 1.0, -0.6));
        assert_eq!(edge_passes_edge(&[e0, e1, g0, g1], 1e-9), None);
        // Parallel to e, passing over it: g is identically zero, no sign change.
        let h0 = (Vec3::new(-1.0, 0.0, 0.4), Vec3::new(-1.0, 0.0, -0.6));
        let h1 = (Vec3::new(1.0, 0.0, 0.4), Vec3::new(1.0, 0.0, -0.6));
        assert_eq!(edge_passes_edge(&[e0, e1, h0, h1], 1e-9), None);
    }

    #[test]
    fn reaching_the_face_is_a_passage_and_stopping_short_is_not() {
        let a = (Vec3::new(0.0, 0.0, 0.1), Vec3::new(0.0, 0.0, 0.1));
        let b = (Vec3::new(1.0, 0.0, 0.1), Vec3::new(1.0, 0.0, 0.1));
        let c = (Vec3::new(0.0, 1.0, 0.1), Vec3::new(0.0, 1.0, 0.1));
        let p = (Vec3::new(0.2, 0.2, 0.5), Vec3::new(0.2, 0.2, 0.1));
        // Ends exactly on the face: a root at t = 1 reached from one side, which is a passage
        // only if the sign changes; g(1) = 0 counts as reaching it.
        assert_eq!(vertex_passes_triangle(&[a, b, c, p], 1e-9), Some(1.0));
        // The same from below stays below.
        let q = (Vec3::new(0.2, 0.2, -0.5), Vec3::new(0.2, 0.2, 0.0));
        assert_eq!(vertex_passes_triangle(&[a, b, c, q], 1e-9), None);
    }

    /// Against sampling: random paths, the passage found agrees with a fine scan of the sign
    /// and the distance (where the scan sees a clear change of side over the face).
    #[test]
    fn passages_agree_with_a_fine_scan() {
        let mut rnd = uniform(7);
        let mut agreed = 0;
        for _ in 0..2000 {
            let mut v = || Vec3::new(rnd(), rnd(), rnd());
            let path: Path = [(v(), v()), (v(), v()), (v(), v()), (v(), v())];
            let found = vertex_passes_triangle(&path, 1e-9);
            // The scan: the first step whose sign flips with the vertex over the face.
            let k = coplanarity(&path);
            let steps = 20_000;
            let mut scan = None;
            for i in 0..steps {
                let (t0, t1) = (i as f64 / steps as f64, (i + 1) as f64 / steps as f64);
                if eval(&k, t0).signum() != eval(&k, t1).signum() {
                    let t = 0.5 * (t0 + t1);
                    let [a, b, c, p] = path.each_ref().map(|q| at(q, t));
                    let (w, _) = offset_from_triangle(&p, &a, &b, &c);
                    if w.iter().all(|&x| x > 1e-3) {
                        scan = Some(t);
                        break;
                    }
                    if w.iter().all(|&x| x > -1e-3) {
                        // On the border: either answer is right.
                        scan = None;
                        break;
                    }
                }
            }
            if let Some(ts) = scan {
                let tf = found.expect("the scan saw a passage the cubic missed");
                assert!((tf - ts).abs() < 1e-3, "{tf} vs {ts}");
                agreed += 1;
            }
        }
        assert!(agreed > 50, "the scan saw enough passages to compare: {agreed}");
    }
}
