//! Self-collision's look: the pairs within reach found afresh (the unfolded proof first, then
//! the triangles' tree walked against itself, the near pairs in chunks), each with its side from
//! the old list or from where it is now.

use super::*;

/// The pairs of the vertices in no triangle (`orphans`), one query each of the triangles'
/// tree, into `out`.
fn orphan_pairs(search: &Search<'_>, tri_bvh: &Bvh, orphans: &[u32], out: &mut Found) {
    for &p in orphans {
        let q = Aabb {
            min: search.x[p as usize],
            max: search.x[p as usize],
        }
        .inflated(0.5 * search.reach);
        tri_bvh.overlapping(&q, |t| {
            if room_for(&mut out.vt, 1) {
                search.vertex_pair(p, t, &mut out.vt);
            } else {
                out.failed = true;
            }
        });
    }
}

/// Whether vertex `p` and triangle `t` of positions `x` are surely further than `reach` apart:
/// the vertex's distance from the triangle's centroid less the farthest corner's is.
#[inline]
fn ball_apart(x: &[Vec3], p: u32, t: &[u32; 3], reach: f64) -> bool {
    let [a, b, c] = t.map(|i| x[i as usize]);
    let centre = (a + b + c) / 3.0;
    let radius2 = (a - centre)
        .norm_squared()
        .max((b - centre).norm_squared())
        .max((c - centre).norm_squared());
    (x[p as usize] - centre).norm() - radius2.sqrt() >= reach
}

/// Whether edges `e` and `f` of positions `x` are surely further than `reach` apart: the
/// distance of their midpoints less their half lengths (the balls around them) is.
#[inline]
fn balls_apart(x: &[Vec3], e: &[u32; 2], f: &[u32; 2], reach: f64) -> bool {
    let (p0, p1, q0, q1) = (
        x[e[0] as usize],
        x[e[1] as usize],
        x[f[0] as usize],
        x[f[1] as usize],
    );
    let gap = 0.5 * ((p0 + p1) - (q0 + q1)).norm() - 0.5 * ((p1 - p0).norm() + (q1 - q0).norm());
    gap >= reach
}

/// The most looks a failed proof is put off for ([`SelfCollision::look`]).
const PROOF_BACKOFF: u32 = 16;

/// How many listed near pairs a task tests.
const NEAR_CHUNK: usize = 4096;

/// Pairs found by part of a look, with the walk's stack. Kept from look to look, so a look
/// allocates nothing once its lists have grown; they grow fallibly (`failed` when the
/// allocator refused: the look is an out-of-memory error, not an abort).
#[derive(Clone, Debug, Default)]
pub(super) struct Found {
    vt: Vec<Pair>,
    ee: Vec<Pair>,
    stack: Vec<(u32, u32)>,
    failed: bool,
}

impl Found {
    fn clear(&mut self) {
        self.vt.clear();
        self.ee.clear();
        self.failed = false;
    }
}

/// Room in `list` for `k` more pairs, asked of the allocator fallibly; false when refused.
fn room_for(list: &mut Vec<Pair>, k: usize) -> bool {
    list.capacity() - list.len() >= k || list.try_reserve(list.len().max(64).max(k)).is_ok()
}

/// What a look's tests read: the positions, the boxes, the neighbours and the old list.
struct Search<'a> {
    x: &'a [Vec3],
    triangles: &'a [[u32; 3]],
    edges: &'a [[u32; 2]],
    reach: f64,
    /// Each triangle's box grown by the reach, each edge's by half the reach.
    tri_boxes: &'a [Aabb],
    edge_boxes: &'a [Aabb],
    owners: &'a Ownership,
    excluded: &'a Exclusions,
    old_vt: &'a [Pair],
    old_ee: &'a [Pair],
}

/// The side remembered for pair `(a, b)` in the sorted list `old`.
fn remembered(old: &[Pair], a: u32, b: u32) -> Option<i8> {
    old.binary_search_by(|q| (q.0, q.1).cmp(&(a, b)))
        .ok()
        .map(|k| old[k].2)
}

