//! The carried water's turning forces ([`super::inertia::turning_forces`]) on a grid's
//! triangles: a row of cells at a time in component arrays, each vertex gathering its faces'
//! terms, instead of each face scattering its terms to its corners.
//!
//! A grid built by [`crate::topology::GridSpec`] splits every cell `(i, j)` (corners
//! `a = (i, j)`, `b = (i + 1, j)`, `c = (i, j + 1)`, `d = (i + 1, j + 1)`) into `[a, c, b]`
//! and `[b, c, d]`, cell after cell, row after row ([`Topology::grid_faces`]). So a vertex
//! knows its faces, and which corner of each it is, from its place in the grid, and in which
//! order a scatter over the faces reaches it: cell `(i - 1, j - 1)`'s second face, both of
//! `(i, j - 1)`'s, both of `(i - 1, j)`'s and `(i, j)`'s first. Each vertex adds its faces'
//! terms in that order, computed with the same operations, so it gets the scatter's bits
//! (a test compares them on every shape of grid). Cell row j's terms are computed a vector
//! of cells at a time ([`BLOCK`]) and finish vertex row j's sums and begin row j + 1's; the
//! rows of vertices, cells and sums are a few rows of component arrays, in cache.
//!
//! A band of rows is walked once: its cell rows' area terms make its vertex rows' sums, a few
//! rows of sums at a time take their patch terms (`w`, [`PATCH_ROWS_VERTICES`]) while in
//! cache, and each cell row whose two vertex rows' `w` are there takes its gradients at once.
//! So the sums never leave the cache, and positions, forces and `w` are read once a step
//! where the passes apart read them twice. On the pool the rows are cut into
//! bands, one task each; the cell rows that read another band's `w` (above a band's first
//! row, and its last) wait for a small pass after every band's walk ([`edges`]). A cell row
//! two bands need is computed by both, with the same values: the bits do not depend on the
//! bands, the rows kept or the thread count (a unit test against the scatter; the
//! determinism hashes run the underwater preset on 1, 2 and 8 threads). This replaces, for
//! grids, the chunks and wavefront that other meshes take (`inertia.rs`).
//!
//! Measured (AMD EPYC, `docs/benchmarks.md`, alternated with the scatter's build), ns
//! a particle-step of the underwater preset: 61 x 41 58-60 against 64-66; 201 x 201 on one
//! thread 63-64 against 71-74, on two 33-35 against 41; 1001 x 1001 on two threads 48-49
//! against 54-55 (1.77-1.84 times one thread's 87-88). The scatter's chain of stores and
//! reloads (a vertex is a corner of six faces, three of them consecutive) was the cost on one
//! thread; the chunks' borders and wavefront on two. Walking each band once (above) saves
//! more: see `docs/benchmarks.md` for the figures.

use super::patch::{patch_range, PatchOut};
use crate::math::Vec3;
use crate::parallel;
use crate::topology::Topology;

/// The face terms of a row of cells, each `cw` long, three components each: the first pass's
/// area vectors and rates of the first and second face of every cell.
const F0: usize = 0;
const R0: usize = 3;
const F1: usize = 6;
/// The second pass's gradients at the corners of the first face (`[a, c, b]`: its corners 1,
/// 2 and 0 are c, b, a) and of the second (`[b, c, d]`: c, d, b).
const G0B: usize = 0;
const G0C: usize = 3;
const G0A: usize = 6;
const G1B: usize = 9;
const G1C: usize = 12;
const G1A: usize = 15;
const SLOTS: usize = 18;

/// Cells per block of the face passes: one AVX-512 vector of f64.
const BLOCK: usize = 8;

/// Vertices (whole rows, at least one) whose sums and rates the first pass keeps before taking
/// their patch terms: 192 KB of sums and rates, in the second-level cache. A band of no more
/// takes them in one range, as it did before the rows were chunked.
pub(super) const PATCH_ROWS_VERTICES: usize = 4096;

/// The buffers [`turning_grid`] fills: each band's rows of vertices' vectors, of a row of
/// cells' terms and of sums, in component arrays (a few rows, in cache); each vertex's sums of
/// its faces' area vectors and rates, and its `w`.
pub(super) struct GridBuffers<'a> {
    pub bands: &'a mut Vec<Vec<f64>>,
    pub sums: &'a mut Vec<Vec3>,
    pub rates: &'a mut Vec<Vec3>,
    pub patches: &'a mut Vec<Vec3>,
}

