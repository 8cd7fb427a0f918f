use super::*;
use crate::collide::shapes::{bar, uv_sphere};

/// Inside a closed sphere mesh every point gets a negative distance and an outward push,
/// however deep; outside, the distance is that of the sphere within the facets' sag.
#[test]
fn closed_mesh_tells_inside_from_outside() {
    let (x, t) = uv_sphere(Vec3::zeros(), 0.5, 24, 12);
    let mut m = MeshCollider::new(&x, &t, None).unwrap();
    assert!(m.is_closed());
    m.begin_call(1.0 / 30.0, 0.03).expect("room");
    let cloth_tris: Vec<[u32; 3]> = Vec::new();
    let probes = [
        Vec3::new(0.0, 0.52, 0.0),
        Vec3::new(0.3, 0.1, -0.2),
        Vec3::new(0.0, 0.0, 0.01),
        Vec3::new(-0.49, 0.0, 0.0),
    ];
    let mut out = Vec::new();
    m.contacts(&probes, &cloth_tris, 1.0, 0.05, 0.02, 10.0, &mut out)
        .expect("room for a test mesh");
    assert_eq!(out.len(), 4, "{out:?}");
    for (c, p) in out.iter().zip(&probes) {
        let radial = p.try_normalize(0.0).unwrap_or(Vec3::z());
        assert!(c.dir.dot(&radial) > 0.9, "{p:?}: {:?}", c.dir);
        let expect = 0.05 - (p.norm() - 0.5);
        // The facets sag inward by at most r (1 - cos(pi/12)) = 0.017.
        assert!((c.depth - expect).abs() < 0.02, "{p:?}: {} vs {expect}", c.depth);
    }
}

/// A closed mesh wound inside out (normals flipped) has the same inside.
#[test]
fn an_inside_out_mesh_is_turned_round() {
    let (x, t) = uv_sphere(Vec3::zeros(), 0.5, 16, 8);
    let flipped: Vec<[u32; 3]> = t.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let mut m = MeshCollider::new(&x, &flipped, None).unwrap();
    m.begin_call(1.0 / 30.0, 0.03).expect("room");
    let mut out = Vec::new();
    // Just outside (not in contact) and just inside (pushed out).
    m.contacts(
        &[Vec3::new(0.0, 0.53, 0.0), Vec3::new(0.0, 0.45, 0.0)],
        &[],
        1.0,
        0.01,
        0.02,
        1.0,
        &mut out,
    )
    .expect("room for a test mesh");
    assert_eq!(out.len(), 1, "{out:?}");
    assert_eq!(out[0].idx[0], 1);
    assert!(out[0].dir.y > 0.9);
}

/// A mesh's borders and its folds sharper than the threshold are active edges; an edge
/// between two faces in one plane is not.
#[test]
fn borders_and_folds_are_active_edges_and_flat_ones_are_not() {
    // A square of two triangles folded along its diagonal: flat, then at 90 degrees.
    let flat = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let tris = [[0, 1, 2], [0, 2, 3]];
    let mut m = MeshCollider::new(&flat, &tris, None).unwrap();
    m.begin_call(0.01, 0.01).expect("room");
    assert_eq!(m.edges.len(), 4, "the four borders: {:?}", m.edges);
    assert!(!m.edges.contains(&[0, 2]));
    let mut folded = flat;
    folded[3] = Vec3::new(0.5, 0.5, 0.7);
    m.set(&folded, None).unwrap();
    m.begin_call(0.01, 0.01).expect("room");
    assert!(m.edges.contains(&[0, 2]), "the fold: {:?}", m.edges);
    // A cloth edge crossing under the fold, its ends far from the mesh, is pushed by it.
    let cloth = vec![
        Vec3::new(0.2, 0.8, -0.005),
        Vec3::new(1.4, -0.4, -0.005),
        Vec3::new(5.0, 5.0, 5.0),
    ];
    let mut out = Vec::new();
    m.contacts(&cloth, &[[0, 1, 2]], 1.0, 0.01, 0.01, 1.0, &mut out)
        .expect("room for a test mesh");
    let edge = out.iter().find(|c| c.len == 2).expect("an edge contact");
    assert_eq!(edge.idx[..2], [0, 1]);
    assert!(
        edge.dir.z < -0.99 && (edge.depth - 0.005).abs() < 1e-9,
        "{edge:?}"
    );
    // Flat again: the diagonal is no longer active.
    m.set(&flat, None).unwrap();
    m.begin_call(0.01, 0.01).expect("room");
    assert_eq!(m.edges.len(), 4, "{:?}", m.edges);
}

