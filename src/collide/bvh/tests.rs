use super::*;

#[test]
fn the_nodes_fit_their_room() {
    // `try_build` reserves 4n / LEAF + 1 nodes: the tree never needs more (a push past it
    // would reallocate, infallibly). Boxes on a line and in a cloud, 0 to 3000 of them.
    for n in (0..200).chain([257, 1000, 1023, 1024, 1025, 3000]) {
        for cloud in [false, true] {
            let boxes: Vec<Aabb> = (0..n)
                .map(|k| {
                    let t = k as f64;
                    let c = if cloud {
                        Vec3::new((t * 0.618).fract(), (t * 0.414).fract(), (t * 0.732).fract())
                    } else {
                        Vec3::new(t, 0.0, 0.0)
                    };
                    Aabb { min: c, max: c }
                })
                .collect();
            let bvh = Bvh::try_build(&boxes).expect("room");
            assert!(
                bvh.nodes.len() <= 4 * n / LEAF + 1,
                "{n} boxes: {} nodes",
                bvh.nodes.len()
            );
            let room = if n == 0 { 0 } else { 4 * n / LEAF + 1 };
            assert_eq!(bvh.nodes.capacity(), room, "{n} boxes: no growth");
            assert_eq!(bvh.len(), n);
        }
    }
}

#[test]
fn a_tree_split_in_parallel_is_the_tree_split_on_one_thread() {
    // Past the size a node's halves go to two threads at, several levels deep; and a
    // sheet's boxes, many of them with equal centres along an axis.
    let sheet: Vec<Aabb> = (0..300 * 200)
        .map(|k| {
            let c = Vec3::new((k % 300) as f64, (k / 300) as f64, 0.0) * 0.01;
            Aabb { min: c, max: c }.inflated(0.004)
        })
        .collect();
    for b in [boxes(100_000), sheet, boxes(3)] {
        let (one, two) = (Bvh::build(&b), Bvh::build_on(&b, true));
        assert_eq!(one.order, two.order);
        assert_eq!(one.boxes, two.boxes);
        assert_eq!(one.nodes.len(), two.nodes.len());
        for (p, q) in one.nodes.iter().zip(&two.nodes) {
            assert_eq!((p.bounds, p.first, p.count), (q.bounds, q.first, q.count));
        }
    }
}

fn boxes(n: usize) -> Vec<Aabb> {
    let mut seed = 3u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
            let e = Vec3::new(rnd(), rnd(), rnd()) * 0.5;
            Aabb {
                min: c - e,
                max: c + e,
            }
        })
        .collect()
}

/// The gap a query returns is never more than the separation of any box it did not
/// report, and is often that separation's minimum (when the walk reaches the nearest
/// one's leaf); it reports what `overlapping` does.
#[test]
fn a_query_tells_how_far_the_boxes_it_missed_are() {
    let b = boxes(700);
    let bvh = Bvh::build(&b);
    let mut r = crate::testing::numbers(5);
    let mut exact = 0;
    for k in 0..300 {
        let c = Vec3::new(r(), r(), r()) * 14.0 - Vec3::repeat(2.0);
        let q = Aabb { min: c, max: c }.inflated(0.3 * r());
        let (mut found, mut apart) = (Vec::new(), Vec::new());
        let gap = bvh.overlapping_apart(&q, |i| found.push(i));
        bvh.overlapping(&q, |i| apart.push(i));
        assert_eq!(found, apart, "query {k}");
        let missed = (0..b.len())
            .filter(|i| !found.contains(&(*i as u32)))
            .map(|i| b[i].separation(&q))
            .fold(f64::INFINITY, f64::min);
        assert!(
            gap <= missed,
            "query {k}: gap {gap} past the nearest missed box's {missed}"
        );
        assert!(gap > 0.0 || missed == 0.0 || found.len() == b.len(), "query {k}");
        exact += usize::from(gap == missed);
        // No box reported is apart, and none missed overlaps.
        assert!(found.iter().all(|&i| b[i as usize].overlaps(&q)));
        assert!(missed > 0.0);
    }
    // Many queries reach the leaf of the nearest box they miss (145 of 300 when written):
    // the bound is not merely safe but often tight.
    assert!(exact > 100, "{exact} of 300 exact");
    assert_eq!(
        Bvh::build(&[]).overlapping_apart(&boxes(1)[0], |_| ()),
        f64::INFINITY
    );
    // Separation: along the axis furthest apart, 0 when overlapping.
    let unit = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(1.0),
    };
    let moved = |d: Vec3| Aabb {
        min: unit.min + d,
        max: unit.max + d,
    };
    assert_eq!(unit.separation(&moved(Vec3::new(3.0, 1.5, -0.5))), 2.0);
    assert_eq!(unit.separation(&moved(Vec3::new(-1.25, 0.0, 0.0))), 0.25);
    assert_eq!(unit.separation(&moved(Vec3::new(0.5, 0.5, 0.5))), 0.0);
}

