//! The guard: neighbour pairs self-collision never lists (nearer than its exclusion at rest),
//! handed to the impact zones' continuous check in the steps where they might pass through
//! each other.
//!
//! Two kinds, neither sharing a vertex:
//! - **edge pairs**: across a 1 cm grid's cells, the parallel diagonals of two adjacent quads
//!   lie 7.1 mm apart at rest (under the 8.8 mm exclusion of a 4 mm thickness); a fold across
//!   the row pulls one through the other with no listed pair passing;
//! - **vertex-triangle pairs**: a vertex folded through a triangle beside it (its edges then go
//!   through the triangle's face, not its edges, so no edge pair sees it).
//!
//! `examples/crumple_crossings.rs` and docs/collisions.md show both in the brisk crumple.
//!
//! **The watch.** Checking every pair at every step costs a continuous test each; most pairs
//! are far from passing. The watch keeps where the cloth was when it last measured its pairs,
//! and the box of every displacement since (grown by each step's start and end). A pair
//! measured at least the skin apart stays at least the skin less that box's diagonal apart at
//! any instant since (two points' displacements, and those of the points of a straight path
//! between, lie in the box), so while that is above the tolerance it cannot meet and is not
//! checked; when the cloth has deformed further, the pairs are measured again. Every pair that
//! can meet is always checked, so a step finds the same passages as a check of every pair
//! would.
//!
//! **Measuring again by bounds.** A pair's distance shrinks by no more than its points'
//! displacements differ: a vertex and a triangle by at most the largest difference between
//! the vertex's displacement and a corner's, two edges by at most the largest between an end
//! of one and an end of the other. So when the watch measures again it first lowers each
//! pair's last distance (or bound) by that, from the displacements since it last measured; only
//! a pair whose bound falls under the skin is measured exactly. A neighbour pair's points move
//! almost together, so most pairs are decided by the bound (a few differences instead of a
//! closest-point search), and the pairs checked are the ones an exact measure of every pair
//! gives. (Groups of pairs with a box each, measured again one group at a time, were tried: the
//! boxes' vertices overlap, and growing them cost more than the measures they saved, 1.65-1.79x
//! the swing without self-collision against 1.47-1.48x; docs/collisions.md.)

use super::bvh::Aabb;
use crate::error::Error;
use crate::math::Vec3;

/// The guard's skin against its pairs' rest distances: a pair nearer than this fraction of
/// the [`GUARD_QUANTILE`] of the rest distances, where the guard last measured it, is checked
/// at every step; the others once the cloth has deformed by the skin since. Below the rest
/// distance, so an undeformed cloth checks almost none (a 1 cm grid at 4 mm: its diagonals
/// 7.1 mm apart, a skin of 6 mm; 3 mm at 1.5 mm: 2.1 mm apart, 1.8 mm).
pub const GUARD_SKIN: f64 = 0.85;

/// Which of the guard pairs' rest distances sets the skin (the fifth nearest of every
/// hundred): a mesh's few nearest pairs are checked at every step rather than making every
/// pair's skin theirs.
pub const GUARD_QUANTILE: f64 = 0.05;

/// The guard's pairs and watch; see the module docs.
#[derive(Clone, Debug, Default)]
pub struct Guard {
    edge_pairs: Vec<(u32, u32)>,
    vertex_pairs: Vec<(u32, u32)>,
    skin: f64,
    /// Positions when the watch last measured its pairs (empty before), and the box of the
    /// displacements since.
    base: Vec<Vec3>,
    moved: Aabb,
    /// The pairs the current step checks: those nearer than the skin when measured
    /// (ascending), or every pair.
    close_edges: Vec<(u32, u32)>,
    close_vertices: Vec<(u32, u32)>,
    /// Each pair's distance, or a lower bound of it, at `base` (edge pairs, then vertex
    /// pairs); empty when not measured.
    apart: Vec<f64>,
    /// The displacements since `base` (scratch of the measure).
    moves: Vec<Vec3>,
}

/// Two lists of pairs: edge pairs `(e, f)`, vertex-triangle pairs `(p, t)`.
pub type PairLists<'a> = (&'a [(u32, u32)], &'a [(u32, u32)]);

/// Distance between the segments `e` and `f` of positions `x`.
fn edge_distance(x: &[Vec3], e: &[u32; 2], f: &[u32; 2]) -> f64 {
    super::pair::edge_edge(x, e, f).0
}

/// Distance between vertex `p` and triangle `t` of positions `x`.
fn vertex_distance(x: &[Vec3], p: u32, t: &[u32; 3]) -> f64 {
    super::pair::vertex_triangle(x, p, t).0
}

