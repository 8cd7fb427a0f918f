//! Self-collision: the cloth keeps `thickness` from itself, as [`Contact`] elements between a
//! vertex and a triangle, and between two edges, that are not neighbours.
//!
//! **Pairs** are found with one [`Bvh`] over the cloth's triangles (refitted, never rebuilt),
//! walked against itself: each vertex and each edge is *owned* by one of its triangles
//! ([`Ownership`]), so a pair of overlapping triangle boxes yields each vertex-triangle and
//! edge-edge pair once. Triangles near each other at rest (mostly neighbours) are left out of
//! the walk: their pairs that are not neighbours are listed once (`neighbours.rs`) and
//! tested directly. Box and ball tests come before the exact distances. Pairs within
//! `thickness + skin` of each other are kept in a list; the
//! list is looked up again once some vertex has moved `skin / 2` since the last look (a Verlet
//! list, `skin = thickness`). No pair outside the list can come within the thickness before
//! the next look. Pairs nearer than 2.2 thicknesses at rest (neighbours of a fine mesh)
//! are left out, found once, so a flat cloth has no pairs at all.
//!
//! **Sides.** Each pair remembers which side of the triangle (of the two edges) it was on when
//! it entered the list and keeps it for as long as it stays; a vertex pushed through a
//! triangle in one step is pushed back, not on through, and so is one found on the other side
//! past the thickness but within the list's reach (no step brings a pair more than a thickness
//! closer, so it went through; a longer step is taken only where the proof of `unfolded.rs`
//! shows no pair within reach at any instant of it). A pair apart and off the face (past an edge's end, or edges
//! near parallel) forgets its side: it may go round the border of a fold. Together with the step limit (no
//! vertex moves more than half the thickness in a step: a substep that would is split, or as a last
//! resort its fast vertices slowed, `cloth/split.rs`, `Cloth::limit_collision_step`) no pair can cross
//! unnoticed. The sides are the only state self-collision keeps (snapshots carry them).
//! Neighbours left out of the list (edge pairs and vertex-triangle pairs nearer than the
//! exclusion at rest) are watched by the [`Guard`], whose pairs the impact zones check when
//! they might pass through each other.
//!
//! Forces: the vertex or edge point is pushed along the remembered side's normal (outside the
//! triangle's interior, along the line between the closest points) with the model's
//! `collision_stiffness` and `collision_damping`; friction is the contacts' velocity
//! correction with `self_collision_friction`.

use super::bvh::{Aabb, Bvh};
use super::contact::Contact;
use super::geometry::edges_of;
use super::guard::Guard;
use super::impact_zones::{PairRef, Passage};
use super::neighbours::{Exclusions, NearPairs, RestTree};
use super::ownership::Ownership;
use super::pair::{edge_edge, vertex_triangle};
use super::room::{Full, Room};
use super::unfolded::Unfolded;
use crate::error::Error;
use crate::math::Vec3;

/// The skin of the pair list, in thicknesses: pairs within `(1 + SKIN)` thicknesses are kept,
/// and the list is looked up again when the cloth has deformed by half the skin.
pub const SKIN: f64 = 1.0;
/// Edges whose directions make a smaller sine than this are near parallel: their side is not
/// kept relative to `e x f`.
const PARALLEL_SINE: f64 = 0.05;
/// Pairs nearer than this many thicknesses at rest are never tested (neighbours).
pub const EXCLUDED: f64 = 2.2;
/// How far past the exclusion, in exclusions, the least rest distance of a tested pair is
/// looked for (the proof of `unfolded.rs` starts there): a 1 cm grid at 4 mm has its first at
/// 10 mm, 1.14 exclusions, where the proof needs the cloth's deformation to keep 80 % of a
/// rest distance instead of 91 % at the exclusion.
const NEAREST_CAP: f64 = 1.25;
/// The proof's cells are at least this many times that least distance a side: pairs from it to
/// a cell's side are proved over windows of 2 cells, the next band (to 2 sides) over windows
/// of 3, where the bound needs only 64 % of the distance kept. (At 1, the cells of a 1 cm grid
/// 10 mm, every pair from 10 mm was in the band of windows of 3 cells and the 0.5 Hz swing's
/// bent shapes failed it: 1.10 of 1.21 looks a frame proved over 12 s, against 1.21 of 1.21 at
/// 1.25 and 1.16 at 1.5; `collision_cost 1 0 12`.)
const CELL_OVER_FIRST: f64 = 1.25;
/// At most this many pairs a vertex, on average, in the lists worked out from the rest shape
/// (the neighbours left out and the rest-near pairs listed). A 61 x 61 grid of 1 cm spacing
/// has 55 a vertex at a thickness of 4 mm, 294 at 1 cm and 702 at 2 cm: they grow about as
/// the square of thickness / spacing (a little slower on a grid this small, whose border
/// has fewer neighbours), and so do the memory and the time of every look. Past it
/// a cloth refuses the thickness (at create, or when given it).
pub const PAIRS_PER_VERTEX: usize = 1024;