/// `data` cut into `N` consecutive slices of `len`.
fn cut<const N: usize>(data: &mut [f64], len: usize) -> [&mut [f64]; N] {
    let mut parts = data.chunks_exact_mut(len.max(1));
    std::array::from_fn(|_| parts.next().unwrap_or_default())
}

/// Writes the components of `from` into `to[0..3]`.
#[inline(always)]
fn transpose(from: &[Vec3], to: &mut [&mut [f64]]) {
    for (k, p) in from.iter().enumerate() {
        for c in 0..3 {
            to[c][k] = p[c];
        }
    }
}

/// Writes the components `from[0..3]` into `to`.
#[inline(always)]
fn untranspose(from: &[&mut [f64]], to: &mut [Vec3]) {
    for (k, p) in to.iter_mut().enumerate() {
        *p = Vec3::new(from[0][k], from[1][k], from[2][k]);
    }
}

/// `a x b` in components, as `Vec3::cross` computes it.
#[inline(always)]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Adds to vertex row j the terms of its faces in cell row j (`acc` the row, `w` long; the
/// cell row's terms `cw = w - 1` long): the first face of cell i - 1 (`a`), its second (`b`)
/// and the first of cell i (`c`), in that order.
#[inline(always)]
fn below(acc: &mut [f64], a: &[f64], b: &[f64], c: &[f64]) {
    let cw = a.len();
    let (acc, b, c) = (&mut acc[..cw + 1], &b[..cw], &c[..cw]);
    acc[0] += c[0];
    for i in 1..cw {
        acc[i] = ((acc[i] + a[i - 1]) + b[i - 1]) + c[i];
    }
    acc[cw] = (acc[cw] + a[cw - 1]) + b[cw - 1];
}

/// Adds to vertex row j + 1 the terms of its faces in cell row j: the second face of cell
/// i - 1 (`a`), the first of cell i (`b`) and its second (`c`), in that order.
#[inline(always)]
fn above(acc: &mut [f64], a: &[f64], b: &[f64], c: &[f64]) {
    let cw = a.len();
    let (acc, b, c) = (&mut acc[..cw + 1], &b[..cw], &c[..cw]);
    acc[0] = (acc[0] + b[0]) + c[0];
    for i in 1..cw {
        acc[i] = ((acc[i] + a[i - 1]) + b[i]) + c[i];
    }
    acc[cw] += a[cw - 1];
}

