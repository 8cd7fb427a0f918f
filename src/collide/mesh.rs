//! Triangle-mesh colliders, static, moving and deforming: the host gives the mesh's vertices
//! once and new positions (same topology) whenever it moves; the cloth keeps `collision_margin`
//! from it, as from the analytic colliders.
//!
//! **Motion within a step call.** The mesh travels in a straight line from where it was when
//! the call began (`start`) to where the host put it (`target`), as the pins do; a substep
//! that ends at fraction f of the call sees the mesh at `start + f (target - start)`. Its
//! surface velocity is the host's, or `(target - start) / dt`.
//!
//! **Contacts, two ways** ([`Contact`] elements):
//! - *cloth vertex against mesh triangle*: the nearest triangle within reach; on a closed mesh
//!   (every edge shared by two triangles) the side comes from the angle-weighted pseudo-normal
//!   of the nearest feature (Baerentzen & Aanaes 2005), so a vertex that ends up inside is
//!   pushed out along it, however deep (a vertex found inside no triangle's reach is matched
//!   to the nearest triangle of the whole mesh, looked up again at every substep; one deeper
//!   than the reach but within some triangle's box is pushed along the nearest of those, not
//!   always the shortest way out); an open mesh is a two-sided shell.
//! - *mesh vertex against cloth triangle*: a mesh vertex within the margin of a cloth triangle
//!   none of whose corners touches the mesh already pushes the triangle's three vertices by
//!   their barycentric weights, so a collider thinner than the cloth's spacing (a bar, a fin, a
//!   finger tip) cannot slip between cloth vertices; where a corner touches, its vertex contact
//!   holds the triangle (else a finely tessellated mesh would push a triangle once per mesh
//!   vertex under it: a contact stiffness that grew with the mesh's resolution).
//! - *mesh edge against cloth edge*: where the nearest points of a mesh edge and a cloth edge
//!   lie inside both (not at an end) and within the margin, and neither cloth vertex touches
//!   the mesh already, the cloth edge's two vertices are pushed by their weights: a thin
//!   collider whose vertices are all far from the cloth (a bar longer than the towel, crossing
//!   it between two rows) cannot slip between cloth vertices either. Only the mesh's *active*
//!   edges take part (a border, or a fold sharper than [`ACTIVE_EDGE_DEGREES`] between its two
//!   faces, at the mesh's target each call): across a smooth surface the faces are as near as
//!   the edges, and the vertex contacts hold the cloth.
//!
//! **Search.** Each call the swept boxes of the mesh's triangles and vertices (start to target)
//! are refitted into three [`Bvh`]s (with its edges). Each cloth vertex keeps the candidates
//! found within `margin + skin` of where it was when it last looked, and looks again once it has
//! moved more than its slack (a Verlet list); its triangles and edges look again with it. The
//! slack is `skin / 2`, and half as much again as the gap its lookups left to what they did
//! not find: far from the mesh, where nearly every lookup finds nothing, a vertex looks again
//! only when it may have come near (`refresh_candidates` says why the lists stay whole). Most
//! substeps test only a few exact distances, and visit only the vertices, triangles and edges
//! that have candidates.

use super::bvh::{Aabb, Bvh};
use super::ccd::{edge_passes_edge, start_sign, vertex_passes_triangle, Path};
use super::contact::Contact;
use super::geometry::{closest_on_segments, closest_on_triangle, edges_of, offset_from_triangle};
use super::room::{Full, Room};
use crate::error::Error;
use crate::math::Vec3;
use crate::topology::Adjacency;

const NONE: u32 = u32::MAX;

/// A mesh edge whose two faces turn by more than this (degrees), or with one face, is active
/// (takes part in edge contacts).
pub const ACTIVE_EDGE_DEGREES: f64 = 20.0;

/// Most vertices (and triangles) a mesh collider may have.
pub const MAX_MESH_COLLIDER_VERTICES: usize = 1 << 26;

/// A triangle-mesh collider; see the module docs.
#[derive(Clone, Debug)]
pub struct MeshCollider {
    triangles: Vec<[u32; 3]>,
    /// The triangle across edge k (from corner k to corner k+1) of each triangle, or NONE.
    neighbours: Vec<[u32; 3]>,
    closed: bool,
    start: Vec<Vec3>,
    target: Vec<Vec3>,
    /// The host's velocities, or empty (then from the motion over the call).
    given_velocity: Vec<Vec3>,
    /// Velocities over the current call.
    velocity: Vec<Vec3>,
    face_normal: Vec<Vec3>,
    vertex_normal: Vec<Vec3>,
    tri_boxes: Vec<Aabb>,
    vert_boxes: Vec<Aabb>,
    tri_bvh: Bvh,
    vert_bvh: Bvh,
    /// Each active edge once, its ends in ascending order (at the last refresh).
    edges: Vec<[u32; 2]>,
    edge_boxes: Vec<Aabb>,
    edge_bvh: Bvh,
    /// The farthest any vertex travels over the current call, m.
    travel: f64,
    /// Whether the boxes and normals are those of `start` and `target` at `reach`.
    fresh_at: f64,
    /// Coulomb friction coefficient.
    pub friction: f64,
    /// Its own margin, m, or the cloth's (`None`).
    pub margin: Option<f64>,
    cache: Candidates,
}

/// A passage of the cloth through a mesh collider in a step: the cloth vertices it takes (one,
/// two or three, repeated to fill) and the mesh's displacement there over the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPassage {
    pub cloth: [u32; 3],
    pub carry: Vec3,
}

