//! Per-vertex adjacency in compressed rows (CSR): which springs and triangles touch each
//! vertex, in ascending order. The force passes gather over these lists instead of scattering
//! into shared arrays, so particles can be split among threads without races or atomics, and
//! every vertex sums its terms in the same order whatever the split (bitwise-identical
//! results for any thread count).

use super::Spring;

/// Compressed rows: the entries of vertex `p` are `entries[offsets[p]..offsets[p + 1]]`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Adjacency {
    offsets: Vec<u32>,
    entries: Vec<u32>,
}

impl Adjacency {
    /// Builds rows for `n` vertices from `(vertex, entry)` pairs given in ascending entry
    /// order; each row keeps that order.
    pub(super) fn from_pairs(n: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Self {
        let mut offsets = vec![0u32; n + 1];
        for (p, _) in pairs.clone() {
            offsets[p as usize + 1] += 1;
        }
        for k in 0..n {
            offsets[k + 1] += offsets[k];
        }
        let mut fill = offsets.clone();
        let mut entries = vec![0u32; offsets[n] as usize];
        for (p, e) in pairs {
            entries[fill[p as usize] as usize] = e;
            fill[p as usize] += 1;
        }
        Self { offsets, entries }
    }

    /// Springs of each vertex; an entry is `2 s` when the vertex is the spring's `i` end and
    /// `2 s + 1` when it is the `j` end (the force on j is minus the force on i).
    pub fn springs(n: usize, springs: &[Spring]) -> Self {
        let pairs = springs
            .iter()
            .enumerate()
            .flat_map(|(s, sp)| [(sp.i, 2 * s as u32), (sp.j, 2 * s as u32 + 1)]);
        Self::from_pairs(n, pairs)
    }

    /// Triangles of each vertex.
    pub fn triangles(n: usize, triangles: &[[u32; 3]]) -> Self {
        Self::elements(n, triangles)
    }

    /// Edges (each `[i, j]`) of each vertex.
    pub fn edges(n: usize, edges: &[[u32; 2]]) -> Self {
        Self::elements(n, edges)
    }

    /// Elements of `K` vertices each, of each vertex.
    fn elements<const K: usize>(n: usize, elements: &[[u32; K]]) -> Self {
        let pairs = elements
            .iter()
            .enumerate()
            .flat_map(|(e, ends)| ends.map(|v| (v, e as u32)));
        Self::from_pairs(n, pairs)
    }

    /// Runs touching each chunk of `crate::parallel::CHUNK` vertices (as the `i` end or as
    /// the `j` end), in ascending run order.
    pub fn chunk_runs(n: usize, runs: &[super::SpringRun]) -> Self {
        let chunk = crate::parallel::CHUNK;
        let pairs = runs.iter().enumerate().flat_map(move |(r, run)| {
            let i0 = run.first_vertex as usize;
            let j0 = i0 + run.offset as usize;
            let len = run.len as usize;
            let i_chunks = i0 / chunk..=(i0 + len - 1) / chunk;
            let j_chunks = j0 / chunk..=(j0 + len - 1) / chunk;
            // Both ranges, each chunk once, ascending.
            let (lo, hi) = (*i_chunks.start(), *j_chunks.end());
            (lo..=hi)
                .filter(move |c| i_chunks.contains(c) || j_chunks.contains(c))
                .map(move |c| (c as u32, r as u32))
        });
        Self::from_pairs(n.div_ceil(chunk), pairs)
    }

    /// Entries of vertex `p`.
    #[inline]
    pub fn row(&self, p: usize) -> &[u32] {
        &self.entries[self.offsets[p] as usize..self.offsets[p + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::SpringKind;

    #[test]
    fn rows_list_each_incidence_once_in_ascending_order() {
        let s = |i, j| Spring {
            i,
            j,
            rest: 1.0,
            kind: SpringKind::Stretch,
        };
        let a = Adjacency::springs(4, &[s(0, 1), s(1, 2), s(0, 2), s(2, 3)]);
        assert_eq!(a.row(0), &[0, 4]);
        assert_eq!(a.row(1), &[1, 2]);
        assert_eq!(a.row(2), &[3, 5, 6]);
        assert_eq!(a.row(3), &[7]);
        let t = Adjacency::triangles(4, &[[0, 1, 2], [2, 1, 3]]);
        assert_eq!(t.row(1), &[0, 1]);
        assert_eq!(t.row(3), &[1]);
        assert_eq!(t.row(0), &[0]);
    }
}
