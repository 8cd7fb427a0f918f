//! Form drag on the large-scale normal velocity ([`crate::model::Water::form_drag_scale`]).
//!
//! Form drag comes from the flow separating around the cloth's edges and bulges. Ripples much
//! shorter than the cloth carry the water beside them to and fro between crest and trough and
//! shed little; the motion of the sheet at large does. This term takes the normal velocity
//! relative to the water, `u_i = (v_i - c) . n_i`, smooths it over the mesh (`w = S u`, `S` a
//! fixed low-pass of vertex-face-vertex averages weighted by rest areas) and applies the
//! quadratic drag to the smooth part through the transpose:
//!
//! `f_i = -n_i (S^T g)_i`, `g_j = 1/2 rho_w C_d A_j |w_j| w_j`.
//!
//! Its power is `sum_i f_i . v_rel,i = -sum_j 1/2 rho_w C_d A_j |w_j|^3 <= 0` for any `S`: the
//! term only ever takes energy out. A uniform normal velocity (a current face on, the whole
//! sheet swinging) passes `S` unchanged and meets the plain form drag.
//!
//! `S` is `k` passes of [`one_pass`] and a last partial one, `k` from the length: one pass
//! spreads a vertex's value over its first ring with mean square radius `r1^2` (measured on
//! the rest mesh, [`pass_spread`]), and the mean squares of passes add, so a smoothing of rms
//! radius `L` takes `L^2 / r1^2` passes: the same length on any mesh, at any resolution (and
//! a cost that grows as `(L / spacing)^2`: about 1.4 passes at 1 cm for the preset's 1 cm (2 for
//! the 1.2 cm it had before 0.9.26), 5.6 at
//! 0.5 cm, at most [`MAX_PASSES`]). A pass runs its rows in blocks of eight, one vector lane a
//! row ([`Blocks`]), with the bits of the rows summed one by one.

use crate::math::Vec3;
use crate::model::Model;
use crate::topology::Topology;

/// Buffers of the wide drag, kept between steps; the rest-mesh weights are filled on the
/// first step.
#[derive(Clone, Debug, Default)]
pub struct WideDragScratch {
    a: Vec<f64>,
    b: Vec<f64>,
    rest: Option<RestWeights>,
}

/// One pass as rows of vertex weights: `out_i = sum_k weights[k] u[cols[k]]` over row i.
#[derive(Clone, Debug, Default)]
struct Stencil {
    offsets: Vec<u32>,
    cols: Vec<u32>,
    weights: Vec<f64>,
}

/// Rows a block holds (one vector of f64 at AVX-512).
const LANES: usize = 8;

/// The rows of a [`Stencil`] in blocks of [`LANES`]: block b holds as many entries a lane as its
/// longest row (`starts[b] .. starts[b + 1]`, in units of a lane's entry); entry k of lane l at
/// `(starts[b] + k) * LANES + l`. A shorter row is padded after its entries with weight 0 on
/// column `rows`, the first slot of the values' padding, which holds -0.0 ([`apply`]): each lane
/// sums its row's entries in the row's order and then adds `0 x -0.0 = -0.0`, which leaves any
/// sum as it is, a zero's sign included: the bits of the rows summed one by one, in a shape the
/// vector unit takes whole.
///
/// **Shifted blocks.** A block whose rows are one row shifted (row `first + l` has entries at
/// columns `first + l + d_k` with weights `w_k`, the same `d_k` and `w_k` bit for bit in every
/// lane: a regular grid's rows away from its border) stores no entries: it names its shape in
/// `shapes` and reads `u` as plain slices, no column loads, no gathers. A 1001 x 1001 grid's
/// matrix then shrinks from 84 bytes a row to four, which is what a pass streamed from memory
/// once the cloth leaves the cache (`docs/benchmarks.md`). Same entries in the same order: the
/// same bits.
///
/// **Windowed blocks.** A stored block whose rows' columns all lie within a few offsets of their
/// rows (the union of its rows' offsets, at most [`MAX_WINDOW`]: an irregular mesh numbered in
/// rows, such as a grid with random diagonals) reads `u` as plain slices at those offsets, as a
/// shifted block does, with a weight per lane ([`ABSENT`] where the lane's row has no entry):
/// no column loads, no gathers. The offsets ascend, so each lane meets its row's entries in the
/// row's order: the same bits.
#[derive(Clone, Debug, Default)]
struct Blocks {
    /// Rows.
    rows: usize,
    starts: Vec<u32>,
    cols: Vec<u32>,
    weights: Vec<f64>,
    /// Per block: the index of its shape in `shapes`, or [`STORED`] when its entries are stored.
    shape: Vec<u32>,
    /// The distinct shapes of shifted blocks.
    shapes: Vec<Shape>,
    /// Per stored block: the index of its window in `windows`, or [`STORED`] when its lanes
    /// gather their columns.
    window: Vec<u32>,
    /// The distinct windows of windowed blocks.
    windows: Vec<Vec<isize>>,
}