/// Each cloth vertex's, triangle's and edge's candidates (see the module docs), and which of
/// them have any (the contact loops visit only those, in ascending order).
#[derive(Clone, Debug, Default)]
struct Candidates {
    vertex: Vec<Vec<u32>>,
    vertex_at: Vec<Vec3>,
    /// How far each cloth vertex may move from `vertex_at` before it looks again: half the
    /// skin, and half the gap its own and its triangles' and edges' last lookups left to what
    /// they did not find (`Bvh::overlapping_apart`), see `refresh_candidates`.
    vertex_slack: Vec<f64>,
    /// The gaps of the last lookups of each cloth vertex, triangle and edge.
    vertex_gap: Vec<f64>,
    triangle_gap: Vec<f64>,
    edge_gap: Vec<f64>,
    /// The vertices that looked at this refresh (set while it runs), and those still to look.
    looked_now: Vec<bool>,
    pending: Vec<u32>,
    /// The vertices whose slack a round of lookups changed.
    affected: Vec<u32>,
    triangle: Vec<Vec<u32>>,
    /// The cloth's edges (each once) and each one's candidate mesh edges.
    cloth_edges: Vec<[u32; 2]>,
    edge: Vec<Vec<u32>>,
    /// The cloth's triangles and edges of each vertex (a triangle or edge looks again when
    /// one of its vertices does).
    vertex_triangles: Adjacency,
    vertex_edges: Adjacency,
    /// The vertices, triangles and edges with candidates, ascending.
    with_vertex: Vec<u32>,
    with_triangle: Vec<u32>,
    with_edge: Vec<u32>,
    /// Vertices, triangles and edges that look again at this substep.
    looked: Vec<u32>,
    dirty_triangles: Vec<u32>,
    dirty_edges: Vec<u32>,
    /// Each cloth vertex's nearest triangle at the last substep (tested first).
    nearest: Vec<u32>,
    /// Whether each cloth vertex touches the mesh at this substep (its edges then need no
    /// edge contact), and the vertices set.
    touching: Vec<bool>,
    /// Whether each cloth vertex is inside the (closed) mesh at this substep (touching too).
    inside: Vec<bool>,
    /// Each cloth vertex's (unsigned) distance from its nearest candidate triangle at this
    /// substep (infinite with none), for the continuous check's first cut.
    distance: Vec<f64>,
    touched: Vec<u32>,
    /// Every list must be looked up again (the mesh moved, or the cloth changed).
    stale: bool,
    /// Entries in all the lists together.
    total: usize,
}

impl Candidates {
    /// Holds nothing, as a new one, but keeps its lists' room: each list is emptied and every
    /// one is looked up again at the next refresh (`stale`). The lists by cloth vertex,
    /// triangle and edge keep their count (the cloth's), and the cloth's edges and incidences
    /// are kept: they are the same cloth's.
    fn empty_keeping_room(&mut self) {
        for list in self
            .vertex
            .iter_mut()
            .chain(&mut self.triangle)
            .chain(&mut self.edge)
        {
            list.clear();
        }
        for list in [
            &mut self.with_vertex,
            &mut self.with_triangle,
            &mut self.with_edge,
            &mut self.looked,
            &mut self.dirty_triangles,
            &mut self.dirty_edges,
            &mut self.nearest,
            &mut self.touched,
            &mut self.pending,
            &mut self.affected,
        ] {
            list.clear();
        }
        for list in [
            &mut self.vertex_slack,
            &mut self.vertex_gap,
            &mut self.triangle_gap,
            &mut self.edge_gap,
        ] {
            list.clear();
        }
        self.looked_now.clear();
        self.touching.clear();
        self.inside.clear();
        self.distance.clear();
        self.stale = true;
        self.total = 0;
    }
}

/// Room for a mesh collider's candidate lists: this many entries a cloth vertex (vertex,
/// triangle and edge lists together) above [`CANDIDATES_FLOOR`]. A cloth near a mesh has a few
/// a vertex (a towel on the 10k-triangle ball: under 10); a margin many times the mesh's
/// triangles across makes every cloth vertex keep every triangle within it, and past this room
/// the step is refused with an error instead of filling memory.
pub const CANDIDATES_PER_VERTEX: usize = 256;
/// Room every cloth has, whatever its size (4 MB of entries).
pub const CANDIDATES_FLOOR: usize = 1 << 20;

/// The entries a mesh collider's candidate lists may hold against a cloth of `vertices`.
pub(crate) fn candidate_room(vertices: usize) -> usize {
    CANDIDATES_PER_VERTEX
        .saturating_mul(vertices)
        .saturating_add(CANDIDATES_FLOOR)
}

/// Refills `list` with what `query` finds (it calls its argument once a feature, and returns
/// the gap to what it did not find) within `room`: the gap, or `None` when the room refused.
fn refill(
    list: &mut Vec<u32>,
    room: &mut Room,
    query: impl FnOnce(&mut dyn FnMut(u32)) -> f64,
) -> Option<f64> {
    room.give_back(list.len());
    list.clear();
    let gap = query(&mut |t| {
        room.push(list, t);
    });
    room.full.is_none().then_some(gap)
}

/// Updates `with` (ascending indices of non-empty `lists`) after the lists of `changed` were
/// looked up again.
fn update_with(with: &mut Vec<u32>, lists: &[Vec<u32>], changed: &[u32]) {
    if changed.is_empty() {
        return;
    }
    with.retain(|&k| !lists[k as usize].is_empty());
    let before = with.len();
    with.extend(changed.iter().filter(|&&k| !lists[k as usize].is_empty()));
    if with.len() > before {
        with.sort_unstable();
        with.dedup();
    }
}

fn check_points(what: &str, p: &[Vec3]) -> Result<(), Error> {
    match p
        .iter()
        .position(|v| !(v.iter().all(|c| c.is_finite()) && v.amax() < 1e15))
    {
        None => Ok(()),
        Some(i) => Err(Error::invalid(format!(
            "mesh collider: {what} {i} is not finite (or beyond 1e15 m): {:?}",
            p[i]
        ))),
    }
}

