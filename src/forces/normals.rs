//! Area-weighted vertex normals from the triangle list.

use crate::math::Vec3;
use crate::parallel;
use crate::topology::Adjacency;

/// Unit normal of every vertex (zero for a vertex in no non-degenerate triangle).
pub fn vertex_normals(x: &[Vec3], triangles: &[[u32; 3]], out: &mut [Vec3]) {
    let adjacency = Adjacency::triangles(x.len(), triangles);
    let mut faces = vec![Vec3::zeros(); triangles.len()];
    vertex_normals_with(x, triangles, &adjacency, false, &mut faces, out);
}

/// [`vertex_normals`] with the vertex-triangle adjacency and the per-triangle buffer supplied
/// (no allocation): face normals (twice the area) first, then each vertex sums its triangles
/// in ascending order.
pub fn vertex_normals_with(
    x: &[Vec3],
    triangles: &[[u32; 3]],
    adjacency: &Adjacency,
    parallel: bool,
    faces: &mut [Vec3],
    out: &mut [Vec3],
) {
    parallel::chunks(parallel, faces, parallel::CHUNK, |first, chunk| {
        for (f, t) in chunk.iter_mut().zip(&triangles[first..]) {
            let [a, b, c] = t.map(|i| i as usize);
            *f = (x[b] - x[a]).cross(&(x[c] - x[a]));
        }
    });
    let faces = &*faces;
    parallel::chunks(parallel, out, parallel::CHUNK, |first, chunk| {
        for (k, o) in chunk.iter_mut().enumerate() {
            let mut n = Vec3::zeros();
            for &t in adjacency.row(first + k) {
                n += faces[t as usize];
            }
            let len = n.norm();
            *o = if len > 0.0 { n / len } else { n };
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::GridSpec;

    #[test]
    fn flat_grid_faces_plus_z() {
        let t = GridSpec {
            width: 4,
            height: 3,
            spacing: 0.1,
            total_mass: 1.0,
        }
        .build()
        .unwrap();
        let mut n = vec![Vec3::zeros(); t.vertex_count()];
        vertex_normals(&t.rest_positions, &t.triangles, &mut n);
        for v in n {
            assert!((v - Vec3::z()).norm() < 1e-12, "{v:?}");
        }
    }
}
