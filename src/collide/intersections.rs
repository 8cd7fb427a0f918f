//! Counting a mesh's self-intersections exactly: every pair of its triangles that cross
//! (sharing no vertex: an edge of one passes through the other; sharing one: the edge
//! opposite the shared corner does). Triangles sharing an edge are not counted. What the
//! collision tests and the baker's report count.

use super::bvh::{Aabb, Bvh};
use super::geometry::{triangles_cross, triangles_sharing_a_vertex_cross};
use crate::math::Vec3;

/// The number of crossing triangle pairs of `triangles` at positions `x`.
pub fn self_intersections(x: &[Vec3], triangles: &[[u32; 3]]) -> usize {
    crossing_pairs(x, triangles).len()
}

/// The crossing triangle pairs `(a, b)`, a < b, of `triangles` at positions `x`.
pub fn crossing_pairs(x: &[Vec3], triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let boxes: Vec<Aabb> = triangles
        .iter()
        .map(|t| Aabb::of(t.iter().map(|&i| &x[i as usize])))
        .collect();
    let bvh = Bvh::build(&boxes);
    let mut pairs = Vec::new();
    for (a, ta) in triangles.iter().enumerate() {
        bvh.overlapping(&boxes[a], |b| {
            if (b as usize) <= a {
                return;
            }
            let tb = &triangles[b as usize];
            let shared: Vec<u32> = ta.iter().copied().filter(|v| tb.contains(v)).collect();
            let p = |t: &[u32; 3], k: usize| &x[t[k] as usize];
            let crossed = match shared.as_slice() {
                [] => triangles_cross([p(ta, 0), p(ta, 1), p(ta, 2)], [p(tb, 0), p(tb, 1), p(tb, 2)]),
                [s] => {
                    // The shared corner first in both.
                    let ra = ta.iter().position(|v| v == s).unwrap_or(0);
                    let rb = tb.iter().position(|v| v == s).unwrap_or(0);
                    let ca = [p(ta, ra), p(ta, (ra + 1) % 3), p(ta, (ra + 2) % 3)];
                    let cb = [p(tb, rb), p(tb, (rb + 1) % 3), p(tb, (rb + 2) % 3)];
                    triangles_sharing_a_vertex_cross(ca, cb)
                }
                _ => false,
            };
            if crossed {
                pairs.push((a as u32, b));
            }
        });
    }
    pairs
}

/// Cloth vertices inside a closed mesh `(positions, triangles)`, by the winding number (the
/// solid angle the mesh subtends, over 4 pi; Jacobson et al. 2013): exact for a closed mesh.
pub fn vertices_inside(x: &[Vec3], mesh_x: &[Vec3], mesh_t: &[[u32; 3]]) -> usize {
    let bounds = Aabb::of(mesh_x.iter());
    x.iter()
        .filter(|p| bounds.contains(p) && winding_number(p, mesh_x, mesh_t) > 0.5)
        .count()
}

/// The generalised winding number of a closed mesh at `p` (1 inside, 0 outside).
pub fn winding_number(p: &Vec3, mesh_x: &[Vec3], mesh_t: &[[u32; 3]]) -> f64 {
    let mut total = 0.0;
    for t in mesh_t {
        let [a, b, c] = t.map(|i| mesh_x[i as usize] - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
        total += 2.0 * num.atan2(den);
    }
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collide::shapes::{torus, uv_sphere};

    #[test]
    fn a_flat_grid_has_none_and_a_pierced_one_has_some() {
        let grid = crate::topology::GridSpec {
            width: 6,
            height: 6,
            spacing: 0.1,
            total_mass: 1.0,
        }
        .build()
        .unwrap();
        let mut x = grid.rest_positions.clone();
        let t = &grid.triangles;
        assert_eq!(self_intersections(&x, t), 0);
        // Fold the last two rows back through the middle of the cloth.
        let normal = (x[1] - x[0]).cross(&(x[6] - x[0])).normalize();
        let n = x.len();
        for i in n - 6..n {
            x[i] = x[i - 18] + normal * 0.05 + (x[7] - x[1]) * 0.5;
        }
        for i in n - 12..n - 6 {
            x[i] = x[i - 12] - normal * 0.05 + (x[7] - x[1]) * 0.5;
        }
        assert!(self_intersections(&x, t) > 0);
    }

    #[test]
    fn winding_number_tells_inside() {
        let (sx, st) = uv_sphere(Vec3::zeros(), 1.0, 16, 8);
        assert!((winding_number(&Vec3::new(0.1, 0.2, 0.1), &sx, &st) - 1.0).abs() < 1e-9);
        assert!(winding_number(&Vec3::new(1.5, 0.0, 0.0), &sx, &st).abs() < 1e-9);
        let (tx, tt) = torus(Vec3::zeros(), 0.5, 0.2, 24, 12);
        assert_eq!(
            vertices_inside(&[Vec3::zeros(), Vec3::new(0.5, 0.0, 0.0)], &tx, &tt),
            1
        );
    }
}