impl MeshCollider {
    /// A collider of `positions` (m) and `triangles` (indices into them), with the vertices'
    /// velocities (m/s) or `None` (then from the motion between calls).
    pub fn new(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        velocities: Option<&[Vec3]>,
    ) -> Result<MeshCollider, Error> {
        let n = positions.len();
        if n == 0 || triangles.is_empty() {
            return Err(Error::invalid(
                "mesh collider: needs at least one vertex and one triangle",
            ));
        }
        if n > MAX_MESH_COLLIDER_VERTICES || triangles.len() > MAX_MESH_COLLIDER_VERTICES {
            return Err(Error::invalid(format!(
                "mesh collider: at most {MAX_MESH_COLLIDER_VERTICES} vertices and triangles, got {n} and {}",
                triangles.len()
            )));
        }
        if let Some(t) = triangles.iter().position(|t| t.iter().any(|&i| i as usize >= n)) {
            return Err(Error::out_of_range(format!(
                "mesh collider: triangle {t} has index {:?} beyond the {n} vertices",
                triangles[t]
            )));
        }
        check_points("vertex", positions)?;
        crate::memory::ensure_available(
            (n as u64 * 8 + triangles.len() as u64 * 16) * 24,
            "a mesh collider",
        )?;
        let neighbours = neighbours(triangles);
        let closed = neighbours.iter().all(|t| t.iter().all(|&o| o != NONE));
        let mut triangles = triangles.to_vec();
        if closed && signed_volume(positions, &triangles) < 0.0 {
            // Wound inside out (clockwise seen from outside, as after a normals flip): turn
            // every triangle round, so its inside is the mesh's. Edges and neighbours are the
            // same, their order within a triangle is not: recompute.
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        let neighbours = if closed {
            self::neighbours(&triangles)
        } else {
            neighbours
        };
        let mut mesh = MeshCollider {
            triangles,
            neighbours,
            closed,
            start: positions.to_vec(),
            target: positions.to_vec(),
            given_velocity: Vec::new(),
            velocity: vec![Vec3::zeros(); n],
            face_normal: Vec::new(),
            vertex_normal: Vec::new(),
            tri_boxes: Vec::new(),
            vert_boxes: Vec::new(),
            tri_bvh: Bvh::default(),
            vert_bvh: Bvh::default(),
            edges: Vec::new(),
            edge_boxes: Vec::new(),
            edge_bvh: Bvh::default(),
            // Unknown until a call begins: the continuous check then cuts nothing by distance.
            travel: f64::INFINITY,
            fresh_at: f64::NAN,
            friction: 0.0,
            margin: None,
            cache: Candidates::default(),
        };
        mesh.set_velocities(velocities)?;
        Ok(mesh)
    }

    /// New positions (the same vertices, in order) and velocities: where the mesh is at the end
    /// of the next step call.
    pub fn set(&mut self, positions: &[Vec3], velocities: Option<&[Vec3]>) -> Result<(), Error> {
        if positions.len() != self.target.len() {
            return Err(Error::invalid(format!(
                "mesh collider: {} positions given for a mesh of {} vertices (the topology is fixed; remove it and add a new one)",
                positions.len(),
                self.target.len()
            )));
        }
        check_points("vertex", positions)?;
        self.set_velocities(velocities)?;
        // A mesh handed again where it is (a host that sends every collider each frame) keeps
        // its boxes, trees and every cloth element's candidates: nothing moved.
        let same = |a: &Vec3, b: &Vec3| a.iter().zip(b.iter()).all(|(p, q)| p.to_bits() == q.to_bits());
        if !self.target.iter().zip(positions).all(|(a, b)| same(a, b)) {
            self.target.copy_from_slice(positions);
            self.fresh_at = f64::NAN;
        }
        Ok(())
    }

    fn set_velocities(&mut self, velocities: Option<&[Vec3]>) -> Result<(), Error> {
        match velocities {
            Some(v) if v.len() != self.target.len() => Err(Error::invalid(format!(
                "mesh collider: {} velocities for {} vertices",
                v.len(),
                self.target.len()
            ))),
            Some(v) => {
                check_points("velocity", v)?;
                // Into the room of the last call's (a host gives them every frame): no
                // allocation once it holds a mesh's worth, and nothing changed when refused.
                if self.given_velocity.capacity() < v.len() {
                    let mut room = Vec::new();
                    room.try_reserve_exact(v.len()).map_err(|_| {
                        Error::out_of_memory(format!(
                            "mesh collider: the velocities of {} vertices cannot be allocated",
                            v.len()
                        ))
                    })?;
                    self.given_velocity = room;
                }
                self.given_velocity.clear();
                self.given_velocity.extend_from_slice(v);
                Ok(())
            }
            None => {
                self.given_velocity.clear();
                Ok(())
            }
        }
    }

    /// Vertex count.
    pub fn vertex_count(&self) -> usize {
        self.target.len()
    }

    /// The triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Where the host last put the vertices.
    pub fn positions(&self) -> &[Vec3] {
        &self.target
    }

    /// Where the vertices were when the current (or next) call began.
    pub fn start_positions(&self) -> &[Vec3] {
        &self.start
    }

    /// The velocities the host gave, if it gave them.
    pub fn given_velocities(&self) -> Option<&[Vec3]> {
        (!self.given_velocity.is_empty()).then_some(&self.given_velocity[..])
    }

    /// The mean length of its triangles' edges where the host last put it, m (0 with none).
    pub fn mean_edge(&self) -> f64 {
        let x = &self.target;
        let total: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| x[i as usize]);
                (b - a).norm() + (c - b).norm() + (a - c).norm()
            })
            .sum();
        total / (3 * self.triangles.len()).max(1) as f64
    }

    /// Whether every edge joins exactly two triangles (then inside and outside are told apart).
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// A step call of `dt` seconds begins: velocities over it, boxes swept from start to target.
    pub(crate) fn begin_call(&mut self, dt: f64, reach: f64) -> Result<(), Error> {
        if self.given_velocity.is_empty() {
            for ((v, s), t) in self.velocity.iter_mut().zip(&self.start).zip(&self.target) {
                *v = (t - s) / dt;
            }
        } else {
            self.velocity.copy_from_slice(&self.given_velocity);
        }
        self.travel = self
            .start
            .iter()
            .zip(&self.target)
            .map(|(s, t)| (t - s).norm_squared())
            .fold(0.0, f64::max)
            .sqrt();
        self.refresh(reach)
    }

    /// The swept boxes and normals for the mesh's current start and target, if not yet made.
    pub(crate) fn refresh(&mut self, reach: f64) -> Result<(), Error> {
        if self.fresh_at == reach {
            return Ok(());
        }
        // Into the lists of the last refresh (a moving mesh refreshes every call), grown
        // fallibly: the mesh's size is the host's.
        let (t, n) = (self.triangles.len(), self.target.len());
        for list in [&mut self.face_normal, &mut self.vertex_normal] {
            list.clear();
        }
        for list in [&mut self.tri_boxes, &mut self.vert_boxes, &mut self.edge_boxes] {
            list.clear();
        }
        self.edges.clear();
        self.face_normal
            .try_reserve(t)
            .and_then(|()| self.vertex_normal.try_reserve(n))
            .and_then(|()| self.tri_boxes.try_reserve(t))
            .and_then(|()| self.vert_boxes.try_reserve(n))
            // Each triangle has three edges: room for all of them active.
            .and_then(|()| self.edges.try_reserve(3 * t))
            .and_then(|()| self.edge_boxes.try_reserve(3 * t))
            .map_err(|_| self.no_room())?;
        self.face_normal.extend(self.triangles.iter().map(|t| {
            let [a, b, c] = t.map(|i| self.target[i as usize]);
            (b - a)
                .cross(&(c - a))
                .try_normalize(0.0)
                .unwrap_or_else(Vec3::zeros)
        }));
        angle_weighted_normals(&self.target, &self.triangles, &mut self.vertex_normal);
        self.tri_boxes.extend(self.triangles.iter().map(|t| {
            Aabb::of(
                t.iter()
                    .flat_map(|&i| [&self.start[i as usize], &self.target[i as usize]]),
            )
        }));
        self.vert_boxes.extend(
            self.start
                .iter()
                .zip(&self.target)
                .map(|(s, t)| Aabb::of([s, t]).inflated(reach)),
        );
        self.active_edges();
        self.edge_boxes.extend(self.edges.iter().map(|e| {
            Aabb::of(
                e.iter()
                    .flat_map(|&i| [&self.start[i as usize], &self.target[i as usize]]),
            )
            .inflated(reach)
        }));
        // Each tree refit when it holds as many items, else built (a build refused by the
        // allocator last time is made again), split on the pool for a large mesh (the same
        // tree: `bvh.rs`).
        let parallel = |n: usize| crate::parallel::worth_it(n);
        if self.tri_bvh.len() == self.tri_boxes.len() {
            self.tri_bvh.refit(&self.tri_boxes);
        } else {
            self.tri_bvh = Bvh::try_build_on(&self.tri_boxes, parallel(self.tri_boxes.len()))
                .map_err(|_| self.no_room())?;
        }
        if self.vert_bvh.len() == self.vert_boxes.len() {
            self.vert_bvh.refit(&self.vert_boxes);
        } else {
            self.vert_bvh = Bvh::try_build_on(&self.vert_boxes, parallel(self.vert_boxes.len()))
                .map_err(|_| self.no_room())?;
        }
        // The active edges may change as the mesh deforms: rebuilt, unless the same count.
        if self.edge_bvh.len() == self.edge_boxes.len() && !self.edge_bvh.is_empty() {
            self.edge_bvh.refit(&self.edge_boxes);
        } else {
            self.edge_bvh = Bvh::try_build_on(&self.edge_boxes, parallel(self.edge_boxes.len()))
                .map_err(|_| self.no_room())?;
        }
        self.fresh_at = reach;
        self.cache.stale = true;
        Ok(())
    }

    /// Takes the room of `old`'s lists (a collider this one replaces at the same slot of the
    /// same cloth: a snapshot's, when a load is accepted), so this one's first refreshes and
    /// lookups grow nothing. Only room moves: what the lists hold is made again as for a new
    /// collider (this one is not fresh, its candidates all looked up again). The trees move
    /// too when the two meshes have the same triangles (they are refitted to this one's
    /// boxes, as a moving mesh's are from call to call); else this one builds its own.
    pub(crate) fn take_room(&mut self, old: &mut MeshCollider) {
        /// `theirs`'s room for `mine` when larger, emptied (`refresh` fills it again).
        fn larger<T>(mine: &mut Vec<T>, theirs: &mut Vec<T>) {
            if mine.capacity() < theirs.capacity() {
                std::mem::swap(mine, theirs);
                mine.clear();
            }
        }
        larger(&mut self.face_normal, &mut old.face_normal);
        larger(&mut self.vertex_normal, &mut old.vertex_normal);
        larger(&mut self.tri_boxes, &mut old.tri_boxes);
        larger(&mut self.vert_boxes, &mut old.vert_boxes);
        larger(&mut self.edge_boxes, &mut old.edge_boxes);
        larger(&mut self.edges, &mut old.edges);
        if self.triangles == old.triangles && self.tri_bvh.is_empty() {
            std::mem::swap(&mut self.tri_bvh, &mut old.tri_bvh);
            std::mem::swap(&mut self.vert_bvh, &mut old.vert_bvh);
            std::mem::swap(&mut self.edge_bvh, &mut old.edge_bvh);
        }
        self.fresh_at = f64::NAN;
        if self.cache.vertex.is_empty() {
            std::mem::swap(&mut self.cache, &mut old.cache);
            self.cache.empty_keeping_room();
        }
    }

    /// The error when a refresh's lists cannot be allocated (the mesh is left to refresh
    /// again: nothing is marked fresh).
    fn no_room(&self) -> Error {
        Error::out_of_memory(format!(
            "mesh collider of {} triangles: its normals, boxes and trees cannot be allocated",
            self.triangles.len()
        ))
    }

    /// The active edges at the target (face normals already computed): borders, and folds
    /// sharper than [`ACTIVE_EDGE_DEGREES`].
    fn active_edges(&mut self) {
        let cos = ACTIVE_EDGE_DEGREES.to_radians().cos();
        self.edges.clear();
        for (t, (tri, across)) in self.triangles.iter().zip(&self.neighbours).enumerate() {
            for k in 0..3 {
                let n = across[k];
                let active = if n == NONE {
                    true
                } else {
                    (t as u32) < n && self.face_normal[t].dot(&self.face_normal[n as usize]) < cos
                };
                if active {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    self.edges.push([a.min(b), a.max(b)]);
                }
            }
        }
        // An edge of three or more faces appears once per face.
        self.edges.sort_unstable();
        self.edges.dedup();
    }

    /// The call succeeded: the mesh is where the host put it.
    pub(crate) fn arrive(&mut self) {
        if self.start != self.target {
            self.start.copy_from_slice(&self.target);
            self.fresh_at = f64::NAN;
        }
    }

    fn at(&self, i: u32, f: f64) -> Vec3 {
        let i = i as usize;
        self.start[i] + f * (self.target[i] - self.start[i])
    }

    fn corners(&self, t: u32, f: f64) -> [Vec3; 3] {
        self.triangles[t as usize].map(|i| self.at(i, f))
    }

    /// Outward pseudo-normal of the feature of triangle `t` at barycentric weights `w`.
    fn pseudo_normal(&self, t: u32, w: [f64; 3]) -> Vec3 {
        pseudo_normal(
            &self.triangles,
            &self.neighbours,
            &self.face_normal,
            &self.vertex_normal,
            t,
            w,
        )
    }

    /// Unsigned distance from triangle `t` (at fraction `f`) to `p`, the closest point's
    /// weights and the vector from it to `p`.
    fn nearest_on(&self, t: u32, f: f64, p: &Vec3) -> (f64, [f64; 3], Vec3) {
        let [a, b, c] = self.corners(t, f);
        let (w, r) = offset_from_triangle(p, &a, &b, &c);
        (r.norm(), w, r)
    }

    /// Signed distance (negative inside a closed mesh; unsigned on an open one) and outward
    /// direction of a point at unsigned distance `d` and offset `r` from triangle `t`'s point
    /// of weights `w`.
    fn signed(&self, t: u32, d: f64, w: [f64; 3], r: &Vec3) -> (f64, Vec3) {
        let n = self.pseudo_normal(t, w);
        if self.closed {
            let inside = r.dot(&n) < 0.0;
            let dir = if d > 1e-12 && !inside { r / d } else { n };
            (if inside { -d } else { d }, dir)
        } else {
            let dir = if d > 1e-12 { r / d } else { n };
            (d, dir)
        }
    }

    fn surface_velocity(&self, t: u32, w: [f64; 3]) -> Vec3 {
        let tri = &self.triangles[t as usize];
        (0..3).fold(Vec3::zeros(), |s, k| s + w[k] * self.velocity[tri[k] as usize])
    }

    /// The contacts of the cloth (positions `x`, triangles `cloth_triangles`) with this mesh at
    /// fraction `f` of the call, appended to `out`: penetration `margin - d`, at most
    /// `max_depth` (a vertex deep inside is pushed out at a bounded rate).
    #[allow(clippy::too_many_arguments)] // the cloth's arrays and the contact's three lengths
    pub(crate) fn contacts(
        &mut self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        f: f64,
        margin: f64,
        skin: f64,
        max_depth: f64,
        out: &mut Vec<Contact>,
    ) -> Result<(), Full> {
        if let Err(why) = self.refresh_candidates(x, cloth_triangles, margin, skin) {
            self.cache.stale = true;
            return Err(why);
        }
        let c = &mut self.cache;
        c.nearest.resize(x.len(), NONE);
        for &i in &c.touched {
            c.touching[i as usize] = false;
            c.inside[i as usize] = false;
        }
        c.touched.clear();
        c.touching.resize(x.len(), false);
        c.inside.resize(x.len(), false);
        c.distance.resize(x.len(), f64::INFINITY);
        self.vertex_contacts(x, f, margin, max_depth, out);
        self.triangle_contacts(x, cloth_triangles, f, margin, max_depth, out);
        self.edge_contacts(x, f, margin, max_depth, out);
        Ok(())
    }

    /// Each cloth vertex at `x` against its nearest candidate triangle (the mesh at fraction
    /// `f` of the call): a contact within `margin` (depth at most `max_depth`), and what the
    /// other contacts and the continuous check read of it (touching, inside, distance).
    fn vertex_contacts(&mut self, x: &[Vec3], f: f64, margin: f64, max_depth: f64, out: &mut Vec<Contact>) {
        let friction = self.friction;
        for &i in &self.cache.with_vertex {
            let i = i as usize;
            let cands = &self.cache.vertex[i];
            let p = &x[i];
            let mut best: Option<(f64, u32, [f64; 3], Vec3)> = None;
            // The last nearest first; then only triangles whose swept box is not farther than
            // the best so far (the box holds the triangle at every fraction of the call).
            // Nearest by unsigned distance, the lower index among equals (a point on an edge
            // two triangles share is as near to both: the contact does not depend on the
            // order they are tried in); the side only for the nearest.
            let hint = self.cache.nearest.get(i).copied().filter(|t| cands.contains(t));
            for &t in hint.iter().chain(cands.iter().filter(|&&t| Some(t) != hint)) {
                if let Some(b) = &best {
                    if self.tri_boxes[t as usize].distance2(p) > b.0 * b.0 {
                        continue;
                    }
                }
                let (d, w, r) = self.nearest_on(t, f, p);
                if best.is_none_or(|b| d < b.0 || (d == b.0 && t < b.1)) {
                    best = Some((d, t, w, r));
                }
            }
            if let (Some(b), Some(slot)) = (&best, self.cache.nearest.get_mut(i)) {
                *slot = b.1;
            }
            if let Some(slot) = self.cache.distance.get_mut(i) {
                *slot = best.as_ref().map_or(f64::INFINITY, |b| b.0);
            }
            if let Some((d, t, w, r)) = best {
                let (d, dir) = self.signed(t, d, w, &r);
                if d < margin {
                    self.cache.touching[i] = true;
                    self.cache.inside[i] = d < 0.0;
                    self.cache.touched.push(i as u32);
                    out.push(Contact {
                        idx: [i as u32, 0, 0, 0],
                        coef: [1.0, 0.0, 0.0, 0.0],
                        len: 1,
                        dir,
                        depth: (margin - d).min(max_depth),
                        surface_velocity: self.surface_velocity(t, w),
                        friction,
                        scale: 1.0,
                    });
                }
            }
        }
    }

    /// Each mesh vertex against its candidate cloth triangles, where no corner of the triangle
    /// touches the mesh already.
    fn triangle_contacts(
        &self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        f: f64,
        margin: f64,
        max_depth: f64,
        out: &mut Vec<Contact>,
    ) {
        let friction = self.friction;
        for &t in &self.cache.with_triangle {
            let cands = &self.cache.triangle[t as usize];
            let tri = cloth_triangles[t as usize];
            // Where a corner touches the mesh already, its vertex contact holds the triangle:
            // a finely tessellated mesh under the cloth would otherwise push each triangle once
            // per mesh vertex under it, a stiffness that grows with the mesh's resolution.
            if tri.iter().any(|&i| self.cache.touching[i as usize]) {
                continue;
            }
            let [a, b, c] = tri.map(|i| x[i as usize]);
            let near = Aabb::of([&a, &b, &c]).inflated(margin);
            for &m in cands {
                let q = self.at(m, f);
                if !near.contains(&q) {
                    continue;
                }
                let w = closest_on_triangle(&q, &a, &b, &c);
                // Only where the mesh vertex faces the triangle's inside: at an edge or a corner
                // the neighbouring triangle or the vertex contact takes it.
                if w.iter().any(|&wk| wk <= 0.0) {
                    continue;
                }
                let r = w[0] * a + w[1] * b + w[2] * c - q;
                let d = r.norm();
                if d >= margin || d <= 1e-12 {
                    continue;
                }
                out.push(Contact {
                    idx: [tri[0], tri[1], tri[2], 0],
                    coef: [w[0], w[1], w[2], 0.0],
                    len: 3,
                    dir: r / d,
                    depth: (margin - d).min(max_depth),
                    surface_velocity: self.velocity[m as usize],
                    friction,
                    scale: 1.0,
                });
            }
        }
    }

    /// Mesh edge against cloth edge, where the nearest points are inside both edges (at an
    /// end, a vertex contact above takes it) and neither cloth vertex touches the mesh
    /// already: edge contacts catch what the vertices miss (a thin collider between them),
    /// and do not double the push where the cloth lies on the mesh.
    fn edge_contacts(&self, x: &[Vec3], f: f64, margin: f64, max_depth: f64, out: &mut Vec<Contact>) {
        let friction = self.friction;
        for &e in &self.cache.with_edge {
            let cands = &self.cache.edge[e as usize];
            let [i0, i1] = self.cache.cloth_edges[e as usize];
            if self.cache.touching[i0 as usize] || self.cache.touching[i1 as usize] {
                continue;
            }
            let (p0, p1) = (x[i0 as usize], x[i1 as usize]);
            for &m in cands {
                let [j0, j1] = self.edges[m as usize];
                let (q0, q1) = (self.at(j0, f), self.at(j1, f));
                let (s, t) = closest_on_segments(&p0, &p1, &q0, &q1);
                if !(s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) {
                    continue;
                }
                let r = (p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0));
                let d = r.norm();
                if d >= margin || d <= 1e-12 {
                    continue;
                }
                let (v0, v1) = (self.velocity[j0 as usize], self.velocity[j1 as usize]);
                out.push(Contact {
                    idx: [i0, i1, 0, 0],
                    coef: [1.0 - s, s, 0.0, 0.0],
                    len: 2,
                    dir: r / d,
                    depth: (margin - d).min(max_depth),
                    surface_velocity: v0 + t * (v1 - v0),
                    friction,
                    scale: 1.0,
                });
            }
        }
    }

    /// The cloth's passages through this mesh over a step (continuous check, `ccd.rs`): the
    /// cloth moving from `x0` to `x1` and the mesh from fraction `f0` to `f1` of the call, each
    /// cloth vertex against its candidate triangles, each cloth triangle against its candidate
    /// mesh vertices and each cloth edge against its candidate active edges. Each passage is
    /// appended to `out` as the cloth vertices it takes and the mesh's displacement there over
    /// the step (the mean of the mesh element's vertices'), which carries them.
    #[allow(clippy::too_many_arguments)] // the cloth's arrays, the step's ends and the tolerance
    pub(crate) fn passages(
        &self,
        x0: &[Vec3],
        x1: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        f0: f64,
        f1: f64,
        tolerance: f64,
        out: &mut Vec<MeshPassage>,
    ) {
        let c = &self.cache;
        // A closed mesh has an inside: a vertex found there is being pushed out, and its way
        // out through the surface is not stopped (nor are its triangles' and edges').
        let inside = |i: u32| self.closed && c.inside.get(i as usize).copied().unwrap_or(false);
        let path = |i: u32| (x0[i as usize], x1[i as usize]);
        let mesh_path = |m: u32| (self.at(m, f0), self.at(m, f1));
        let carry = |ms: &[u32]| {
            ms.iter()
                .fold(Vec3::zeros(), |s, &m| s + (self.at(m, f1) - self.at(m, f0)))
                / ms.len() as f64
        };
        // Swept boxes first: a passage needs the two elements' boxes over the step to meet.
        let swept = |ps: &[(Vec3, Vec3)]| Aabb::of(ps.iter().flat_map(|p| [&p.0, &p.1])).inflated(tolerance);
        // No part of the mesh moves farther than this in the step.
        let travel = (f1 - f0).abs() * self.travel + tolerance;
        for &i in &c.with_vertex {
            let pi = path(i);
            // A vertex farther from the mesh (where it starts, from where the mesh ends) than
            // both can move in the step meets none of its triangles.
            let reach = (pi.1 - pi.0).norm() + travel;
            if c.distance.get(i as usize).is_none_or(|&d| d > reach) {
                continue;
            }
            let own = swept(&[pi]);
            for &t in &c.vertex[i as usize] {
                let [a, b, m] = self.triangles[t as usize];
                let p: Path = [mesh_path(a), mesh_path(b), mesh_path(m), pi];
                if !own.overlaps(&swept(&p[..3])) {
                    continue;
                }
                // Through a closed mesh's face from behind it (the faces wind outwards): on
                // its way out.
                if self.closed && start_sign(&p) < 0 {
                    continue;
                }
                if vertex_passes_triangle(&p, tolerance).is_some() {
                    out.push(MeshPassage {
                        cloth: [i, i, i],
                        carry: carry(&[a, b, m]),
                    });
                }
            }
        }
        for &t in &c.with_triangle {
            let tri = cloth_triangles[t as usize];
            if tri.iter().any(|&i| inside(i)) {
                continue;
            }
            let corners = tri.map(path);
            let own = swept(&corners);
            for &m in &c.triangle[t as usize] {
                let q = mesh_path(m);
                if !own.overlaps(&swept(&[q])) {
                    continue;
                }
                let p: Path = [corners[0], corners[1], corners[2], q];
                if vertex_passes_triangle(&p, tolerance).is_some() {
                    out.push(MeshPassage {
                        cloth: tri,
                        carry: carry(&[m]),
                    });
                }
            }
        }
        for &e in &c.with_edge {
            let [i0, i1] = c.cloth_edges[e as usize];
            if inside(i0) || inside(i1) {
                continue;
            }
            let ends = [path(i0), path(i1)];
            let own = swept(&ends);
            for &m in &c.edge[e as usize] {
                let [j0, j1] = self.edges[m as usize];
                let other = [mesh_path(j0), mesh_path(j1)];
                if !own.overlaps(&swept(&other)) {
                    continue;
                }
                let p: Path = [ends[0], ends[1], other[0], other[1]];
                if edge_passes_edge(&p, tolerance).is_some() {
                    out.push(MeshPassage {
                        cloth: [i0, i1, i1],
                        carry: carry(&[j0, j1]),
                    });
                }
            }
        }
    }

    /// Looks up again the candidates of every cloth vertex that moved more than its slack
    /// since it last looked, and of its triangles and edges (all of them after the mesh moved).
    /// Refused past the lists' room ([`CANDIDATES_PER_VERTEX`]); the caller then marks every
    /// list to be looked up again.
    ///
    /// **Why the lists stay whole.** Each lookup also returns its gap `G`: how far its query
    /// box is from every box it did not find, along the axis they are furthest apart on. A
    /// vertex's slack is `skin / 2 + min(G) / 2` over its own lookup and its triangles' and
    /// edges' (the rule before gaps, `skin / 2`, when every `G` is 0), recomputed whenever one
    /// of them looks. Then:
    /// - *the vertex's own list*: it has moved at most its slack, under `skin + G_v`, since
    ///   its query box (`margin + skin` around it) missed every other triangle's box by `G_v`;
    ///   so no triangle it did not find comes within `margin` of it;
    /// - *a triangle's (an edge's) list*: each of its vertices has moved at most twice its
    ///   slack, `skin + G_t`, since the triangle looked (it was within its slack of where it
    ///   last looked both then and now, and its slack held `G_t` from then on; a vertex past
    ///   the new slack when the triangle looks, looks with it). The query took the triangle's
    ///   box grown by `skin` against the mesh vertices' boxes grown by `margin + skin`, so a
    ///   mesh vertex it did not find is `2 skin + margin + G_t` from where the box was, and
    ///   the box has moved at most `skin + G_t`: still past `margin`.
    ///
    /// So what each list holds within `margin` (the contacts) is what a fresh lookup finds;
    /// far from the mesh, where nearly every lookup finds nothing, the gaps let the cloth
    /// move much further between lookups.
    fn refresh_candidates(
        &mut self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        margin: f64,
        skin: f64,
    ) -> Result<(), Full> {
        // The lists apart from the mesh they are looked up in, for the refresh's steps.
        let mut c = std::mem::take(&mut self.cache);
        let done = self.refresh_lists(&mut c, x, cloth_triangles, margin + skin, skin);
        self.cache = c;
        done
    }

    /// [`Self::refresh_candidates`] on the lists `c`, `reach` the margin and the skin.
    fn refresh_lists(
        &self,
        c: &mut Candidates,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        reach: f64,
        skin: f64,
    ) -> Result<(), Full> {
        let capacity = candidate_room(x.len());
        let all = c.prepare(x, cloth_triangles);
        let mut room = Room::new(capacity.saturating_sub(c.total));
        // The entries the lists hold once the room is spent as far as it is.
        let refused = |c: &mut Candidates, room: &Room| {
            c.total = capacity - room.left();
            for &i in c.looked.iter().chain(&c.pending) {
                c.looked_now[i as usize] = false;
            }
            Err(room.full.unwrap_or(Full::Entries))
        };
        c.looked.clear();
        c.dirty_triangles.clear();
        c.dirty_edges.clear();
        c.pending.clear();
        c.pending.extend((0..x.len() as u32).filter(|&i| {
            all || moved(
                &c.vertex_at[i as usize],
                &x[i as usize],
                c.vertex_slack[i as usize],
            )
        }));
        // Rounds: the vertices that moved past their slack look, with their triangles and
        // edges; a vertex of those triangles and edges that is past its new slack looks in the
        // next round (rarely more than one).
        while !c.pending.is_empty() {
            let from = (c.dirty_triangles.len(), c.dirty_edges.len());
            for k in 0..c.pending.len() {
                let i = c.pending[k] as usize;
                if !self.vertex_looks(c, &mut room, x, i, reach) {
                    return refused(c, &room);
                }
                if !all {
                    c.dirty_triangles.extend_from_slice(c.vertex_triangles.row(i));
                    c.dirty_edges.extend_from_slice(c.vertex_edges.row(i));
                }
            }
            if all {
                c.dirty_triangles.extend(0..cloth_triangles.len() as u32);
                c.dirty_edges.extend(0..c.cloth_edges.len() as u32);
            } else {
                sort_dedup_tail(&mut c.dirty_triangles, from.0);
                sort_dedup_tail(&mut c.dirty_edges, from.1);
            }
            if !self.dirty_look(c, &mut room, x, cloth_triangles, skin, from) {
                return refused(c, &room);
            }
            c.next_round(x, cloth_triangles, skin, all, from);
        }
        c.finish(all);
        c.total = capacity - room.left();
        Ok(())
    }

    /// Cloth vertex `i` at `x` looks up its candidate triangles within `reach` into its list
    /// (in `room`); one that finds none inside a closed mesh takes the nearest of the whole
    /// mesh. False when the room is spent.
    fn vertex_looks(&self, c: &mut Candidates, room: &mut Room, x: &[Vec3], i: usize, reach: f64) -> bool {
        let p = x[i];
        c.vertex_at[i] = p;
        c.looked_now[i] = true;
        c.looked.push(i as u32);
        let q = Aabb { min: p, max: p }.inflated(reach);
        let Some(gap) = refill(&mut c.vertex[i], room, |push| {
            self.tri_bvh.overlapping_apart(&q, push)
        }) else {
            return false;
        };
        c.vertex_gap[i] = gap;
        let list = &mut c.vertex[i];
        if list.is_empty() && self.closed && self.tri_bvh.bounds().contains(&p) {
            // Possibly deep inside: the nearest triangle of the whole mesh decides.
            let (tris, target) = (&self.triangles, &self.target);
            let nearest = self.tri_bvh.nearest(&p, f64::INFINITY, |t| {
                closest_at(target, &tris[t as usize], &p).1.norm_squared()
            });
            if let Some((t, _)) = nearest {
                if !room.push(list, t) {
                    return false;
                }
                // Inside, the nearest of the whole mesh changes with every move: looked up
                // again at the next substep (outside, it is beyond reach: no contact).
                let (w, r) = closest_at(target, &tris[t as usize], &p);
                let n = pseudo_normal(
                    tris,
                    &self.neighbours,
                    &self.face_normal,
                    &self.vertex_normal,
                    t,
                    w,
                );
                if r.dot(&n) < 0.0 {
                    c.vertex_at[i] = Vec3::repeat(f64::INFINITY);
                }
            }
        }
        true
    }

    /// The cloth triangles and edges made dirty in this round (from `from`) look up their
    /// candidate mesh vertices and edges (the mesh's boxes hold the reach already; theirs grow
    /// by the skin). False when the room is spent.
    fn dirty_look(
        &self,
        c: &mut Candidates,
        room: &mut Room,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        skin: f64,
        (triangles_from, edges_from): (usize, usize),
    ) -> bool {
        for &t in &c.dirty_triangles[triangles_from..] {
            let tri = &cloth_triangles[t as usize];
            let q = Aabb::of(tri.iter().map(|&i| &x[i as usize])).inflated(skin);
            let Some(gap) = refill(&mut c.triangle[t as usize], room, |push| {
                self.vert_bvh.overlapping_apart(&q, push)
            }) else {
                return false;
            };
            c.triangle_gap[t as usize] = gap;
        }
        for &e in &c.dirty_edges[edges_from..] {
            let [i0, i1] = c.cloth_edges[e as usize];
            let q = Aabb::of([&x[i0 as usize], &x[i1 as usize]]).inflated(skin);
            let Some(gap) = refill(&mut c.edge[e as usize], room, |push| {
                self.edge_bvh.overlapping_apart(&q, push)
            }) else {
                return false;
            };
            c.edge_gap[e as usize] = gap;
        }
        true
    }
}