/// Most column offsets a windowed block may read a lane: a 3 x 3 neighbourhood of a mesh
/// numbered in rows (the nine offsets of a grid-like mesh with random diagonals), and some.
const MAX_WINDOW: usize = 12;

/// A windowed block's weight for an offset its lane's row has no entry at: 0, which no weight
/// of a windowed block's rows is (a block with a zero weight, from a face of no area, stays
/// stored), so the lane adds `-0.0` there (no change to any sum, a zero's sign included)
/// whatever it reads.
const ABSENT: f64 = 0.0;

/// [`Blocks::shape`] of a block whose entries are stored.
const STORED: u32 = u32::MAX;

/// The entries every row of a shifted block has: column offsets from the row and weights.
#[derive(Clone, Debug, Default, PartialEq)]
struct Shape {
    offsets: Vec<isize>,
    weights: Vec<f64>,
}

impl Shape {
    /// The shape rows `rows` of `s` share, if they are one row shifted (a full block).
    fn of(s: &Stencil, rows: std::ops::Range<usize>) -> Option<Self> {
        if rows.len() != LANES {
            return None;
        }
        let entries = |i: usize| s.offsets[i] as usize..s.offsets[i + 1] as usize;
        let first = rows.start;
        let shape = Self {
            offsets: entries(first)
                .map(|e| s.cols[e] as isize - first as isize)
                .collect(),
            weights: entries(first).map(|e| s.weights[e]).collect(),
        };
        let same = |i: usize| {
            entries(i).len() == shape.offsets.len()
                && entries(i)
                    .zip(&shape.offsets)
                    .zip(&shape.weights)
                    .all(|((e, &d), w)| {
                        s.cols[e] as isize - i as isize == d && s.weights[e].to_bits() == w.to_bits()
                    })
        };
        rows.skip(1).all(same).then_some(shape)
    }
}