pub use super::pair::Pair;

/// What self-collision remembers across steps, saved by a rollback.
#[derive(Clone, Debug, Default)]
pub struct SavedMemory {
    vertex_triangle: Vec<Pair>,
    edge_edge: Vec<Pair>,
    looked_at: Vec<Vec3>,
}

/// Self-collision's search and memory; see the module docs.
#[derive(Clone, Debug, Default)]
pub struct SelfCollision {
    /// Every edge of the triangles once, `[i, j]` with i < j.
    edges: Vec<[u32; 2]>,
    /// Each triangle's box grown by the reach and each edge's by half of it, at the last look.
    tri_boxes: Vec<Aabb>,
    edge_boxes: Vec<Aabb>,
    /// The triangles' boxes grown by half the reach, in the tree.
    tree_boxes: Vec<Aabb>,
    tri_bvh: Bvh,
    /// Which triangle owns each vertex and edge (the walk meets each pair once).
    owners: Ownership,
    /// The triangles of each vertex (the impact zones' test of a pair already tangled).
    vertex_triangles: crate::topology::Adjacency,
    /// Positions at the last look; empty before the first.
    looked_at: Vec<Vec3>,
    /// Vertex-triangle and edge-edge pairs, sorted, with their sides.
    pub(crate) vertex_triangle: Vec<Pair>,
    pub(crate) edge_edge: Vec<Pair>,
    /// How many times the list was looked up again (for benchmarks).
    pub looks: u64,
    /// What the impact zones did after the steps (`impact_zones.rs`).
    pub zones: super::impact_zones::ZoneTotals,
    /// Pairs never tested: nearer than 2.2 thicknesses at rest (neighbours), per vertex and
    /// per edge, for the thickness they were found at.
    excluded: Exclusions,
    /// The pairs of triangles near each other at rest, tested directly.
    near: NearPairs,
    /// Their rest boxes in the tree's order ([`Bvh::in_order`]); empty when the tree or the
    /// near pairs are new.
    rest_in_order: Vec<Aabb>,
    /// The neighbour pairs the proximity search leaves out, whose passage through each other
    /// the impact zones' continuous check watches ([`Guard`]).
    guard: Guard,
    /// The proof that an unfolded sheet keeps its distances ([`Unfolded`]): the pairs nearer
    /// at rest than what it proves are not tested.
    unfolded: Unfolded,
    /// Looks without it (tests compare looks with and without).
    pub(crate) full_looks: bool,
    /// Looks to make without trying the proof, and how many it was last put off for.
    proof_wait: u32,
    proof_backoff: u32,
    /// The triangles' plain rest boxes gathered by the tree's nodes; empty when the tree or
    /// the rest shape is new.
    rest_nodes: Vec<Aabb>,
    /// Looks the proof settled whole, testing nothing (for benchmarks).
    pub certified_looks: u64,
    /// Whether the last look was settled whole by the proof.
    last_proved: bool,
    /// A look's working lists, kept for the next look: the parts' finds, the walk's tasks,
    /// and a copy of the remembered pairs (their sides, read while the new lists are made).
    found: Vec<Found>,
    tasks: Vec<(u32, u32)>,
    tasks_spare: Vec<(u32, u32)>,
    old_vt: Vec<Pair>,
    old_ee: Vec<Pair>,
}