impl Guard {
    /// The guard of the excluded pairs `edge_pairs` (edges `(e, f)` of `edges`) and
    /// `vertex_pairs` (vertices `(p, t)` against triangles of `triangles`), none sharing a
    /// vertex, of a cloth at rest at `rest`. Fails when memory runs out.
    pub fn new(
        rest: &[Vec3],
        edges: &[[u32; 2]],
        triangles: &[[u32; 3]],
        edge_pairs: Vec<(u32, u32)>,
        vertex_pairs: Vec<(u32, u32)>,
    ) -> Result<Guard, Error> {
        let oom = |_| Error::out_of_memory("self-collision: its guarded neighbour pairs cannot be allocated");
        let all = edge_pairs.len() + vertex_pairs.len();
        let mut g = Guard {
            edge_pairs,
            vertex_pairs,
            ..Guard::default()
        };
        // The skin, from the pairs' rest distances.
        let mut apart = Vec::new();
        apart.try_reserve_exact(all).map_err(oom)?;
        apart.extend(
            g.edge_pairs
                .iter()
                .map(|&(e, f)| edge_distance(rest, &edges[e as usize], &edges[f as usize])),
        );
        apart.extend(
            g.vertex_pairs
                .iter()
                .map(|&(p, t)| vertex_distance(rest, p, &triangles[t as usize])),
        );
        if all > 0 {
            let k = ((all as f64 * GUARD_QUANTILE) as usize).min(all - 1);
            g.skin = GUARD_SKIN * *apart.select_nth_unstable_by(k, f64::total_cmp).1;
        }
        // Room for the watch: a step allocates nothing.
        g.close_edges.try_reserve_exact(g.edge_pairs.len()).map_err(oom)?;
        g.close_vertices
            .try_reserve_exact(g.vertex_pairs.len())
            .map_err(oom)?;
        let n = if all > 0 { rest.len() } else { 0 };
        g.base.try_reserve_exact(n).map_err(oom)?;
        g.moves.try_reserve_exact(n).map_err(oom)?;
        g.apart.try_reserve_exact(all).map_err(oom)?;
        Ok(g)
    }

    pub fn is_empty(&self) -> bool {
        self.edge_pairs.is_empty() && self.vertex_pairs.is_empty()
    }

    /// The watch's skin, m.
    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// Every guarded pair: edge pairs, vertex-triangle pairs.
    pub fn pairs(&self) -> PairLists<'_> {
        (&self.edge_pairs, &self.vertex_pairs)
    }

    /// The pairs that might pass in the step `x0 -> x1` (after [`Guard::watch`] for it): edge
    /// pairs, vertex-triangle pairs.
    pub fn close(&self) -> PairLists<'_> {
        (&self.close_edges, &self.close_vertices)
    }

    /// Where the watch last measured and each pair's distance or bound there (edge pairs,
    /// then vertex pairs), if it has.
    #[cfg(test)]
    pub(super) fn measure(&self) -> Option<(&[Vec3], &[f64])> {
        (!self.base.is_empty()).then_some((&self.base, &self.apart))
    }

    /// Forgets the watch's measure (the next step measures again).
    pub fn forget(&mut self) {
        self.base.clear();
        self.apart.clear();
    }

    /// Readies [`Guard::close`] for the step `x0 -> x1`, where two points meet within
    /// `tolerance` (module docs).
    pub fn watch(
        &mut self,
        x0: &[Vec3],
        x1: &[Vec3],
        edges: &[[u32; 2]],
        triangles: &[[u32; 3]],
        tolerance: f64,
    ) {
        if self.is_empty() {
            self.close_edges.clear();
            self.close_vertices.clear();
            return;
        }
        let skin = self.skin;
        let within = |b: &Aabb| (b.max - b.min).norm() < skin - tolerance;
        // Both ends: a step's start is usually an earlier step's end, but the host may have
        // moved the cloth between steps (`set_positions`, a loaded snapshot).
        let grown = |base: &[Vec3], b: Aabb| b.grown_by_differences(x0, base).grown_by_differences(x1, base);
        let measured = self.base.len() == x0.len();
        if measured {
            self.moved = grown(&self.base, self.moved);
            if within(&self.moved) {
                return;
            }
        }
        self.close_edges.clear();
        self.close_vertices.clear();
        let mut start = Aabb::empty();
        start.grow(&Vec3::zeros());
        let moved = grown(x0, start);
        if !within(&moved) {
            // A step that deforms the cloth by more than the skin: every pair, and measured
            // afresh the next step.
            self.forget();
            self.close_edges.extend_from_slice(&self.edge_pairs);
            self.close_vertices.extend_from_slice(&self.vertex_pairs);
            return;
        }
        // The last measures, lowered by the displacements since, where there are any.
        let bounded = measured && self.apart.len() == self.edge_pairs.len() + self.vertex_pairs.len();
        self.moves.clear();
        if bounded {
            self.moves.extend(x0.iter().zip(&self.base).map(|(p, q)| p - q));
        } else {
            self.apart.clear();
            self.apart
                .resize(self.edge_pairs.len() + self.vertex_pairs.len(), f64::NEG_INFINITY);
        }
        let (apart_e, apart_v) = self.apart.split_at_mut(self.edge_pairs.len());
        let moves = &self.moves;
        for (&(e, f), apart) in self.edge_pairs.iter().zip(apart_e) {
            let (ee, ff) = (&edges[e as usize], &edges[f as usize]);
            if bounded {
                *apart -= edge_motion(moves, ee, ff);
            }
            if *apart < skin {
                *apart = edge_distance(x0, ee, ff);
                if *apart < skin {
                    self.close_edges.push((e, f));
                }
            }
        }
        for (&(p, t), apart) in self.vertex_pairs.iter().zip(apart_v) {
            let tri = &triangles[t as usize];
            if bounded {
                *apart -= vertex_motion(moves, p, tri);
            }
            if *apart < skin {
                *apart = vertex_distance(x0, p, tri);
                if *apart < skin {
                    self.close_vertices.push((p, t));
                }
            }
        }
        self.base.clear();
        self.base.extend_from_slice(x0);
        self.moved = moved;
    }
}

