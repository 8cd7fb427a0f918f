//! What the cloth's rest shape says about self-collision's pairs, worked out once:
//!
//! - [`Exclusions`]: pairs nearer than a radius at rest (neighbours of a fine mesh), never
//!   tested;
//! - [`NearPairs`]: the pairs of triangles whose rest boxes lie within that radius of each
//!   other, and what is left of their vertex-triangle and edge-edge pairs once the excluded
//!   ones and the ones sharing a vertex are taken out. A look tests these directly and
//!   leaves such triangle pairs out of its tree walk: the walk meets mostly neighbours, and
//!   this way it drops each in one box test.

use super::bvh::{Aabb, Bvh};
use super::ownership::Ownership;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, AtomicU8, AtomicUsize, Ordering::Relaxed};

use super::pair::{edge_edge, vertex_triangle};
use super::room::{make_room, Full, Room};
use crate::math::Vec3;

/// The triangles' rest boxes grown by half the exclusion radius, and their tree: two triangles
/// are rest-near when their boxes overlap, and a vertex is within the radius of a triangle's
/// box when its own point grown by half the radius overlaps it. Built once for both lists.
pub(super) struct RestTree {
    boxes: Vec<Aabb>,
    bvh: Bvh,
    half: f64,
}

impl RestTree {
    /// The tree split on rayon's current pool when `parallel` (the same tree either way).
    pub(super) fn new(rest: &[Vec3], triangles: &[[u32; 3]], radius: f64, parallel: bool) -> RestTree {
        let half = 0.5 * radius;
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| Aabb::of(t.iter().map(|&i| &rest[i as usize])).inflated(half))
            .collect();
        let bvh = Bvh::build_on(&boxes, parallel);
        RestTree { boxes, bvh, half }
    }
}

/// Each vertex's (edge's) excluded triangles (edges), sorted, as compressed rows.
#[derive(Clone, Debug, Default)]
pub(super) struct Exclusions {
    pub(super) radius: f64,
    /// A bound under the least rest distance of a pair left in, at least the radius, at most
    /// the cap it was looked for to ([`Exclusions::with_nearest`]). On a grid of spacing `s`
    /// with every vertex within `s` excluded it is `s` (a vertex and a triangle whose nearest
    /// corner is a neighbour, and their boxes, are `s` apart): where the proof of
    /// `unfolded.rs` starts, not the exclusion radius under it.
    pub(super) nearest: f64,
    pub(super) vt_start: Vec<u32>,
    vt: Vec<u32>,
    ee_start: Vec<u32>,
    ee: Vec<u32>,
}

impl Exclusions {
    /// The pairs nearer than `radius` at the rest positions `rest` (`tree` the triangles' at
    /// that radius); `None` when `room` ran out (it says why). The searches run on rayon's
    /// current pool when `parallel`; the lists, and whether the room suffices, are the same
    /// either way.
    #[cfg(test)]
    pub(super) fn new(
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
        radius: f64,
        tree: &RestTree,
        room: &mut Room,
        parallel: bool,
    ) -> Option<Exclusions> {
        Self::with_nearest(rest, triangles, edges, radius, radius, tree, room, parallel)
    }

