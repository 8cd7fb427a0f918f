//! Impact zones (Provot 1997; Bridson, Fedkiw and Anderson 2002), the fail-safe after a step
//! with self-collision: where a vertex would pass through a triangle, or an edge through an
//! edge, during the step (continuous check, `ccd.rs`), the four vertices are joined into a
//! zone that moves as one, and zones are joined until no listed pair passes.
//!
//! A zone moves by a translation: its free vertices' mass-weighted mean displacement (their
//! momentum kept), or, where the zone holds kinematic vertices (hard pins), the mean of
//! theirs, so a point pressed by a pinned row is carried with it instead of through it. A
//! translation keeps the zone's shape, so pairs inside a zone without kinematic vertices
//! cannot pass each other. The contacts' penalty keeps the thickness; the zones only stop a
//! passage the penalty failed to stop, so a step without one is left exactly as it was.

use super::ccd::{edge_passes_edge, start_sign, vertex_passes_triangle, Path};
use super::geometry::segment_crosses_triangle;
use super::pair::Pair;
use crate::math::Vec3;
use crate::topology::Adjacency;

/// At most this many rounds of finding passages and joining zones.
pub const MAX_ROUNDS: usize = 64;

/// What the zones did in a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ZoneReport {
    /// Passages found in the first round (0: the step was left as it was).
    pub passages: usize,
    /// Free vertices moved with a zone.
    pub moved: usize,
    /// Passages left when the rounds stopped (zones with kinematic vertices that move
    /// apart, or the rounds used up): 0 when every listed pair was kept from passing.
    pub unresolved: usize,
}

/// What the impact zones did over many steps (summed [`ZoneReport`]s).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ZoneTotals {
    /// Steps in which some pair would have passed through another.
    pub steps: u64,
    /// Passages found (in the first round of each step).
    pub passages: u64,
    /// Free vertices moved with a zone, summed over the steps.
    pub moved: u64,
    /// Passages left after the zones (0: every listed pair was kept from passing).
    pub unresolved: u64,
}

impl ZoneTotals {
    pub(crate) fn add(&mut self, r: &ZoneReport) {
        if r.passages > 0 {
            self.steps += 1;
        }
        self.passages += r.passages as u64;
        self.moved += r.moved as u64;
        self.unresolved += r.unresolved as u64;
    }
}

/// The step's geometry: where the vertices start and what the pairs are made of.
pub struct ZoneInput<'a> {
    pub x0: &'a [Vec3],
    pub masses: &'a [f64],
    pub kinematic: &'a [bool],
    pub triangles: &'a [[u32; 3]],
    pub edges: &'a [[u32; 2]],
    /// The triangles of each vertex.
    pub vertex_triangles: &'a Adjacency,
    /// Each vertex's neighbour triangles (near it at rest, so never listed) as compressed rows
    /// `(starts, triangles)`; empty rows for none. Checked around the vertices a zone moved:
    /// a zone's translation shears the triangles at its border, and a vertex may pass
    /// through a neighbouring triangle there.
    pub neighbours: (&'a [u32], &'a [u32]),
    /// Vertex-triangle pairs `(vertex, triangle, _)` and edge-edge pairs `(edge, edge, _)`.
    /// Every passage of a pair not tangled at the start is stopped, whatever side the pair
    /// remembers: a cloth that starts the step without crossing itself ends it without (for
    /// the pairs listed). A pair tangled at the start (an edge of the vertex's triangles
    /// through the triangle; an edge through a triangle of the other edge) may pass: that
    /// is the way out of a crossing made where no pair was listed (neighbours at rest).
    pub vertex_triangle: &'a [Pair],
    pub edge_edge: &'a [Pair],
    /// How near the points must come at a coplanar instant to meet, m.
    pub tolerance: f64,
    /// Edge-edge neighbour pairs `(edge, edge)` (near each other at rest, so never listed,
    /// sharing no vertex) checked like the listed pairs, at every round: across a fold the
    /// parallel diagonals of two adjacent cells pass through each other with no listed pair
    /// passing (`SelfCollision::guarded`: those that might in this step).
    pub guard: &'a [(u32, u32)],
    /// Vertex-triangle neighbour pairs `(vertex, triangle)` (near each other at rest, the
    /// vertex not the triangle's) checked the same way: a vertex folded through a triangle
    /// beside it (`SelfCollision::guarded`).
    pub guard_vertices: &'a [(u32, u32)],
}

