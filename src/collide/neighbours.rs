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
use super::room::Room;
use super::self_collision::{edge_edge, vertex_triangle};
use crate::math::Vec3;

/// Each vertex's (edge's) excluded triangles (edges), sorted, as compressed rows.
#[derive(Clone, Debug, Default)]
pub(super) struct Exclusions {
    pub(super) radius: f64,
    pub(super) vt_start: Vec<u32>,
    vt: Vec<u32>,
    ee_start: Vec<u32>,
    ee: Vec<u32>,
}

impl Exclusions {
    /// The pairs nearer than `radius` at the rest positions `rest`; `None` when `room` ran out
    /// (it says why).
    pub(super) fn new(
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
        radius: f64,
        room: &mut Room,
    ) -> Option<Exclusions> {
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| Aabb::of(t.iter().map(|&i| &rest[i as usize])).inflated(radius))
            .collect();
        let bvh = Bvh::build(&boxes);
        let (mut vt_start, mut vt) = (vec![0u32], Vec::new());
        for p in 0..rest.len() as u32 {
            let first = vt.len();
            let q = Aabb {
                min: rest[p as usize],
                max: rest[p as usize],
            };
            bvh.overlapping(&q, |t| {
                let tri = &triangles[t as usize];
                if tri.contains(&p) || vertex_triangle(rest, p, tri).0 < radius {
                    room.push(&mut vt, t);
                }
            });
            if room.full.is_some() {
                return None;
            }
            vt[first..].sort_unstable();
            vt_start.push(vt.len() as u32);
        }
        let boxes: Vec<Aabb> = edges
            .iter()
            .map(|e| Aabb::of(e.iter().map(|&i| &rest[i as usize])).inflated(0.5 * radius))
            .collect();
        let bvh = Bvh::build(&boxes);
        let (mut ee_start, mut ee) = (vec![0u32], Vec::new());
        for (e, edge) in edges.iter().enumerate() {
            let first = ee.len();
            bvh.overlapping(&boxes[e], |f| {
                let other = &edges[f as usize];
                if f as usize > e
                    && (edge.iter().any(|v| other.contains(v)) || edge_edge(rest, edge, other).0 < radius)
                {
                    room.push(&mut ee, f);
                }
            });
            if room.full.is_some() {
                return None;
            }
            ee[first..].sort_unstable();
            ee_start.push(ee.len() as u32);
        }
        Some(Exclusions {
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
    /// (their radius is the one that tells rest-near triangles); `None` when `room` ran out.
    pub(super) fn new(
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
        owners: &Ownership,
        excluded: &Exclusions,
        room: &mut Room,
    ) -> Option<NearPairs> {
        let rest_boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| Aabb::of(t.iter().map(|&i| &rest[i as usize])).inflated(0.5 * excluded.radius))
            .collect();
        let bvh = Bvh::build(&rest_boxes);
        let (mut vt, mut ee) = (Vec::new(), Vec::new());
        for task in bvh.self_tasks(1) {
            bvh.self_overlapping(task, |i, j| {
                // A triangle pair yields at most 6 vertex-triangle and 9 edge-edge pairs.
                if !room.reserve(&mut vt, 6) || !room.reserve(&mut ee, 9) {
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
                room.spend(vt.len() + ee.len() - before);
            });
        }
        if room.full.is_some() {
            return None;
        }
        // In order, so that a vertex's (an edge's) pairs come together.
        vt.sort_unstable();
        ee.sort_unstable();
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