impl Blocks {
    fn new(s: &Stencil) -> Self {
        let n = s.offsets.len().saturating_sub(1);
        let row = |i: usize| s.offsets[i] as usize..s.offsets[i + 1] as usize;
        let mut b = Self {
            rows: n,
            starts: vec![0],
            ..Self::default()
        };
        for first in (0..n).step_by(LANES) {
            let rows = first..(first + LANES).min(n);
            if let Some(shape) = Shape::of(s, rows.clone()) {
                let k = match b.shapes.iter().position(|q| *q == shape) {
                    Some(k) => k,
                    None => {
                        b.shapes.push(shape);
                        b.shapes.len() - 1
                    }
                };
                b.shape.push(k as u32);
                b.window.push(STORED);
                b.starts.push((b.cols.len() / LANES) as u32);
                continue;
            }
            b.shape.push(STORED);
            let at = b.cols.len();
            if let Some(offsets) = Self::window_of(s, rows.clone()) {
                // One entry a lane per offset, ABSENT where the lane's row has none there.
                let k = match b.windows.iter().position(|w| *w == offsets) {
                    Some(k) => k,
                    None => {
                        b.windows.push(offsets.clone());
                        b.windows.len() - 1
                    }
                };
                b.window.push(k as u32);
                b.cols.resize(at + offsets.len() * LANES, n as u32);
                b.weights.resize(at + offsets.len() * LANES, ABSENT);
                for i in rows {
                    for e in row(i) {
                        let d = s.cols[e] as isize - i as isize;
                        let k = offsets.iter().position(|&o| o == d).expect("in the window");
                        b.weights[at + k * LANES + i - first] = s.weights[e];
                    }
                }
                b.starts.push((b.cols.len() / LANES) as u32);
                continue;
            }
            b.window.push(STORED);
            let width = rows.clone().map(|i| row(i).len()).max().unwrap_or(0);
            b.cols.resize(at + width * LANES, n as u32);
            b.weights.resize(at + width * LANES, 0.0);
            for i in rows {
                for (k, e) in row(i).enumerate() {
                    b.cols[at + k * LANES + i - first] = s.cols[e];
                    b.weights[at + k * LANES + i - first] = s.weights[e];
                }
            }
            b.starts.push((b.cols.len() / LANES) as u32);
        }
        b.cols.shrink_to_fit();
        b.weights.shrink_to_fit();
        b
    }
}

impl Blocks {
    /// The ascending column offsets rows `rows` of `s` read, if they make a window: a full
    /// block, at most [`MAX_WINDOW`] offsets, every lane's slice at every offset inside the
    /// rows (`0 ..= n - LANES`), and no weight of 0 ([`ABSENT`]).
    fn window_of(s: &Stencil, rows: std::ops::Range<usize>) -> Option<Vec<isize>> {
        let n = s.offsets.len().saturating_sub(1);
        if rows.len() != LANES {
            return None;
        }
        let first = rows.start;
        let mut offsets: Vec<isize> = Vec::new();
        for i in rows {
            for e in s.offsets[i] as usize..s.offsets[i + 1] as usize {
                if s.weights[e] == 0.0 {
                    return None;
                }
                let d = s.cols[e] as isize - i as isize;
                if let Err(k) = offsets.binary_search(&d) {
                    offsets.insert(k, d);
                }
            }
        }
        let inside = |d: &isize| {
            let at = first as isize + d;
            at >= 0 && at as usize + LANES <= n
        };
        (offsets.len() <= MAX_WINDOW && offsets.iter().all(inside)).then_some(offsets)
    }
}

crate::simd_dispatch! { fn blocks_widest(b: &Blocks, first: usize, u: &[f64], out: &mut [f64]) => apply_blocks }

