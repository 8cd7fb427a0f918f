//! The forces of the water a cloth carries as it turns: Lagrange's `dT/dx - (dM/dt) v` for the
//! mass matrix of [`super::inertia`], summed over the faces' patches ([`turning_forces`]): on a
//! grid by rows of cells (`turning_grid.rs`), on other meshes by chunks of faces and a
//! wavefront on the pool; each patch's terms by `patch.rs`.

use super::patch::{corner_term, face_gradients, face_gradients_at, patch_range, PatchOut};
use crate::math::Vec3;
use crate::model::Model;
use crate::parallel;
use crate::topology::Topology;

/// Scratch of [`turning_forces`]: per vertex the sums of its faces' area vectors and of their
/// rates, and its weight; and how the pool's path splits the cloth.
#[derive(Clone, Debug, Default)]
pub struct TurningScratch {
    sums: Vec<Vec3>,
    rates: Vec<Vec3>,
    patches: Vec<Vec3>,
    /// A grid's bands' rows of vertices and of cells, in component arrays
    /// ([`super::turning_grid`]).
    bands: Vec<Vec<f64>>,
    /// How the pool's path splits the cloth.
    split: TurningSplit,
}

/// The unit normal of every vertex and how much of its patch's rest area faces along it.
///
/// A vertex's patch is its triangles; `N_i` is the sum of their normals each twice its area
/// (as [`super::vertex_normals`] sums them). The ratio `p_i = |N_i| / |N_i(rest)|` (1 at rest,
/// growing as the patch stretches and falling to 0 as it folds onto itself) scales the normal
/// added mass: `m_a A_i p_i^2`. The water a patch carries is that of its projected area, and
/// the kinetic energy `1/2 m_a A_i (v . a_i)^2`, `a_i = N_i / |N_i(rest)|`, is a polynomial in
/// the positions: no normal to divide by where a fold makes it vanish.
pub fn patch_normals(x: &[Vec3], t: &Topology, normals: &mut [Vec3], projected: &mut [f64]) {
    let (triangles, vertex_triangles) = (&t.triangles, &t.vertex_triangles);
    let faces: Vec<Vec3> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| i as usize);
            (x[b] - x[a]).cross(&(x[c] - x[a]))
        })
        .collect();
    for i in 0..x.len() {
        let big_n: Vec3 = vertex_triangles.row(i).iter().map(|&t| faces[t as usize]).sum();
        let len = big_n.norm();
        normals[i] = if len > 0.0 { big_n / len } else { big_n };
        projected[i] = len * t.patch_scale[i];
    }
}