    /// [`Exclusions::new`], and a bound under the least rest distance of the pairs left in
    /// (a vertex and a triangle not its own, two edges sharing no vertex, at least `radius`
    /// apart), found by the same searches grown to `cap` ([`Exclusions::nearest`]): the least,
    /// under `cap`, of their exact distances and, for pairs whose boxes are the radius apart,
    /// of their boxes' distances (an exact distance for each pair a spacing apart was 2.7
    /// times the searches' time at a million particles).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn with_nearest(
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
        radius: f64,
        cap: f64,
        tree: &RestTree,
        room: &mut Room,
        parallel: bool,
    ) -> Option<Exclusions> {
        let cap = cap.max(radius);
        // The least tested distance seen, as the bits of a positive f64 (whose order is the
        // numbers'): the same whatever order the tasks run in.
        let nearest = AtomicU64::new(cap.to_bits());
        // Once a row (each row's least; most rows find nothing nearer than what is known, and
        // read it without writing).
        let seen = |d: f64| {
            if d < f64::from_bits(nearest.load(Relaxed)) {
                nearest.fetch_min(d.to_bits(), Relaxed);
            }
        };
        // Whether a pair whose boxes are `gap` apart is excluded (its `exact` distance under the
        // radius, measured only when the boxes are nearer than that); a pair left in lowers
        // `least` to its boxes' distance or its exact one, both at most its distance.
        let excludes = |gap: f64, exact: &dyn Fn() -> f64, least: &mut f64| {
            let d = if gap >= radius { gap } else { exact() };
            if d >= radius {
                *least = least.min(d);
            }
            d < radius
        };
        let grow = (cap - radius) + tree.half;
        let (vt_start, vt) = rows(rest.len(), parallel, room, |p, push| {
            let q = Aabb {
                min: rest[p as usize],
                max: rest[p as usize],
            }
            .inflated(grow);
            let mut least = cap;
            let point = &rest[p as usize];
            tree.bvh.overlapping(&q, |t| {
                let tri = &triangles[t as usize];
                if tri.contains(&p) {
                    push(t);
                    return;
                }
                let gap = Aabb::of(tri.iter().map(|&i| &rest[i as usize]))
                    .distance2(point)
                    .sqrt();
                if excludes(gap, &|| vertex_triangle(rest, p, tri).0, &mut least) {
                    push(t);
                }
            });
            seen(least);
        })?;
        let boxes: Vec<Aabb> = edges
            .iter()
            .map(|e| Aabb::of(e.iter().map(|&i| &rest[i as usize])).inflated(0.5 * radius))
            .collect();
        let bvh = Bvh::build_on(&boxes, parallel);
        let (ee_start, ee) = rows(edges.len(), parallel, room, |e, push| {
            let edge = &edges[e as usize];
            let mut least = cap;
            bvh.overlapping(&boxes[e as usize].inflated(cap - radius), |f| {
                let other = &edges[f as usize];
                if f <= e {
                    return;
                }
                if edge.iter().any(|v| other.contains(v)) {
                    push(f);
                    return;
                }
                let plain = |e: &[u32; 2]| Aabb::of(e.iter().map(|&i| &rest[i as usize]));
                let gap = plain(edge).gap2(&plain(other)).sqrt();
                if excludes(gap, &|| edge_edge(rest, edge, other).0, &mut least) {
                    push(f);
                }
            });
            seen(least);
        })?;
        Some(Exclusions {
            nearest: f64::from_bits(nearest.load(Relaxed)),
            radius,
            vt_start,
            vt,
            ee_start,
            ee,
        })
    }

    /// Entries in the rows (excluded vertex-triangle and edge-edge pairs).
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.vt.len() + self.ee.len()
    }

    /// The excluded triangles of every vertex as compressed rows (starts, entries).
    pub(super) fn vertex_rows(&self) -> (&[u32], &[u32]) {
        (&self.vt_start, &self.vt)
    }

    pub(super) fn vertex_excludes(&self, p: u32, t: u32) -> bool {
        let (a, b) = (
            self.vt_start[p as usize] as usize,
            self.vt_start[p as usize + 1] as usize,
        );
        self.vt[a..b].binary_search(&t).is_ok()
    }

    /// Every excluded edge pair `(e, f)`, e < f (those sharing a vertex included), by `e` and
    /// then `f` ascending.
    pub(super) fn edge_pairs(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        (0..self.ee_start.len().saturating_sub(1)).flat_map(move |e| {
            self.ee[self.ee_start[e] as usize..self.ee_start[e + 1] as usize]
                .iter()
                .map(move |&f| (e as u32, f))
        })
    }

    pub(super) fn edge_excludes(&self, e: u32, f: u32) -> bool {
        let (a, b) = (
            self.ee_start[e as usize] as usize,
            self.ee_start[e as usize + 1] as usize,
        );
        self.ee[a..b].binary_search(&f).is_ok()
    }
}

/// Items per task of [`rows`]: fixed, so the rows never depend on the thread count.
const ROWS_PER_TASK: usize = 4096;