/// Rows `first ..` (a multiple of [`LANES`]) of `b` times `u`, into `out`; `u.len()` a power of
/// two, so that a column masked by `u.len() - 1` (a no-op: every column is below it) needs no
/// bounds check and the lanes load as one gather.
#[inline(always)]
fn apply_blocks(b: &Blocks, first: usize, u: &[f64], out: &mut [f64]) {
    let mask = u.len() - 1;
    let u = &u[..=mask];
    for (k, o) in out.chunks_mut(LANES).enumerate() {
        let block = first / LANES + k;
        if let Some(shape) = b.shapes.get(b.shape[block] as usize) {
            // A shifted block (full, so every lane's column is a row's entry, below `rows`).
            let row0 = first + k * LANES;
            let mut acc = [-0.0f64; LANES];
            for (&d, &w) in shape.offsets.iter().zip(&shape.weights) {
                let at = row0.wrapping_add_signed(d);
                let v: &[f64; LANES] = u[at..at + LANES].try_into().expect("a block's columns");
                for l in 0..LANES {
                    acc[l] += w * v[l];
                }
            }
            o.copy_from_slice(&acc);
            continue;
        }
        let (lo, hi) = (b.starts[block] as usize, b.starts[block + 1] as usize);
        let weights = &b.weights[lo * LANES..hi * LANES];
        if let Some(window) = b.windows.get(b.window[block] as usize) {
            // A windowed block (full, every slice inside the rows): plain slices, a weight a
            // lane. An ABSENT weight adds `0 x u = +-0`, which leaves every sum as the row's
            // own unless that sum is zero (a -0.0 may come out +0.0): a lane that sums to zero
            // is summed again over its own entries (rare: a field that vanishes on a row).
            let row0 = first + k * LANES;
            let mut acc = [-0.0f64; LANES];
            for (&d, w) in window.iter().zip(weights.chunks_exact(LANES)) {
                let at = row0.wrapping_add_signed(d);
                let v: &[f64; LANES] = u[at..at + LANES].try_into().expect("a block's columns");
                let w: &[f64; LANES] = w.try_into().expect("a lane's entries");
                for l in 0..LANES {
                    acc[l] += w[l] * v[l];
                }
            }
            if acc.contains(&0.0) {
                for (l, a) in acc.iter_mut().enumerate().filter(|(_, a)| **a == 0.0) {
                    *a = window
                        .iter()
                        .zip(weights.chunks_exact(LANES))
                        .filter(|(_, w)| w[l] != ABSENT)
                        .map(|(&d, w)| w[l] * u[(row0 + l).wrapping_add_signed(d)])
                        .fold(-0.0, |s, t| s + t);
                }
            }
            o.copy_from_slice(&acc);
            continue;
        }
        let cols = &b.cols[lo * LANES..hi * LANES];
        // Each lane's sum starts as an iterator's sum of f64 does (-0.0), so the first entry
        // comes through exactly.
        let mut acc = [-0.0f64; LANES];
        for (c, w) in cols.chunks_exact(LANES).zip(weights.chunks_exact(LANES)) {
            let c: &[u32; LANES] = c.try_into().expect("a lane's entries");
            let w: &[f64; LANES] = w.try_into().expect("a lane's entries");
            for l in 0..LANES {
                acc[l] += w[l] * u[c[l] as usize & mask];
            }
        }
        o.copy_from_slice(&acc[..o.len()]);
    }
}

impl Blocks {
    /// `out = rows . u`, `u` padded with zeros to a power of two (at least `out.len()`); rows in
    /// chunks, so a large cloth spreads them over the pool with the same bits.
    fn apply(&self, u: &[f64], out: &mut [f64]) {
        debug_assert!(u.len().is_power_of_two() && u.len() >= out.len());
        let parallel = crate::parallel::worth_it(out.len());
        crate::parallel::chunks(parallel, out, crate::parallel::CHUNK, |first, chunk| {
            blocks_widest(self, first, u, chunk)
        });
    }
}

impl Stencil {
    /// `out = rows . u`, each row summed in order: the reference [`Blocks::apply`] is tested
    /// against.
    #[cfg(test)]
    fn apply(&self, u: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            let (a, b) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
            *o = self.cols[a..b]
                .iter()
                .zip(&self.weights[a..b])
                .map(|(&j, w)| w * u[j as usize])
                .sum();
        }
    }

    /// The transposed rows, each in ascending column order.
    fn transpose(&self, n: usize) -> Self {
        let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
        for i in 0..n {
            let (a, b) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
            for (&j, &w) in self.cols[a..b].iter().zip(&self.weights[a..b]) {
                rows[j as usize].push((i as u32, w));
            }
        }
        Self::from_rows(rows)
    }

    fn from_rows(rows: Vec<Vec<(u32, f64)>>) -> Self {
        let mut s = Self::default();
        s.offsets.push(0);
        for row in rows {
            for (j, w) in row {
                s.cols.push(j);
                s.weights.push(w);
            }
            s.offsets.push(s.cols.len() as u32);
        }
        s
    }
}

/// The smoothing's weights on the rest mesh.
#[derive(Clone, Debug)]
struct RestWeights {
    /// One pass ([`one_pass`]) and its transpose.
    forward: Blocks,
    backward: Blocks,
    /// Whole passes and the weight of the last partial one, for the model's length.
    passes: usize,
    partial: f64,
    /// The length they were computed for, m.
    length: f64,
}