/// Whether a vertex at `p` has moved past `slack` from `at`.
fn moved(at: &Vec3, p: &Vec3, slack: f64) -> bool {
    (p - at).norm_squared() > slack * slack
}

impl Candidates {
    /// Sizes the lists for a cloth at `x` of `cloth_triangles` (its edges and incidences
    /// found once); whether every list is looked up again (the mesh moved, or the cloth
    /// changed), every list then emptied.
    fn prepare(&mut self, x: &[Vec3], cloth_triangles: &[[u32; 3]]) -> bool {
        let c = self;
        let resized = c.vertex.len() != x.len() || c.triangle.len() != cloth_triangles.len();
        if resized || c.cloth_edges.is_empty() {
            // The cloth's edges and incidences once (a moving mesh makes every call `all`).
            c.cloth_edges = edges_of(cloth_triangles);
            c.vertex_triangles = Adjacency::triangles(x.len(), cloth_triangles);
            c.vertex_edges = Adjacency::edges(x.len(), &c.cloth_edges);
        }
        let all = c.stale || resized;
        if all {
            c.vertex.resize_with(x.len(), Vec::new);
            c.vertex_at.resize(x.len(), Vec3::zeros());
            c.triangle.resize_with(cloth_triangles.len(), Vec::new);
            c.edge.resize_with(c.cloth_edges.len(), Vec::new);
            for list in c.vertex.iter_mut().chain(&mut c.triangle).chain(&mut c.edge) {
                list.clear();
            }
            // Every list is looked up below, and every gap with it.
            c.vertex_slack.resize(x.len(), 0.0);
            c.vertex_gap.resize(x.len(), 0.0);
            c.triangle_gap.resize(cloth_triangles.len(), 0.0);
            c.edge_gap.resize(c.cloth_edges.len(), 0.0);
            c.looked_now.resize(x.len(), false);
            c.total = 0;
            c.stale = false;
        }
        all
    }

