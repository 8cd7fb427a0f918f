//! Which triangle *owns* each vertex and each edge of a mesh: the lowest-numbered triangle that
//! contains it. A walk over pairs of triangles then meets every pair of a vertex and a triangle,
//! and every pair of two edges, exactly once, through the pair of their owners (self-collision's
//! search, `self_collision.rs`).
//!
//! Vertices in no triangle are *orphans*, listed apart.

/// Each triangle's owned vertices and edges, as compressed rows, and the orphan vertices.
#[derive(Clone, Debug, Default)]
pub struct Ownership {
    vertex_start: Vec<u32>,
    vertices: Vec<u32>,
    edge_start: Vec<u32>,
    edge_items: Vec<u32>,
    orphans: Vec<u32>,
    vertex_count: usize,
}

/// Compressed rows from `(row, item)` entries already in row order.
fn rows(count: usize, entries: &[(u32, u32)]) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; count + 1];
    for &(r, _) in entries {
        start[r as usize + 1] += 1;
    }
    for k in 0..count {
        start[k + 1] += start[k];
    }
    (start, entries.iter().map(|&(_, i)| i).collect())
}

impl Ownership {
    /// The ownership of `vertex_count` vertices and the sorted, deduplicated `edges`
    /// (`[i, j]`, i < j, as [`edges_of`](super::geometry::edges_of) gives them) by `triangles`.
    pub fn new(vertex_count: usize, triangles: &[[u32; 3]], edges: &[[u32; 2]]) -> Ownership {
        let mut vertex_owner = vec![u32::MAX; vertex_count];
        let mut edge_owner = vec![u32::MAX; edges.len()];
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                if let Some(o) = vertex_owner.get_mut(tri[k] as usize) {
                    *o = (*o).min(t as u32);
                }
                let e = [tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3])];
                if let Ok(i) = edges.binary_search(&e) {
                    edge_owner[i] = edge_owner[i].min(t as u32);
                }
            }
        }
        let owned = |owner: &[u32]| -> Vec<(u32, u32)> {
            let mut v: Vec<(u32, u32)> = owner
                .iter()
                .enumerate()
                .filter(|(_, &o)| o != u32::MAX)
                .map(|(i, &o)| (o, i as u32))
                .collect();
            v.sort_unstable();
            v
        };
        let (vertex_start, vertices) = rows(triangles.len(), &owned(&vertex_owner));
        let (edge_start, edge_items) = rows(triangles.len(), &owned(&edge_owner));
        let orphans = (0..vertex_count as u32)
            .filter(|&p| vertex_owner[p as usize] == u32::MAX)
            .collect();
        Ownership {
            vertex_start,
            vertices,
            edge_start,
            edge_items,
            orphans,
            vertex_count,
        }
    }

    /// Whether this was made for `vertex_count` vertices and `triangle_count` triangles.
    pub fn fits(&self, vertex_count: usize, triangle_count: usize) -> bool {
        self.vertex_count == vertex_count && self.vertex_start.len() == triangle_count + 1
    }

    /// The vertices triangle `t` owns, ascending.
    #[inline]
    pub fn vertices(&self, t: u32) -> &[u32] {
        let t = t as usize;
        &self.vertices[self.vertex_start[t] as usize..self.vertex_start[t + 1] as usize]
    }

    /// The edges (indices into the edge list) triangle `t` owns, ascending.
    #[inline]
    pub fn edges(&self, t: u32) -> &[u32] {
        let t = t as usize;
        &self.edge_items[self.edge_start[t] as usize..self.edge_start[t + 1] as usize]
    }

    /// The vertices in no triangle, ascending.
    pub fn orphans(&self) -> &[u32] {
        &self.orphans
    }

    /// The pairs triangles `i` and `j` meet through their owners: `vertex(p, t)` for each vertex
    /// of one against the other triangle, then `edge(e, f)` (e < f) for each edge of `i`
    /// against each of `j`.
    #[inline]
    pub fn pairs_of(&self, i: u32, j: u32, mut vertex: impl FnMut(u32, u32), mut edge: impl FnMut(u32, u32)) {
        for (a, b) in [(i, j), (j, i)] {
            for &p in self.vertices(a) {
                vertex(p, b);
            }
        }
        for &e in self.edges(i) {
            for &f in self.edges(j) {
                edge(e.min(f), e.max(f));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collide::geometry::edges_of;

    #[test]
    fn every_vertex_and_edge_has_one_owner_that_contains_it() {
        // Two quads sharing an edge, triangles listed out of order, and vertex 6 in none.
        let triangles = [[4, 5, 2], [0, 1, 3], [0, 3, 2], [1, 4, 3], [3, 4, 2]];
        let edges = edges_of(&triangles);
        let own = Ownership::new(7, &triangles, &edges);
        assert!(own.fits(7, 5));
        assert_eq!(own.orphans(), &[6]);
        let mut seen_v = vec![0; 7];
        let mut seen_e = vec![0; edges.len()];
        for t in 0..triangles.len() as u32 {
            let tri = &triangles[t as usize];
            for &p in own.vertices(t) {
                seen_v[p as usize] += 1;
                assert!(tri.contains(&p));
                // The lowest-numbered triangle that contains it.
                assert!(triangles[..t as usize].iter().all(|u| !u.contains(&p)));
            }
            for &e in own.edges(t) {
                seen_e[e as usize] += 1;
                let [i, j] = edges[e as usize];
                assert!(tri.contains(&i) && tri.contains(&j));
                assert!(triangles[..t as usize]
                    .iter()
                    .all(|u| !(u.contains(&i) && u.contains(&j))));
            }
        }
        assert_eq!(seen_v, vec![1, 1, 1, 1, 1, 1, 0]);
        assert!(seen_e.iter().all(|&c| c == 1));
        // Triangle 0 owns 2, 4 and 5 and all three of its edges.
        assert_eq!(own.vertices(0), &[2, 4, 5]);
        assert_eq!(own.edges(0).len(), 3);
    }
}