/// A mesh vertex within the margin of a cloth triangle pushes the triangle's vertices.
#[test]
fn a_thin_bar_pushes_the_cloth_triangle_it_is_under() {
    let (x, t) = bar(Vec3::new(0.3, 0.3, -1.0), Vec3::new(0.3, 0.3, 1.0), 0.002, 2);
    let mut m = MeshCollider::new(&x, &t, None).unwrap();
    m.begin_call(0.01, 0.03).expect("room");
    // One big cloth triangle 5 mm above the bar's middle.
    let cloth = vec![
        Vec3::new(-1.0, 0.305, -1.0),
        Vec3::new(2.0, 0.305, -1.0),
        Vec3::new(-1.0, 0.305, 2.0),
    ];
    let mut out = Vec::new();
    m.contacts(&cloth, &[[0, 2, 1]], 1.0, 0.01, 0.01, 1.0, &mut out)
        .expect("room for a test mesh");
    assert!(out.iter().any(|c| c.len == 3 && c.dir.y > 0.99), "{out:?}");
}

/// A bar that moves right through a cloth triangle within one step is found passing it
/// (a bar vertex through the triangle), with the bar's displacement to carry it by; the
/// same bar stopping short of the triangle is not.
#[test]
fn a_bar_through_a_cloth_triangle_in_one_step_is_a_passage() {
    let (x, t) = bar(Vec3::new(0.3, 0.29, -1.0), Vec3::new(0.3, 0.29, 1.0), 0.002, 2);
    let cloth = vec![
        Vec3::new(-1.0, 0.305, -1.0),
        Vec3::new(2.0, 0.305, -1.0),
        Vec3::new(-1.0, 0.305, 2.0),
    ];
    let tris = [[0, 2, 1]];
    for (rise, passes) in [(0.03, true), (0.01, false)] {
        let mut m = MeshCollider::new(&x, &t, None).unwrap();
        let moved: Vec<Vec3> = x.iter().map(|p| p + Vec3::new(0.0, rise, 0.0)).collect();
        m.set(&moved, None).unwrap();
        m.begin_call(0.01, 0.03).expect("room");
        m.contacts(&cloth, &tris, 1.0, 0.01, 0.01, 1.0, &mut Vec::new())
            .expect("room for a test mesh");
        let mut out = Vec::new();
        m.passages(&cloth, &cloth, &tris, 0.0, 1.0, 1e-6, &mut out);
        assert_eq!(!out.is_empty(), passes, "rise {rise}: {out:?}");
        assert_eq!(out.iter().any(|p| p.cloth == [0, 2, 1]), passes, "{out:?}");
        for p in &out {
            // Through the triangle, or a bar edge through a cloth edge.
            assert!(p.cloth.iter().all(|i| [0, 1, 2].contains(i)), "{p:?}");
            assert!((p.carry - Vec3::new(0.0, rise, 0.0)).norm() < 1e-12, "{p:?}");
        }
    }
}

/// Through a closed mesh's surface inwards is a passage; outwards (a vertex found inside,
/// on its way out) is not.
#[test]
fn only_the_way_into_a_closed_mesh_is_a_passage() {
    let (x, t) = uv_sphere(Vec3::zeros(), 0.5, 24, 12);
    let mut m = MeshCollider::new(&x, &t, None).unwrap();
    m.begin_call(1.0 / 30.0, 0.03).expect("room");
    let outside = vec![Vec3::new(0.0, 0.51, 0.0)];
    let inside = vec![Vec3::new(0.0, 0.47, 0.0)];
    for (from, to, passes) in [(&outside, &inside, true), (&inside, &outside, false)] {
        m.contacts(from, &[], 1.0, 0.05, 0.02, 10.0, &mut Vec::new())
            .expect("room for a test mesh");
        let mut out = Vec::new();
        m.passages(from, to, &[], 0.0, 1.0, 1e-6, &mut out);
        assert_eq!(!out.is_empty(), passes, "{from:?} -> {to:?}: {out:?}");
    }
}