    /// The new slacks of the vertices that looked in this round and of every vertex of the
    /// triangles and edges that looked (from `from`; a vertex in no triangle has only its own
    /// lookup): those past theirs look in the next round.
    fn next_round(
        &mut self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        skin: f64,
        all: bool,
        (triangles_from, edges_from): (usize, usize),
    ) {
        let c = self;
        c.affected.clear();
        if all {
            c.affected.extend(0..x.len() as u32);
        } else {
            c.affected.extend_from_slice(&c.pending);
            c.affected.extend(
                c.dirty_triangles[triangles_from..]
                    .iter()
                    .flat_map(|&t| cloth_triangles[t as usize])
                    .chain(
                        c.dirty_edges[edges_from..]
                            .iter()
                            .flat_map(|&e| c.cloth_edges[e as usize]),
                    ),
            );
            sort_dedup_tail(&mut c.affected, 0);
        }
        c.pending.clear();
        for &b in &c.affected {
            let b = b as usize;
            let gap = c
                .vertex_triangles
                .row(b)
                .iter()
                .map(|&t| c.triangle_gap[t as usize])
                .chain(c.vertex_edges.row(b).iter().map(|&e| c.edge_gap[e as usize]))
                .fold(c.vertex_gap[b], f64::min);
            let slack = if skin > 0.0 { 0.5 * (skin + gap) } else { 0.0 };
            c.vertex_slack[b] = slack;
            if !c.looked_now[b] && moved(&c.vertex_at[b], &x[b], slack) {
                c.looked_now[b] = true;
                c.pending.push(b as u32);
            }
        }
    }