impl Search<'_> {
    /// Vertex `p` and triangle `t`, not sharing a vertex (and, unless `check`, known not to be
    /// neighbours): kept if within reach, with the remembered side or the side it is on now.
    /// Cheap rejections first: the box, the triangle's enclosing ball, the neighbours.
    #[inline(always)]
    fn vertex_near(&self, p: u32, t: u32, check: bool, out: &mut Vec<Pair>) {
        let (x, tri) = (self.x, &self.triangles[t as usize]);
        if !self.tri_boxes[t as usize].contains(&x[p as usize])
            || ball_apart(x, p, tri, self.reach)
            || (check && self.excluded.vertex_excludes(p, t))
        {
            return;
        }
        let (d, w, r) = vertex_triangle(x, p, tri);
        if d >= self.reach {
            return;
        }
        let s = remembered(self.old_vt, p, t).unwrap_or_else(|| {
            // Known only where the vertex is over the face (beside it, the plane's side says
            // nothing): else 0, set when it first comes over the face.
            let [a, b, c] = tri.map(|i| x[i as usize]);
            if w.iter().all(|&wk| wk > 0.0) {
                side(r.dot(&(b - a).cross(&(c - a))))
            } else {
                0
            }
        });
        out.push((p, t, s));
    }

    /// Any vertex and triangle: its own triangles and neighbours out.
    fn vertex_pair(&self, p: u32, t: u32, out: &mut Vec<Pair>) {
        if !self.triangles[t as usize].contains(&p) {
            self.vertex_near(p, t, true, out);
        }
    }

    /// Edges `e` < `f`, not sharing a vertex (and, unless `check`, known not to be
    /// neighbours): likewise.
    #[inline(always)]
    fn edge_near(&self, e: u32, f: u32, check: bool, out: &mut Vec<Pair>) {
        let (x, edge, other) = (self.x, &self.edges[e as usize], &self.edges[f as usize]);
        if !self.edge_boxes[e as usize].overlaps(&self.edge_boxes[f as usize])
            || balls_apart(x, edge, other, self.reach)
            || (check && self.excluded.edge_excludes(e, f))
        {
            return;
        }
        let (d, a, b, r, n) = edge_edge(x, edge, other);
        if d >= self.reach {
            return;
        }
        let interior = a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0;
        let s = remembered(self.old_ee, e, f).unwrap_or(if interior { side(r.dot(&n)) } else { 0 });
        out.push((e, f, s));
    }

    /// Any two edges `e` < `f`: edges sharing a vertex and neighbours out.
    fn edge_pair(&self, e: u32, f: u32, out: &mut Vec<Pair>) {
        let (edge, other) = (&self.edges[e as usize], &self.edges[f as usize]);
        if !edge.iter().any(|v| other.contains(v)) {
            self.edge_near(e, f, true, out);
        }
    }

    /// Triangles `i` and `j`, not near each other at rest, whose tree boxes overlap: each
    /// vertex of one against the other triangle, each edge of one against each of the other's,
    /// through their owners (so each pair once). Kept out of line: the walk's other calls
    /// return at once.
    #[inline(never)]
    fn far_triangles(&self, i: u32, j: u32, found: &mut Found) {
        let (vt, ee) = (&mut found.vt, &mut found.ee);
        // A triangle pair yields at most 6 vertex-triangle and 9 edge-edge pairs (each vertex
        // and edge has one owner): room for them first, so the pushes below never allocate.
        if !room_for(vt, 6) || !room_for(ee, 9) {
            found.failed = true;
            return;
        }
        self.owners.pairs_of(
            i,
            j,
            |p, t| self.vertex_pair(p, t, vt),
            |e, f| self.edge_pair(e, f, ee),
        );
    }

    /// Chunk `k` of the near pairs' lists, into `found` (at most one pair each: room for all
    /// first).
    fn near_chunk(&self, near: &NearPairs, k: usize, found: &mut Found) {
        let part = |len: usize| (k * NEAR_CHUNK).min(len)..((k + 1) * NEAR_CHUNK).min(len);
        let (vt, ee) = (
            &near.vertex_triangle[part(near.vertex_triangle.len())],
            &near.edge_edge[part(near.edge_edge.len())],
        );
        if !room_for(&mut found.vt, vt.len()) || !room_for(&mut found.ee, ee.len()) {
            found.failed = true;
            return;
        }
        for &(p, t) in vt {
            self.vertex_near(p, t, false, &mut found.vt);
        }
        for &(e, f) in ee {
            self.edge_near(e, f, false, &mut found.ee);
        }
    }
}

