//! A self-collision pair and its distances: the pair the search remembers, and the distance of a
//! vertex-triangle or edge-edge pair, shared by the search (`self_collision.rs`), its guard, the
//! neighbour exclusions and the impact zones.

use super::geometry::{closest_on_segments, offset_from_triangle};
use crate::math::Vec3;

/// A remembered pair: the two elements and the side, +1 or -1 (0: not known yet, until the
/// vertex first comes over the triangle's face, or the edges' closest points first lie inside
/// both).
pub type Pair = (u32, u32, i8);

/// Distance between vertex `p` and triangle `t` of positions `x`, with the weights and the
/// vector from the triangle's closest point to `p`.
pub(super) fn vertex_triangle(x: &[Vec3], p: u32, t: &[u32; 3]) -> (f64, [f64; 3], Vec3) {
    let [a, b, c] = t.map(|i| x[i as usize]);
    let q = x[p as usize];
    let (w, r) = offset_from_triangle(&q, &a, &b, &c);
    (r.norm(), w, r)
}

/// Distance between edges `e` and `f` of positions `x`, the parameters, the vector from the
/// second's closest point to the first's and the (unnormalised) normal `e x f`.
pub(super) fn edge_edge(x: &[Vec3], e: &[u32; 2], f: &[u32; 2]) -> (f64, f64, f64, Vec3, Vec3) {
    let (p0, p1, q0, q1) = (
        x[e[0] as usize],
        x[e[1] as usize],
        x[f[0] as usize],
        x[f[1] as usize],
    );
    let (s, t) = closest_on_segments(&p0, &p1, &q0, &q1);
    let r = (p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0));
    (r.norm(), s, t, r, (p1 - p0).cross(&(q1 - q0)))
}