/// Why a task of [`rows`] stopped early.
const STOPPED_ENTRIES: u8 = 1;
const STOPPED_MEMORY: u8 = 2;

/// Compressed rows (starts, entries) of items `0..count`: item `i`'s entries are what
/// `row(i, push)` pushes, sorted. Tasks of [`ROWS_PER_TASK`] items run in parallel when
/// `parallel`; their rows are joined in order, so the result never depends on the split. Every
/// row is counted against `room` exactly once, whole, so whether the room suffices does not
/// depend on the order the tasks run in (a sum of some rows past it means the sum of all is);
/// every list grows fallibly. `None` (with `room.full` saying why) when the room or memory ran
/// out.
fn rows<F>(count: usize, parallel: bool, room: &mut Room, row: F) -> Option<(Vec<u32>, Vec<u32>)>
where
    F: Fn(u32, &mut dyn FnMut(u32)) + Sync,
{
    if room.full.is_some() {
        return None;
    }
    let left = AtomicUsize::new(room.left());
    let stopped = AtomicU8::new(0);
    // One task: its rows' lengths and entries.
    let task = |k: usize| -> Option<(Vec<u32>, Vec<u32>)> {
        let items = k * ROWS_PER_TASK..((k + 1) * ROWS_PER_TASK).min(count);
        let (mut lengths, mut entries) = (Vec::new(), Vec::<u32>::new());
        if lengths.try_reserve_exact(items.len()).is_err() {
            stopped.store(STOPPED_MEMORY, Relaxed);
            return None;
        }
        for i in items {
            if stopped.load(Relaxed) != 0 {
                return None;
            }
            let first = entries.len();
            let mut refused = false;
            row(i as u32, &mut |t| {
                if make_room(&mut entries, 1) {
                    entries.push(t);
                } else {
                    refused = true;
                }
            });
            let len = entries.len() - first;
            if refused {
                stopped.store(STOPPED_MEMORY, Relaxed);
                return None;
            }
            if left
                .fetch_update(Relaxed, Relaxed, |l| l.checked_sub(len))
                .is_err()
            {
                stopped.store(STOPPED_ENTRIES, Relaxed);
                return None;
            }
            entries[first..].sort_unstable();
            lengths.push(len as u32);
        }
        Some((lengths, entries))
    };
    let tasks = count.div_ceil(ROWS_PER_TASK);
    let done: Vec<Option<(Vec<u32>, Vec<u32>)>> = if parallel {
        (0..tasks).into_par_iter().map(task).collect()
    } else {
        (0..tasks).map(task).collect()
    };
    match stopped.load(Relaxed) {
        STOPPED_ENTRIES => room.full = Some(Full::Entries),
        STOPPED_MEMORY => room.full = Some(Full::Memory),
        _ => {}
    }
    let total: usize = done.iter().flatten().map(|(_, e)| e.len()).sum();
    let (mut starts, mut entries) = (Vec::new(), Vec::new());
    if room.full.is_none()
        && (starts.try_reserve_exact(count + 1).is_err() || entries.try_reserve_exact(total).is_err())
    {
        room.full = Some(Full::Memory);
    }
    if room.full.is_some() {
        return None;
    }
    room.spend(total);
    starts.push(0u32);
    for (lengths, part) in done.into_iter().flatten() {
        for len in lengths {
            let end = starts.last().copied().unwrap_or(0) + len;
            starts.push(end);
        }
        entries.extend_from_slice(&part);
    }
    Some((starts, entries))
}

/// The rest-near triangle pairs' vertex-triangle and edge-edge pairs that are neither excluded
/// nor share a vertex, with the triangles' rest boxes that tell rest-near pairs.
#[derive(Clone, Debug, Default)]
pub(super) struct NearPairs {
    /// The triangles' rest boxes grown by half the radius: two triangles are rest-near when
    /// theirs overlap.
    rest_boxes: Vec<Aabb>,
    /// `(vertex, triangle)`, the vertex owned by a triangle rest-near the other.
    pub(super) vertex_triangle: Vec<(u32, u32)>,
    /// `(e, f)`, e < f, owned by two rest-near triangles.
    pub(super) edge_edge: Vec<(u32, u32)>,
    /// The furthest apart at rest any two points of a listed pair are (0 with none).
    pub(super) max_span: f64,
}