/// A pair, by its place in its list (or a neighbour pair, in none).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairRef {
    VertexTriangle(u32),
    EdgeEdge(u32),
    Neighbour,
}

/// A pair that would pass in the step: its four vertices, and the sign its coplanarity cubic
/// had at the start ([`start_sign`]: for a vertex over a triangle's face, or two edges'
/// interior closest points, the side they are on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passage {
    pub vs: [u32; 4],
    pub pair: PairRef,
    pub sign: i8,
}

/// The buffers [`keep_from_passing`] reuses from step to step: once grown, a step with
/// passages allocates nothing (and the union-find's, one number a vertex, is reserved
/// fallibly).
#[derive(Clone, Debug, Default)]
pub struct ZoneScratch {
    passing: Vec<Passage>,
    members: Vec<u32>,
    seen: Vec<u32>,
    parent: Vec<u32>,
    sums: Vec<ZoneSums>,
}

/// Per zone root: the sums of its free vertices' mass-weighted displacements and masses, and of
/// its kinematic vertices' displacements and count.
type ZoneSums = (u32, Vec3, f64, Vec3, f64);

/// Union-find over the vertices.
struct Zones<'a> {
    parent: &'a mut [u32],
}

impl Zones<'_> {
    fn root(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let p = self.parent[i as usize];
            self.parent[i as usize] = self.parent[p as usize];
            i = p;
        }
        i
    }

    /// Joins the zones of `vs`; says whether any two were apart. The smaller root stays the
    /// root, so the zones do not depend on the order the pairs come in.
    fn join(&mut self, vs: [u32; 4]) -> bool {
        let mut joined = false;
        for &v in &vs[1..] {
            let (a, b) = (self.root(vs[0]), self.root(v));
            if a != b {
                self.parent[a.max(b) as usize] = a.min(b);
                joined = true;
            }
        }
        joined
    }
}