    /// The refresh is done: the looked flags cleared, the dirty lists each once, and the
    /// lists of what has candidates brought up to date.
    fn finish(&mut self, all: bool) {
        let c = self;
        for &i in &c.looked {
            c.looked_now[i as usize] = false;
        }
        if !all {
            c.dirty_triangles.sort_unstable();
            c.dirty_triangles.dedup();
            c.dirty_edges.sort_unstable();
            c.dirty_edges.dedup();
        }
        if all {
            c.with_vertex.clear();
            c.with_triangle.clear();
            c.with_edge.clear();
        }
        update_with(&mut c.with_vertex, &c.vertex, &c.looked);
        update_with(&mut c.with_triangle, &c.triangle, &c.dirty_triangles);
        update_with(&mut c.with_edge, &c.edge, &c.dirty_edges);
    }
}

/// Sorts `list[from..]` and removes its repeats in place, leaving `list[..from]` as it is.
fn sort_dedup_tail(list: &mut Vec<u32>, from: usize) {
    list[from..].sort_unstable();
    let mut kept = from;
    for k in from..list.len() {
        if k == from || list[k] != list[kept - 1] {
            list[kept] = list[k];
            kept += 1;
        }
    }
    list.truncate(kept);
}

/// The weights of the point of triangle `tri` (of vertices `x`) nearest to `p`, and the vector
/// from that point to `p`.
fn closest_at(x: &[Vec3], tri: &[u32; 3], p: &Vec3) -> ([f64; 3], Vec3) {
    let [a, b, c] = tri.map(|k| x[k as usize]);
    offset_from_triangle(p, &a, &b, &c)
}