/// [`super::inertia::turning_forces`] for a grid of `w` x `h` vertices whose triangles are
/// [`Topology::grid_faces`]'s: the same terms in the same order, so the same bits. In bands of
/// `band` vertex rows, on the pool when `par`, keeping the sums of `kept` vertices (whole rows,
/// [`PATCH_ROWS_VERTICES`] in the step): first each band walks its rows once, taking their
/// sums, patch terms and the gradients of the cell rows inside it; then the rows where bands
/// meet take the gradients that read another band's `w`. A cell row two bands need is
/// computed by both, with the same values: the bits do not depend on the bands.
#[allow(clippy::too_many_arguments)] // the step's arrays the passes read and write
pub(super) fn turning_grid(
    ma: f64,
    t: &Topology,
    (w, h): (usize, usize),
    x: &[Vec3],
    v: &[Vec3],
    buffers: GridBuffers<'_>,
    (band, par, kept): (usize, bool, usize),
    projected: &mut [f64],
    normals: &mut [Vec3],
    out: &mut [Vec3],
) {
    let GridBuffers {
        bands,
        sums,
        rates,
        patches,
    } = buffers;
    let n = w * h;
    let band = band.clamp(1, h);
    let count = h.div_ceil(band);
    // Two sets of rows: the first pass's (areas) and the gradients'.
    let len = 2 * (24 * w + SLOTS * (w - 1));
    if bands.len() != count || bands.iter().any(|b| b.len() != len) {
        bands.clear();
        bands.resize(count, vec![0.0; len]);
    }
    // A few rows of sums and rates a band: their patch terms are taken while they are in cache.
    let chunk = kept.div_ceil(w).clamp(1, band);
    for a in [&mut *sums, &mut *rates] {
        a.resize(count * chunk * w, Vec3::zeros());
    }
    patches.resize(n, Vec3::zeros());
    let (x, v) = (&x[..n], &v[..n]);
    let rows = parallel::Disjoint::new(&mut bands[..]);
    {
        let d = [&mut patches[..], &mut normals[..n], &mut out[..n]].map(parallel::Disjoint::new);
        let row_sums = [&mut sums[..], &mut rates[..]].map(parallel::Disjoint::new);
        let projected = parallel::Disjoint::new(&mut projected[..n]);
        parallel::for_chunks(par, h, band, |first, len| {
            let r = first * w..(first + len) * w;
            let b = first / band;
            // SAFETY: every task borrows only its own band's rows of each array, and its own
            // row buffer and row of sums.
            let [patches, normals, out] = d.each_ref().map(|a| unsafe { a.range(r.clone()) });
            // SAFETY: as above.
            let [sums, rates] = row_sums
                .each_ref()
                .map(|a| unsafe { a.range(b * chunk * w..(b + 1) * chunk * w) });
            // SAFETY: as above.
            let (projected, rows) = unsafe { (projected.range(r.clone()), rows.range(b..b + 1)) };
            let mine = Band {
                rows: first..first + len,
                buffer: &mut rows[0],
            };
            let patch_out = PatchOut {
                o: out,
                projected,
                normals,
                w: patches,
            };
            areas_and_patches_widest(ma, t, w, h, x, v, mine, [sums, rates], patch_out);
        });
    }
    if count == 1 {
        // One band: it took every face's gradients itself.
        return;
    }
    // The rows where bands meet: each band's gradients of the cell rows that read another
    // band's `w` (the one above its first row and its own last one).
    let (patches, d) = (&patches[..], parallel::Disjoint::new(&mut out[..n]));
    parallel::for_chunks(par, h, band, |first, len| {
        // SAFETY: as above.
        let (out, rows) = unsafe {
            (
                d.range(first * w..(first + len) * w),
                rows.range(first / band..first / band + 1),
            )
        };
        let mine = Band {
            rows: first..first + len,
            buffer: &mut rows[0],
        };
        edges_widest(w, h, x, patches, mine, out);
    });
}

/// A band of vertex rows and its row buffer.
struct Band<'a> {
    rows: std::ops::Range<usize>,
    buffer: &'a mut [f64],
}

crate::simd_dispatch! { fn areas_and_patches_widest(ma: f64, t: &Topology, w: usize, h: usize, x: &[Vec3], v: &[Vec3], band: Band<'_>, into: [&mut [Vec3]; 2], patch_out: PatchOut<'_>) => areas_and_patches }

/// A band's sums and rates ([`areas`]), their patch terms ([`patch_range`], into `patch_out`:
/// the band's rows), a few rows at a time while they are in cache (`into`: room for the sums
/// and rates of those rows, whole rows), and the gradients of the cell rows whose `w` the band
/// holds ([`Gradients`]), each as soon as its two rows' `w` are there. What is left (the cell
/// rows that read another band's `w`) is [`edges`]'s.
#[allow(clippy::too_many_arguments)] // the step's arrays the passes read and write
#[inline(always)]
fn areas_and_patches(
    ma: f64,
    t: &Topology,
    w: usize,
    h: usize,
    x: &[Vec3],
    v: &[Vec3],
    band: Band<'_>,
    into: [&mut [Vec3]; 2],
    patch_out: PatchOut<'_>,
) {
    let [sums, rates] = into;
    let Band { rows, buffer } = band;
    let (first, second) = buffer.split_at_mut(buffer.len() / 2);
    let (vectors, terms, cur, next) = carve(second, w);
    let mut rows_done = PatchRows {
        ma,
        t,
        top: rows.start,
        end: rows.end,
        from: rows.start,
        w,
        v,
        sums,
        rates,
        out: patch_out,
        gradients: Gradients {
            x: &x[rows.start * w..rows.end * w],
            vectors,
            terms,
            cur,
            next,
            cell: rows.start,
        },
    };
    let band = Band { rows, buffer: first };
    areas(w, h, x, v, band, &mut rows_done);
}