pub use super::guard::{GUARD_QUANTILE, GUARD_SKIN};

/// The contact of vertex `p` with triangle `tri` at `x` (signed distance, direction, the
/// triangle's weights), its remembered side `s` learnt or forgotten on the way; `None` when
/// the pair is apart or its direction is not defined.
#[inline]
fn vertex_triangle_contact(
    x: &[Vec3],
    p: u32,
    tri: &[u32; 3],
    s: &mut i8,
    thickness: f64,
    reach: f64,
) -> Option<(f64, Vec3, [f64; 3])> {
    let (d, w, r) = vertex_triangle(x, p, tri);
    let [a, b, c] = tri.map(|i| x[i as usize]);
    let interior = w.iter().all(|&wk| wk > 0.0);
    let normal = (b - a).cross(&(c - a)).try_normalize(0.0)?;
    if d >= thickness {
        // Apart. Over the face on the other side of the remembered one, within the
        // reach: it went through (a step moves a pair at most one thickness closer, so
        // it cannot be past the reach already) and is pushed back. Else nothing
        // crossed and the side is learnt afresh (a triangle that turned over).
        let now = side(r.dot(&normal));
        if !interior {
            // Beside the face it may go round the triangle's border: forgotten.
            *s = 0;
            return None;
        }
        if settled_apart(s, now, d, reach) {
            return None;
        }
    }
    if *s == 0 && interior {
        // First over the triangle's face: the side it comes from is known now.
        *s = side(r.dot(&normal));
    }
    let side_n = f64::from(*s) * normal;
    let (dist, dir) = if interior && r.dot(&side_n) <= 0.0 {
        (-d, side_n)
    } else if interior && *s != 0 {
        (r.dot(&side_n), side_n)
    } else if d > 1e-12 {
        (d, r / d)
    } else {
        return None;
    };
    Some((dist, dir, w))
}

/// The contact of edges `ee` and `ff` at `x` (signed distance, direction, the parameters of
/// the closest points), their remembered side `s` learnt or forgotten on the way; `None` when
/// they are apart, past an end, or their direction is not defined.
#[inline]
fn edge_edge_contact(
    x: &[Vec3],
    ee: &[u32; 2],
    ff: &[u32; 2],
    s: &mut i8,
    thickness: f64,
    reach: f64,
) -> Option<(f64, Vec3, f64, f64)> {
    let (d, a, b, r, n) = edge_edge(x, ee, ff);
    if !(a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0) {
        if d >= thickness {
            // Apart and past an end: it may go round the edge's end, forgotten.
            *s = 0;
        }
        return None;
    }
    // The side is kept relative to e x f, which means something only while the edges
    // are not near parallel (and flips as they turn through parallel).
    let lengths =
        (x[ee[1] as usize] - x[ee[0] as usize]).norm() * (x[ff[1] as usize] - x[ff[0] as usize]).norm();
    let n_len = n.norm();
    let conditioned = n_len > PARALLEL_SINE * lengths;
    if d >= thickness {
        // Apart: as for a vertex and a triangle, on the other side within the reach
        // they went through each other; else the side is learnt afresh (edges that
        // turned). Turning through parallel flips `e x f` without crossing, so near
        // parallel the side is forgotten.
        if !conditioned {
            *s = 0;
            return None;
        }
        let now = side(r.dot(&n));
        if settled_apart(s, now, d, reach) {
            return None;
        }
    }
    let (dist, dir) = if conditioned {
        let n = n / n_len;
        if *s == 0 {
            *s = side(r.dot(&n));
        }
        let side_n = f64::from(*s) * n;
        if r.dot(&side_n) <= 0.0 {
            (-d, side_n)
        } else {
            (d, r / d)
        }
    } else if d > 1e-12 {
        // Near parallel: pushed apart along the line between them (the vertex-triangle
        // pairs of their triangles keep the sides).
        (d, r / d)
    } else {
        return None;
    };
    Some((dist, dir, a, b))
}

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