/// Outward pseudo-normal of the feature of triangle `t` (of a mesh with these neighbours,
/// face normals and vertex normals) at barycentric weights `w`.
fn pseudo_normal(
    triangles: &[[u32; 3]],
    neighbours: &[[u32; 3]],
    face_normal: &[Vec3],
    vertex_normal: &[Vec3],
    t: u32,
    w: [f64; 3],
) -> Vec3 {
    let tri = &triangles[t as usize];
    let face = face_normal[t as usize];
    match [w[0] <= 0.0, w[1] <= 0.0, w[2] <= 0.0] {
        // On the edge opposite corner z: edge (z+1, z+2), which is edge index (z+1) % 3.
        [true, false, false] | [false, true, false] | [false, false, true] => {
            let z = w.iter().position(|&wk| wk <= 0.0).unwrap_or(0);
            let o = neighbours[t as usize][(z + 1) % 3];
            if o == NONE {
                face
            } else {
                (face + face_normal[o as usize])
                    .try_normalize(0.0)
                    .unwrap_or(face)
            }
        }
        // At the corner whose weight is not zero.
        [false, true, true] => vertex_normal[tri[0] as usize],
        [true, false, true] => vertex_normal[tri[1] as usize],
        [true, true, false] => vertex_normal[tri[2] as usize],
        _ => face,
    }
}

