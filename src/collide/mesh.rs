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

mod candidates;
mod contacts;
mod passages;
#[cfg(test)]
mod tests;

pub(crate) use candidates::candidate_room;
use candidates::Candidates;
pub use candidates::{CANDIDATES_FLOOR, CANDIDATES_PER_VERTEX};

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