/// The mean length of the edges `edges` at positions `x` (0 with no edge).
fn mean_edge(x: &[Vec3], edges: &[[u32; 2]]) -> f64 {
    let total: f64 = edges
        .iter()
        .map(|e| (x[e[1] as usize] - x[e[0] as usize]).norm())
        .sum();
    total / edges.len().max(1) as f64
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

/// For a pair apart (past the thickness) at distance `d`, now on side `now` of its remembered
/// side `s`: whether it is settled there, its side learnt afresh (unknown before, the same,
/// or past the `reach`, where no step from a contact can have brought it). Else it went
/// through and is to be pushed back.
fn settled_apart(s: &mut i8, now: i8, d: f64, reach: f64) -> bool {
    let settled = *s == 0 || now == *s || d >= reach;
    if settled {
        *s = now;
    }
    settled
}

fn side(v: f64) -> i8 {
    if v < 0.0 {
        -1
    } else {
        1
    }
}

/// The most looks a failed proof is put off for ([`SelfCollision::look`]).
const PROOF_BACKOFF: u32 = 16;

/// How many listed near pairs a task tests.
const NEAR_CHUNK: usize = 4096;

/// Pairs found by part of a look, with the walk's stack. Kept from look to look, so a look
/// allocates nothing once its lists have grown; they grow fallibly (`failed` when the
/// allocator refused: the look is an out-of-memory error, not an abort).
#[derive(Clone, Debug, Default)]
struct Found {
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
    /// Sets up the search for a cloth of these triangles.
    pub fn new(triangles: &[[u32; 3]]) -> SelfCollision {
        let n = triangles.iter().flatten().max().map_or(0, |&m| m as usize + 1);
        SelfCollision {
            edges: edges_of(triangles),
            vertex_triangles: crate::topology::Adjacency::triangles(n, triangles),
            ..SelfCollision::default()
        }
    }

    /// Whether the lists worked out from the rest shape are there for `n` vertices and
    /// exclusion radius `radius`.
    fn prepared(&self, n: usize, triangle_count: usize, radius: f64) -> bool {
        self.owners.fits(n, triangle_count)
            && self.excluded.radius == radius
            && self.excluded.vt_start.len() == n + 1
    }

    /// Works out what the rest shape `rest` says for self-collision at `thickness` (which
    /// pairs are neighbours, never tested; which are listed to be tested directly), unless
    /// done already. Fails, with nothing changed, when the lists would hold more than
    /// [`PAIRS_PER_VERTEX`] entries a vertex (a thickness large against the mesh's spacing:
    /// the message says how large a one the mesh takes) or memory runs out.
    pub fn prepare(&mut self, rest: &[Vec3], triangles: &[[u32; 3]], thickness: f64) -> Result<(), Error> {
        if thickness <= 0.0 || self.prepared(rest.len(), triangles.len(), EXCLUDED * thickness) {
            return Ok(());
        }
        // Not all of it is asked for fallibly (the boxes and trees the lists are found with):
        // the room for it is checked first.
        crate::memory::ensure_available(
            (rest.len() as u64).saturating_mul(crate::memory::SELF_COLLISION_BYTES_PER_PARTICLE),
            &format!("self-collision for {} vertices", rest.len()),
        )?;
        self.prepare_within(rest, triangles, EXCLUDED * thickness)
    }

    fn prepare_within(&mut self, rest: &[Vec3], triangles: &[[u32; 3]], radius: f64) -> Result<(), Error> {
        // The exclusions' rows start at u32 offsets.
        let entries = PAIRS_PER_VERTEX.saturating_mul(rest.len()).saturating_add(4096);
        let mut room = Room::new(entries.min(u32::MAX as usize - 1));
        let owners = Ownership::new(rest.len(), triangles, &self.edges);
        // Set up on the pool for a cloth large enough that its step uses it (a million
        // particles: 9-11 s on one thread, docs/collisions.md); the lists are the same either way.
        let parallel = crate::parallel::worth_it(rest.len());
        let tree = RestTree::new(rest, triangles, radius, parallel);
        let edges = &self.edges;
        let mut unfolded = Unfolded::new(rest, triangles);
        // Where the proof applies, the least rest distance of a tested pair is looked for too.
        let cap = match unfolded.applies() {
            true => NEAREST_CAP * radius,
            false => radius,
        };
        let lists = Exclusions::with_nearest(rest, triangles, edges, radius, cap, &tree, &mut room, parallel)
            .and_then(|excluded| {
                if unfolded.applies() {
                    // The pairs the proof keeps out of reach start there; its cells a little
                    // wider, so that the first band is proved over windows of 2 cells
                    // (`unfolded.rs`).
                    let first = excluded.nearest;
                    unfolded.set_first(first, CELL_OVER_FIRST * first, rest, triangles);
                }
                NearPairs::new(
                    rest, triangles, edges, &owners, &excluded, tree, &mut room, parallel,
                )
                .map(|near| (excluded, near))
            });
        match (lists, room.full) {
            (Some((excluded, near)), _) => {
                let apart = |&(e, f): &(u32, u32)| {
                    let (a, b) = (edges[e as usize], edges[f as usize]);
                    !a.iter().any(|v| b.contains(v))
                };
                // The guard's pairs: excluded edge pairs and vertex-triangle pairs that share
                // no vertex.
                let oom = |_| {
                    Error::out_of_memory(format!(
                        "self-collision at a thickness of {} m: its neighbour pairs cannot be allocated",
                        radius / EXCLUDED
                    ))
                };
                let (vt_start, vt_rows) = excluded.vertex_rows();
                let vertex_pairs = || {
                    (0..rest.len()).flat_map(move |p| {
                        vt_rows[vt_start[p] as usize..vt_start[p + 1] as usize]
                            .iter()
                            .filter(move |&&t| !triangles[t as usize].contains(&(p as u32)))
                            .map(move |&t| (p as u32, t))
                    })
                };
                let (mut edge_pairs, mut guard_vt) = (Vec::new(), Vec::new());
                edge_pairs
                    .try_reserve_exact(excluded.edge_pairs().filter(apart).count())
                    .map_err(oom)?;
                guard_vt.try_reserve_exact(vertex_pairs().count()).map_err(oom)?;
                edge_pairs.extend(excluded.edge_pairs().filter(apart));
                guard_vt.extend(vertex_pairs());
                let guard = Guard::new(rest, &self.edges, triangles, edge_pairs, guard_vt)?;
                self.owners = owners;
                self.excluded = excluded;
                self.near = near;
                self.rest_in_order.clear();
                self.guard = guard;
                self.unfolded = unfolded;
                Ok(())
            }
            (None, Some(Full::Memory)) => Err(Error::out_of_memory(format!(
                "self-collision at a thickness of {} m: its lists of neighbours cannot be allocated",
                radius / EXCLUDED
            ))),
            (None, _) => {
                let mean = mean_edge(rest, &self.edges);
                Err(Error::invalid(format!(
                    "self_collision_thickness {:.4} m (with self_collision_relative times the spacing added) is too large for this mesh, whose edges are {:.4} m long on average: \
                     the neighbours it would leave out or list pass {} a vertex; use a thickness of at most about {:.4} m \
                     (1.5 mean edge lengths), or a coarser mesh",
                    radius / EXCLUDED,
                    mean,
                    PAIRS_PER_VERTEX,
                    1.5 * mean
                )))
            }
        }
    }

    /// The contacts of the cloth (positions `x`, velocities unused here, rest positions `rest`)
    /// with itself at thickness `thickness`, appended to `out`, after [`SelfCollision::prepare`]
    /// at that thickness. Looks the pairs up again when the cloth has deformed enough. Every
    /// list it grows (the pairs, the look's working lists, `out`) is asked of the allocator
    /// fallibly and kept for the next call: an out-of-memory error, not an abort, when memory
    /// runs out, and no allocation once the lists have grown to what the shapes need.
    pub fn contacts(
        &mut self,
        x: &[Vec3],
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        thickness: f64,
        friction: f64,
        out: &mut Vec<Contact>,
    ) -> Result<(), Error> {
        let skin = SKIN * thickness;
        let reach = thickness + skin;
        if self.deformed(x, skin) {
            self.look(x, rest, triangles, reach, EXCLUDED * thickness)?;
        }
        // At most one contact a pair: room for all of them, so the pushes never allocate.
        let pairs = self.vertex_triangle.len() + self.edge_edge.len();
        out.try_reserve(pairs).map_err(|_| {
            Error::out_of_memory(format!("self-collision: {pairs} contacts cannot be allocated"))
        })?;
        let cap = 2.0 * thickness;
        // A contact between four vertices at signed distance `dist` along `dir`, if within the
        // thickness.
        let push = |out: &mut Vec<Contact>, idx: [u32; 4], coef: [f64; 4], dist: f64, dir: Vec3| {
            if dist < thickness {
                out.push(Contact {
                    idx,
                    coef,
                    len: 4,
                    dir,
                    depth: (thickness - dist).min(cap),
                    surface_velocity: Vec3::zeros(),
                    friction,
                    scale: 1.0,
                });
            }
        };
        for (p, t, s) in self.vertex_triangle.iter_mut().map(|q| (q.0, q.1, &mut q.2)) {
            let tri = &triangles[t as usize];
            if let Some((dist, dir, w)) = vertex_triangle_contact(x, p, tri, s, thickness, reach) {
                push(
                    out,
                    [p, tri[0], tri[1], tri[2]],
                    [1.0, -w[0], -w[1], -w[2]],
                    dist,
                    dir,
                );
            }
        }
        for (e, f, s) in self.edge_edge.iter_mut().map(|p| (p.0, p.1, &mut p.2)) {
            let (ee, ff) = (&self.edges[e as usize], &self.edges[f as usize]);
            if let Some((dist, dir, a, b)) = edge_edge_contact(x, ee, ff, s, thickness, reach) {
                push(
                    out,
                    [ee[0], ee[1], ff[0], ff[1]],
                    [1.0 - a, a, -(1.0 - b), -b],
                    dist,
                    dir,
                );
            }
        }
        Ok(())
    }

    /// Whether the cloth at `x` may have brought a pair from beyond `thickness + skin` to
    /// within `thickness` since the last look: some vertex moved more than `skin / 2` relative
    /// to the centre of all the displacements' box. Two points' distance changes by at most
    /// the difference of their displacements, at most twice that, so a swing that carries the
    /// whole cloth along does not look again for the carrying.
    fn deformed(&self, x: &[Vec3], skin: f64) -> bool {
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
    fn look(
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

    /// Forgets the positions of the last look (the next step looks again; sides are kept).
    pub(crate) fn look_again(&mut self) {
        self.looked_at.clear();
        // The guard's watch too: its skin is the thickness's.
        self.guard.forget();
    }

    /// Copies what self-collision remembers (the pairs with their sides, and where it last
    /// looked) into `saved`, reusing its buffers.
    pub(crate) fn save_memory(&self, saved: &mut SavedMemory) {
        saved.vertex_triangle.clone_from(&self.vertex_triangle);
        saved.edge_edge.clone_from(&self.edge_edge);
        saved.looked_at.clone_from(&self.looked_at);
    }

    /// Swaps what self-collision remembers with `saved` (a rollback: the failed step's memory
    /// goes to `saved`).
    pub(crate) fn swap_memory(&mut self, saved: &mut SavedMemory) {
        std::mem::swap(&mut self.vertex_triangle, &mut saved.vertex_triangle);
        std::mem::swap(&mut self.edge_edge, &mut saved.edge_edge);
        std::mem::swap(&mut self.looked_at, &mut saved.looked_at);
    }

    /// Whether the last look was settled whole by the proof (the cloth out of its own reach):
    /// then [`SelfCollision::out_of_reach_throughout`] may well prove the next step too.
    pub(crate) fn last_look_proved(&self) -> bool {
        self.last_proved
    }

    /// Whether no pair self-collision tests can come within its reach during a step that moves
    /// each point on a straight line from `x0` to `x1` (the proof of `unfolded.rs` over the
    /// step): its step limit is then not needed, however far the step moves a vertex. False
    /// where the proof does not apply (a rest shape not a flat convex sheet, a lone vertex).
    pub(crate) fn out_of_reach_throughout(
        &mut self,
        x0: &[Vec3],
        x1: &[Vec3],
        triangles: &[[u32; 3]],
        thickness: f64,
    ) -> bool {
        if self.full_looks || !self.owners.orphans().is_empty() || thickness.is_nan() || thickness <= 0.0 {
            return false;
        }
        let reach = thickness * (1.0 + SKIN);
        self.unfolded
            .out_of_reach_throughout(x0, x1, triangles, reach, EXCLUDED * thickness)
    }

    /// The remembered pairs (vertex-triangle, edge-edge).
    pub fn pairs(&self) -> (&[Pair], &[Pair]) {
        (&self.vertex_triangle, &self.edge_edge)
    }

    /// Replaces the remembered pairs (a snapshot's; none after a teleport).
    pub(crate) fn set_pairs(&mut self, vertex_triangle: Vec<Pair>, edge_edge: Vec<Pair>) {
        // Into the lists already there when they have the room (a teleport, which clears
        // them, keeps their room for the next look), else the new ones are taken.
        for (list, new) in [
            (&mut self.vertex_triangle, vertex_triangle),
            (&mut self.edge_edge, edge_edge),
        ] {
            if list.capacity() >= new.len() {
                list.clear();
                list.extend_from_slice(&new);
            } else {
                *list = new;
            }
        }
        self.looked_at.clear();
    }

    /// Sets the side of every pair in `stopped` to the sign it started its step with (the
    /// impact zones kept it there).
    pub(crate) fn relearn_sides(&mut self, stopped: &[Passage]) {
        for p in stopped {
            let pair = match p.pair {
                PairRef::VertexTriangle(k) => self.vertex_triangle.get_mut(k as usize),
                PairRef::EdgeEdge(k) => self.edge_edge.get_mut(k as usize),
                PairRef::Neighbour => None,
            };
            if let Some(pair) = pair {
                pair.2 = p.sign;
            }
        }
    }

    /// Each vertex's excluded triangles (neighbours at rest) as compressed rows.
    pub(crate) fn excluded_rows(&self) -> (&[u32], &[u32]) {
        self.excluded.vertex_rows()
    }

    pub(crate) fn vertex_triangles(&self) -> &crate::topology::Adjacency {
        &self.vertex_triangles
    }

    /// The guarded neighbour pairs that might pass in the step `x0 -> x1`, for the impact zones
    /// to check, after [`SelfCollision::watch_guard`] for the same step: edge pairs, and
    /// vertex-triangle pairs ([`Guard`]).
    pub(crate) fn guarded(&self) -> super::guard::PairLists<'_> {
        self.guard.close()
    }

    /// Readies [`SelfCollision::guarded`] for the step `x0 -> x1`, where two points meet
    /// within `tolerance` ([`Guard::watch`]).
    pub(crate) fn watch_guard(&mut self, x0: &[Vec3], x1: &[Vec3], triangles: &[[u32; 3]], tolerance: f64) {
        self.guard.watch(x0, x1, &self.edges, triangles, tolerance);
    }

    pub(crate) fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }
}

#[cfg(test)]
mod tests {
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
}
