use super::*;

/// A sheet of `cols` x `rows` vertices 1 cm apart folded along its middle row, the lower
/// half 3 mm under the upper, vertices moved at random by up to 2 mm, and a vertex in no
/// triangle lying on it: (positions, rest positions, triangles).
fn folded_sheet(cols: u32, rows: u32) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>) {
    let h = 0.01;
    let mut r = crate::testing::numbers(11);
    let mut x: Vec<Vec3> = Vec::new();
    let mut rest: Vec<Vec3> = Vec::new();
    for j in 0..rows {
        for i in 0..cols {
            rest.push(Vec3::new(f64::from(i) * h, -f64::from(j) * h, 0.0));
            let fold = f64::from(rows - 1) / 2.0;
            let (y, z) = if f64::from(j) <= fold {
                (-f64::from(j) * h, 0.0)
            } else {
                (-(2.0 * fold - f64::from(j)) * h, 0.003)
            };
            x.push(Vec3::new(f64::from(i) * h, y, z) + 0.002 * Vec3::new(r(), r(), r()));
        }
    }
    // A lone vertex over the sheet, in no triangle.
    rest.push(Vec3::new(0.5, 0.5, 0.5));
    x.push(Vec3::new(0.055, -0.02, 0.0015));
    let at = |i: u32, j: u32| j * cols + i;
    let mut triangles = Vec::new();
    for j in 0..rows - 1 {
        for i in 0..cols - 1 {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (x, rest, triangles)
}

/// Every pair within `reach` at `x` that is not excluded at `rest`, with its side, by
/// testing every pair.
fn every_pair(
    x: &[Vec3],
    rest: &[Vec3],
    triangles: &[[u32; 3]],
    edges: &[[u32; 2]],
    reach: f64,
    excluded_within: f64,
) -> (Vec<Pair>, Vec<Pair>) {
    let excluded = Exclusions::new(
        rest,
        triangles,
        edges,
        excluded_within,
        &RestTree::new(rest, triangles, excluded_within, false),
        &mut Room::new(usize::MAX),
        false,
    )
    .expect("room for a test mesh");
    let mut vt = Vec::new();
    for p in 0..x.len() as u32 {
        for (t, tri) in triangles.iter().enumerate() {
            if tri.contains(&p) || excluded.vertex_excludes(p, t as u32) {
                continue;
            }
            let (d, w, r) = vertex_triangle(x, p, tri);
            if d < reach {
                let [a, b, c] = tri.map(|i| x[i as usize]);
                let s = if w.iter().all(|&wk| wk > 0.0) {
                    side(r.dot(&(b - a).cross(&(c - a))))
                } else {
                    0
                };
                vt.push((p, t as u32, s));
            }
        }
    }
    let mut ee = Vec::new();
    for (e, edge) in edges.iter().enumerate() {
        for (f, other) in edges.iter().enumerate().skip(e + 1) {
            if edge.iter().any(|v| other.contains(v)) || excluded.edge_excludes(e as u32, f as u32) {
                continue;
            }
            let (d, a, b, r, n) = edge_edge(x, edge, other);
            if d < reach {
                let interior = a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0;
                ee.push((e as u32, f as u32, if interior { side(r.dot(&n)) } else { 0 }));
            }
        }
    }
    (vt, ee)
}

/// The look finds exactly the pairs a test of every pair finds, sides included: on a sheet
/// folded onto itself (many pairs within reach, between triangles near and far at rest)
/// with vertices moved at random, and with a vertex that belongs to no triangle lying on
/// the sheet.
#[test]
fn the_look_finds_what_testing_every_pair_finds() {
    let (x, rest, triangles) = folded_sheet(12, 9);
    let (thickness, reach) = (0.004, 0.008);
    let mut sc = SelfCollision::new(&triangles);
    sc.look(&x, &rest, &triangles, reach, EXCLUDED * thickness)
        .expect("room");
    assert!(
        sc.vertex_triangle.len() > 50 && sc.edge_edge.len() > 50,
        "a fold has pairs"
    );
    let (vt, ee) = every_pair(&x, &rest, &triangles, &sc.edges, reach, EXCLUDED * thickness);
    assert!(
        vt.iter().any(|q| q.0 == x.len() as u32 - 1),
        "the lone vertex has pairs"
    );
    assert_eq!(sc.vertex_triangle, vt);
    assert_eq!(sc.edge_edge, ee);
}

/// The proof that an unfolded sheet keeps its distances (`unfolded.rs`) changes no look:
/// the pairs, sides included, are those of a look without it and of a test of every pair,
/// on a sheet waved gently (the proof covers every pair: nothing tested), rolled into a
/// spiral whose turns lie 6 mm apart (the proof covers the short distances; the pairs a
/// turn apart are found), creased by a radian along a diagonal (nothing in reach: proved
/// whole since the proof starts at the nearest tested pair, 10 mm; at the 8.8 mm
/// exclusion it was not), folded back over itself
/// round 3 mm (nothing proved), and the folded sheet with its lone vertex (never proved
/// whole).
#[test]
fn the_proof_leaves_every_look_as_it_was() {
    let (rest, triangles) = crate::testing::flat_grid(41, 11, 0.01);
    let waved: Vec<Vec3> = rest
        .iter()
        .map(|p| p + Vec3::new(0.0, 0.0, 0.01 * (p.x * 20.0).sin() + 0.004 * (p.y * 30.0).cos()))
        .collect();
    let rolled: Vec<Vec3> = rest
        .iter()
        .map(|p| {
            let (mut angle, mut s) = (0.0_f64, 0.0);
            let r = |angle: f64| 0.05 + 0.006 * angle / std::f64::consts::TAU;
            while s < p.x {
                let step = 1e-4 / r(angle);
                s += r(angle) * step;
                angle += step;
            }
            Vec3::new(r(angle) * angle.sin(), p.y, r(angle) * angle.cos())
        })
        .collect();
    let creased: Vec<Vec3> = rest
        .iter()
        .map(|p| {
            let off = (p.x - p.y - 0.15) / 2f64.sqrt();
            if off <= 0.0 {
                *p
            } else {
                let across = Vec3::new(1.0, -1.0, 0.0) / 2f64.sqrt();
                p - off * across + off * (1f64.cos() * across + 1f64.sin() * Vec3::z())
            }
        })
        .collect();
    // Folded back over itself round a radius of 3 mm, the halves 6 mm apart.
    let folded: Vec<Vec3> = rest
        .iter()
        .map(|p| crate::testing::folded_over(p, 0.2, 0.003))
        .collect();
    let (thickness, reach) = (0.004, 0.008);
    let excluded = EXCLUDED * thickness;
    for (name, x, whole) in [
        ("waved", &waved, true),
        ("rolled", &rolled, false),
        ("creased", &creased, true),
        ("folded", &folded, false),
    ] {
        let mut proved = SelfCollision::new(&triangles);
        proved.prepare(&rest, &triangles, thickness).expect("prepared");
        let below = proved.unfolded.certified_below(x, &triangles, reach, excluded);
        if name == "rolled" {
            assert!(
                below > 2.0 * excluded && below < 0.3,
                "{name}: proved below {below} m"
            );
        }
        proved.look(x, &rest, &triangles, reach, excluded).expect("room");
        assert_eq!(proved.certified_looks, u64::from(whole), "{name}");
        let mut full = SelfCollision::new(&triangles);
        full.full_looks = true;
        full.look(x, &rest, &triangles, reach, excluded).expect("room");
        assert_eq!(full.certified_looks, 0);
        assert_eq!(proved.vertex_triangle, full.vertex_triangle, "{name}");
        assert_eq!(proved.edge_edge, full.edge_edge, "{name}");
        let (vt, ee) = every_pair(x, &rest, &triangles, &proved.edges, reach, excluded);
        if whole {
            assert!(vt.is_empty() && ee.is_empty(), "{name}: nothing in reach");
        }
        assert_eq!(proved.vertex_triangle, vt, "{name}");
        assert_eq!(proved.edge_edge, ee, "{name}");
        if name == "rolled" || name == "folded" {
            assert!(
                vt.len() > 100 && ee.len() > 100,
                "{name}: the layers find each other"
            );
        }
    }
    let (x, rest, triangles) = folded_sheet(12, 9);
    let mut sc = SelfCollision::new(&triangles);
    sc.look(&x, &rest, &triangles, reach, excluded).expect("room");
    let mut full = SelfCollision::new(&triangles);
    full.full_looks = true;
    full.look(&x, &rest, &triangles, reach, excluded).expect("room");
    assert_eq!(sc.vertex_triangle, full.vertex_triangle);
    assert_eq!(sc.edge_edge, full.edge_edge);
}

/// The guard's watch leaves out of a step's check only neighbour pairs (edge pairs and
/// vertex-triangle pairs) that stay further apart than the tolerance throughout the step
/// (sampled along the straight paths). The sheet is squeezed across its rows a little
/// every step (its rows 10 -> 2.2 mm apart over the run, so the pairs come nearer by far
/// more than any one step moves them, the upper rows faster half the time), with noise
/// and now and then a large step. A tolerance of 5 mm (the skin is 6 mm) makes pairs come
/// within it, so the test can fail: it does when the watch bounds each step's own motion
/// instead of the motion since it measured, or when its box leaves out vertices (both
/// checked). The watch still skips pairs, and some watched pairs of both kinds come within
/// the tolerance.
#[test]
fn the_guard_watch_leaves_out_only_pairs_that_cannot_meet() {
    let (_, rest, triangles) = folded_sheet(12, 9);
    let (thickness, tolerance) = (0.004, 0.005);
    let mut sc = SelfCollision::new(&triangles);
    sc.prepare(&rest, &triangles, thickness).expect("prepared");
    let (edge_pairs, vertex_pairs) = (sc.guard.pairs().0.to_vec(), sc.guard.pairs().1.to_vec());
    assert!(
        edge_pairs.len() > 100 && vertex_pairs.len() > 100,
        "a 1 cm grid has neighbour pairs at 4 mm: {} {}",
        edge_pairs.len(),
        vertex_pairs.len()
    );
    let mut r = crate::testing::numbers(3);
    let mut x0 = rest.clone();
    let (mut skipped, mut met) = (0usize, [0usize; 2]);
    // The least distance of a pair's points along the step's straight paths.
    let least = |x0: &[Vec3], x1: &[Vec3], vs: &[u32], d: &dyn Fn(&[Vec3]) -> f64| {
        let mut xs = x0.to_vec();
        (0..=32)
            .map(|k| {
                let s = f64::from(k) / 32.0;
                for &i in vs {
                    let i = i as usize;
                    xs[i] = x0[i] + s * (x1[i] - x0[i]);
                }
                d(&xs)
            })
            .fold(f64::INFINITY, f64::min)
    };
    for step in 0..300 {
        let noise = if step % 60 == 59 { 0.003 } else { 0.00002 };
        let x1: Vec<Vec3> = x0
            .iter()
            .map(|p| {
                let squeeze = if p.y > 0.05 && step % 40 < 20 { 0.99 } else { 0.995 };
                Vec3::new(p.x, p.y * squeeze, p.z) + noise * Vec3::new(r(), r(), r())
            })
            .collect();
        sc.watch_guard(&x0, &x1, &triangles, tolerance);
        let (watched_e, watched_v) = (sc.guarded().0.to_vec(), sc.guarded().1.to_vec());
        skipped += edge_pairs.len() + vertex_pairs.len() - watched_e.len() - watched_v.len();
        for &(e, f) in &edge_pairs {
            let (a, b) = (sc.edges[e as usize], sc.edges[f as usize]);
            let vs = [a[0], a[1], b[0], b[1]];
            if least(&x0, &x1, &vs, &|xs| edge_edge(xs, &a, &b).0) < tolerance {
                assert!(
                    watched_e.contains(&(e, f)),
                    "step {step}: edges {e}, {f} met unwatched"
                );
                met[0] += 1;
            }
        }
        for &(p, t) in &vertex_pairs {
            let tri = triangles[t as usize];
            let vs = [p, tri[0], tri[1], tri[2]];
            if least(&x0, &x1, &vs, &|xs| vertex_triangle(xs, p, &tri).0) < tolerance {
                assert!(
                    watched_v.contains(&(p, t)),
                    "step {step}: vertex {p}, triangle {t} met unwatched"
                );
                met[1] += 1;
            }
        }
        x0 = x1;
    }
    assert!(
        skipped > 0 && met[0] > 0 && met[1] > 0,
        "skipped {skipped}, met {met:?}"
    );
}

/// When the watch measures again by bounds, each pair's bound is at most its distance where
/// it measured, and the pairs it checks are exactly those an exact measure of every pair
/// there puts within the skin. The sheet waves and is squeezed, and now and then its
/// vertices jump each its own way. Fails with a bound that leaves out one pair of edge
/// ends or a triangle's first corner (each checked), and when every pair is measured
/// exactly (no bound below a distance: nothing decided by the bound).
#[test]
fn the_guard_measures_again_by_bounds_what_it_would_measure_exactly() {
    let (_, rest, triangles) = folded_sheet(12, 9);
    let (thickness, tolerance) = (0.004, 1e-6);
    let mut sc = SelfCollision::new(&triangles);
    sc.prepare(&rest, &triangles, thickness).expect("prepared");
    let (edge_pairs, vertex_pairs) = (sc.guard.pairs().0.to_vec(), sc.guard.pairs().1.to_vec());
    let skin = sc.guard.skin();
    let mut r = crate::testing::numbers(5);
    let mut x0 = rest.clone();
    let (mut measures, mut by_bound, mut within) = (0usize, 0usize, 0usize);
    for step in 0..400 {
        let t = f64::from(step) * 0.01;
        // Now and then the vertices jump each its own way (a corner towards a vertex).
        let noise = if step % 25 == 24 { 0.0008 } else { 0.00005 };
        let x1: Vec<Vec3> = x0
            .iter()
            .zip(&rest)
            .map(|(p, q)| {
                let wave = 0.02 * (40.0 * q.x + 3.0 * t).sin() * (1.0 - (-t).exp());
                let squeeze = 1.0 - 0.3 * (1.0 - (-0.5 * t).exp());
                let target = Vec3::new(q.x, q.y * squeeze, wave);
                p + 0.2 * (target - p) + noise * Vec3::new(r(), r(), r())
            })
            .collect();
        sc.watch_guard(&x0, &x1, &triangles, tolerance);
        let (close_e, close_v) = (sc.guarded().0.to_vec(), sc.guarded().1.to_vec());
        if let Some((base, apart)) = sc.guard.measure() {
            if base != x0.as_slice() {
                x0 = x1;
                continue;
            }
            measures += 1;
            let exact_e = edge_pairs
                .iter()
                .map(|&(e, f)| edge_edge(base, &sc.edges[e as usize], &sc.edges[f as usize]).0);
            let exact_v = vertex_pairs
                .iter()
                .map(|&(p, t)| vertex_triangle(base, p, &triangles[t as usize]).0);
            let pairs = edge_pairs
                .iter()
                .map(|&q| (q, true))
                .chain(vertex_pairs.iter().map(|&q| (q, false)));
            for (((q, is_edge), exact), &bound) in pairs.zip(exact_e.chain(exact_v)).zip(apart) {
                assert!(
                    bound <= exact,
                    "step {step}: pair {q:?} bound {bound} past its distance {exact}"
                );
                by_bound += usize::from(bound < exact);
                within += usize::from(exact < skin);
                let checked = if is_edge {
                    close_e.contains(&q)
                } else {
                    close_v.contains(&q)
                };
                assert_eq!(
                    checked,
                    exact < skin,
                    "step {step}: pair {q:?} at {exact} (skin {skin})"
                );
            }
        }
        x0 = x1;
    }
    assert!(
        measures > 5 && by_bound > 0 && within > 0,
        "measures {measures}, decided by bound {by_bound}, within the skin {within}"
    );
}

/// On a sheet large enough for the pool (its walk split into tasks and the near pairs into
/// chunks), the look finds the same pairs on two threads as on one.
#[test]
fn the_look_finds_the_same_pairs_on_two_threads() {
    let (x, rest, triangles) = folded_sheet(130, 125);
    assert!(
        x.len() >= crate::parallel::min_parallel(),
        "large enough for the pool"
    );
    let (thickness, reach) = (0.004, 0.008);
    let look = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        pool.install(|| {
            let mut sc = SelfCollision::new(&triangles);
            sc.look(&x, &rest, &triangles, reach, EXCLUDED * thickness)
                .expect("room");
            (sc.vertex_triangle, sc.edge_edge)
        })
    };
    let (vt1, ee1) = look(1);
    assert!(vt1.len() > 5000 && ee1.len() > 5000, "a fold has pairs");
    assert_eq!((vt1, ee1), look(2));
}

/// Two parallel squares 3 mm apart: pairs are found across them, none within one square,
/// and each vertex is pushed away from the other square.
#[test]
fn two_sheets_find_each_other_and_only_each_other() {
    let sq = |y: f64, o: u32| {
        let x = vec![
            Vec3::new(0.0, y, 0.0),
            Vec3::new(0.1, y, 0.0),
            Vec3::new(0.0, y, 0.1),
            Vec3::new(0.1, y, 0.1),
        ];
        (x, vec![[o, o + 2, o + 1], [o + 1, o + 2, o + 3]])
    };
    let (mut x, mut t) = sq(0.0, 0);
    let (x2, t2) = sq(0.003, 4);
    x.extend(x2);
    t.extend(t2);
    // At rest the sheets are far apart (so the pairs are not neighbours).
    let rest: Vec<Vec3> = x
        .iter()
        .enumerate()
        .map(|(i, p)| if i >= 4 { p + Vec3::new(0.0, 1.0, 0.0) } else { *p })
        .collect();
    let mut sc = SelfCollision::new(&t);
    let mut out = Vec::new();
    sc.contacts(&x, &rest, &t, 0.005, 0.0, &mut out).expect("room");
    assert!(!out.is_empty());
    for c in &out {
        let first_top = c.idx[0] >= 4;
        assert!(c.idx[1..].iter().all(|&i| (i >= 4) != first_top) || c.coef[1] >= 0.0);
        // The first element is pushed away from the other sheet.
        let away = if x[c.idx[0] as usize].y > 0.001 { 1.0 } else { -1.0 };
        assert!(c.dir.y * away > 0.99, "{c:?}");
        assert!((c.depth - 0.002).abs() < 1e-12);
    }
    // Apart, nothing.
    let far: Vec<Vec3> = rest.clone();
    sc.look_again();
    out.clear();
    sc.contacts(&far, &rest, &t, 0.005, 0.0, &mut out).expect("room");
    assert!(out.is_empty());
}

/// A large triangle in the plane y = 0 and, 4 mm over its face, vertex 3 of a small second
/// triangle (the triangles, the positions, the rest positions: the second triangle 5 m
/// away, so the pair is no neighbour).
fn vertex_over_a_triangle() -> (Vec<[u32; 3]>, Vec<Vec3>, Vec<Vec3>) {
    let t = vec![[0, 1, 2], [3, 4, 5]];
    let x = vec![
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.004, 0.0),
        Vec3::new(0.0, 0.5, 0.1),
        Vec3::new(0.1, 0.5, 0.0),
    ];
    let rest: Vec<Vec3> = x
        .iter()
        .map(|p| p + Vec3::new(0.0, 0.0, 5.0 * (p.y > 0.001) as u8 as f64))
        .collect();
    (t, x, rest)
}

