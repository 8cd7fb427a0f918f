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

mod contacts;
mod look;
#[cfg(test)]
mod tests;

use look::Found;

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

/// The mean length of the edges `edges` at positions `x` (0 with no edge).
fn mean_edge(x: &[Vec3], edges: &[[u32; 2]]) -> f64 {
    let total: f64 = edges
        .iter()
        .map(|e| (x[e[1] as usize] - x[e[0] as usize]).norm())
        .sum();
    total / edges.len().max(1) as f64
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

fn side(v: f64) -> i8 {
    if v < 0.0 {
        -1
    } else {
        1
    }
}