/// What [`areas_and_patches`] does with each vertex row's sums and rates once complete: keeps
/// them until its room is full or the band ends, then takes their patch terms and the
/// gradients they make ready.
struct PatchRows<'a> {
    ma: f64,
    t: &'a Topology,
    /// The band's rows.
    top: usize,
    end: usize,
    /// The first row kept.
    from: usize,
    w: usize,
    v: &'a [Vec3],
    /// Room for the sums and rates of whole rows.
    sums: &'a mut [Vec3],
    rates: &'a mut [Vec3],
    /// The band's rows.
    out: PatchOut<'a>,
    gradients: Gradients<'a>,
}

impl PatchRows<'_> {
    /// Keeps vertex row `row`'s sums and rates (`cur`: their components); takes the patch terms
    /// of the rows kept when there is no room for another or the band ends, then the gradients
    /// that were waiting for their `w`. A method, not a closure: inlined into the caller, it runs
    /// at the caller's vector width.
    #[inline(always)]
    fn done(&mut self, row: usize, cur: &[&mut [f64]]) {
        let w = self.w;
        let at = (row - self.from) * w..(row - self.from + 1) * w;
        untranspose(&cur[..3], &mut self.sums[at.clone()]);
        untranspose(&cur[3..], &mut self.rates[at.clone()]);
        if at.end + w <= self.sums.len() && row + 1 < self.end {
            return;
        }
        let g = self.from * w..(row + 1) * w;
        let r = g.start - self.top * w..g.end - self.top * w;
        let PatchOut {
            o,
            projected,
            normals,
            w: patches,
        } = &mut self.out;
        let out = PatchOut {
            o: &mut o[r.clone()],
            projected: &mut projected[r.clone()],
            normals: &mut normals[r.clone()],
            w: &mut patches[r],
        };
        let t = self.t;
        let (sums, rates) = (&self.sums[..at.end], &self.rates[..at.end]);
        patch_range(
            self.ma,
            &t.areas[g.clone()],
            &t.patch_scale[g.clone()],
            sums,
            rates,
            &self.v[g],
            out,
        );
        self.from = row + 1;
        self.gradients.advance(self.top, self.end, row, w, patches, o);
    }
}