/// A cloth lying on a mesh much finer than itself is held by its vertices' contacts alone:
/// the mesh's vertices under its triangles add nothing (else the push would grow with the
/// mesh's resolution). Where no corner touches, they do push
/// (`a_thin_bar_pushes_the_cloth_triangle_it_is_under`).
#[test]
fn a_fine_mesh_under_the_cloth_pushes_only_its_vertices() {
    // A 60 x 60 mm floor of 1 mm squares at y = 0, two triangles each way.
    let n = 61u32;
    let x: Vec<Vec3> = (0..n * n)
        .map(|k| {
            Vec3::new(
                f64::from(k % n) * 0.001 - 0.02,
                0.0,
                f64::from(k / n) * 0.001 - 0.02,
            )
        })
        .collect();
    let t: Vec<[u32; 3]> = (0..n - 1)
        .flat_map(|r| (0..n - 1).map(move |c| r * n + c))
        .flat_map(|k| [[k, k + n, k + 1], [k + 1, k + n, k + n + 1]])
        .collect();
    let mut m = MeshCollider::new(&x, &t, None).unwrap();
    m.begin_call(0.01, 0.015).expect("room");
    // A 2 cm cloth square 5 mm above it, inside the margin of 1 cm.
    let cloth = vec![
        Vec3::new(0.0, 0.005, 0.0),
        Vec3::new(0.02, 0.005, 0.0),
        Vec3::new(0.0, 0.005, 0.02),
        Vec3::new(0.02, 0.005, 0.02),
    ];
    let tris = [[0, 2, 1], [1, 2, 3]];
    let mut out = Vec::new();
    m.contacts(&cloth, &tris, 1.0, 0.01, 0.005, 1.0, &mut out)
        .expect("room for a test mesh");
    assert_eq!(out.len(), 4, "contacts: {}", out.len());
    assert!(out.iter().all(|c| c.len == 1 && c.dir.y > 0.99));
}

/// Steps a sheet of 12 x 12 vertices `spacing` apart, vertex `(u, v)` (centred) at
/// `sheet(u, v, s)` at time `s`, and a vertex in no triangle, for `steps` substeps of 1 ms
/// against a ball and a thin bar, comparing each substep's contacts from the kept
/// candidates with a fresh search's: how many vertex, triangle and edge contacts it compared.
fn compare_kept_with_fresh(
    steps: u32,
    spacing: f64,
    sheet: impl Fn(f64, f64, f64) -> Vec3,
) -> (usize, usize, usize) {
    use crate::collide::shapes::{bar, uv_sphere};
    let (mut x, mut t) = uv_sphere(Vec3::new(0.0, 0.0, 0.0), 0.05, 24, 13);
    let (bx, bt) = bar(Vec3::new(-0.2, 0.02, 0.03), Vec3::new(0.2, 0.02, 0.03), 0.002, 4);
    let base = x.len() as u32;
    x.extend(bx);
    t.extend(bt.iter().map(|tri| tri.map(|i| i + base)));
    let mut kept = MeshCollider::new(&x, &t, None).unwrap();
    kept.begin_call(0.01, 0.015).expect("room");
    let n = 12u32;
    let tris: Vec<[u32; 3]> = (0..n - 1)
        .flat_map(|r| (0..n - 1).map(move |c| r * n + c))
        .flat_map(|k| [[k, k + n, k + 1], [k + 1, k + n, k + n + 1]])
        .collect();
    let (mut with_vertex, mut with_triangle, mut with_edge) = (0, 0, 0);
    for step in 0..steps {
        let s = f64::from(step) * 1e-3;
        // And a vertex in no triangle, half a spacing off the sheet's middle.
        let cloth: Vec<Vec3> = (0..n * n)
            .map(|k| {
                let at = |i: u32| (f64::from(i) - 5.5) * spacing;
                sheet(at(k % n), at(k / n), s)
            })
            .chain([sheet(0.3 * spacing, 0.4 * spacing, s)])
            .collect();
        let mut a = Vec::new();
        kept.contacts(&cloth, &tris, 1.0, 0.01, 0.005, 0.03, &mut a)
            .expect("room for a test mesh");
        let mut fresh = kept.clone();
        fresh.cache = Candidates::default();
        let mut b = Vec::new();
        fresh
            .contacts(&cloth, &tris, 1.0, 0.01, 0.005, 0.03, &mut b)
            .expect("room for a test mesh");
        // The same contacts, to rounding; a vertex deeper inside the ball than the reach
        // (margin and skin) is pushed out along a triangle near it, not always the nearest
        // (module docs), so only its contact is compared.
        assert_eq!(a.len(), b.len(), "step {step}");
        for (p, q) in a.iter().zip(&b) {
            let deep = p.depth >= 0.015 && q.depth >= 0.015;
            let close = p.idx == q.idx
                && p.len == q.len
                && (deep
                    || (0..4).all(|k| (p.coef[k] - q.coef[k]).abs() < 1e-12)
                        && (p.dir - q.dir).norm() < 1e-12
                        && (p.depth - q.depth).abs() < 1e-15);
            assert!(close, "step {step}: {p:?} against {q:?}");
        }
        with_vertex += a.iter().filter(|c| c.len == 1).count();
        with_triangle += a.iter().filter(|c| c.len == 3).count();
        with_edge += a.iter().filter(|c| c.len == 2).count();
    }
    (with_vertex, with_triangle, with_edge)
}