impl SelfCollision {
    /// Whether the cloth at `x` may have brought a pair from beyond `thickness + skin` to
    /// within `thickness` since the last look: some vertex moved more than `skin / 2` relative
    /// to the centre of all the displacements' box. Two points' distance changes by at most
    /// the difference of their displacements, at most twice that, so a swing that carries the
    /// whole cloth along does not look again for the carrying.
    pub(super) fn deformed(&self, x: &[Vec3], skin: f64) -> bool {
        if self.looked_at.len() != x.len() {
            return true;
        }
        let b = Aabb::empty().grown_by_differences(x, &self.looked_at);
        let c = 0.5 * (b.min + b.max);
        let limit = 0.25 * skin * skin;
        // No displacement is further from the box's centre than its half diagonal: while that
        // is within the limit, no vertex need be looked at.
        if 0.25 * (b.max - b.min).norm_squared() <= limit {
            return false;
        }
        x.iter()
            .zip(&self.looked_at)
            .any(|(p, q)| (p - q - c).norm_squared() > limit)
    }

    /// Looks the pairs up again at positions `x`: every pair within `reach`, not neighbours
    /// ([`Exclusions`]: nearer than `excluded_within` at rest), with its side from the old list
    /// or, when new, from where it is now.
    pub(super) fn look(
        &mut self,
        x: &[Vec3],
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        reach: f64,
        excluded_within: f64,
    ) -> Result<(), Error> {
        let oom = |what: &str| Error::out_of_memory(format!("self-collision: {what} cannot be allocated"));
        self.looks += 1;
        self.last_proved = false;
        // Looked at afresh by the next step unless this look completes.
        self.looked_at.clear();
        self.looked_at
            .try_reserve(x.len())
            .map_err(|_| oom("the positions of a look"))?;
        if !self.prepared(x.len(), triangles.len(), excluded_within) {
            // Unreachable through a cloth (it prepares at create and on a new model); a
            // direct caller that did not prepare gets the default room and, past it, no pairs.
            if self.prepare_within(rest, triangles, excluded_within).is_err() {
                self.vertex_triangle.clear();
                self.edge_edge.clear();
                self.looked_at.extend_from_slice(x);
                return Ok(());
            }
        }
        let below = self.proof_below(x, triangles, reach, excluded_within);
        if below == f64::INFINITY && self.owners.orphans().is_empty() {
            // Every pair: nothing in reach, nothing to remember.
            self.certified_looks += 1;
            self.last_proved = true;
            self.vertex_triangle.clear();
            self.edge_edge.clear();
            self.looked_at.extend_from_slice(x);
            return Ok(());
        }
        self.make_boxes(x, triangles, reach)?;
        if below > excluded_within && self.rest_nodes.is_empty() {
            self.make_rest_nodes(rest, triangles)?;
        }
        self.copy_old_pairs()?;
        let parts = self.search_pairs(x, triangles, reach, below, excluded_within)?;
        self.gather_found(parts)?;
        self.looked_at.extend_from_slice(x);
        Ok(())
    }

    /// The distance at rest below which the unfolded proof (`unfolded.rs`) shows every pair
    /// out of reach at `x` (`excluded_within` when it proves nothing or is not tried). A
    /// proof that proved nothing is not tried again for the next looks, twice as many each
    /// time it fails in a row up to `PROOF_BACKOFF` (a cloth bent at every look pays for it
    /// once in that many), and at once after one that did.
    fn proof_below(&mut self, x: &[Vec3], triangles: &[[u32; 3]], reach: f64, excluded_within: f64) -> f64 {
        if self.full_looks {
            excluded_within
        } else if self.proof_wait > 0 {
            self.proof_wait -= 1;
            excluded_within
        } else {
            let below = self
                .unfolded
                .certified_below(x, triangles, reach, excluded_within);
            if below > excluded_within {
                self.proof_backoff = 0;
            } else {
                self.proof_backoff = (2 * self.proof_backoff).clamp(1, PROOF_BACKOFF);
                self.proof_wait = self.proof_backoff;
            }
            below
        }
    }