/// Most passes a smoothing takes (64 rings: beyond any cloth's ripples at any spacing the
/// library is used at; a longer length on a finer mesh smooths over this many).
const MAX_PASSES: f64 = 64.0;

impl RestWeights {
    fn new(t: &Topology, length: f64) -> Self {
        let forward = one_pass(t);
        let spread = pass_spread(t, &forward);
        let total = if spread > 0.0 {
            (length * length / spread).min(MAX_PASSES)
        } else {
            0.0
        };
        let passes = total.floor();
        Self {
            backward: Blocks::new(&forward.transpose(t.vertex_count())),
            forward: Blocks::new(&forward),
            passes: passes as usize,
            partial: total - passes,
            length,
        }
    }
}

/// One smoothing pass as vertex rows: each face takes the mean of its corners, each vertex the
/// rest-area weighted mean of its faces (a vertex with no face area keeps its value); rows
/// equal to within rounding share their weights ([`shared_rounding`]).
fn one_pass(t: &Topology) -> Stencil {
    Stencil::from_rows(shared_rounding(pass_rows(t)))
}

/// [`one_pass`]'s rows, each vertex's `(column, weight)` in ascending columns, as computed.
fn pass_rows(t: &Topology) -> Vec<Vec<(u32, f64)>> {
    let x = &t.rest_positions;
    let face_area: Vec<f64> = t
        .triangles
        .iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|i| i as usize);
            0.5 * (x[b] - x[a]).cross(&(x[c] - x[a])).norm()
        })
        .collect();
    (0..x.len())
        .map(|i| {
            let faces = t.vertex_triangles.row(i);
            let total: f64 = faces.iter().map(|&f| face_area[f as usize]).sum();
            if total <= 0.0 {
                return vec![(i as u32, 1.0)];
            }
            let mut row: Vec<(u32, f64)> = Vec::new();
            for &f in faces {
                let w = face_area[f as usize] / total / 3.0;
                for &j in &t.triangles[f as usize] {
                    match row.iter_mut().find(|(k, _)| *k == j) {
                        Some((_, acc)) => *acc += w,
                        None => row.push((j, w)),
                    }
                }
            }
            row.sort_by_key(|&(j, _)| j);
            row
        })
        .collect()
}

/// Relative difference below which two rows' weights are the same weights rounded differently.
const ROUNDING: f64 = 1e-12;

/// Rows that are one row shifted up to rounding (the same column offsets from the row, weights
/// within [`ROUNDING`]: a regular grid's interior, whose face areas round differently at
/// different coordinates) take the first such row's weights bit for bit, so [`Blocks`] can
/// store them once. Weights move by rounding only (1e-16 relative); an irregular mesh's rows,
/// whose weights differ by more, keep theirs.
fn shared_rounding(mut rows: Vec<Vec<(u32, f64)>>) -> Vec<Vec<(u32, f64)>> {
    let mut seen: std::collections::HashMap<Vec<i64>, Vec<f64>> = std::collections::HashMap::new();
    for (i, row) in rows.iter_mut().enumerate() {
        let offsets: Vec<i64> = row.iter().map(|&(j, _)| i64::from(j) - i as i64).collect();
        match seen.get(&offsets) {
            Some(w)
                if row
                    .iter()
                    .zip(w)
                    .all(|(&(_, a), &b)| (a - b).abs() <= ROUNDING * b.abs()) =>
            {
                for ((_, a), &b) in row.iter_mut().zip(w) {
                    *a = b;
                }
            }
            Some(_) => {}
            None => {
                seen.insert(offsets, row.iter().map(|&(_, w)| w).collect());
            }
        }
    }
    rows
}

/// Mean square distance, m^2, over which one pass spreads a vertex's value:
/// `sum_j S_ij |X_j - X_i|^2` over each row at rest, averaged over the vertices.
fn pass_spread(t: &Topology, s: &Stencil) -> f64 {
    let x = &t.rest_positions;
    let n = x.len();
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = (0..n)
        .map(|i| {
            let (a, b) = (s.offsets[i] as usize, s.offsets[i + 1] as usize);
            s.cols[a..b]
                .iter()
                .zip(&s.weights[a..b])
                .map(|(&j, w)| w * (x[j as usize] - x[i]).norm_squared())
                .sum::<f64>()
        })
        .sum();
    sum / n as f64
}

