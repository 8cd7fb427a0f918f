use super::*;
use crate::forces::inertia::CARRIED_FULL;
use crate::forces::turning::{turning_forces, turning_serial, TurningScratch};
use crate::Model;

/// The grid's gathered passes give the scatter's bits (forces added to what was there,
/// projected-area ratios, unit normals) on grids of every shape the rows allow (one cell,
/// one row or column of cells, rows shorter and longer than a block), crumpled, with
/// patches stretched past the carried water's bound; in one band and in bands of one, two,
/// three and seven rows, on one thread and on the pool.
#[test]
fn the_grid_passes_keep_the_scatters_bits() {
    let mut m = Model::underwater();
    m.water.added_mass = 8.0;
    for (w, h, seed) in [
        (2, 2, 1),
        (3, 2, 2),
        (2, 5, 3),
        (9, 8, 4),
        (10, 3, 5),
        (23, 17, 6),
        (61, 41, 7),
    ] {
        let (t, mut x, v) = crate::testing::crumpled_grid(w, h, seed);
        let size = (w as usize, h as usize);
        assert_eq!(t.grid_faces, Some(size));
        let n = x.len();
        // Some patches stretched well past the bound.
        for k in (0..n).step_by(5) {
            x[k] *= 1.6;
        }
        let prior: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(i as f64, -0.5, 0.25 * i as f64))
            .collect();
        let run = |how: Option<(usize, bool, usize)>| {
            let mut s = TurningScratch::default();
            let (mut p, mut nr, mut out) = (vec![0.0; n], vec![Vec3::zeros(); n], prior.clone());
            // Twice: buffers sized by the first call are reused by the second.
            for _ in 0..2 {
                out.clone_from(&prior);
                match how {
                    None => turning_serial(8.0, &t, &x, &v, &mut s, &mut p, &mut nr, &mut out, None),
                    Some(bands) => {
                        let mut b = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
                        let buffers = GridBuffers {
                            bands: &mut b.0,
                            sums: &mut b.1,
                            rates: &mut b.2,
                            patches: &mut b.3,
                        };
                        turning_grid(8.0, &t, size, &x, &v, buffers, bands, &mut p, &mut nr, &mut out);
                    }
                }
            }
            (out, p, nr)
        };
        let want = run(None);
        assert!(
            want.1.iter().any(|&p| p * p > CARRIED_FULL),
            "{w}x{h}: no patch past the bound"
        );
        assert!(want.0.iter().zip(&prior).all(|(a, b)| a != b));
        let bits = |a: &[Vec3]| -> Vec<u64> {
            a.iter()
                .flat_map(|p| p.iter().map(|c| c.to_bits()))
                .collect::<Vec<_>>()
        };
        let ratios = |a: &[f64]| a.iter().map(|p| p.to_bits()).collect::<Vec<_>>();
        // Bands, and the vertices whose sums are kept before their patch terms are taken:
        // a row, a few, and a whole band.
        for bands in [
            (h as usize, false, PATCH_ROWS_VERTICES),
            (h as usize, false, 1),
            (h as usize, true, 3 * w as usize - 1),
            (1, false, PATCH_ROWS_VERTICES),
            (2, true, 1),
            (3, true, PATCH_ROWS_VERTICES),
            (7, false, 2 * w as usize),
            (7, true, 1),
            (1, true, PATCH_ROWS_VERTICES),
        ] {
            let got = run(Some(bands));
            assert_eq!(bits(&got.0), bits(&want.0), "forces, {w}x{h}, bands {bands:?}");
            assert_eq!(bits(&got.2), bits(&want.2), "normals, {w}x{h}, bands {bands:?}");
            assert_eq!(
                ratios(&got.1),
                ratios(&want.1),
                "ratios, {w}x{h}, bands {bands:?}"
            );
        }
        // And the step's own choice.
        let mut s = TurningScratch::default();
        let (mut p, mut nr, mut out) = (vec![0.0; n], vec![Vec3::zeros(); n], prior.clone());
        turning_forces(&m, &t, &x, &v, &mut s, &mut p, &mut nr, &mut out, None);
        assert_eq!(bits(&out), bits(&want.0), "forces, {w}x{h}, the step's choice");
    }
}

/// A grid's triangles are recognised only when they are exactly the ones a grid makes.
#[test]
fn only_a_grids_own_triangles_are_taken_for_a_grid() {
    let (t, _, _) = crate::testing::crumpled_grid(4, 3, 1);
    assert_eq!(t.grid_faces, Some((4, 3)));
    let with = |triangles: Vec<[u32; 3]>| {
        Topology::new(
            t.rest_positions.clone(),
            t.masses.clone(),
            t.springs.clone(),
            triangles,
            t.grid,
        )
    };
    assert_eq!(with(t.triangles.clone()).grid_faces, Some((4, 3)));
    // Two faces in another order; a face's corners turned the other way.
    let mut moved = t.triangles.clone();
    moved.swap(2, 3);
    assert_eq!(with(moved).grid_faces, None);
    let mut flipped = t.triangles.clone();
    flipped[5] = [flipped[5][0], flipped[5][2], flipped[5][1]];
    assert_eq!(with(flipped).grid_faces, None);
    let jittered = crate::testing::jittered_mesh(5, 4);
    assert_eq!(jittered.grid_faces, None);
}