impl ZoneInput<'_> {
    /// Whether segment `a b` crosses a triangle of the vertex `v` that also holds `w` (every
    /// triangle of `v` when `w` is `v`), at the start.
    fn crosses_star(&self, a: u32, b: u32, v: u32, w: u32) -> bool {
        let x = self.x0;
        self.vertex_triangles.row(v as usize).iter().any(|&t| {
            let tri = self.triangles[t as usize];
            tri.contains(&w)
                && !tri.contains(&a)
                && !tri.contains(&b)
                && segment_crosses_triangle(
                    &x[a as usize],
                    &x[b as usize],
                    &x[tri[0] as usize],
                    &x[tri[1] as usize],
                    &x[tri[2] as usize],
                )
        })
    }

    /// Vertex `p` and triangle `t` tangled at the start: an edge from `p` (of its triangles)
    /// through `t`.
    fn vertex_tangled(&self, p: u32, t: [u32; 3]) -> bool {
        let x = self.x0;
        let [a, b, c] = t.map(|i| x[i as usize]);
        self.vertex_triangles.row(p as usize).iter().any(|&s| {
            self.triangles[s as usize].iter().any(|&q| {
                q != p
                    && !t.contains(&q)
                    && segment_crosses_triangle(&x[p as usize], &x[q as usize], &a, &b, &c)
            })
        })
    }

    /// Edges `e` and `f` tangled at the start: one through a triangle of the other.
    fn edges_tangled(&self, e: [u32; 2], f: [u32; 2]) -> bool {
        self.crosses_star(e[0], e[1], f[0], f[1]) || self.crosses_star(f[0], f[1], e[0], e[1])
    }

    /// The neighbour pairs (vertex, triangle near it at rest, sharing no vertex) of the
    /// vertices `around` and of the corners of their neighbour triangles that pass in the
    /// step `x0 -> x1`, appended to `out`.
    fn neighbour_passages(&self, x1: &[Vec3], around: &[u32], seen: &mut Vec<u32>, out: &mut Vec<Passage>) {
        let (starts, rows) = self.neighbours;
        if starts.len() != self.x0.len() + 1 {
            return;
        }
        let row = |p: u32| &rows[starts[p as usize] as usize..starts[p as usize + 1] as usize];
        seen.clear();
        for &m in around {
            seen.push(m);
            for &t in row(m) {
                seen.extend_from_slice(&self.triangles[t as usize]);
            }
        }
        seen.sort_unstable();
        seen.dedup();
        for &p in seen.iter() {
            for &t in row(p) {
                if !self.triangles[t as usize].contains(&p) {
                    out.extend(self.vertex_passage(x1, p, t, PairRef::Neighbour));
                }
            }
        }
    }

    /// Whether any of `vs` moves in the step `x0 -> x1`.
    fn moving(&self, x1: &[Vec3], vs: &[u32; 4]) -> bool {
        vs.iter().any(|&i| x1[i as usize] != self.x0[i as usize])
    }

    /// Vertex `p`'s passage through triangle `t` in the step `x0 -> x1`, as `pair`: none if
    /// they do not move, do not meet, or are tangled at the start.
    fn vertex_passage(&self, x1: &[Vec3], p: u32, t: u32, pair: PairRef) -> Option<Passage> {
        let tri = self.triangles[t as usize];
        self.passage(
            x1,
            [tri[0], tri[1], tri[2], p],
            pair,
            vertex_passes_triangle,
            || self.vertex_tangled(p, tri),
        )
    }

    /// The passage of the four vertices `vs` in the step `x0 -> x1` by the test `meets`, as
    /// `pair`: none if they do not move, do not meet, or are `tangled` at the start.
    fn passage(
        &self,
        x1: &[Vec3],
        vs: [u32; 4],
        pair: PairRef,
        meets: fn(&Path, f64) -> Option<f64>,
        tangled: impl FnOnce() -> bool,
    ) -> Option<Passage> {
        if !self.moving(x1, &vs) {
            return None;
        }
        let path = self.path(x1, vs);
        (meets(&path, self.tolerance).is_some() && !tangled()).then(|| Passage {
            vs,
            pair,
            sign: start_sign(&path),
        })
    }

    fn path(&self, x1: &[Vec3], vs: [u32; 4]) -> Path {
        vs.map(|i| (self.x0[i as usize], x1[i as usize]))
    }

    /// The pairs that pass in the step `x0 -> x1`, as their four vertices.
    fn passages(&self, x1: &[Vec3], out: &mut Vec<Passage>) {
        out.clear();
        for (k, &(p, t, _)) in self.vertex_triangle.iter().enumerate() {
            out.extend(self.vertex_passage(x1, p, t, PairRef::VertexTriangle(k as u32)));
        }
        for (k, &(e, f, _)) in self.edge_edge.iter().enumerate() {
            out.extend(self.edge_passage(x1, e, f, PairRef::EdgeEdge(k as u32)));
        }
        for &(e, f) in self.guard {
            out.extend(self.edge_passage(x1, e, f, PairRef::Neighbour));
        }
        for &(p, t) in self.guard_vertices {
            out.extend(self.vertex_passage(x1, p, t, PairRef::Neighbour));
        }
    }

    /// Edge `e`'s passage through edge `f` in the step `x0 -> x1`, as `pair`: none if they do
    /// not move, do not meet, or are tangled at the start.
    fn edge_passage(&self, x1: &[Vec3], e: u32, f: u32, pair: PairRef) -> Option<Passage> {
        let (edge, other) = (self.edges[e as usize], self.edges[f as usize]);
        self.passage(
            x1,
            [edge[0], edge[1], other[0], other[1]],
            pair,
            edge_passes_edge,
            || self.edges_tangled(edge, other),
        )
    }
}