/// `u <- S u` (`transpose`: `u <- S^T u`): the whole passes, then the partial one,
/// `(1 - p) u + p S1 u`. `S^T` applies the transposed passes in reverse order.
fn apply(w: &RestWeights, transpose: bool, u: &mut Vec<f64>, b: &mut Vec<f64>) {
    // Both buffers padded with -0.0 to a power of two above `n` (the blocked rows read `u`
    // without bounds checks and their padding entries read slot `n`, [`Blocks`]); the rows
    // write the first `n`, the padding stays -0.0.
    let n = u.len();
    let padded = (n + 1).next_power_of_two();
    u.resize(padded, -0.0);
    // `b`'s first `n` are written before they are read; only its padding must be -0.0.
    b.resize(padded, -0.0);
    b[n..].fill(-0.0);
    let one = if transpose { &w.backward } else { &w.forward };
    let par = crate::parallel::worth_it(n);
    let partial = |u: &mut Vec<f64>, b: &mut Vec<f64>| {
        if w.partial > 0.0 {
            one.apply(u, &mut b[..n]);
            let b = &b[..n];
            crate::parallel::chunks(par, &mut u[..n], crate::parallel::CHUNK, |first, u| {
                for (ui, bi) in u.iter_mut().zip(&b[first..]) {
                    *ui += w.partial * (bi - *ui);
                }
            });
        }
    };
    if transpose {
        partial(u, b);
    }
    for _ in 0..w.passes {
        one.apply(u, &mut b[..n]);
        std::mem::swap(u, b);
    }
    if !transpose {
        partial(u, b);
    }
    u.truncate(n);
}

/// Whether the form drag of `m` acts on the smoothed normal velocity (this module) rather than
/// particle by particle (`terms::FORM_DRAG`).
pub fn wide(m: &Model) -> bool {
    m.water.form_drag != 0.0 && m.water.form_drag_scale > 0.0
}

/// Adds the wide form drag of `m` with unit vertex normals `normals`, velocities relative to
/// the water `v`, to `out` (one per particle); nothing unless [`wide`].
pub fn add_wide_form_drag(
    m: &Model,
    t: &Topology,
    normals: &[Vec3],
    v: &[Vec3],
    scratch: &mut WideDragScratch,
    out: &mut [Vec3],
) {
    if !wide(m) {
        return;
    }
    let WideDragScratch { a, b, rest } = scratch;
    let length = m.water.form_drag_scale;
    let w = match rest {
        Some(w) if w.length == length && w.forward.rows == normals.len() => w,
        _ => rest.insert(RestWeights::new(t, length)),
    };
    // The element-wise loops run in chunks over the pool on a large cloth (same bits).
    let (par, chunk) = (crate::parallel::worth_it(normals.len()), crate::parallel::CHUNK);
    a.resize(normals.len(), 0.0);
    crate::parallel::chunks(par, a, chunk, |first, a| {
        for ((u, n), v) in a.iter_mut().zip(&normals[first..]).zip(&v[first..]) {
            *u = n.dot(v);
        }
    });
    apply(w, false, a, b);
    let c = 0.5 * m.water_density * m.water.form_drag;
    let areas = &t.areas;
    crate::parallel::chunks(par, a, chunk, |first, a| {
        for (g, area) in a.iter_mut().zip(&areas[first..]) {
            *g *= c * area * g.abs();
        }
    });
    apply(w, true, a, b);
    let g = &a[..];
    crate::parallel::chunks(par, out, chunk, |first, out| {
        for ((o, n), g) in out.iter_mut().zip(&normals[first..]).zip(&g[first..]) {
            *o -= *g * n;
        }
    });
}

#[cfg(test)]
mod tests;
