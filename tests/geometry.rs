//! The index buffer and vertex normals through the C ABI, against the topology and a fold whose
//! normals are known.

use fraccloth::ffi::FcStatus::{FC_ERROR_INVALID_ARGUMENT, FC_ERROR_NULL_ARGUMENT, FC_OK};
use fraccloth::ffi::*;

fn grid(width: u32, height: u32, spacing: f32) -> *mut FcCloth {
    let mut d = fc_cloth_desc_default();
    d.width = width;
    d.height = height;
    d.spacing = spacing;
    let mut c = std::ptr::null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(&d, &mut c) }, FC_OK);
    c
}

#[test]
fn the_index_buffer_is_the_clothes_triangles() {
    let c = grid(61, 41, 0.01);
    unsafe {
        let t = fc_cloth_triangle_count(c);
        assert_eq!(t, 2 * 60 * 40);
        let mut idx = vec![u32::MAX; 3 * t];
        assert_eq!(fc_cloth_get_triangles(c, idx.as_mut_ptr(), idx.len()), FC_OK);
        assert!(idx.iter().all(|&i| (i as usize) < fc_cloth_vertex_count(c)));
        // Every triangle faces +z at rest (counter-clockwise seen from +z), and each vertex
        // appears: an index buffer a renderer can draw as is.
        let mut xyz = vec![0f32; 3 * 61 * 41];
        fc_cloth_get_positions(c, xyz.as_mut_ptr(), xyz.len());
        let p = |i: u32| [xyz[3 * i as usize], xyz[3 * i as usize + 1]];
        for tri in idx.chunks(3) {
            let (a, b, cc) = (p(tri[0]), p(tri[1]), p(tri[2]));
            let z = (b[0] - a[0]) * (cc[1] - a[1]) - (b[1] - a[1]) * (cc[0] - a[0]);
            assert!(z > 0.0);
        }
        let mut seen = vec![false; 61 * 41];
        idx.iter().for_each(|&i| seen[i as usize] = true);
        assert!(seen.iter().all(|&s| s));
        // Wrong count and NULL are refused.
        assert_eq!(
            fc_cloth_get_triangles(c, idx.as_mut_ptr(), idx.len() - 3),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            fc_cloth_get_triangles(c, std::ptr::null_mut(), idx.len()),
            FC_ERROR_NULL_ARGUMENT
        );
        fc_cloth_destroy(c);
    }
}

#[test]
fn normals_are_plus_z_at_rest_and_follow_a_fold() {
    let c = grid(5, 3, 1.0);
    unsafe {
        let n = fc_cloth_vertex_count(c);
        let mut nrm = vec![0f32; 3 * n];
        assert_eq!(fc_cloth_get_normals(c, nrm.as_mut_ptr(), nrm.len()), FC_OK);
        for v in nrm.chunks(3) {
            assert_eq!(v, [0.0, 0.0, 1.0]);
        }
        // Fold the sheet along the middle column: z = |x - x_mid|. The left half is the plane
        // z = -(x - x_mid), whose upward unit normal is (1, 0, 1)/sqrt 2; the right half's is
        // (-1, 0, 1)/sqrt 2; the middle column's lies between the two, weighted by the areas of
        // the triangles it has on each side (the split of the quads is not symmetric).
        let mut xyz = vec![0f32; 3 * n];
        fc_cloth_get_positions(c, xyz.as_mut_ptr(), xyz.len());
        let mid = xyz[3 * 2];
        for v in xyz.chunks_mut(3) {
            v[2] = (v[0] - mid).abs();
        }
        assert_eq!(fc_cloth_set_positions(c, xyz.as_ptr(), xyz.len()), FC_OK);
        assert_eq!(fc_cloth_get_normals(c, nrm.as_mut_ptr(), nrm.len()), FC_OK);
        let h = std::f32::consts::FRAC_1_SQRT_2;
        for (k, v) in nrm.chunks(3).enumerate() {
            let col = k % 5;
            let want = match col {
                0 | 1 => [h, 0.0, h],
                3 | 4 => [-h, 0.0, h],
                _ => {
                    assert!(
                        v[1].abs() < 1e-6 && v[2] > h && v[0].abs() < h,
                        "vertex {k}: {v:?}"
                    );
                    assert!(((v[0] * v[0] + v[2] * v[2]).sqrt() - 1.0).abs() < 1e-6);
                    continue;
                }
            };
            for a in 0..3 {
                assert!((v[a] - want[a]).abs() < 1e-6, "vertex {k}: {v:?} vs {want:?}");
            }
        }
        assert_eq!(
            fc_cloth_get_normals(c, nrm.as_mut_ptr(), 3),
            FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            fc_cloth_get_normals(c, std::ptr::null_mut(), nrm.len()),
            FC_ERROR_NULL_ARGUMENT
        );
        fc_cloth_destroy(c);
    }
}