/// Signed volume enclosed by closed triangles (positive when they face outward).
fn signed_volume(x: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| x[i as usize]);
            a.dot(&b.cross(&c))
        })
        .sum::<f64>()
        / 6.0
}

/// The triangle across each edge (corner k to corner k+1) of each triangle, if exactly one.
fn neighbours(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), t as u32, k as u8));
        }
    }
    edges.sort_unstable();
    let mut out = vec![[NONE; 3]; triangles.len()];
    let mut k = 0;
    while k < edges.len() {
        let mut e = k + 1;
        while e < edges.len() && (edges[e].0, edges[e].1) == (edges[k].0, edges[k].1) {
            e += 1;
        }
        if e - k == 2 {
            let (p, q) = (edges[k], edges[k + 1]);
            out[p.2 as usize][p.3 as usize] = q.2;
            out[q.2 as usize][q.3 as usize] = p.2;
        }
        k = e;
    }
    out
}

/// Each vertex's normal, the sum of its triangles' unit normals weighted by their angles there.
/// Into `n`, which has room for one a vertex.
fn angle_weighted_normals(x: &[Vec3], triangles: &[[u32; 3]], n: &mut Vec<Vec3>) {
    n.clear();
    n.resize(x.len(), Vec3::zeros());
    for tri in triangles {
        let p = tri.map(|i| x[i as usize]);
        let Some(face) = (p[1] - p[0]).cross(&(p[2] - p[0])).try_normalize(0.0) else {
            continue;
        };
        for k in 0..3 {
            let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let angle = u.angle(&v);
            if angle.is_finite() {
                n[tri[k] as usize] += angle * face;
            }
        }
    }
    for v in n.iter_mut() {
        *v = v.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
    }
}

#[cfg(test)]
mod tests {
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
}
