//! Adding per-spring values (forces, matrix blocks) to the particles at their two ends,
//! chunk of particles by chunk, with no write shared between chunks.
//!
//! Each particle receives its springs in an order fixed by the topology, never by how the
//! particles are split among threads, so results are bitwise identical for any thread count.
//! Two ways, chosen by [`Topology::long_runs`]:
//! - run by run: for each [`crate::topology::SpringRun`] touching the chunk (ascending), the
//!   value times `+1` on the slice of its `i` ends, then times `j_sign` on the slice of its
//!   `j` ends; contiguous slices, so the additions vectorise (compiled for AVX2/AVX-512 too);
//! - vertex by vertex (meshes whose springs form short runs): each particle walks its
//!   adjacency row, in two interleaved partial sums so additions do not wait on each other.

use std::ops::{AddAssign, Mul};

use bytemuck::Pod;

use crate::topology::Topology;

/// Adds `values[s]` (times 1 at the `i` end, `j_sign` at the `j` end) of every spring touching
/// particles `first .. first + out.len()` to `out`. `first` must be a multiple of
/// `crate::parallel::CHUNK` and `out` at most one chunk long.
pub fn add_spring_values<T>(t: &Topology, first: usize, values: &[T], j_sign: f64, out: &mut [T])
where
    T: Pod + AddAssign + Mul<f64, Output = T>,
{
    if t.long_runs() {
        by_runs(t, first, values, j_sign, out);
    } else {
        by_vertex(t, first, values, j_sign, out);
    }
}

/// Run by run, for particles `first .. first + out.len()`, a range inside one chunk.
fn by_runs<T: Pod>(t: &Topology, first: usize, values: &[T], j_sign: f64, out: &mut [T]) {
    let end = first + out.len();
    let width = std::mem::size_of::<T>() / std::mem::size_of::<f64>();
    for &r in t.chunk_runs.row(first / crate::parallel::CHUNK) {
        let run = &t.spring_runs[r as usize];
        let s0 = run.first_spring as usize;
        let len = run.len as usize;
        let v = &values[s0..s0 + len];
        let i0 = run.first_vertex as usize;
        for (start, sign) in [(i0, 1.0), (i0 + run.offset as usize, j_sign)] {
            let (lo, hi) = (start.max(first), (start + len).min(end));
            if lo < hi {
                let src: &[f64] = bytemuck::cast_slice(&v[lo - start..hi - start]);
                let dst: &mut [f64] = bytemuck::cast_slice_mut(&mut out[lo - first..hi - first]);
                debug_assert_eq!(src.len(), (hi - lo) * width);
                add_scaled_widest(sign, src, dst);
            }
        }
    }
}

fn by_vertex<T>(t: &Topology, first: usize, values: &[T], j_sign: f64, out: &mut [T])
where
    T: Pod + AddAssign + Mul<f64, Output = T>,
{
    for (k, o) in out.iter_mut().enumerate() {
        let row = t.vertex_springs.row(first + k);
        *o += row_sum(row, |e| {
            values[(e >> 1) as usize] * if e & 1 == 0 { 1.0 } else { j_sign }
        });
    }
}

/// Particles per tile of [`add_spring_forces`]: the tile's three sums stay in L1 cache.
pub(super) use crate::parallel::TILE;

/// Sets `acc[c][k]` to the sum of the forces of every spring touching particle `p0 + k`
/// (`+f` at its `i` end, `-f` at its `j` end), for `k < len <= TILE`, from the per-spring
/// component arrays `f`. The tile must lie inside one `crate::parallel::CHUNK`. Each
/// particle's springs are added in a fixed order (run by run, or along its adjacency row), so
/// the sums do not depend on tiles, chunks or threads.
pub(super) fn add_spring_forces(
    t: &Topology,
    p0: usize,
    len: usize,
    f: [&[f64]; 3],
    acc: &mut [[f64; TILE]; 3],
) {
    for a in acc.iter_mut() {
        a[..len].fill(0.0);
    }
    if t.long_runs() {
        // Component by component: each particle receives its springs in the same order.
        for c in 0..3 {
            by_runs(t, p0, f[c], -1.0, &mut acc[c][..len]);
        }
    } else {
        for k in 0..len {
            let row = t.vertex_springs.row(p0 + k);
            for c in 0..3 {
                let fc = f[c];
                acc[c][k] = row_sum(row, |e| {
                    if e & 1 == 0 {
                        fc[(e >> 1) as usize]
                    } else {
                        -fc[(e >> 1) as usize]
                    }
                });
            }
        }
    }
}

/// `sum term(e)` over the adjacency row, in two interleaved partial sums (so additions do not
/// wait on each other), even entries then odd, combined at the end: a fixed order.
#[inline]
fn row_sum<T: Pod + AddAssign>(row: &[u32], term: impl Fn(u32) -> T) -> T {
    let (mut even, mut odd) = (T::zeroed(), T::zeroed());
    let mut pairs = row.chunks_exact(2);
    for pair in &mut pairs {
        even += term(pair[0]);
        odd += term(pair[1]);
    }
    if let [last] = pairs.remainder() {
        even += term(*last);
    }
    even += odd;
    even
}

crate::simd_dispatch! { pub(super) fn add_scaled_widest(sign: f64, src: &[f64], dst: &mut [f64]) => add_scaled }

/// `dst += sign * src`, element by element.
#[inline(always)]
fn add_scaled(sign: f64, src: &[f64], dst: &mut [f64]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d += sign * s;
    }
}