/// Moves the proposed positions `x1` so that no listed pair passes through another in the
/// step from `input.x0`, by impact zones (module docs). `moved` receives the free vertices
/// moved (ascending), whose velocities the caller makes their new displacement over the step;
/// `stopped` every passage stopped (in the order found, a pair once for each round it was
/// found in), whose sides the caller learns afresh.
pub fn keep_from_passing(
    input: &ZoneInput,
    x1: &mut [Vec3],
    moved: &mut Vec<u32>,
    stopped: &mut Vec<Passage>,
    scratch: &mut ZoneScratch,
) -> Result<ZoneReport, std::collections::TryReserveError> {
    moved.clear();
    stopped.clear();
    let ZoneScratch {
        passing,
        members,
        seen,
        parent,
        sums,
    } = scratch;
    input.passages(x1, passing);
    members.clear();
    let mut report = ZoneReport {
        passages: passing.len(),
        ..ZoneReport::default()
    };
    if passing.is_empty() {
        return Ok(report);
    }
    let n = input.x0.len();
    parent.clear();
    parent.try_reserve(n)?;
    parent.extend(0..n as u32);
    let mut zones = Zones { parent };
    for _ in 0..MAX_ROUNDS {
        let mut joined = false;
        for p in passing.iter() {
            joined |= zones.join(p.vs);
            members.extend_from_slice(&p.vs);
        }
        stopped.extend_from_slice(passing);
        if !joined {
            // Every passage is inside a zone already moved as one: zones whose kinematic
            // vertices move apart. Nothing more a translation can do.
            break;
        }
        members.sort_unstable();
        members.dedup();
        move_zones(input, &mut zones, members, sums, x1);
        input.passages(x1, passing);
        input.neighbour_passages(x1, members, seen, passing);
        if passing.is_empty() {
            break;
        }
    }
    report.unresolved = passing.len();
    moved.extend(members.iter().copied().filter(|&i| !input.kinematic[i as usize]));
    report.moved = moved.len();
    Ok(report)
}