/// Adds the forces of the carried water as the cloth turns and stretches,
/// `dT/dx - (dM/dt) v`, to `out` (one per particle), for the normal added mass of `m` at
/// positions `x` and velocities relative to the water `v`, and writes every vertex's
/// projected-area ratio into `projected` ([`patch_normals`]) and its unit normal into
/// `normals` (the same bits as [`super::vertex_normals_with`]: the same face sums in the same
/// order, so the force pass need not sum them again). Nothing without normal added mass.
///
/// With `a_i = N_i / |N_i(rest)|` (see [`patch_normals`]) and `k_i = m_a A_i`, the water's kinetic
/// energy is `T = 1/2 sum k_i (v_i . a_i)^2` and its mass matrix `k_i a_i a_i^T`:
/// - `(dM_i/dt) v_i = k_i (adot_i (a_i . v_i) + a_i (adot_i . v_i))`, `adot_i` from the
///   rates of its faces' normals (`(v_b - v_a) x e2 + e1 x (v_c - v_a)`);
/// - `dT/dx_j = sum_i (dN_i/dx_j)^T w_i`, `w_i = k_i (a_i . v_i) v_i / |N_i(rest)|`: per face
///   `c = e1 x e2` (`e1 = x_b - x_a`, `e2 = x_c - x_a`) and `W` the sum of its vertices' w,
///   the gradient of `W . c` is `e2 x W` at b, `W x e1` at c and minus their sum at a.
///
/// Both are quadratic in the velocity and bounded (no division by the normal's length):
/// they enter every integrator as known forces of the step's start.
#[allow(clippy::too_many_arguments)] // the step's arrays the passes read and write
pub fn turning_forces(
    m: &Model,
    t: &Topology,
    x: &[Vec3],
    v: &[Vec3],
    scratch: &mut TurningScratch,
    projected: &mut [f64],
    normals: &mut [Vec3],
    out: &mut [Vec3],
    coarse: Option<&mut super::coarse_water::CoarseWater>,
) {
    let ma = m.water.added_mass;
    if ma == 0.0 && coarse.is_none() {
        return;
    }
    // Faces, vertices and faces again; every path gives every vertex the same terms in the same
    // order, so a large cloth spreads them over the pool with the same bits. A grid's cells
    // say which faces a vertex has: it takes the rows path (`turning_grid.rs`) on one thread
    // and on the pool. (One path would
    // do: the pool's with one chunk. Measured, its chunk lists, wavefront marks and border
    // tests cost more than they save on one thread: at 61 x 41 9.06 G instructions against
    // 8.12 G (the pool's path before the wavefront), at 201 x 201 the turning forces 1.69 G
    // against 1.47 G, and no faster at 1001 x 1001.)
    let n = x.len();
    let par = parallel::worth_it(n);
    if let (Some(size), None) = (t.grid_faces, coarse.as_ref()) {
        // A grid: in bands of rows, four a thread on the pool, so that it can even out uneven
        // bands; one band on one thread.
        let band = if par {
            size.1.div_ceil(4 * rayon::current_num_threads())
        } else {
            size.1
        };
        let TurningScratch {
            sums,
            rates,
            patches,
            bands,
            ..
        } = scratch;
        let buffers = super::turning_grid::GridBuffers {
            bands,
            sums,
            rates,
            patches,
        };
        let split = (band, par, super::turning_grid::PATCH_ROWS_VERTICES);
        super::turning_grid::turning_grid(ma, t, size, x, v, buffers, split, projected, normals, out);
    } else if par && coarse.is_none() {
        // Four chunks a thread, so that the pool can even out uneven chunks.
        let chunk = n.div_ceil(4 * rayon::current_num_threads()).max(1);
        turning_chunked(ma, t, x, v, scratch, chunk, true, projected, normals, out);
    } else {
        turning_serial_widest(ma, t, x, v, scratch, projected, normals, out, coarse);
    }
}

crate::simd_dispatch! { fn turning_serial_widest(ma: f64, t: &Topology, x: &[Vec3], v: &[Vec3], scratch: &mut TurningScratch, projected: &mut [f64], normals: &mut [Vec3], out: &mut [Vec3], coarse: Option<&mut super::coarse_water::CoarseWater>) => turning_serial }