/// The gradients a band takes as its `w` comes ([`PatchRows`]): the cell rows from its first
/// to its last but one, whose two vertex rows are the band's. Vertex row `r` adds its faces'
/// terms in ascending face order, cell row `r - 1`'s then `r`'s, after its patch terms; so the
/// band's first row (but the grid's first) waits for the cell row above it, and its last (but
/// the grid's last) for its own cell row: [`edges`] adds those.
struct Gradients<'a> {
    /// The band's positions.
    x: &'a [Vec3],
    /// Two vertex rows of positions and `w` (the band's rows counted from its first).
    vectors: VertexRows<'a>,
    terms: [&'a mut [f64]; SLOTS],
    /// The forces of the row being finished and of the one begun (three components, then
    /// spare).
    cur: [&'a mut [f64]; 6],
    next: [&'a mut [f64]; 6],
    /// The next cell row to take.
    cell: usize,
}

impl Gradients<'_> {
    /// Takes the cell rows whose `w` are there (vertex rows up to `ready`; `patches` and `out`
    /// the band's rows, from `top` to `end`).
    #[inline(always)]
    fn advance(
        &mut self,
        top: usize,
        end: usize,
        ready: usize,
        w: usize,
        patches: &[Vec3],
        out: &mut [Vec3],
    ) {
        let at = |row: usize| (row - top) * w..(row - top + 1) * w;
        let local = [self.x, patches];
        // Cell row c reads vertex rows c and c + 1: both the band's, and both ready.
        while self.cell < ready.min(end - 1) {
            let c = self.cell;
            if c == top {
                self.vectors.start(0, local, w);
                if c == 0 {
                    transpose(&out[at(0)], &mut self.cur[..3]);
                }
            }
            self.vectors
                .cell_row(c - top, local, w, gradient_terms, &mut self.terms[..]);
            let terms = &self.terms;
            // Cell row c completes vertex row c's forces (unless c is the band's first row and
            // not the grid's: it waits for the cell row above) and begins row c + 1's.
            if c > top || c == 0 {
                for q in 0..3 {
                    below(self.cur[q], terms[G0C + q], terms[G1A + q], terms[G0A + q]);
                }
                untranspose(&self.cur[..3], &mut out[at(c)]);
            }
            transpose(&out[at(c + 1)], &mut self.next[..3]);
            for q in 0..3 {
                above(self.next[q], terms[G1C + q], terms[G0B + q], terms[G1B + q]);
            }
            std::mem::swap(&mut self.cur, &mut self.next);
            self.cell += 1;
        }
        if ready + 1 == end && self.cell > top {
            // The band's last row, begun by the cell row above it: finished when it is the
            // grid's last, else waiting for its own cell row ([`edges`]).
            untranspose(&self.cur[..3], &mut out[at(end - 1)]);
        }
    }
}

crate::simd_dispatch! { fn edges_widest(w: usize, h: usize, x: &[Vec3], patches: &[Vec3], band: Band<'_>, out: &mut [Vec3]) => edges }

/// The cell rows whose terms a band of vertex rows `rows` needs (the one above it too), of a
/// grid `h` rows high.
fn cell_rows(rows: &std::ops::Range<usize>, h: usize) -> std::ops::Range<usize> {
    rows.start.saturating_sub(1)..rows.end.min(h - 1)
}

/// Each vertex of the band's sums of its faces' area vectors and rates, in ascending face order
/// from zero, as a scatter adds them, handed to `done` row by row (the row, then the sums' and
/// the rates' components).
#[inline(always)]
fn areas(w: usize, h: usize, x: &[Vec3], v: &[Vec3], band: Band<'_>, done: &mut PatchRows<'_>) {
    let Band { rows, buffer } = band;
    let (mut vectors, mut terms, mut cur, mut next) = carve(buffer, w);
    let cells = cell_rows(&rows, h);
    for a in cur.iter_mut() {
        a.fill(0.0);
    }
    vectors.start(cells.start, [x, v], w);
    for c in cells {
        vectors.cell_row(c, [x, v], w, area_terms, &mut terms[..12]);
        // Cell row c completes vertex row c's sums and begins row c + 1's.
        for k in 0..6 {
            let slot = if k < 3 { F0 + k } else { R0 + k - 3 };
            let (t0, t1) = (&*terms[slot], &*terms[slot + F1 - F0]);
            below(cur[k], t0, t1, t0);
            next[k].fill(0.0);
            above(next[k], t1, t0, t1);
        }
        if c >= rows.start {
            done.done(c, &cur);
        }
        std::mem::swap(&mut cur, &mut next);
    }
    if rows.end == h {
        done.done(h - 1, &cur);
    }
}

/// The gradients [`Gradients`] leaves at a band's edges, once every band's `w` is there
/// (`patches` every vertex's; `out` the band's rows): its first row's (but the grid's first),
/// cell row above it then its own, and its last row's (but the grid's last), its own cell row.
#[inline(always)]
fn edges(w: usize, h: usize, x: &[Vec3], patches: &[Vec3], band: Band<'_>, out: &mut [Vec3]) {
    let Band { rows, buffer } = band;
    let (mut vectors, mut terms, mut cur, _) = carve(buffer, w);
    let (top, end) = (rows.start, rows.end);
    let at = |row: usize| (row - top) * w..(row - top + 1) * w;
    let from = [x, patches];
    if top > 0 {
        vectors.start(top - 1, from, w);
        vectors.cell_row(top - 1, from, w, gradient_terms, &mut terms[..]);
        transpose(&out[at(top)], &mut cur[..3]);
        for q in 0..3 {
            above(cur[q], terms[G1C + q], terms[G0B + q], terms[G1B + q]);
        }
        if top + 1 < h {
            vectors.cell_row(top, from, w, gradient_terms, &mut terms[..]);
            for q in 0..3 {
                below(cur[q], terms[G0C + q], terms[G1A + q], terms[G0A + q]);
            }
        }
        untranspose(&cur[..3], &mut out[at(top)]);
    }
    // The last row, unless it is the grid's or the first row above took its cell row.
    if end < h && !(end - 1 == top && top > 0) {
        vectors.start(end - 1, from, w);
        vectors.cell_row(end - 1, from, w, gradient_terms, &mut terms[..]);
        transpose(&out[at(end - 1)], &mut cur[..3]);
        for q in 0..3 {
            below(cur[q], terms[G0C + q], terms[G1A + q], terms[G0A + q]);
        }
        untranspose(&cur[..3], &mut out[at(end - 1)]);
    }
}

/// A row of three component arrays.
type Row<'a> = [&'a mut [f64]; 3];

/// Two vertex rows (the top and the one below it) of two per-vertex vectors (positions and
/// velocities, or positions and `w`), in component arrays.
struct VertexRows<'a> {
    top: [Row<'a>; 2],
    bottom: [Row<'a>; 2],
}

impl VertexRows<'_> {
    /// Reads vertex row `r` of `from` into the bottom rows.
    #[inline(always)]
    fn start(&mut self, r: usize, from: [&[Vec3]; 2], w: usize) {
        for (to, from) in self.bottom.iter_mut().zip(from) {
            transpose(&from[r * w..(r + 1) * w], to);
        }
    }

    /// Cell row `c`'s terms by `kernel` into `terms`: the bottom rows move up and vertex row
    /// `c + 1` of `from` is read into the bottom ones.
    #[inline(always)]
    fn cell_row<const K: usize>(
        &mut self,
        c: usize,
        from: [&[Vec3]; 2],
        w: usize,
        kernel: fn(Corners, Corners) -> [[f64; 3]; K],
        terms: &mut [&mut [f64]],
    ) {
        std::mem::swap(&mut self.top, &mut self.bottom);
        self.start(c + 1, from, w);
        let [t0, t1] = &self.top;
        let [b0, b1] = &self.bottom;
        blocks(w - 1, [row(t0), row(b0)], [row(t1), row(b1)], kernel, terms);
    }
}

/// `rows` carved for a grid `w` wide: two vertex rows of two vectors, a row of cells' terms
/// and two rows of six sums.
#[allow(clippy::type_complexity)]
fn carve(
    rows: &mut [f64],
    w: usize,
) -> (
    VertexRows<'_>,
    [&mut [f64]; SLOTS],
    [&mut [f64]; 6],
    [&mut [f64]; 6],
) {
    let cw = w - 1;
    let (vectors, rest) = rows.split_at_mut(12 * w);
    let (terms, sums) = rest.split_at_mut(SLOTS * cw);
    let [a, b, c, d] = cut::<4>(vectors, 3 * w).map(|r| cut::<3>(r, w));
    let [e, f] = cut::<2>(sums, 6 * w).map(|r| cut::<6>(r, w));
    let vectors = VertexRows {
        top: [a, c],
        bottom: [b, d],
    };
    (vectors, cut(terms, cw), e, f)
}

/// The first `w` of each component of a row.
fn row<'a>(r: &'a [&mut [f64]; 3]) -> [&'a [f64]; 3] {
    [&r[0][..], &r[1][..], &r[2][..]]
}

/// A cell's four corners' vectors: a, b, c, d.
type Corners = [[f64; 3]; 4];

/// A cell's two faces' area vectors and rates (`[f0, r0, f1, r1]`) from its corners'
/// positions and velocities (`a, b, c, d`), as `inertia::face_and_rate` computes them.
#[inline(always)]
fn area_terms([a, b, c, d]: Corners, [va, vb, vc, vd]: Corners) -> [[f64; 3]; 4] {
    // [a, c, b]: e1 = c - a, e2 = b - a; the rate (v_c - v_a) x e2 + e1 x (v_b - v_a).
    let (e1, e2) = (sub(c, a), sub(b, a));
    let f0 = cross(e1, e2);
    let r0 = add(cross(sub(vc, va), e2), cross(e1, sub(vb, va)));
    // [b, c, d]: e1 = c - b, e2 = d - b.
    let (e1, e2) = (sub(c, b), sub(d, b));
    let f1 = cross(e1, e2);
    let r1 = add(cross(sub(vc, vb), e2), cross(e1, sub(vd, vb)));
    [f0, r0, f1, r1]
}

/// A cell's two faces' gradients at their corners (`[gb, gc, ga, hb, hc, ha]`: the first
/// face's at c, b, a, the second's at c, d, b) from its corners' positions and `w`, as
/// `inertia::face_gradients` computes them (and `-(gb + gc)` at the first corner).
#[inline(always)]
fn gradient_terms([a, b, c, d]: Corners, [wa, wb, wc, wd]: Corners) -> [[f64; 3]; 6] {
    let zero = [0.0; 3];
    // [a, c, b]: W = w_a + w_c + w_b from zero; e1 = c - a, e2 = b - a.
    let sum = add(add(add(zero, wa), wc), wb);
    let (e1, e2) = (sub(c, a), sub(b, a));
    let (gb, gc) = (cross(e2, sum), cross(sum, e1));
    let ga = add(gb, gc).map(|g| -g);
    // [b, c, d]: W = w_b + w_c + w_d; e1 = c - b, e2 = d - b.
    let sum = add(add(add(zero, wb), wc), wd);
    let (e1, e2) = (sub(c, b), sub(d, b));
    let (hb, hc) = (cross(e2, sum), cross(sum, e1));
    let ha = add(hb, hc).map(|g| -g);
    [gb, gc, ga, hb, hc, ha]
}

/// Runs `kernel` for the cells `0..len` of a row, [`BLOCK`] at a time: the corners' two
/// vectors (`first` at the row's top and bottom: a, b = top[i], top[i + 1]; c, d = bottom[i],
/// bottom[i + 1]; `second` likewise) are loaded into arrays a block at a time, the kernel
/// runs lane by lane over the block (the compiler runs it a vector at a time), and its `K`
/// results go to `out[3 k + component][i]`.
#[inline(always)]
fn blocks<const K: usize>(
    len: usize,
    first: [[&[f64]; 3]; 2],
    second: [[&[f64]; 3]; 2],
    kernel: fn(Corners, Corners) -> [[f64; 3]; K],
    out: &mut [&mut [f64]],
) {
    const B: usize = BLOCK;
    let whole = len / B * B;
    let mut i0 = 0;
    while i0 < whole {
        block(i0, &first, &second, kernel, out);
        i0 += B;
    }
    if whole < len {
        if len >= B {
            // The last block again, ending at the row's end: a cell's terms depend on its
            // corners only, so the cells done twice get the same values twice.
            block(len - B, &first, &second, kernel, out);
        } else {
            for i in 0..len {
                let at = |r: &[&[f64]; 3], i: usize| [r[0][i], r[1][i], r[2][i]];
                let lane = |rows: &[[&[f64]; 3]; 2]| {
                    [
                        at(&rows[0], i),
                        at(&rows[0], i + 1),
                        at(&rows[1], i),
                        at(&rows[1], i + 1),
                    ]
                };
                let r = kernel(lane(&first), lane(&second));
                for k in 0..K {
                    for q in 0..3 {
                        out[3 * k + q][i] = r[k][q];
                    }
                }
            }
        }
    }
}

/// One block of [`blocks`]: the cells `i0 .. i0 + BLOCK`.
#[inline(always)]
fn block<const K: usize>(
    i0: usize,
    first: &[[&[f64]; 3]; 2],
    second: &[[&[f64]; 3]; 2],
    kernel: fn(Corners, Corners) -> [[f64; 3]; K],
    out: &mut [&mut [f64]],
) {
    const B: usize = BLOCK;
    // [side][corner][component][lane]
    let mut p = [[[[0.0; B]; 3]; 4]; 2];
    for (side, rows) in [first, second].into_iter().enumerate() {
        for q in 0..3 {
            p[side][0][q].copy_from_slice(&rows[0][q][i0..i0 + B]);
            p[side][1][q].copy_from_slice(&rows[0][q][i0 + 1..i0 + 1 + B]);
            p[side][2][q].copy_from_slice(&rows[1][q][i0..i0 + B]);
            p[side][3][q].copy_from_slice(&rows[1][q][i0 + 1..i0 + 1 + B]);
        }
    }
    let mut res = [[[0.0; B]; 3]; K];
    for l in 0..B {
        let mut u = [[[0.0; 3]; 4]; 2];
        for side in 0..2 {
            for corner in 0..4 {
                for q in 0..3 {
                    u[side][corner][q] = p[side][corner][q][l];
                }
            }
        }
        let r = kernel(u[0], u[1]);
        for k in 0..K {
            for q in 0..3 {
                res[k][q][l] = r[k][q];
            }
        }
    }
    for k in 0..K {
        for q in 0..3 {
            out[3 * k + q][i0..i0 + B].copy_from_slice(&res[k][q]);
        }
    }
}

#[cfg(test)]
mod tests;