/// Moves every zone touching `members` by its translation (module docs).
fn move_zones(
    input: &ZoneInput,
    zones: &mut Zones,
    members: &[u32],
    sums: &mut Vec<ZoneSums>,
    x1: &mut [Vec3],
) {
    // Per root: sums of (mass-weighted free, kinematic) displacements and their weights.
    sums.clear();
    for &i in members {
        let r = zones.root(i);
        let k = match sums.binary_search_by_key(&r, |s| s.0) {
            Ok(k) => k,
            Err(k) => {
                sums.insert(k, (r, Vec3::zeros(), 0.0, Vec3::zeros(), 0.0));
                k
            }
        };
        let d = x1[i as usize] - input.x0[i as usize];
        let s = &mut sums[k];
        if input.kinematic[i as usize] {
            s.3 += d;
            s.4 += 1.0;
        } else {
            let m = input.masses[i as usize];
            s.1 += m * d;
            s.2 += m;
        }
    }
    for &i in members {
        if input.kinematic[i as usize] {
            continue;
        }
        let r = zones.root(i);
        let Ok(k) = sums.binary_search_by_key(&r, |s| s.0) else {
            continue;
        };
        let (_, free, mass, kin, count) = sums[k];
        let d = if count > 0.0 {
            kin / count
        } else if mass > 0.0 {
            free / mass
        } else {
            continue;
        };
        x1[i as usize] = input.x0[i as usize] + d;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The masses of [`scene`]'s vertices.
    const MASSES: [f64; 5] = [1.0, 1.0, 1.0, 1.0, 3.0];

    /// Positions, triangles, edges and the triangles' adjacency.
    type Scene = (Vec<Vec3>, Vec<[u32; 3]>, Vec<[u32; 2]>, Adjacency);

    /// A triangle (0, 1, 2) over a vertex 3 below it, with an edge (3, 4) beside.
    fn scene() -> Scene {
        let x0 = vec![
            Vec3::new(0.0, 0.0, 0.01),
            Vec3::new(1.0, 0.0, 0.01),
            Vec3::new(0.0, 1.0, 0.01),
            Vec3::new(0.2, 0.2, 0.0),
            Vec3::new(0.2, 0.2, -0.5),
        ];
        let tris = vec![[0, 1, 2]];
        let adj = Adjacency::triangles(x0.len(), &tris);
        (x0, tris, vec![[3, 4]], adj)
    }

    /// A proposed step with the triangle (vertices 0, 1, 2) dropped 3 cm, the rest left.
    fn triangle_down(x0: &[Vec3]) -> Vec<Vec3> {
        let mut x1 = x0.to_vec();
        for p in &mut x1[..3] {
            *p -= Vec3::new(0.0, 0.0, 0.03);
        }
        x1
    }

    /// [`scene`]'s proposed step with vertex 3 flying 5 cm up, through the triangle.
    fn vertex_up(x0: &[Vec3]) -> Vec<Vec3> {
        let mut x1 = x0.to_vec();
        x1[3] += Vec3::new(0.0, 0.0, 0.05);
        x1
    }

    /// The zones' input for these tests: no edge pairs, no neighbour rows.
    fn input<'a>(
        x0: &'a [Vec3],
        masses: &'a [f64],
        kinematic: &'a [bool],
        triangles: &'a [[u32; 3]],
        adjacency: &'a Adjacency,
        edges: &'a [[u32; 2]],
        vt: &'a [Pair],
    ) -> ZoneInput<'a> {
        ZoneInput {
            x0,
            masses,
            kinematic,
            triangles,
            vertex_triangles: adjacency,
            neighbours: (&[], &[]),
            guard: &[],
            guard_vertices: &[],
            edges,
            vertex_triangle: vt,
            edge_edge: &[],
            tolerance: 1e-9,
        }
    }

    /// [`keep_from_passing`] with fresh buffers.
    fn zones(
        zi: &ZoneInput,
        x1: &mut [Vec3],
        moved: &mut Vec<u32>,
        stopped: &mut Vec<Passage>,
    ) -> ZoneReport {
        keep_from_passing(zi, x1, moved, stopped, &mut ZoneScratch::default()).expect("room for the zones")
    }

    /// A step `step(guarded)` of a neighbour pair dropped through each other: guarded, one
    /// passage found and stopped; not guarded, none found. The positions after each.
    fn stopped_only_when_guarded(
        step: impl Fn(bool) -> (ZoneReport, Vec<Vec3>, Vec<Passage>),
    ) -> (Vec<Vec3>, Vec<Vec3>) {
        let (report, guarded, stopped) = step(true);
        assert_eq!(report.passages, 1);
        assert_eq!(report.unresolved, 0);
        assert_eq!(stopped[0].pair, PairRef::Neighbour);
        let (report, unguarded, _) = step(false);
        assert_eq!(report.passages, 0);
        (guarded, unguarded)
    }

    /// An edge-edge pair that is not listed (neighbours at rest) but guarded passes through
    /// in a step: the zones stop it, as a listed pair's; not guarded, nothing is checked.
    #[test]
    fn a_guarded_neighbour_edge_pair_is_kept_from_passing() {
        let x0 = vec![
            Vec3::new(-1.0, 0.0, 0.01),
            Vec3::new(1.0, 0.0, 0.01),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let edges = [[0u32, 1], [2, 3]];
        let (masses, kinematic) = ([1.0; 4], [false; 4]);
        let adjacency = Adjacency::triangles(4, &[]);
        let step = |guard: &[(u32, u32)]| {
            let zi = ZoneInput {
                guard,
                ..input(&x0, &masses, &kinematic, &[], &adjacency, &edges, &[])
            };
            // The first edge dropped 3 cm, through the second.
            let mut x1 = x0.clone();
            for p in &mut x1[..2] {
                *p -= Vec3::new(0.0, 0.0, 0.03);
            }
            let (mut moved, mut stopped) = (Vec::new(), Vec::new());
            let report = zones(&zi, &mut x1, &mut moved, &mut stopped);
            (report, x1, stopped)
        };
        let (x1, unguarded) =
            stopped_only_when_guarded(|guarded| step(if guarded { &[(0, 1)] } else { &[] }));
        // One zone, moved by its momentum: the first edge still above the second.
        assert!(x1[0].z > x1[2].z && x1[1].z > x1[3].z, "{x1:?}");
        assert!(unguarded[0].z < unguarded[2].z, "unguarded, it passes");
    }

    /// A vertex-triangle pair that is not listed but guarded (a vertex folded through a
    /// triangle beside it) passes through in a step: the zones stop it; not guarded, it passes.
    #[test]
    fn a_guarded_neighbour_vertex_triangle_pair_is_kept_from_passing() {
        let x0 = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.2, 0.2, 0.01),
        ];
        let tris = [[0u32, 1, 2]];
        let (masses, kinematic) = ([1.0; 4], [false; 4]);
        let adjacency = Adjacency::triangles(4, &tris);
        let step = |guard_vertices: &[(u32, u32)]| {
            let zi = ZoneInput {
                guard_vertices,
                ..input(&x0, &masses, &kinematic, &tris, &adjacency, &[], &[])
            };
            // The vertex dropped 3 cm, through the triangle.
            let mut x1 = x0.clone();
            x1[3].z -= 0.03;
            let (mut moved, mut stopped) = (Vec::new(), Vec::new());
            let report = zones(&zi, &mut x1, &mut moved, &mut stopped);
            (report, x1, stopped)
        };
        let (x1, unguarded) =
            stopped_only_when_guarded(|guarded| step(if guarded { &[(3, 0)] } else { &[] }));
        assert!(x1[3].z > x1[0].z, "{x1:?}");
        assert!(unguarded[3].z < unguarded[0].z, "unguarded, it passes");
    }

    #[test]
    fn a_pinned_triangle_carries_the_vertex_it_would_push_through() {
        let (x0, tris, edges, adj) = scene();
        let pinned = [true, true, true, false, false];
        // The vertex is below the triangle: side -1.
        let vt = [(3, 0, -1)];
        let zi = input(&x0, &MASSES, &pinned, &tris, &adj, &edges, &vt);
        // The pinned triangle drops 3 cm; the vertex stays.
        let mut x1 = triangle_down(&x0);
        let mut moved = Vec::new();
        let report = zones(&zi, &mut x1, &mut moved, &mut Vec::new());
        assert_eq!(report.passages, 1);
        assert_eq!(report.unresolved, 0);
        assert_eq!(moved, vec![3]);
        assert!((x1[3] - (x0[3] - Vec3::new(0.0, 0.0, 0.03))).norm() < 1e-15);
        // Vertex 4 was in no passage: left as proposed.
        assert_eq!(x1[4], x0[4]);
    }

    #[test]
    fn free_vertices_keep_their_momentum_and_stop_passing() {
        let (x0, tris, edges, adj) = scene();
        let free = [false; 5];
        let vt = [(3, 0, 0)];
        let zi = input(&x0, &MASSES, &free, &tris, &adj, &edges, &vt);
        // The vertex flies up through the triangle, which moves a little down.
        let mut x1 = vertex_up(&x0);
        for p in &mut x1[..3] {
            *p -= Vec3::new(0.0, 0.0, 0.001);
        }
        let momentum = |x: &[Vec3]| (0..4).map(|i| x[i] - x0[i]).sum::<Vec3>();
        let before = momentum(&x1);
        let mut moved = Vec::new();
        let report = zones(&zi, &mut x1, &mut moved, &mut Vec::new());
        assert_eq!((report.passages, report.unresolved), (1, 0));
        assert_eq!(moved, vec![0, 1, 2, 3]);
        assert!((momentum(&x1) - before).norm() < 1e-15);
        let path = zi.path(&x1, [0, 1, 2, 3]);
        assert_eq!(vertex_passes_triangle(&path, 1e-9), None);
    }

    #[test]
    fn a_passage_is_stopped_whatever_side_the_pair_remembers_and_its_start_sign_reported() {
        let (x0, tris, edges, adj) = scene();
        let free = [false; 5];
        // Remembered above (+1), though it starts below (-1): the memory is wrong, not the
        // geometry, and the vertex is still kept from going through.
        let vt = [(3, 0, 1)];
        let zi = input(&x0, &MASSES, &free, &tris, &adj, &edges, &vt);
        let mut x1 = vertex_up(&x0);
        let (mut moved, mut stopped) = (Vec::new(), Vec::new());
        let report = zones(&zi, &mut x1, &mut moved, &mut stopped);
        assert_eq!((report.passages, report.unresolved), (1, 0));
        assert_eq!(
            stopped,
            vec![Passage {
                vs: [0, 1, 2, 3],
                pair: PairRef::VertexTriangle(0),
                sign: -1
            }]
        );
        assert_eq!(vertex_passes_triangle(&zi.path(&x1, [0, 1, 2, 3]), 1e-9), None);
    }

    #[test]
    fn a_vertex_whose_edge_already_pierces_the_triangle_may_pass_back() {
        // Vertex 3 is above triangle (0, 1, 2) but its triangle (3, 4, 5) reaches below it:
        // edge 3-4 pierces the triangle, a crossing made where no pair was listed. Moving 3
        // down through the triangle takes that edge out of it: let through.
        let x0 = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.2, 0.2, 0.01),
            Vec3::new(0.25, 0.25, -0.5),
            Vec3::new(2.0, 2.0, 0.01),
        ];
        let tris = vec![[0, 1, 2], [3, 4, 5]];
        let adj = Adjacency::triangles(x0.len(), &tris);
        let free = [false; 6];
        let vt = [(3, 0, 1)];
        let zi = input(&x0, &[1.0; 6], &free, &tris, &adj, &[], &vt);
        let mut x1 = x0.clone();
        x1[3] -= Vec3::new(0.0, 0.0, 0.05);
        let proposed = x1.clone();
        let report = zones(&zi, &mut x1, &mut Vec::new(), &mut Vec::new());
        assert_eq!(report, ZoneReport::default());
        assert_eq!(x1, proposed);
        // With the far corner above the triangle's plane, nothing pierces it: stopped.
        let mut untangled = x0.clone();
        untangled[4] = Vec3::new(0.25, 0.25, 0.5);
        let zi = ZoneInput { x0: &untangled, ..zi };
        let mut x1 = untangled.clone();
        x1[3] -= Vec3::new(0.0, 0.0, 0.05);
        let report = zones(&zi, &mut x1, &mut Vec::new(), &mut Vec::new());
        assert_eq!((report.passages, report.unresolved), (1, 0));
    }

    #[test]
    fn zones_grow_until_nothing_passes() {
        // A stack: vertex 3 below triangle (0, 1, 2), and triangle (5, 6, 7) below vertex 3.
        // The top triangle is pinned and drops through 3; carried with it, 3 then passes the
        // bottom triangle, which joins the zone in the next round.
        let mut x0 = scene().0;
        for p in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
            x0.push(Vec3::new(p.0, p.1, -0.005));
        }
        let tris = vec![[0, 1, 2], [5, 6, 7]];
        let kinematic = [true, true, true, false, false, false, false, false];
        let vt = [(3, 0, -1), (3, 1, 1)];
        let adj = Adjacency::triangles(x0.len(), &tris);
        let zi = input(&x0, &[1.0; 8], &kinematic, &tris, &adj, &[], &vt);
        let mut x1 = triangle_down(&x0);
        let mut moved = Vec::new();
        let report = zones(&zi, &mut x1, &mut moved, &mut Vec::new());
        assert_eq!(report.passages, 1);
        assert_eq!(report.unresolved, 0);
        assert_eq!(moved, vec![3, 5, 6, 7]);
        for i in [3, 5, 6, 7] {
            assert!((x1[i] - x0[i] + Vec3::new(0.0, 0.0, 0.03)).norm() < 1e-15, "{i}");
        }
        let mut again = Vec::new();
        zi.passages(&x1, &mut again);
        assert!(again.is_empty());
    }
}