/// A vertex pushed through a triangle keeps the side it came from.
#[test]
fn a_crossed_vertex_is_pushed_back() {
    let (t, mut x, rest) = vertex_over_a_triangle();
    let mut sc = SelfCollision::new(&t);
    let mut out = Vec::new();
    sc.contacts(&x, &rest, &t, 0.005, 0.0, &mut out).expect("room");
    let up = out.iter().find(|c| c.idx[0] == 3).unwrap();
    assert!(up.dir.y > 0.99);
    // Through the triangle by 1 mm (less than the skin: no new look).
    x[3].y = -0.001;
    out.clear();
    sc.contacts(&x, &rest, &t, 0.005, 0.0, &mut out).expect("room");
    let up = out.iter().find(|c| c.idx[0] == 3).unwrap();
    assert!(up.dir.y > 0.99 && (up.depth - 0.006).abs() < 1e-12, "{up:?}");
}

/// A vertex driven through a triangle past the thickness (but not past the reach) is still
/// known to have crossed and is pushed back with the largest depth; once past the reach it
/// is taken to be on the other side for good (a triangle that turned over).
#[test]
fn a_vertex_through_past_the_thickness_is_pushed_back() {
    let (t, mut x, rest) = vertex_over_a_triangle();
    let mut sc = SelfCollision::new(&t);
    let mut out = Vec::new();
    let h = 0.005;
    sc.contacts(&x, &rest, &t, h, 0.0, &mut out).expect("room");
    assert!(out.iter().any(|c| c.idx[0] == 3));
    // Through by 1.5 thicknesses, in steps of less than the step limit's two vertices.
    for y in [0.0015, -0.001, -0.004, -0.0075] {
        x[3].y = y;
        out.clear();
        sc.contacts(&x, &rest, &t, h, 0.0, &mut out).expect("room");
    }
    let up = out.iter().find(|c| c.idx[0] == 3).expect("still in contact");
    assert!(up.dir.y > 0.99 && (up.depth - 2.0 * h).abs() < 1e-12, "{up:?}");
    // A fresh look here keeps the pair in the list (within the reach); then past the reach
    // (two thicknesses below) and back within it, too little for another look: the pair
    // learnt the new side as its own.
    sc.look_again();
    sc.contacts(&x, &rest, &t, h, 0.0, &mut out).expect("room");
    assert!(sc.pairs().0.iter().any(|q| q.0 == 3 && q.2 == 1));
    for y in [-0.0105, -0.0075] {
        x[3].y = y;
        out.clear();
        sc.contacts(&x, &rest, &t, h, 0.0, &mut out).expect("room");
    }
    assert!(out.iter().all(|c| c.idx[0] != 3), "{out:?}");
    assert!(sc.pairs().0.iter().any(|q| q.0 == 3 && q.2 == -1));
}