/// The passes on one thread, each face's sums scattered to its corners instead of each
/// vertex gathering its faces'. A vertex's faces are listed in ascending order
/// ([`crate::topology::Adjacency`]) and the faces are visited in that order, so every vertex
/// receives the same terms in the same order as [`turning_parallel`] sums them: the same
/// bits, without the per-face arrays and the corner tests of the gather. (A face's corners are
/// distinct: a mesh with a repeated corner is refused when built.)
#[allow(clippy::too_many_arguments)] // the step's arrays the passes read and write
#[inline(always)]
pub(super) fn turning_serial(
    ma: f64,
    t: &Topology,
    x: &[Vec3],
    v: &[Vec3],
    scratch: &mut TurningScratch,
    projected: &mut [f64],
    normals: &mut [Vec3],
    out: &mut [Vec3],
    coarse: Option<&mut super::coarse_water::CoarseWater>,
) {
    let (areas, triangles) = (&t.areas, &t.triangles);
    let n = x.len();
    let TurningScratch {
        sums, rates, patches, ..
    } = scratch;
    // Each vertex's sums of its faces' area vectors and of their rates.
    for buf in [&mut *sums, &mut *rates] {
        buf.clear();
        buf.resize(n, Vec3::zeros());
    }
    for tri in triangles {
        let (f, r) = face_and_rate(x, v, tri);
        for &i in tri {
            sums[i as usize] += f;
            rates[i as usize] += r;
        }
    }
    patches.clear();
    patches.resize(n, Vec3::zeros());
    patch_range(
        ma,
        &areas[..],
        &t.patch_scale[..],
        sums,
        rates,
        v,
        PatchOut {
            o: out,
            projected,
            normals,
            w: patches,
        },
    );
    if let Some(c) = coarse {
        let ps = &t.patch_scale;
        c.add_turning(|i| (ps[i] * sums[i], ps[i] * rates[i], ps[i]), v, out, patches);
    }
    // W of every face and its gradients at its corners, added to the corners' forces.
    for tri in triangles {
        let [gb, gc] = face_gradients(x, patches, tri);
        let [a, b, c] = tri.map(|i| i as usize);
        out[a] += -(gb + gc);
        out[b] += gb;
        out[c] += gc;
    }
}

/// How the chunked path splits a cloth: chunks of `chunk` vertices, each with the faces whose
/// three corners lie in it (ascending), and which vertices have a face reaching into another
/// chunk (those gather their faces' terms in their own order, the others take them scattered).
/// With it, the order in which a chunk's passes may interleave (a wavefront, see
/// [`turning_chunk`]).
#[derive(Clone, Debug, Default)]
pub struct TurningSplit {
    chunk: usize,
    /// The vertex and face counts it was made for.
    sizes: (usize, usize),
    /// Chunk k's faces: `inner[inner_start[k]..inner_start[k + 1]]`.
    inner_start: Vec<u32>,
    inner: Vec<u32>,
    /// Chunk k's first face when its faces are consecutive (`inner` then need not be read:
    /// a grid's chunks), else `u32::MAX`.
    consecutive: Vec<u32>,
    /// Chunk k's waves, in order: `waves[wave_start[k]..wave_start[k + 1]]`.
    wave_start: Vec<u32>,
    waves: Vec<Wave>,
    border: Vec<bool>,
    /// Chunk k's border vertices: `borders[border_start[k]..border_start[k + 1]]`.
    border_start: Vec<u32>,
    borders: Vec<u32>,
}