/// The contacts from the kept candidates are those of a fresh search at every substep,
/// while a cloth sheet moves about and through a bar and a ball (a vertex, its triangles
/// and its edges look again only once it has moved its slack).
#[test]
fn kept_candidates_give_the_contacts_of_a_fresh_look() {
    // A 12 x 12 sheet of 1 cm, swept across the ball and the bar with a wobble.
    let (v, t, e) = compare_kept_with_fresh(400, 0.01, |u, v, s| {
        Vec3::new(
            u + 0.3 * s - 0.06,
            v,
            0.08 - 0.15 * s + 0.004 * (40.0 * u + 90.0 * s).sin(),
        )
    });
    // Every kind of contact was compared.
    assert!(v > 100 && t > 0 && e > 0, "{v} {t} {e}");
}

/// The same when the sheet comes from far off, fast (2 to 4 mm a substep, a skin in two
/// substeps): the vertices' slacks grown by the gaps their lookups left must shrink in
/// time as it comes near. Its triangles are 3 cm across, so the bar's vertices meet their
/// insides with no corner touching (triangle contacts).
#[test]
fn kept_candidates_stay_whole_for_a_sheet_that_comes_from_far_off() {
    let (v, t, e) = compare_kept_with_fresh(160, 0.03, |u, v, s| {
        // Down 30 cm onto the ball and the bar, tilted, sliding sideways, wobbling.
        Vec3::new(
            u + 0.4 * s - 0.02,
            v + 0.2 * u,
            0.28 + 0.2 * u - 2.5 * s + 0.01 * (30.0 * v + 200.0 * s).sin(),
        )
    });
    println!("far off: {v} vertex, {t} triangle, {e} edge contacts compared");
    assert!(v > 100 && t > 0 && e > 0, "{v} {t} {e}");
}

/// A mesh handed again where it is keeps its boxes and candidates (nothing is looked up
/// again); moved by as little as one bit of one coordinate, it looks everything up again.
#[test]
fn a_mesh_sent_again_where_it_is_keeps_its_search() {
    use crate::collide::shapes::uv_sphere;
    let (x, t) = uv_sphere(Vec3::new(0.0, 0.0, 0.0), 0.05, 24, 13);
    let mut mesh = MeshCollider::new(&x, &t, None).unwrap();
    let cloth = [
        Vec3::new(0.0, 0.0, 0.055),
        Vec3::new(0.01, 0.0, 0.056),
        Vec3::new(0.0, 0.01, 0.056),
    ];
    let tris = [[0u32, 1, 2]];
    let step = |mesh: &mut MeshCollider| {
        mesh.begin_call(0.01, 0.015).expect("room");
        let mut out = Vec::new();
        mesh.contacts(&cloth, &tris, 1.0, 0.01, 0.005, 0.03, &mut out)
            .expect("room");
        mesh.arrive();
        out.len()
    };
    let contacts = step(&mut mesh);
    assert!(contacts >= 3, "{contacts}");
    mesh.set(&x, None).expect("the same positions");
    assert_eq!(mesh.fresh_at, 0.015, "the boxes are kept");
    assert!(!mesh.cache.stale);
    assert_eq!(step(&mut mesh), contacts);
    let mut nudged = x.clone();
    nudged[7].y = f64::from_bits(nudged[7].y.to_bits() + 1);
    mesh.set(&nudged, None).expect("one bit moved");
    assert!(mesh.fresh_at.is_nan(), "made again");
    assert_eq!(step(&mut mesh), contacts);
    assert!(!mesh.cache.stale, "looked up again at the step");
}

#[test]
fn bad_meshes_are_refused() {
    let x = vec![Vec3::zeros(), Vec3::x(), Vec3::y()];
    assert!(MeshCollider::new(&x, &[[0, 1, 3]], None).is_err());
    assert!(MeshCollider::new(&x, &[], None).is_err());
    assert!(MeshCollider::new(
        &[Vec3::new(f64::NAN, 0.0, 0.0), Vec3::x(), Vec3::y()],
        &[[0, 1, 2]],
        None
    )
    .is_err());
    let mut m = MeshCollider::new(&x, &[[0, 1, 2]], None).unwrap();
    assert!(!m.is_closed());
    assert!(m.set(&x[..2], None).is_err());
    assert!(m.set(&x, Some(&x[..1])).is_err());
    assert!(m.set(&x, Some(&x)).is_ok());
}
