//! Closest points and crossings between points, segments and triangles: the exact geometry
//! every collision pass and every intersection count is built on; and a triangle list's edges.
//!
//! Closest point on a triangle: Ericson, *Real-Time Collision Detection* (2005), 5.1.5, by
//! Voronoi regions; closest points of two segments: the same book, 5.1.9. The crossing tests
//! are exact up to rounding: a segment crosses a triangle when its ends lie strictly on
//! opposite sides of the triangle's plane and the crossing point is inside the triangle.

use crate::math::Vec3;

/// The unique edges of some triangles, `[i, j]` with i < j, sorted.
pub fn edges_of(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// The closest point of triangle `(a, b, c)` to `p` as its weights ([`closest_on_triangle`]),
/// and the vector from that point to `p`.
pub fn offset_from_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> ([f64; 3], Vec3) {
    let w = closest_on_triangle(p, a, b, c);
    (w, p - (w[0] * a + w[1] * b + w[2] * c))
}

/// Closest point of triangle `(a, b, c)` to `p`, as barycentric weights `[wa, wb, wc]` (each in
/// [0, 1], summing to 1). A degenerate triangle gives the closest point of its longest edge.
pub fn closest_on_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> [f64; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom <= 0.0 || denom.is_infinite() {
        return closest_on_degenerate(p, a, b, c);
    }
    let (v, w) = (vb / denom, vc / denom);
    [1.0 - v - w, v, w]
}

/// A degenerate (zero-area) triangle's closest point: the best of its three edges.
fn closest_on_degenerate(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> [f64; 3] {
    let on = |u: &Vec3, v: &Vec3| {
        let e = v - u;
        let len2 = e.norm_squared();
        let t = if len2 > 0.0 {
            ((p - u).dot(&e) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t, (u + t * e - p).norm_squared())
    };
    let (t0, d0) = on(a, b);
    let (t1, d1) = on(b, c);
    let (t2, d2) = on(c, a);
    if d0 <= d1 && d0 <= d2 {
        [1.0 - t0, t0, 0.0]
    } else if d1 <= d2 {
        [0.0, 1.0 - t1, t1]
    } else {
        [t2, 0.0, 1.0 - t2]
    }
}

/// Parameters `(s, t)` in [0, 1]^2 of the closest points `p0 + s (p1 - p0)` and
/// `q0 + t (q1 - q0)` of two segments.
pub fn closest_on_segments(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> (f64, f64) {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return (0.0, 0.0);
    }
    if a <= f64::MIN_POSITIVE {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(&r);
    if e <= f64::MIN_POSITIVE {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(&d2);
    let denom = a * e - b * b;
    let mut s = if denom > 0.0 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

/// Whether segment `p q` crosses triangle `(a, b, c)`: its ends strictly on opposite sides of
/// the plane and the crossing point inside the triangle (edges included).
pub fn segment_crosses_triangle(p: &Vec3, q: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> bool {
    let n = (b - a).cross(&(c - a));
    let (dp, dq) = ((p - a).dot(&n), (q - a).dot(&n));
    if !(dp > 0.0 && dq < 0.0 || dp < 0.0 && dq > 0.0) {
        return false;
    }
    let x = p + (dp / (dp - dq)) * (q - p);
    // Inside when the point is on the same side of every edge as the triangle.
    let side = |u: &Vec3, v: &Vec3| (v - u).cross(&(x - u)).dot(&n);
    side(a, b) >= 0.0 && side(b, c) >= 0.0 && side(c, a) >= 0.0
}

/// Whether two triangles that share no vertex cross: an edge of one passes through the other.
/// (Two triangles that cross always have such an edge; coplanar touching is not a crossing.)
pub fn triangles_cross(t: [&Vec3; 3], u: [&Vec3; 3]) -> bool {
    let edges_through = |s: [&Vec3; 3], o: [&Vec3; 3]| {
        (0..3).any(|k| segment_crosses_triangle(s[k], s[(k + 1) % 3], o[0], o[1], o[2]))
    };
    edges_through(t, u) || edges_through(u, t)
}

/// Whether two triangles that share exactly one vertex cross: an edge of one not through the
/// shared vertex passes through the other, or the opposite edge of one crosses the other
/// (the shared corner itself is not a crossing).
pub fn triangles_sharing_a_vertex_cross(t: [&Vec3; 3], u: [&Vec3; 3]) -> bool {
    // The opposite edges (those not at the shared vertex, which callers put first) of each.
    segment_crosses_triangle(t[1], t[2], u[0], u[1], u[2])
        || segment_crosses_triangle(u[1], u[2], t[0], t[1], t[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> [Vec3; 3] {
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ]
    }

    fn point(w: [f64; 3], t: &[Vec3; 3]) -> Vec3 {
        w[0] * t[0] + w[1] * t[1] + w[2] * t[2]
    }

    /// The closest point beats every point of a fine barycentric lattice, in every region.
    #[test]
    fn closest_point_on_triangle_beats_a_lattice() {
        let t = [
            Vec3::new(0.1, -0.2, 0.3),
            Vec3::new(1.2, 0.1, -0.1),
            Vec3::new(-0.3, 0.9, 0.2),
        ];
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..200 {
            let p = Vec3::new(rnd(), rnd(), rnd());
            let w = closest_on_triangle(&p, &t[0], &t[1], &t[2]);
            assert!(w.iter().all(|&x| (-1e-12..=1.0 + 1e-12).contains(&x)));
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let best = (point(w, &t) - p).norm();
            let n = 60;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    let q = point([1.0 - u - v, u, v], &t);
                    assert!(best <= (q - p).norm() + 1e-12, "{p:?}");
                }
            }
        }
    }

    #[test]
    fn closest_point_in_the_face_is_the_projection() {
        let t = tri();
        let w = closest_on_triangle(&Vec3::new(0.25, 0.25, 2.0), &t[0], &t[1], &t[2]);
        assert!((point(w, &t) - Vec3::new(0.25, 0.25, 0.0)).norm() < 1e-15);
        let d = closest_on_triangle(&Vec3::new(2.0, 0.0, 0.0), &t[0], &t[0], &t[0]);
        assert!((point(d, &[t[0]; 3]) - t[0]).norm() < 1e-15);
    }

    /// Segment closest points: against a fine sampling of both segments.
    #[test]
    fn closest_points_of_segments_beat_a_sampling() {
        let cases = [
            (
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.5, -1.0, 1.0),
                Vec3::new(0.5, 1.0, 1.0),
            ),
            (
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.5),
                Vec3::new(3.0, 0.0, 0.5),
            ),
            (
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.2, 0.3, 0.0),
                Vec3::new(0.8, 0.3, 0.0),
            ),
            (
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
            ),
        ];
        for (p0, p1, q0, q1) in cases {
            let (s, t) = closest_on_segments(&p0, &p1, &q0, &q1);
            let d = ((p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0))).norm();
            for i in 0..=100 {
                for j in 0..=100 {
                    let (a, b) = (i as f64 / 100.0, j as f64 / 100.0);
                    let e = ((p0 + a * (p1 - p0)) - (q0 + b * (q1 - q0))).norm();
                    assert!(d <= e + 1e-12);
                }
            }
        }
    }

    #[test]
    fn crossings_are_found_and_near_misses_are_not() {
        let t = tri();
        let through = |p: Vec3, q: Vec3| segment_crosses_triangle(&p, &q, &t[0], &t[1], &t[2]);
        assert!(through(Vec3::new(0.2, 0.2, -1.0), Vec3::new(0.2, 0.2, 1.0)));
        assert!(!through(Vec3::new(0.6, 0.6, -1.0), Vec3::new(0.6, 0.6, 1.0)));
        assert!(!through(Vec3::new(0.2, 0.2, 0.1), Vec3::new(0.2, 0.2, 1.0)));
        // A triangle pierced through its middle, and one moved just clear of it.
        let u = [
            Vec3::new(0.2, 0.2, -1.0),
            Vec3::new(0.3, 0.2, 1.0),
            Vec3::new(0.2, 0.3, 1.0),
        ];
        assert!(triangles_cross([&t[0], &t[1], &t[2]], [&u[0], &u[1], &u[2]]));
        let far = u.map(|p| p + Vec3::new(5.0, 0.0, 0.0));
        assert!(!triangles_cross(
            [&t[0], &t[1], &t[2]],
            [&far[0], &far[1], &far[2]]
        ));
    }
}