/// How much nearer edges `e` and `f` can have come than they were, having moved by `moves`:
/// the largest difference between an end of one's displacement and an end of the other's
/// (the closest points' displacements are weighted means of those).
#[inline]
fn edge_motion(moves: &[Vec3], e: &[u32; 2], f: &[u32; 2]) -> f64 {
    let [a, b] = e.map(|i| moves[i as usize]);
    let [c, d] = f.map(|i| moves[i as usize]);
    let most = [a - c, a - d, b - c, b - d]
        .iter()
        .map(Vec3::norm_squared)
        .fold(0.0, f64::max);
    most.sqrt()
}

/// How much nearer vertex `p` and triangle `t` can have come, having moved by `moves`: the
/// largest difference between the vertex's displacement and a corner's.
#[inline]
fn vertex_motion(moves: &[Vec3], p: u32, t: &[u32; 3]) -> f64 {
    let q = moves[p as usize];
    let most = t
        .iter()
        .map(|&i| (q - moves[i as usize]).norm_squared())
        .fold(0.0, f64::max);
    most.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertex over a triangle, 7 mm apart at rest; the triangle's far corners rise towards it
    /// 0.5 mm a step while the vertex and the near corner stay. The watch must hand the pair
    /// to the check before they meet: it fails when the box leaves out the corners that move,
    /// or bounds each step's own motion (both checked).
    #[test]
    fn a_pair_whose_triangle_folds_towards_its_vertex_is_checked_before_they_meet() {
        let rest = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.01, 0.0, 0.0),
            Vec3::new(0.0, 0.01, 0.0),
            Vec3::new(0.003, 0.003, 0.007),
        ];
        let triangles = [[0, 1, 2]];
        let mut g = Guard::new(&rest, &[], &triangles, vec![], vec![(3, 0)]).expect("guard");
        assert!((g.skin() - 0.85 * 0.007).abs() < 1e-12);
        let tolerance = 0.0005;
        let mut x0 = rest.clone();
        let mut checked_at = None;
        for step in 0..40 {
            let mut x1 = x0.clone();
            x1[1].z += 0.0005;
            x1[2].z += 0.0005;
            g.watch(&x0, &x1, &[], &triangles, tolerance);
            let watched = g.close().1.contains(&(3, 0));
            let d = vertex_distance(&x1, 3, &triangles[0]).min(vertex_distance(&x0, 3, &triangles[0]));
            if watched {
                checked_at.get_or_insert(step);
            }
            if d < tolerance {
                assert!(watched, "step {step}: {d} m apart, not checked");
                break;
            }
            x0 = x1;
        }
        // Not checked at the start (7 mm apart, past the skin), checked before they meet.
        let at = checked_at.expect("they meet within 40 steps");
        assert!(at > 0, "checked from the first step");
    }
}