impl TurningSplit {
    fn new(n: usize, triangles: &[[u32; 3]], chunk: usize) -> Self {
        let chunks = n.div_ceil(chunk);
        let mut border = vec![false; n];
        let mut count = vec![0u32; chunks + 1];
        let home = |tri: &[u32; 3]| {
            let k = tri[0] as usize / chunk;
            tri.iter().all(|&i| i as usize / chunk == k).then_some(k)
        };
        for tri in triangles {
            match home(tri) {
                Some(k) => count[k + 1] += 1,
                None => tri.iter().for_each(|&i| border[i as usize] = true),
            }
        }
        for k in 0..chunks {
            count[k + 1] += count[k];
        }
        let mut fill = count.clone();
        let mut inner = vec![0u32; count[chunks] as usize];
        for (f, tri) in triangles.iter().enumerate() {
            if let Some(k) = home(tri) {
                inner[fill[k] as usize] = f as u32;
                fill[k] += 1;
            }
        }
        // The wavefront's marks, chunk by chunk: how far the faces reach (`reach[q]`: the
        // highest corner of face q and of the chunk's faces before it), and after how many
        // faces each vertex (and every vertex before it) is complete (`ready`, 0 for the border
        // vertices that lead a chunk: they sum their own). From them, each wave's.
        let (mut reach, mut ready) = (vec![0u32; inner.len()], vec![0u32; n]);
        for k in 0..chunks {
            let (lo, hi) = (k * chunk, ((k + 1) * chunk).min(n));
            let (a, b) = (count[k] as usize, count[k + 1] as usize);
            let mut top = lo as u32;
            for q in a..b {
                let tri = &triangles[inner[q] as usize];
                top = top.max(tri[0]).max(tri[1]).max(tri[2]);
                reach[q] = top;
                for &i in tri {
                    ready[i as usize] = (q - a + 1) as u32;
                }
            }
            for i in lo + 1..hi {
                ready[i] = ready[i].max(ready[i - 1]);
            }
        }
        let mut wave_start = Vec::with_capacity(chunks + 1);
        let mut waves = Vec::new();
        for k in 0..chunks {
            wave_start.push(waves.len() as u32);
            let (lo, hi) = (k * chunk, ((k + 1) * chunk).min(n));
            let r = count[k] as usize..count[k + 1] as usize;
            Wave::plan(lo, hi, &reach[r], &ready[lo..hi], &mut waves);
        }
        wave_start.push(waves.len() as u32);
        let consecutive = (0..chunks)
            .map(|k| {
                let faces = &inner[count[k] as usize..count[k + 1] as usize];
                match faces.first() {
                    Some(&f) if faces.iter().zip(f..).all(|(&g, h)| g == h) => f,
                    _ => u32::MAX,
                }
            })
            .collect();
        let borders: Vec<u32> = (0..n as u32).filter(|&i| border[i as usize]).collect();
        let border_start = (0..=chunks)
            .map(|k| borders.partition_point(|&i| (i as usize) < k * chunk) as u32)
            .collect();
        TurningSplit {
            chunk,
            sizes: (n, triangles.len()),
            inner_start: count,
            inner,
            consecutive,
            wave_start,
            waves,
            border,
            border_start,
            borders,
        }
    }

    /// Chunk k's faces and its waves.
    fn inner(&self, k: usize) -> (&[u32], &[Wave]) {
        let r = self.inner_start[k] as usize..self.inner_start[k + 1] as usize;
        let w = self.wave_start[k] as usize..self.wave_start[k + 1] as usize;
        (&self.inner[r], &self.waves[w])
    }

    fn borders(&self, k: usize) -> &[u32] {
        &self.borders[self.border_start[k] as usize..self.border_start[k + 1] as usize]
    }
}

/// One wave of a chunk's wavefront ([`turning_chunk`]): the next [`WAVE`] faces (fewer in the
/// last) are summed into their corners, whose sums are zeroed below `top` first; then the
/// vertices below `done` take their patches' terms, and the faces below `scattered` (in the
/// chunk's list) scatter their gradients. Worked out when the split is made: bisecting the
/// cloth-sized marks in every wave read a score of entries from memory a wave (4.7 % of the
/// chunk pass's samples at 1001 x 1001 on one thread, `perf annotate`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Wave {
    top: u32,
    done: u32,
    scattered: u32,
}

impl Wave {
    /// The waves of the chunk of vertices `lo..hi` whose faces reach `reach` (rising, one per
    /// face of the chunk) and whose vertices are complete after `ready` faces (rising from
    /// the chunk's first non-border vertex), appended to `out`.
    fn plan(lo: usize, hi: usize, reach: &[u32], ready: &[u32], out: &mut Vec<Wave>) {
        let faces = reach.len();
        let (mut summed, mut done, mut scattered) = (0, lo, 0);
        loop {
            let end = (summed + WAVE).min(faces);
            let top = if end == faces {
                hi
            } else {
                reach[end - 1] as usize + 1
            };
            summed = end;
            let last = summed == faces;
            let upto = if last {
                hi
            } else {
                lo + ready.partition_point(|&r| r as usize <= summed)
            };
            done = done.max(upto);
            scattered = scattered.max(reach[..summed].partition_point(|&r| (r as usize) < done));
            out.push(Wave {
                top: top as u32,
                done: done as u32,
                scattered: scattered as u32,
            });
            if last {
                return;
            }
        }
    }
}