/// The lists a thickness needs grow about as (thickness / spacing)^2: on a 61 x 61 grid of
/// 1 cm (the figures of docs/collisions.md, printed here) 4 mm, 1 cm and 2 cm are taken
/// with more entries each, and 6 cm, past [`PAIRS_PER_VERTEX`], is refused with a message
/// that names a thickness the mesh takes; the refusal changes nothing.
#[test]
fn the_lists_grow_with_the_thickness_and_a_thickness_past_the_room_is_refused() {
    let (_, rest, triangles) = folded_sheet(61, 61);
    let mut per_vertex = Vec::new();
    for thickness in [0.004, 0.01, 0.02] {
        let mut sc = SelfCollision::new(&triangles);
        sc.prepare(&rest, &triangles, thickness)
            .expect("a thickness the grid takes");
        let listed = sc.excluded.len() + sc.near.vertex_triangle.len() + sc.near.edge_edge.len();
        per_vertex.push(listed as f64 / rest.len() as f64);
    }
    println!("pairs a vertex at 4 mm, 1 cm, 2 cm: {per_vertex:.0?}");
    assert!(per_vertex.windows(2).all(|w| w[1] > 2.0 * w[0]), "{per_vertex:?}");
    assert!(per_vertex[2] < PAIRS_PER_VERTEX as f64);
    let mut sc = SelfCollision::new(&triangles);
    sc.prepare(&rest, &triangles, 0.004).expect("4 mm");
    let e = sc.prepare(&rest, &triangles, 0.06).unwrap_err();
    assert_eq!(e.kind, crate::ErrorKind::InvalidArgument);
    assert!(e.message.contains("at most about"), "{}", e.message);
    assert!(
        sc.prepared(rest.len(), triangles.len(), EXCLUDED * 0.004),
        "a refusal kept the lists"
    );
}