/// A box grown by differences in one call is the box grown by each, a NaN passed over.
#[test]
fn growing_by_differences_is_growing_point_by_point() {
    let mut r = crate::testing::numbers(11);
    // Fewer points than a block of eight, whole blocks, and blocks with a tail; the
    // extremes in the blocks' lanes and in the tail.
    for n in [1usize, 7, 8, 37, 200] {
        let a: Vec<Vec3> = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
        let base: Vec<Vec3> = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
        let mut start = Aabb::empty();
        start.grow(&Vec3::new(0.1, -0.2, 0.3));
        let each = |a: &[Vec3]| {
            let mut each = start;
            for (p, o) in a.iter().zip(&base) {
                each.grow(&(p - o));
            }
            each
        };
        assert_eq!(start.grown_by_differences(&a, &base), each(&a), "{n} points");
        // A NaN is passed over by both, in a block and in the tail.
        let mut with_nan = a.clone();
        with_nan[n / 3].y = f64::NAN;
        with_nan[n - 1].x = f64::NAN;
        assert_eq!(
            start.grown_by_differences(&with_nan, &base),
            each(&with_nan),
            "{n} points"
        );
    }
    assert_eq!(Aabb::empty().grown_by_differences(&[], &[]), Aabb::empty());
}

/// The tree walked against itself finds every overlapping pair exactly once, whatever
/// the number of tasks it is split into, before and after a refit; and, with other boxes,
/// every overlapping pair whose other boxes are apart.
#[test]
fn self_overlaps_match_brute_force() {
    for n in [0usize, 1, 3, 5, 700] {
        let mut b = boxes(n);
        let mut bvh = Bvh::build(&b);
        for round in 0..2 {
            let mut brute = Vec::new();
            for i in 0..n as u32 {
                for j in i + 1..n as u32 {
                    if b[i as usize].overlaps(&b[j as usize]) {
                        brute.push((i, j));
                    }
                }
            }
            assert!(
                n < 700 || brute.len() > 100,
                "the test meets overlaps: {}",
                brute.len()
            );
            // Other boxes: the first ones shifted, so some overlapping pairs' are apart
            // and some apart pairs' overlap.
            let other: Vec<Aabb> = b
                .iter()
                .enumerate()
                .map(|(k, x)| {
                    let shift = Vec3::new(0.0, (k % 3) as f64 * 0.4, 0.0);
                    Aabb {
                        min: x.min + shift,
                        max: x.max + shift,
                    }
                })
                .collect();
            let apart: Vec<(u32, u32)> = brute
                .iter()
                .copied()
                .filter(|&(i, j)| !other[i as usize].overlaps(&other[j as usize]))
                .collect();
            assert!(n < 700 || (apart.len() > 20 && apart.len() < brute.len()));
            let in_order = bvh.in_order(&other);
            for tasks in [1, 7, 64] {
                let (mut found, mut found_apart) = (Vec::new(), Vec::new());
                let (mut list, mut spare, mut stack) = (Vec::new(), Vec::new(), Vec::new());
                bvh.self_tasks_into(tasks, &mut list, &mut spare);
                assert_eq!(list, bvh.self_tasks(tasks));
                for &task in &list {
                    bvh.self_overlapping(task, |i, j| found.push((i.min(j), i.max(j))));
                    bvh.self_overlapping_apart(task, &in_order, &mut stack, |i, j| {
                        found_apart.push((i.min(j), i.max(j)))
                    });
                }
                found.sort_unstable();
                found_apart.sort_unstable();
                assert_eq!(found, brute, "{n} boxes, round {round}, {tasks} tasks");
                assert_eq!(found_apart, apart, "{n} boxes, round {round}, {tasks} tasks");
            }
            for x in &mut b {
                *x = Aabb {
                    min: x.min * 1.1 + Vec3::new(0.3, 0.0, 0.0),
                    max: x.max * 1.1 + Vec3::new(0.3, 0.0, 0.0),
                };
            }
            bvh.refit(&b);
        }
    }
}

/// Overlap queries find exactly what a brute-force scan finds, before and after a refit.
#[test]
fn overlap_queries_match_brute_force() {
    let mut b = boxes(1000);
    let mut bvh = Bvh::build(&b);
    for round in 0..2 {
        for q in boxes(50) {
            let mut found = Vec::new();
            bvh.overlapping(&q, |i| found.push(i));
            found.sort_unstable();
            let brute: Vec<u32> = (0..b.len() as u32)
                .filter(|&i| b[i as usize].overlaps(&q))
                .collect();
            assert_eq!(found, brute, "round {round}");
        }
        for x in &mut b {
            *x = Aabb {
                min: x.min * 0.9,
                max: x.max * 0.9 + Vec3::repeat(0.1),
            };
        }
        bvh.refit(&b);
    }
}

/// The nearest item (here: nearest box centre) matches a scan.
#[test]
fn nearest_matches_brute_force() {
    let b = boxes(500);
    let bvh = Bvh::build(&b);
    let d2 = |p: &Vec3, i: u32| (b[i as usize].centre() - p).norm_squared();
    for q in boxes(40) {
        let p = q.centre() + Vec3::new(0.013, 0.021, -0.017);
        let (i, d) = bvh.nearest(&p, f64::INFINITY, |i| d2(&p, i)).unwrap();
        let best = (0..b.len() as u32)
            .map(|i| d2(&p, i))
            .fold(f64::INFINITY, f64::min);
        assert_eq!(d, best);
        assert_eq!(d2(&p, i), best);
        assert!(bvh.nearest(&p, best * 0.99, |i| d2(&p, i)).is_none());
    }
    assert!(Bvh::build(&[]).nearest(&Vec3::zeros(), 1.0, |_| 0.0).is_none());
}