/// Faces summed between the wavefront's other two passes: enough for long loops (32 cost
/// 1.4x the one-thread passes' time a vertex at 201 x 201, measured alone), few enough that a
/// wave's sums (about a thousand vertices) are still in cache when read back.
const WAVE: usize = 2048;

/// The passes in chunks of vertices, on the pool when `par`: each chunk scatters the faces
/// that lie in it to their corners, as [`turning_serial`] does, and a vertex with a face in
/// another chunk gathers its faces' terms in its own (ascending) order instead, computing them
/// again. Every vertex so receives the same terms in the same order as on one thread: the same
/// bits for any chunk size and any number of threads. Within a chunk the three passes run as
/// a wavefront ([`turning_chunk`]), so a large cloth streams its arrays once.
#[allow(clippy::too_many_arguments)] // the step's arrays the passes read and write
fn turning_chunked(
    ma: f64,
    t: &Topology,
    x: &[Vec3],
    v: &[Vec3],
    scratch: &mut TurningScratch,
    chunk: usize,
    par: bool,
    projected: &mut [f64],
    normals: &mut [Vec3],
    out: &mut [Vec3],
) {
    let (triangles, vertex_triangles) = (&t.triangles, &t.vertex_triangles);
    let n = x.len();
    let TurningScratch {
        sums,
        rates,
        patches,
        split,
        ..
    } = scratch;
    if split.chunk != chunk || split.sizes != (n, triangles.len()) {
        *split = TurningSplit::new(n, triangles, chunk);
    }
    let split = &*split;
    for buf in [&mut *sums, &mut *rates, &mut *patches] {
        buf.resize(n, Vec3::zeros());
    }
    {
        let d = [
            &mut sums[..],
            &mut rates[..],
            &mut patches[..],
            normals,
            &mut *out,
        ]
        .map(parallel::Disjoint::new);
        let projected = parallel::Disjoint::new(projected);
        parallel::for_chunks(par, n, chunk, |lo, len| {
            let r = lo..lo + len;
            // SAFETY: every task borrows only its own chunk `r` of each array.
            let [sums, rates, w, normals, out] = d.each_ref().map(|a| unsafe { a.range(r.clone()) });
            // SAFETY: as above.
            let projected = unsafe { projected.range(r) };
            let chunk = Chunk {
                lo,
                sums,
                rates,
                w,
                out,
                projected,
                normals,
            };
            turning_chunk_widest(ma, t, x, v, split, lo / split.chunk, chunk);
        });
    }
    if split.borders.is_empty() {
        return;
    }
    // The border vertices' faces' gradients, which read `w` of other chunks' vertices.
    let patches = &*patches;
    let d = parallel::Disjoint::new(out);
    parallel::for_chunks(par, n, chunk, |lo, len| {
        // SAFETY: every task borrows only its own chunk of `out`.
        let out = unsafe { d.range(lo..lo + len) };
        for &i in split.borders(lo / split.chunk) {
            let i = i as usize;
            for &f in vertex_triangles.row(i) {
                let tri = &triangles[f as usize];
                let [gb, gc] = face_gradients(x, patches, tri);
                out[i - lo] += corner_term(tri, i, gb, gc);
            }
        }
    });
}

