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
use super::self_collision::{edge_edge, vertex_triangle};
use crate::math::Vec3;

/// Room for the lists worked out from the rest shape, in entries: every push counts against
/// it and grows its list fallibly. A thickness large against the mesh's spacing makes the
/// lists grow as (thickness / spacing)^2 a vertex; past the room they are refused with an
/// error at create (or reconfigure), not left to exhaust memory, or to overflow the lists'
/// 32-bit offsets, in the middle of a bake.
#[derive(Debug)]
pub(super) struct Room {
    left: usize,
    /// Why a push was refused, once one was: nothing more is pushed after it.
    pub(super) full: Option<Full>,
}

/// Why the room ran out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Full {
    /// More entries than the room allows.
    Entries,
    /// The allocator refused.
    Memory,
}

impl Room {
    pub(super) fn new(entries: usize) -> Room {
        Room {
            left: entries.min(u32::MAX as usize - 1),
            full: None,
        }
    }

    /// Pushes `item` onto `list` if there is room; false (and nothing pushed) when not.
    pub(super) fn push<T>(&mut self, list: &mut Vec<T>, item: T) -> bool {
        if self.full.is_some() {
            return false;
        }
        if self.left == 0 {
            self.full = Some(Full::Entries);
            return false;
        }
        if list.len() == list.capacity() && list.try_reserve(list.len().max(64)).is_err() {
            self.full = Some(Full::Memory);
            return false;
        }
        self.left -= 1;
        list.push(item);
        true
    }

    /// Makes space for `k` more entries in `list` (fallibly); false when it cannot.
    pub(super) fn reserve<T>(&mut self, list: &mut Vec<T>, k: usize) -> bool {
        if self.full.is_some() {
            return false;
        }
        if list.capacity() - list.len() < k && list.try_reserve(list.len().max(64).max(k)).is_err() {
            self.full = Some(Full::Memory);
            return false;
        }
        true
    }

    /// Counts `k` entries pushed after a [`Room::reserve`] against the room.
    pub(super) fn spend(&mut self, k: usize) {
        if k > self.left {
            self.left = 0;
            self.full = Some(Full::Entries);
        } else {
            self.left -= k;
        }
    }
}

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

    pub(super) fn vertex_excludes(&self, p: u32, t: u32) -> bool {
        let (a, b) = (
            self.vt_start[p as usize] as usize,
            self.vt_start[p as usize + 1] as usize,
        );
        self.vt[a..b].binary_search(&t).is_ok()
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
        Some(NearPairs {
            rest_boxes,
            vertex_triangle: vt,
            edge_edge: ee,
        })
    }

    /// Whether triangles `i` and `j` are rest-near (their pairs are listed here). Those that
    /// are not are more than the radius apart at rest in some axis, so none of their vertex
    /// and triangle, or edge and edge, is excluded or shares a vertex.
    #[inline]
    pub(super) fn rest_near(&self, i: u32, j: u32) -> bool {
        self.rest_boxes[i as usize].overlaps(&self.rest_boxes[j as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_room_refuses_past_its_entries_and_keeps_refusing() {
        let mut room = Room::new(3);
        let mut a = Vec::new();
        assert!(room.push(&mut a, 1u32) && room.push(&mut a, 2));
        assert!(room.reserve(&mut a, 9));
        a.push(3);
        room.spend(1);
        assert_eq!(room.full, None);
        assert!(!room.push(&mut a, 4), "a fourth entry in a room of three");
        assert_eq!(room.full, Some(Full::Entries));
        assert_eq!(a, [1, 2, 3]);
        assert!(!room.reserve(&mut a, 1), "nothing more once full");
        // Spending more than is left fills it too; the room never exceeds u32 offsets.
        let mut room = Room::new(2);
        room.spend(3);
        assert_eq!(room.full, Some(Full::Entries));
        assert_eq!(Room::new(usize::MAX).left, u32::MAX as usize - 1);
    }
}