impl NearPairs {
    /// The near pairs of the cloth at rest positions `rest` for the exclusions `excluded`
    /// (`tree` the triangles' at their radius, which tells rest-near triangles; its boxes are
    /// kept); `None` when `room` ran out. The tree's walk runs in tasks on rayon's current pool
    /// when `parallel`; the lists, and whether the room suffices, are the same either way.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
        owners: &Ownership,
        excluded: &Exclusions,
        tree: RestTree,
        room: &mut Room,
        parallel: bool,
    ) -> Option<NearPairs> {
        let RestTree {
            boxes: rest_boxes,
            bvh,
            ..
        } = tree;
        if room.full.is_some() {
            return None;
        }
        // As `rows`: tasks of the tree's walk, each pair counted against the room exactly
        // once, the lists joined and sorted (so neither depends on the split).
        let left = AtomicUsize::new(room.left());
        let stopped = AtomicU8::new(0);
        type Lists = (Vec<(u32, u32)>, Vec<(u32, u32)>);
        let task = |&task: &(u32, u32)| -> Option<Lists> {
            let (mut vt, mut ee) = (Vec::new(), Vec::new());
            bvh.self_overlapping(task, |i, j| {
                if stopped.load(Relaxed) != 0 {
                    return;
                }
                // A triangle pair yields at most 6 vertex-triangle and 9 edge-edge pairs.
                if !make_room(&mut vt, 6) || !make_room(&mut ee, 9) {
                    stopped.store(STOPPED_MEMORY, Relaxed);
                    return;
                }
                let before = vt.len() + ee.len();
                owners.pairs_of(
                    i,
                    j,
                    |p, t| {
                        if !triangles[t as usize].contains(&p) && !excluded.vertex_excludes(p, t) {
                            vt.push((p, t));
                        }
                    },
                    |e, f| {
                        let (edge, other) = (&edges[e as usize], &edges[f as usize]);
                        if !edge.iter().any(|v| other.contains(v)) && !excluded.edge_excludes(e, f) {
                            ee.push((e, f));
                        }
                    },
                );
                let added = vt.len() + ee.len() - before;
                if left
                    .fetch_update(Relaxed, Relaxed, |l| l.checked_sub(added))
                    .is_err()
                {
                    stopped.store(STOPPED_ENTRIES, Relaxed);
                }
            });
            (stopped.load(Relaxed) == 0).then_some((vt, ee))
        };
        let tasks = bvh.self_tasks(if parallel { 64 } else { 1 });
        let done: Vec<Option<Lists>> = if parallel {
            tasks.par_iter().map(task).collect()
        } else {
            tasks.iter().map(task).collect()
        };
        match stopped.load(Relaxed) {
            STOPPED_ENTRIES => room.full = Some(Full::Entries),
            STOPPED_MEMORY => room.full = Some(Full::Memory),
            _ => {}
        }
        let (mut vt, mut ee) = (Vec::new(), Vec::new());
        let count = |k: fn(&Lists) -> usize| done.iter().flatten().map(k).sum::<usize>();
        if room.full.is_none()
            && (vt.try_reserve_exact(count(|l| l.0.len())).is_err()
                || ee.try_reserve_exact(count(|l| l.1.len())).is_err())
        {
            room.full = Some(Full::Memory);
        }
        if room.full.is_some() {
            return None;
        }
        for (v, e) in done.into_iter().flatten() {
            vt.extend_from_slice(&v);
            ee.extend_from_slice(&e);
        }
        room.spend(vt.len() + ee.len());
        // In order, so that a vertex's (an edge's) pairs come together.
        if parallel {
            vt.par_sort_unstable();
            ee.par_sort_unstable();
        } else {
            vt.sort_unstable();
            ee.sort_unstable();
        }
        // The furthest points of a vertex and a triangle are corners, of two edges ends.
        let far = |p: u32, q: u32| (rest[p as usize] - rest[q as usize]).norm();
        let max_span = vt
            .iter()
            .map(|&(p, t)| {
                triangles[t as usize]
                    .iter()
                    .map(|&q| far(p, q))
                    .fold(0.0, f64::max)
            })
            .chain(ee.iter().map(|&(e, f)| {
                let (a, b) = (edges[e as usize], edges[f as usize]);
                a.iter()
                    .flat_map(|&p| b.iter().map(move |&q| (p, q)))
                    .map(|(p, q)| far(p, q))
                    .fold(0.0, f64::max)
            }))
            .fold(0.0, f64::max);
        Some(NearPairs {
            rest_boxes,
            vertex_triangle: vt,
            edge_edge: ee,
            max_span,
        })
    }

    /// The triangles' rest boxes (grown by half the radius): triangles are rest-near (their
    /// pairs are listed here) when theirs overlap. Those that are not are more than the
    /// radius apart at rest in some axis, so none of their vertex and triangle, or edge and
    /// edge, is excluded or shares a vertex.
    pub(super) fn rest_boxes(&self) -> &[Aabb] {
        &self.rest_boxes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy 75 x 71 grid of 1 cm (5 325 vertices: two tasks of rows for the vertices, four
    /// for the edges), its triangles and edges.
    fn wavy_grid() -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<[u32; 2]>) {
        let (w, h) = (75u32, 71u32);
        let rest: Vec<Vec3> = (0..h)
            .flat_map(|j| {
                (0..w).map(move |i| {
                    let (x, y) = (0.01 * i as f64, 0.01 * j as f64);
                    Vec3::new(x, y, 0.004 * (7.0 * x).sin() * (5.0 * y).cos())
                })
            })
            .collect();
        let mut triangles = Vec::new();
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let (a, b, c, d) = (j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i);
                // Diagonals alternating, as a DCC's triangulation may.
                if (i + j) % 3 == 0 {
                    triangles.extend([[a, b, d], [b, c, d]]);
                } else {
                    triangles.extend([[a, b, c], [a, c, d]]);
                }
            }
        }
        let edges = super::super::geometry::edges_of(&triangles);
        (rest, triangles, edges)
    }

    #[test]
    fn the_lists_made_in_parallel_are_the_lists_made_on_one_thread_and_every_near_pair() {
        let (rest, triangles, edges) = wavy_grid();
        let radius = 0.0088;
        let owners = Ownership::new(rest.len(), &triangles, &edges);
        let make = |parallel: bool, entries: usize| {
            let mut room = Room::new(entries);
            let tree = RestTree::new(&rest, &triangles, radius, parallel);
            let lists = Exclusions::new(&rest, &triangles, &edges, radius, &tree, &mut room, parallel)
                .and_then(|ex| {
                    NearPairs::new(&rest, &triangles, &edges, &owners, &ex, tree, &mut room, parallel)
                        .map(|near| (ex, near))
                });
            (lists, room.full, room.left())
        };
        let (Some((one, near_one)), None, left) = make(false, usize::MAX) else {
            panic!("room for the test mesh on one thread");
        };
        let (Some((many, near_many)), None, left_many) = make(true, usize::MAX) else {
            panic!("room for the test mesh in parallel");
        };
        assert_eq!(left, left_many, "the same entries counted");
        assert_eq!(
            (&one.vt_start, &one.vt, &one.ee_start, &one.ee),
            (&many.vt_start, &many.vt, &many.ee_start, &many.ee)
        );
        assert_eq!(near_one.vertex_triangle, near_many.vertex_triangle);
        assert_eq!(near_one.edge_edge, near_many.edge_edge);
        assert!(!near_one.vertex_triangle.is_empty() && !near_one.edge_edge.is_empty());
        // Every vertex-triangle pair nearer than the radius at rest is excluded, and no other:
        // against a test of every pair (for a tenth of the vertices, spread over the tasks).
        for p in (0..rest.len() as u32).step_by(10) {
            for (t, tri) in triangles.iter().enumerate() {
                let near = tri.contains(&p) || vertex_triangle(&rest, p, tri).0 < radius;
                assert_eq!(one.vertex_excludes(p, t as u32), near, "vertex {p}, triangle {t}");
            }
        }
        for e in (0..edges.len()).step_by(40) {
            for f in e + 1..edges.len() {
                let (a, b) = (&edges[e], &edges[f]);
                let near = a.iter().any(|v| b.contains(v)) || edge_edge(&rest, a, b).0 < radius;
                assert_eq!(one.edge_excludes(e as u32, f as u32), near, "edges {e}, {f}");
            }
        }
        // A room one entry short is refused on one thread and in parallel alike, as too many
        // entries; one of exactly the entries needed is not.
        let needed = usize::MAX - left;
        for parallel in [false, true] {
            let (lists, full, _) = make(parallel, needed - 1);
            assert!(
                lists.is_none() && full == Some(Full::Entries),
                "parallel {parallel}"
            );
            let (lists, full, left) = make(parallel, needed);
            assert!(
                lists.is_some() && full.is_none() && left == 0,
                "parallel {parallel}"
            );
        }
    }
    /// The nearest tested pair at rest: on a flat 1 cm grid at the exclusion of 4 mm (8.8 mm)
    /// it is 10 mm, a vertex and a triangle whose nearest corner is a neighbour (the diagonals
    /// across a cell, 7.1 mm, are excluded); the same on one thread and in parallel, and no
    /// more than a test of every pair finds on the wavy grid with mixed diagonals; `cap` when
    /// no tested pair is nearer. Looking for it changes no list.
    #[test]
    fn the_nearest_tested_pair_is_found() {
        let flat = crate::testing::flat_grid(21, 17, 0.01);
        let flat_edges = super::super::geometry::edges_of(&flat.1);
        let radius = 0.0088;
        let nearest =
            |rest: &[Vec3], triangles: &[[u32; 3]], edges: &[[u32; 2]], cap: f64, parallel: bool| {
                let tree = RestTree::new(rest, triangles, radius, parallel);
                let mut room = Room::new(usize::MAX);
                let with =
                    Exclusions::with_nearest(rest, triangles, edges, radius, cap, &tree, &mut room, parallel)
                        .expect("room");
                // Looking further changes no list.
                let tree = RestTree::new(rest, triangles, radius, parallel);
                let plain = Exclusions::new(rest, triangles, edges, radius, &tree, &mut room, parallel)
                    .expect("room");
                assert_eq!(
                    (&with.vt_start, &with.vt, &with.ee_start, &with.ee),
                    (&plain.vt_start, &plain.vt, &plain.ee_start, &plain.ee)
                );
                assert_eq!(plain.nearest, radius);
                with.nearest
            };
        let d = nearest(&flat.0, &flat.1, &flat_edges, 1.25 * radius, false);
        assert!((d - 0.01).abs() < 1e-12, "{d}");
        assert_eq!(
            nearest(&flat.0, &flat.1, &flat_edges, 0.0095, false),
            0.0095,
            "nothing tested under the cap"
        );

        let (rest, triangles, edges) = wavy_grid();
        let cap = 1.25 * radius;
        let one = nearest(&rest, &triangles, &edges, cap, false);
        let many = nearest(&rest, &triangles, &edges, cap, true);
        assert_eq!(one.to_bits(), many.to_bits());
        // Every pair (those surely past the cap by a corner's distance, less the longest side,
        // skipped: 1.5 cm on this grid).
        let mut every = cap;
        let far = |a: u32, b: u32| (rest[a as usize] - rest[b as usize]).norm() > cap + 0.03;
        for p in 0..rest.len() as u32 {
            for tri in triangles.iter().filter(|t| !far(p, t[0])) {
                let d = vertex_triangle(&rest, p, tri).0;
                if !tri.contains(&p) && d >= radius {
                    every = every.min(d);
                }
            }
        }
        for (e, a) in edges.iter().enumerate() {
            for b in edges[e + 1..].iter().filter(|b| !far(a[0], b[0])) {
                let d = edge_edge(&rest, a, b).0;
                if !a.iter().any(|v| b.contains(v)) && d >= radius {
                    every = every.min(d);
                }
            }
        }
        // A bound under it (box distances stand for the exact ones of pairs whose boxes are
        // the radius apart).
        assert!(one <= every && one >= radius, "{one} against {every}");
        assert!(one > radius && one < cap, "{one}");
    }
}