    /// The boxes of a look at `x`: the triangles' grown by `reach` (a vertex's candidates), by
    /// half of it (the tree's) and the edges' by half of it; the tree refitted (or built), and
    /// the rest boxes in its order.
    fn make_boxes(&mut self, x: &[Vec3], triangles: &[[u32; 3]], reach: f64) -> Result<(), Error> {
        let oom = |what: &str| Error::out_of_memory(format!("self-collision: {what} cannot be allocated"));
        // A vertex is a candidate for a triangle within `reach` of the triangle's box, two
        // edges for each other when their boxes grown by half the reach overlap. The
        // triangles' tree holds their boxes grown by half the reach: a vertex (an edge) of one
        // triangle near another triangle (an edge of it) puts the two triangles' tree boxes
        // over each other.
        self.tri_boxes.clear();
        self.tree_boxes.clear();
        self.edge_boxes.clear();
        self.tri_boxes
            .try_reserve(triangles.len())
            .and_then(|()| self.tree_boxes.try_reserve(triangles.len()))
            .and_then(|()| self.edge_boxes.try_reserve(self.edges.len()))
            .map_err(|_| oom("the boxes of a look"))?;
        for t in triangles {
            let b = Aabb::of(t.iter().map(|&i| &x[i as usize]));
            self.tri_boxes.push(b.inflated(reach));
            self.tree_boxes.push(b.inflated(0.5 * reach));
        }
        self.edge_boxes.extend(
            self.edges
                .iter()
                .map(|e| Aabb::of(e.iter().map(|&i| &x[i as usize])).inflated(0.5 * reach)),
        );
        if self.tri_bvh.len() == triangles.len() {
            self.tri_bvh.refit(&self.tree_boxes);
        } else {
            // Split on the pool where the step uses it (the same tree: `bvh.rs`).
            let parallel = crate::parallel::worth_it(x.len());
            self.tri_bvh =
                Bvh::try_build_on(&self.tree_boxes, parallel).map_err(|_| oom("the triangles' tree"))?;
            self.rest_in_order.clear();
        }
        if self.rest_in_order.len() != triangles.len() {
            let rest_boxes = self.near.rest_boxes();
            self.rest_in_order.clear();
            self.rest_nodes.clear();
            self.rest_in_order
                .try_reserve(rest_boxes.len())
                .map_err(|_| oom("the rest boxes in the tree's order"))?;
            self.tri_bvh.in_order_into(rest_boxes, &mut self.rest_in_order);
        }
        Ok(())
    }

    /// The plain rest boxes, in the tree's order, gathered by its nodes (the tree's boxes at
    /// most twice its items' count): what the proved walk skips by.
    fn make_rest_nodes(&mut self, rest: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), Error> {
        let oom = |what: &str| Error::out_of_memory(format!("self-collision: {what} cannot be allocated"));
        let (mut boxes, mut plain) = (Vec::new(), Vec::new());
        boxes
            .try_reserve_exact(triangles.len())
            .and_then(|()| plain.try_reserve_exact(triangles.len()))
            .and_then(|()| self.rest_nodes.try_reserve_exact(2 * triangles.len()))
            .map_err(|_| oom("the rest boxes of the tree's nodes"))?;
        boxes.extend(
            triangles
                .iter()
                .map(|t| Aabb::of(t.iter().map(|&i| &rest[i as usize]))),
        );
        self.tri_bvh.in_order_into(&boxes, &mut plain);
        self.tri_bvh.node_boxes_into(&plain, &mut self.rest_nodes);
        Ok(())
    }

    /// The remembered pairs copied aside (the new lists are made where they are), each list
    /// keeping its room from look to look.
    fn copy_old_pairs(&mut self) -> Result<(), Error> {
        let oom = |what: &str| Error::out_of_memory(format!("self-collision: {what} cannot be allocated"));
        self.old_vt.clear();
        self.old_ee.clear();
        self.old_vt
            .try_reserve(self.vertex_triangle.len())
            .and_then(|()| self.old_ee.try_reserve(self.edge_edge.len()))
            .map_err(|_| oom("a copy of the pairs"))?;
        self.old_vt.extend_from_slice(&self.vertex_triangle);
        self.old_ee.extend_from_slice(&self.edge_edge);
        Ok(())
    }