crate::simd_dispatch! { fn turning_chunk_widest(ma: f64, t: &Topology, x: &[Vec3], v: &[Vec3], split: &TurningSplit, k: usize, c: Chunk<'_>) => turning_chunk_any }

/// [`turning_chunk`] for chunk `k`, with the border tests where it has border vertices.
#[inline(always)]
fn turning_chunk_any(
    ma: f64,
    t: &Topology,
    x: &[Vec3],
    v: &[Vec3],
    split: &TurningSplit,
    k: usize,
    c: Chunk<'_>,
) {
    match (split.borders(k).is_empty(), split.consecutive[k] != u32::MAX) {
        (true, false) => turning_chunk::<false, false>(ma, t, x, v, split, k, c),
        (false, false) => turning_chunk::<true, false>(ma, t, x, v, split, k, c),
        (true, true) => turning_chunk::<false, true>(ma, t, x, v, split, k, c),
        (false, true) => turning_chunk::<true, true>(ma, t, x, v, split, k, c),
    }
}

/// One chunk's arrays (`lo` its first vertex).
struct Chunk<'a> {
    lo: usize,
    sums: &'a mut [Vec3],
    rates: &'a mut [Vec3],
    w: &'a mut [Vec3],
    out: &'a mut [Vec3],
    projected: &'a mut [f64],
    normals: &'a mut [Vec3],
}

/// Chunk `k`'s three passes, interleaved: its faces are summed into their corners a wave at a
/// time ([`WAVE`]); each vertex whose faces are all summed (and every vertex before it) takes
/// its patch's terms and its `w`; each face whose corners all have their `w` scatters its
/// gradients. Every vertex still receives its terms in the order of the passes one after the
/// other (its patch's term before its faces' gradients, those in ascending face order), so
/// the bits are theirs, but a large chunk's sums are read back while they are in cache. The
/// border vertices' faces' gradients are left to the caller. `BORDER`: whether the chunk has
/// border vertices (a chunk without skips the tests). `CONSECUTIVE`: whether its faces are
/// consecutive, so read in place rather than through the chunk's list (one read fewer a face:
/// 92.0-92.5 against 94.5-95.3 ns a particle-step at 1001 x 1001 as one chunk on one thread).
#[inline(always)]
fn turning_chunk<const BORDER: bool, const CONSECUTIVE: bool>(
    ma: f64,
    t: &Topology,
    x: &[Vec3],
    v: &[Vec3],
    split: &TurningSplit,
    k: usize,
    c: Chunk<'_>,
) {
    let (areas, triangles, vertex_triangles) = (&t.areas, &t.triangles, &t.vertex_triangles);
    let (lo, sums, rates, w) = (c.lo, c.sums, c.rates, c.w);
    let (out, projected, normals) = (c.out, c.projected, c.normals);
    let hi = lo + w.len();
    let (faces, waves) = split.inner(k);
    let first = split.consecutive[k] as usize;
    // The chunk's face at position q of its list.
    let face = |q: usize| {
        if CONSECUTIVE {
            &triangles[first + q]
        } else {
            &triangles[faces[q] as usize]
        }
    };
    let border = &split.border;
    // Sums zeroed below `zeroed`, faces summed below `summed`, vertices done below `done`,
    // faces' gradients scattered below `scattered`.
    let (mut zeroed, mut summed, mut done, mut scattered) = (lo, 0, lo, 0);
    for wave in waves {
        let end = (summed + WAVE).min(faces.len());
        let top = wave.top as usize;
        if zeroed < top {
            sums[zeroed - lo..top - lo].fill(Vec3::zeros());
            rates[zeroed - lo..top - lo].fill(Vec3::zeros());
            zeroed = top;
        }
        for q in summed..end {
            let tri = face(q);
            let (c, r) = face_and_rate(x, v, tri);
            for &i in tri {
                let i = i as usize;
                if !(BORDER && border[i]) {
                    sums[i - lo] += c;
                    rates[i - lo] += r;
                }
            }
        }
        summed = end;
        // The vertices whose faces are all summed.
        let upto = wave.done as usize;
        if upto > done {
            // A border vertex's sums are its own faces', in its own order (its entries were
            // skipped above); then every vertex of the range takes its patch's terms.
            if BORDER {
                let mine = split.borders(k);
                let from = mine.partition_point(|&b| (b as usize) < done);
                for &i in mine[from..].iter().take_while(|&&b| (b as usize) < upto) {
                    let i = i as usize;
                    let (mut big_n, mut big_ndot) = (Vec3::zeros(), Vec3::zeros());
                    for &f in vertex_triangles.row(i) {
                        let (c, r) = face_and_rate(x, v, &triangles[f as usize]);
                        big_n += c;
                        big_ndot += r;
                    }
                    (sums[i - lo], rates[i - lo]) = (big_n, big_ndot);
                }
            }
            let r = done - lo..upto - lo;
            patch_range(
                ma,
                &areas[done..upto],
                &t.patch_scale[done..upto],
                &sums[r.clone()],
                &rates[r.clone()],
                &v[done..upto],
                PatchOut {
                    o: &mut out[r.clone()],
                    projected: &mut projected[r.clone()],
                    normals: &mut normals[r.clone()],
                    w: &mut w[r],
                },
            );
        }
        done = done.max(upto);
        // The faces whose corners all have their `w`.
        let until = wave.scattered as usize;
        for q in scattered..until.max(scattered) {
            let tri = face(q);
            let [gb, gc] = face_gradients_at(x, w, lo, tri);
            for (&i, g) in tri.iter().zip([-(gb + gc), gb, gc]) {
                let i = i as usize;
                if !(BORDER && border[i]) {
                    out[i - lo] += g;
                }
            }
        }
        scattered = scattered.max(until);
    }
    debug_assert!(summed == faces.len() && scattered == faces.len() && done == hi);
}

/// A face's area vector `e1 x e2` and its rate of change.
#[inline(always)]
fn face_and_rate(x: &[Vec3], v: &[Vec3], t: &[u32; 3]) -> (Vec3, Vec3) {
    let [a, b, c] = t.map(|i| i as usize);
    let (e1, e2) = (x[b] - x[a], x[c] - x[a]);
    (e1.cross(&e2), (v[b] - v[a]).cross(&e2) + e1.cross(&(v[c] - v[a])))
}

/// Test helpers shared with the coarse water's tests.
#[cfg(test)]
pub(crate) mod check {
    use super::*;

    /// The turning forces of `m` (and `coarse`) at `x`, `v`, with the projected-area ratios and
    /// unit normals the pass writes.
    pub(crate) fn turning_of(
        m: &Model,
        t: &Topology,
        x: &[Vec3],
        v: &[Vec3],
        coarse: Option<&mut super::super::coarse_water::CoarseWater>,
    ) -> (Vec<Vec3>, Vec<f64>, Vec<Vec3>) {
        let n = x.len();
        let (mut got, mut projected, mut normals) =
            (vec![Vec3::zeros(); n], vec![0.0; n], vec![Vec3::zeros(); n]);
        let mut s = TurningScratch::default();
        turning_forces(m, t, x, v, &mut s, &mut projected, &mut normals, &mut got, coarse);
        (got, projected, normals)
    }

    /// Asserts that `got` are Lagrange's terms `dT/dx - (dM/dt) v` at `x`, `v` (to 1e-6): `dT/dx`
    /// by central differences of `energy(y)` (the water's kinetic energy at positions y and
    /// velocity v), `(dM/dt) v` by central differences of `momentum(x + s v)[j]` in s (the
    /// water's part of `M(y) v`).
    pub(crate) fn lagranges_terms(
        got: &[Vec3],
        x: &[Vec3],
        v: &[Vec3],
        energy: impl Fn(&[Vec3]) -> f64,
        momentum: impl Fn(&[Vec3], usize) -> Vec3,
    ) {
        let eps = 1e-6;
        for j in 0..x.len() {
            let mut grad = Vec3::zeros();
            for a in 0..3 {
                let shifted = |s: f64| {
                    let mut y = x.to_vec();
                    y[j][a] += s * eps;
                    energy(&y)
                };
                grad[a] = (shifted(1.0) - shifted(-1.0)) / (2.0 * eps);
            }
            let m_v = |s: f64| {
                let y: Vec<Vec3> = x.iter().zip(v).map(|(x, v)| x + s * eps * v).collect();
                momentum(&y, j)
            };
            let want = grad - (m_v(1.0) - m_v(-1.0)) / (2.0 * eps);
            assert!(
                (got[j] - want).norm() < 1e-6 * (1.0 + want.norm()),
                "particle {j}: {} against {}",
                got[j],
                want
            );
        }
    }
}

#[cfg(test)]
mod tests;
