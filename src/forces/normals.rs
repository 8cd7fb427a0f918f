//! Area-weighted vertex normals from the triangle list.

use crate::Vec3;

/// Unit normal of every vertex (zero for a vertex in no non-degenerate triangle).
pub fn vertex_normals(x: &[Vec3], triangles: &[[u32; 3]], out: &mut [Vec3]) {
    out.fill(Vec3::zeros());
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let n = (x[b] - x[a]).cross(&(x[c] - x[a]));
        out[a] += n;
        out[b] += n;
        out[c] += n;
    }
    for n in out.iter_mut() {
        let len = n.norm();
        if len > 0.0 {
            *n /= len;
        }
    }
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