    /// Finds the pairs within `reach` at `x` into the parts of `found`: the triangles' tree
    /// walked against itself (each overlapping pair of boxes once), in tasks for the pool on
    /// a large cloth; triangles near each other at rest left out of it, their pairs listed
    /// (`NearPairs`) and tested in chunks; the vertices in no triangle one query each.
    fn search_pairs(
        &mut self,
        x: &[Vec3],
        triangles: &[[u32; 3]],
        reach: f64,
        below: f64,
        excluded_within: f64,
    ) -> Result<usize, Error> {
        let oom = |what: &str| Error::out_of_memory(format!("self-collision: {what} cannot be allocated"));
        let search = Search {
            x,
            triangles,
            edges: &self.edges,
            reach,
            tri_boxes: &self.tri_boxes,
            edge_boxes: &self.edge_boxes,
            owners: &self.owners,
            excluded: &self.excluded,
            old_vt: &self.old_vt,
            old_ee: &self.old_ee,
        };
        use rayon::prelude::*;
        // On the pool only where the step itself runs there: handing a look from the host's
        // thread to the pool cost more than the second thread saved at 61 x 41 (Intel Xeon,
        // `collision_cost -- 5 0`: 1.34-1.40x the bake without on one thread, 1.46-1.73x on two).
        let par = crate::parallel::worth_it(x.len());
        let (tri_bvh, near, rest_in_order, rest_nodes) =
            (&self.tri_bvh, &self.near, &self.rest_in_order, &self.rest_nodes);
        // The near pairs all proved out of reach, or tested.
        let near_chunks = if near.max_span < below {
            0
        } else {
            near.vertex_triangle
                .len()
                .max(near.edge_edge.len())
                .div_ceil(NEAR_CHUNK)
        };
        let proved = below > excluded_within;
        tri_bvh.self_tasks_into(if par { 64 } else { 1 }, &mut self.tasks, &mut self.tasks_spare);
        let tasks = &self.tasks;
        // One part a task and a chunk, and at least one (the orphans' queries below).
        let parts = (tasks.len() + near_chunks).max(1);
        if self.found.len() < parts {
            self.found
                .try_reserve(parts - self.found.len())
                .map_err(|_| oom("the parts of a look"))?;
            self.found.resize_with(parts, Found::default);
        }
        let part = |k: usize, found: &mut Found| {
            found.clear();
            if let Some(&task) = tasks.get(k) {
                let Found { stack, .. } = found;
                let mut stack = std::mem::take(stack);
                if proved {
                    tri_bvh.self_overlapping_apart_within(
                        task,
                        rest_in_order,
                        rest_nodes,
                        below,
                        &mut stack,
                        |i, j| {
                            search.far_triangles(i, j, found);
                        },
                    );
                } else {
                    tri_bvh.self_overlapping_apart(task, rest_in_order, &mut stack, |i, j| {
                        search.far_triangles(i, j, found);
                    });
                }
                found.stack = stack;
            } else if k - tasks.len() < near_chunks {
                search.near_chunk(near, k - tasks.len(), found);
            }
        };
        let found = &mut self.found[..parts];
        if par {
            found.par_iter_mut().enumerate().for_each(|(k, f)| part(k, f));
        } else {
            found.iter_mut().enumerate().for_each(|(k, f)| part(k, f));
        }
        orphan_pairs(&search, tri_bvh, self.owners.orphans(), &mut found[0]);
        if found.iter().any(|f| f.failed) {
            return Err(oom("the pairs a look found"));
        }
        Ok(parts)
    }

    /// The first `parts` parts' pairs gathered into the remembered lists, sorted; room for them asked
    /// before the lists are emptied, so a refusal leaves the remembered pairs as they were.
    fn gather_found(&mut self, parts: usize) -> Result<(), Error> {
        let oom = |what: &str| Error::out_of_memory(format!("self-collision: {what} cannot be allocated"));
        let (vt, ee) = (&mut self.vertex_triangle, &mut self.edge_edge);
        let found = &self.found[..parts];
        let (vt_len, ee_len) = (
            found.iter().map(|f| f.vt.len()).sum::<usize>(),
            found.iter().map(|f| f.ee.len()).sum::<usize>(),
        );
        vt.try_reserve(vt_len.saturating_sub(vt.len()))
            .and_then(|()| ee.try_reserve(ee_len.saturating_sub(ee.len())))
            .map_err(|_| oom("the pairs a look found"))?;
        vt.clear();
        ee.clear();
        for f in found.iter() {
            vt.extend_from_slice(&f.vt);
            ee.extend_from_slice(&f.ee);
        }
        vt.sort_unstable();
        ee.sort_unstable();
        Ok(())
    }
}
