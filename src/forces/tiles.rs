//! Spring forces summed tile by tile, with no per-spring buffer: the fast path for topologies
//! whose springs form long runs with short offsets (grids, row-ordered meshes).
//!
//! A group of whole chunks of particles `[c0, c1)` ([`Layout`]) is walked in tiles of [`TILE`]
//! particles. For each tile,
//! every run's springs whose `i` end lies in the tile are evaluated into a small buffer, added
//! with `+` at their `i` ends and with `-` at their `j` ends (`j = i + offset`, later in the
//! array; a particle that is both gets `f_i - f_j` in one update), into a rolling window of
//! sums that covers the tile and the `max offset` particles
//! after it. When a tile's springs are done, every spring touching a particle of the tile has
//! been added (its `i` end is never after its `j` end), so the tile is handed to `finish`; the
//! window slides on when the next tile would not fit. Before the first tile, the springs whose
//! `i` end lies before `c0` and whose `j` end lies in the group are evaluated too (the previous
//! group evaluates them as well, for its own `i` ends; a few per group boundary).
//!
//! **Gathered** ([`spring_forces_gathered`], topologies of at most [`GATHER_RUNS`] runs: grids):
//! instead of one window of sums, each run keeps a window of its springs' forces by `i` end
//! (zero where it has none). A tile evaluates its runs into their windows and then each particle
//! `p` sums `F_k[p] - F_k[p - offset_k]` over the runs in registers and writes it once, where the
//! window of sums above is read and written once per run. The windows keep each run's last
//! `offset` forces when they slide. A choice run (a mesh's bend springs by the edge they cross,
//! `topology::Choice`) keeps its keys' select bytes beside its forces, and each particle adds
//! the forces of the keys whose ends take its place ([`gather_choice`]).
//!
//! Everything a tile touches (positions around it, the windows) stays in L1 or L2 cache, and a
//! spring's force is used where it is computed instead of being written out and read back.
//! Each particle receives its springs in an order fixed by the topology and the group grid, so
//! the sums do not depend on the thread count.

use super::inputs::InputWindow;
use super::springs::{run_choice_widest, run_uniform_widest, run_widest, zero_pads_widest, Params};
pub use crate::parallel::TILE;
use crate::topology::{Choice, TileLayout as Layout, TileRuns, Topology, GATHER_RUNS};

/// Numbers of scratch one task of the walk needs: the window of sums, or the gather path's
/// force windows (one per run) and a tile of sums; then its window of spring inputs.
pub(super) fn scratch(l: &Layout) -> usize {
    sums_scratch(l) + InputWindow::scratch(l.inputs)
}

/// The part of [`scratch`] before the window of spring inputs.
pub(super) fn sums_scratch(l: &Layout) -> usize {
    if l.gather_runs > 0 {
        l.force_window * l.gather_components + 3 * TILE
    } else {
        3 * l.window
    }
}

/// Sums the spring forces of particles `c0 .. c0 + len` (one group of [`Layout`]) tile by tile
/// and calls `finish(p0, sums, inputs)` for each tile, `sums[c][k]` being component c of the
/// spring force on particle `p0 + k` (the finisher may add to them), with the tile covered by
/// `inputs`. `window` holds `3 * layout.window` numbers; the springs read their positions and
/// rates from `inputs`, which starts at `c0 - max_offset` (or 0).
pub(super) fn spring_forces<F>(
    p: &Params<'_>,
    t: &Topology,
    c0: usize,
    len: usize,
    window: &mut [f64],
    inputs: &mut InputWindow<'_>,
    mut finish: F,
) where
    F: FnMut(usize, [&mut [f64]; 3], &InputWindow<'_>),
{
    let w = window.len() / 3;
    let c1 = c0 + len;
    let chunk = crate::parallel::CHUNK;
    let rows = &t.tile_runs.chunk_runs;
    let max_offset = t.tile_runs.max_offset;
    let p = &Params {
        rest: &t.tile_runs.rest,
        ..*p
    };
    window.fill(0.0);
    let mut temp = [[0.0; TILE]; 3];
    // Springs from before the group into it: only their j ends are ours (all in its first
    // chunk, as no offset exceeds a chunk).
    let mut start = c0;
    inputs.cover(c0.saturating_sub(max_offset), c0 + max_offset);
    add_range(
        &inputs.params(p),
        t,
        rows.row(c0 / chunk),
        None,
        c0,
        c1,
        start,
        w,
        window,
        &mut temp,
    );
    let mut base = c0;
    while base < c1 {
        let end = (base + TILE).min(c1);
        // Slide the window to this tile when the tile's j ends would run past it.
        if end - start + t.tile_runs.max_offset > w {
            let shift = base - start;
            for c in 0..3 {
                let comp = &mut window[c * w..(c + 1) * w];
                comp.copy_within(shift.., 0);
                comp[w - shift..].fill(0.0);
            }
            start = base;
        }
        // The runs with i ends in this tile are among those of its chunk.
        let runs = rows.row(base / chunk);
        inputs.cover(base, end + max_offset);
        let pt = inputs.params(p);
        add_range(
            &pt,
            t,
            runs,
            Some((base, end)),
            c0,
            c1,
            start,
            w,
            window,
            &mut temp,
        );
        let (n, at) = (end - base, base - start);
        {
            let (x, rest) = window.split_at_mut(w);
            let (y, z) = rest.split_at_mut(w);
            let sums = [&mut x[at..at + n], &mut y[at..at + n], &mut z[at..at + n]];
            finish(base, sums, inputs);
        }
        base = end;
    }
}

/// [`spring_forces`] for topologies with at most [`GATHER_RUNS`] runs (grids), by gathering:
/// each run `k` keeps a window `F_k` of the forces of its springs by `i` end (zero where the run
/// has no spring), and each particle `p` of a tile sums `F_k[p] - F_k[p - offset_k]` over the runs
/// in registers, writing its sum once. No window of sums is read and written back per run, as
/// [`spring_forces`] does. `scratch` holds [`Layout::sums_scratch`] numbers; `layout` is
/// this topology's; `inputs` as for [`spring_forces`].
#[allow(clippy::too_many_arguments)]
pub(super) fn spring_forces_gathered<F>(
    p: &Params<'_>,
    t: &Topology,
    layout: &Layout,
    c0: usize,
    len: usize,
    scratch: &mut [f64],
    inputs: &mut InputWindow<'_>,
    finish: F,
) where
    F: FnMut(usize, [&mut [f64]; 3], &InputWindow<'_>),
{
    // Compiled without the choice runs' steps for topologies that have none.
    let args = (p, t, layout, c0, len);
    if t.tile_runs.select.is_empty() {
        gathered_walk::<false, F>(args, scratch, inputs, finish);
    } else {
        gathered_walk::<true, F>(args, scratch, inputs, finish);
    }
}

/// The arguments of [`spring_forces_gathered`] that [`gathered_walk`] reads whole.
type WalkArgs<'a, 'p> = (&'a Params<'p>, &'a Topology, &'a Layout, usize, usize);

/// [`spring_forces_gathered`], with (`CHOICES`) or without the choice runs' steps.
fn gathered_walk<const CHOICES: bool, F>(
    (p, t, layout, c0, len): WalkArgs<'_, '_>,
    scratch: &mut [f64],
    inputs: &mut InputWindow<'_>,
    mut finish: F,
) where
    F: FnMut(usize, [&mut [f64]; 3], &InputWindow<'_>),
{
    let tr = &t.tile_runs;
    let (runs, w, lead) = (&tr.runs, layout.force_window, layout.lead);
    debug_assert!(runs.len() == layout.gather_runs && w >= lead + TILE && lead >= tr.max_offset);
    let p = &Params { rest: &tr.rest, ..*p };
    // Each run's force window, from component `first[k]` on (`TileRuns::components`).
    let mut first = [0usize; GATHER_RUNS + 1];
    for k in 0..runs.len() {
        first[k + 1] = first[k] + tr.components(k);
    }
    let (forces, sums) = scratch.split_at_mut(w * first[runs.len()]);
    let of_run = |k: usize| -> std::ops::Range<usize> { w * first[k]..w * first[k + 1] };
    // The plain runs' entries for the gather: where each window starts, and its offset.
    let (mut start, mut offset, mut plain) = ([0usize; GATHER_RUNS], [0usize; GATHER_RUNS], 0);
    for (k, run) in runs.iter().enumerate() {
        if tr.choices[k].is_none() {
            (start[plain], offset[plain]) = (w * first[k], run.offset as usize);
            plain += 1;
        }
    }
    let choices = CHOICES && plain < runs.len();
    let c1 = c0 + len;
    // Particle i's entry in a force window is `i + lead - origin`: the windows start `lead`
    // particles before `origin`, so particles before 0 have entries too.
    let mut origin = c0;
    let at = |i: usize, origin: usize| i + lead - origin;
    // The springs from before the group into it (`i` in [c0 - off, c0)); zero where none.
    inputs.cover(c0.saturating_sub(tr.max_offset), c0 + tr.max_offset);
    let pt = inputs.params(p);
    for (k, run) in runs.iter().enumerate() {
        let off = run.offset as usize;
        let range = of_run(k);
        let window = &mut forces[range];
        for c in 0..window.len() / w {
            window[c * w + lead - off..c * w + lead].fill(0.0);
        }
        evaluate::<CHOICES>(&pt, t, k, c0.saturating_sub(off), c0, window, w, lead, origin);
    }
    let mut base = c0;
    while base < c1 {
        let end = (base + TILE).min(c1);
        if at(end, origin) > w {
            // Slide: keep, for each run, the forces of the `offset` particles before `base`.
            let shift = base - origin;
            for (k, run) in runs.iter().enumerate() {
                let off = run.offset as usize;
                let range = of_run(k);
                for comp in forces[range].chunks_exact_mut(w) {
                    comp.copy_within(shift + lead - off..shift + lead, lead - off);
                }
            }
            origin = base;
        }
        inputs.cover(base, end + tr.max_offset);
        let pt = inputs.params(p);
        for k in 0..runs.len() {
            let range = of_run(k);
            evaluate::<CHOICES>(&pt, t, k, base, end, &mut forces[range], w, lead, origin);
        }
        let m = end - base;
        let (sx, rest) = sums.split_at_mut(TILE);
        let (sy, sz) = rest.split_at_mut(TILE);
        let mut plus = [0usize; GATHER_RUNS];
        let mut minus = [0usize; GATHER_RUNS];
        for e in 0..plain {
            plus[e] = start[e] + at(base, origin);
            minus[e] = plus[e] - offset[e];
        }
        let out = [&mut sx[..m], &mut sy[..m], &mut sz[..m]];
        gather_widest(forces, w, plain, plus, minus, out);
        if choices {
            for (k, c) in tr.choices.iter().enumerate() {
                if let Some(c) = c {
                    let out = [&mut sx[..m], &mut sy[..m], &mut sz[..m]];
                    gather_choice_widest(&forces[of_run(k)], w, at(base, origin), c, out);
                }
            }
        }
        finish(base, [&mut sx[..m], &mut sy[..m], &mut sz[..m]], inputs);
        base = end;
    }
}

/// Writes the forces of run `k`'s springs with `i` end (a choice run: key) in `[from, to)` into
/// its force window (`TileRuns::components` arrays of `w` numbers: the force's three
/// components, and a choice run's select bytes; particle `i` at `i + lead - origin`): zero
/// where the run has no spring or a padding slot.
#[allow(clippy::too_many_arguments)]
#[inline]
fn evaluate<const CHOICES: bool>(
    p: &Params<'_>,
    t: &Topology,
    k: usize,
    from: usize,
    to: usize,
    windows: &mut [f64],
    w: usize,
    lead: usize,
    origin: usize,
) {
    let tr = &t.tile_runs;
    let run = &tr.runs[k];
    let i0 = run.first_vertex as usize;
    let at = |i: usize| i + lead - origin;
    // The run's springs in [from, to) are [lo, hi); zero around them (everywhere when none).
    let lo = from.max(i0).min(to);
    let hi = to.min(i0 + run.len as usize).max(lo);
    let (x, rest) = windows.split_at_mut(w);
    let (y, rest) = rest.split_at_mut(w);
    let (z, others) = rest.split_at_mut(w);
    for comp in [&mut *x, &mut *y, &mut *z] {
        comp[at(from)..at(lo)].fill(0.0);
        comp[at(hi)..at(to)].fill(0.0);
    }
    // A choice run's select bytes: zero there too.
    if CHOICES && !others.is_empty() {
        others[at(from)..at(lo)].fill(0.0);
        others[at(hi)..at(to)].fill(0.0);
    }
    if lo == hi {
        return;
    }
    let (a, b) = (at(lo), at(hi));
    let s = run.first_spring as usize + (lo - i0);
    evaluate_slots::<CHOICES>(p, tr, k, s, [&mut x[a..b], &mut y[a..b], &mut z[a..b]]);
    if CHOICES && tr.choices[k].is_some() {
        let select = tr.select_of(s..s + (b - a));
        for (o, &sel) in others[a..b].iter_mut().zip(select) {
            *o = f64::from_bits(u64::from(sel));
        }
    }
}

crate::simd_dispatch! { fn gather_choice_widest(window: &[f64], w: usize, at: usize, c: &Choice, out: [&mut [f64]; 3]) => gather_choice }

/// Adds to `out[c][q]` a choice run's forces on particle `p = tile start + q` from its window
/// (the force's components, then each key's select byte; particle `p` at `at + q`): `+f` of the
/// key `p - a[e]` whose first end takes place `e`, `-f` of the key `p - b[e]` whose second end
/// does, for `e` = 0 and 1.
#[inline(always)]
fn gather_choice(window: &[f64], w: usize, at: usize, c: &Choice, out: [&mut [f64]; 3]) {
    let m = out[0].len();
    let [a0, a1, b0, b1] = [c.a[0], c.a[1], c.b[0], c.b[1]].map(|s| at - s as usize);
    let sel = &window[3 * w..4 * w];
    let (sa0, sa1, sb0, sb1) = (
        &sel[a0..a0 + m],
        &sel[a1..a1 + m],
        &sel[b0..b0 + m],
        &sel[b1..b1 + m],
    );
    for (comp, o) in out.into_iter().enumerate() {
        let f = &window[comp * w..(comp + 1) * w];
        let (fa0, fa1, fb0, fb1) = (&f[a0..a0 + m], &f[a1..a1 + m], &f[b0..b0 + m], &f[b1..b1 + m]);
        let o = &mut o[..m];
        for q in 0..m {
            // Each term when the key's end is at this place, else 0.
            let on = |s: f64, bit: u64, want: u64| (s.to_bits() >> bit) & 1 == want;
            let pa0 = if on(sa0[q], 0, 0) { fa0[q] } else { 0.0 };
            let pa1 = if on(sa1[q], 0, 1) { fa1[q] } else { 0.0 };
            let mb0 = if on(sb0[q], 1, 0) { fb0[q] } else { 0.0 };
            let mb1 = if on(sb1[q], 1, 1) { fb1[q] } else { 0.0 };
            o[q] += (pa0 - mb0) + (pa1 - mb1);
        }
    }
}

/// Evaluates the slots `s .. s + out[0].len()` of run `k` into `out`; padding slots were
/// evaluated like springs and are set to no force: from the list of pads where they are few
/// (a grid's, at its row ends), by a mask over the rest lengths where they are many (an
/// irregular mesh's runs).
#[inline]
fn evaluate_slots<const CHOICES: bool>(
    p: &Params<'_>,
    tr: &TileRuns,
    k: usize,
    s: usize,
    out: [&mut [f64]; 3],
) {
    let run = &tr.runs[k];
    let [x, y, z] = out;
    let slots = s..s + x.len();
    // A choice run never has one rest length: a grid's runs take the first arm, as before.
    let choice = if CHOICES { tr.choices[k].as_ref() } else { None };
    match (tr.uniform_rest[k], choice) {
        (Some(r), _) => run_uniform_widest(p, run, s, r, [&mut *x, &mut *y, &mut *z]),
        (None, None) => run_widest(p, run, s, [&mut *x, &mut *y, &mut *z]),
        (None, Some(c)) => {
            let select = tr.select_of(slots.clone());
            run_choice_widest(p, run, c, select, s, [&mut *x, &mut *y, &mut *z]);
        }
    }
    if tr.many_pads[k] {
        zero_pads_widest(&tr.rest[slots], [x, y, z]);
    } else {
        for q in tr.pads_in(slots) {
            (x[q - s], y[q - s], z[q - s]) = (0.0, 0.0, 0.0);
        }
    }
}

crate::simd_dispatch! { fn gather_widest(forces: &[f64], w: usize, runs: usize, plus: [usize; GATHER_RUNS], minus: [usize; GATHER_RUNS], out: [&mut [f64]; 3]) => gather }

/// `out[c][q] = sum_k (forces[plus[k] + c w + q] - forces[minus[k] + c w + q])` over the first
/// `runs` runs, in run order: one loop per run count, so the runs are unrolled and the sum stays
/// in registers.
#[inline(always)]
fn gather(
    forces: &[f64],
    w: usize,
    runs: usize,
    plus: [usize; GATHER_RUNS],
    minus: [usize; GATHER_RUNS],
    out: [&mut [f64]; 3],
) {
    macro_rules! by_count {
        ($($r:literal)*) => {
            match runs {
                $($r => gather_n::<$r>(forces, w, &plus, &minus, out),)*
                _ => unreachable!("at most GATHER_RUNS runs"),
            }
        };
    }
    by_count!(0 1 2 3 4 5 6 7 8 9 10 11 12)
}

#[inline(always)]
fn gather_n<const R: usize>(
    forces: &[f64],
    w: usize,
    plus: &[usize; GATHER_RUNS],
    minus: &[usize; GATHER_RUNS],
    out: [&mut [f64]; 3],
) {
    for (c, o) in out.into_iter().enumerate() {
        let m = o.len();
        let pl: [&[f64]; R] = std::array::from_fn(|k| &forces[plus[k] + c * w..plus[k] + c * w + m]);
        let mi: [&[f64]; R] = std::array::from_fn(|k| &forces[minus[k] + c * w..minus[k] + c * w + m]);
        // Blocks of 8 as fixed-size arrays (no bounds checks, so the loop vectorises), then the
        // rest; the same operations in the same order either way.
        const B: usize = 8;
        let whole = m / B * B;
        for q in (0..whole).step_by(B) {
            let mut sum = [0.0; B];
            for k in 0..R {
                let a: &[f64; B] = pl[k][q..q + B].try_into().expect("a block of 8");
                let b: &[f64; B] = mi[k][q..q + B].try_into().expect("a block of 8");
                for l in 0..B {
                    sum[l] += a[l] - b[l];
                }
            }
            o[q..q + B].copy_from_slice(&sum);
        }
        for q in whole..m {
            let mut sum = 0.0;
            for k in 0..R {
                sum += pl[k][q] - mi[k][q];
            }
            o[q] = sum;
        }
    }
}

/// Evaluates the springs of `runs` whose `i` end is in `tile` (or, for `None`, whose `i` end is
/// before `c0` and `j` end in `[c0, c1)`) and adds them to the window (which starts at particle
/// `base`): `+f` at `i` ends inside `[c0, c1)`, `-f` at `j` ends inside `[c0, c1)`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn add_range(
    p: &Params<'_>,
    t: &Topology,
    runs: &[u32],
    tile: Option<(usize, usize)>,
    c0: usize,
    c1: usize,
    base: usize,
    w: usize,
    window: &mut [f64],
    temp: &mut [[f64; TILE]; 3],
) {
    let tr = &t.tile_runs;
    for &r in runs {
        let run = &tr.runs[r as usize];
        let i0 = run.first_vertex as usize;
        let off = run.offset as usize;
        let i_end = i0 + run.len as usize;
        let (mut lo, hi) = match tile {
            Some((a, b)) => (i0.max(a), i_end.min(b)),
            None => (
                i0.max(c0.saturating_sub(off)),
                i_end.min(c0).min(c1.saturating_sub(off)),
            ),
        };
        while lo < hi {
            let m = (hi - lo).min(TILE);
            let s = run.first_spring as usize + (lo - i0);
            let [tx, ty, tz] = temp;
            evaluate_slots::<false>(p, tr, r as usize, s, [&mut tx[..m], &mut ty[..m], &mut tz[..m]]);
            // +f at the i ends and -f at the j ends inside the group.
            let ends = Ends {
                i: (lo.max(c0), (lo + m).min(c1)),
                j: ((lo + off).max(c0), (lo + m + off).min(c1)),
            };
            add_piece(temp, lo, off, ends, window, base, w);
            lo += m;
        }
    }
}

/// The particles a piece adds to, as ranges `[start, end)` (empty when `start >= end`): its
/// springs' `i` ends and its springs' `j` ends inside the group.
#[derive(Clone, Copy)]
struct Ends {
    i: (usize, usize),
    j: (usize, usize),
}

/// Adds the forces `temp` of the springs `lo ..` (offset `off`) into the window (which starts at
/// particle `base`): `+f` at the particles of `ends.i`, `-f` at those of `ends.j`. A particle
/// that is both (a spring's `i` end and another's `j` end; most are, as runs are long) gets
/// its net force `f_i - f_j` in one update, so the window is read and written once per
/// particle per piece.
fn add_piece(
    temp: &[[f64; TILE]; 3],
    lo: usize,
    off: usize,
    ends: Ends,
    window: &mut [f64],
    base: usize,
    w: usize,
) {
    let ((ia, ib), (ja, jb)) = (ends.i, ends.j);
    // Both: [oa, ob), empty when the two ranges do not overlap.
    let (oa, ob) = (ia.max(ja), ib.min(jb));
    let plus = |a: usize, b: usize, window: &mut [f64]| {
        if a < b {
            add3_widest(true, temp, a - lo, b - lo, window, a - base, w);
        }
    };
    let minus = |a: usize, b: usize, window: &mut [f64]| {
        if a < b {
            add3_widest(false, temp, a - lo - off, b - lo - off, window, a - base, w);
        }
    };
    if oa < ob {
        plus(ia, ib.min(oa), window);
        plus(ia.max(ob), ib, window);
        minus(ja, jb.min(oa), window);
        minus(ja.max(ob), jb, window);
        net3_widest(temp, oa - lo, oa - lo - off, ob - oa, window, oa - base, w);
    } else {
        plus(ia, ib, window);
        minus(ja, jb, window);
    }
}

crate::simd_dispatch! { fn net3_widest(temp: &[[f64; TILE]; 3], from_i: usize, from_j: usize, len: usize, window: &mut [f64], at: usize, w: usize) => net3 }

/// `window[c][at + k] += temp[c][from_i + k] - temp[c][from_j + k]` for `k < len` and the three
/// components: the net force of the spring with its `i` end there and the one with its `j` end
/// there.
#[inline(always)]
fn net3(
    temp: &[[f64; TILE]; 3],
    from_i: usize,
    from_j: usize,
    len: usize,
    window: &mut [f64],
    at: usize,
    w: usize,
) {
    for (c, src) in temp.iter().enumerate() {
        let dst = &mut window[c * w + at..c * w + at + len];
        let (si, sj) = (&src[from_i..from_i + len], &src[from_j..from_j + len]);
        for ((d, a), b) in dst.iter_mut().zip(si).zip(sj) {
            *d += *a - *b;
        }
    }
}

crate::simd_dispatch! { fn add3_widest(plus: bool, temp: &[[f64; TILE]; 3], from: usize, to: usize, window: &mut [f64], at: usize, w: usize) => add3 }

/// `window[c][at..] += temp[c][from..to]` (or `-=` unless `plus`) for the three components:
/// one dispatched call for all three, and a subtraction rather than a multiplication by -1
/// (the same bits: `d + (-1 * s)` is `d - s` exactly).
#[inline(always)]
fn add3(
    plus: bool,
    temp: &[[f64; TILE]; 3],
    from: usize,
    to: usize,
    window: &mut [f64],
    at: usize,
    w: usize,
) {
    for (c, src) in temp.iter().enumerate() {
        let dst = &mut window[c * w + at..c * w + at + (to - from)];
        let src = &src[from..to];
        if plus {
            for (d, s) in dst.iter_mut().zip(src) {
                *d += *s;
            }
        } else {
            for (d, s) in dst.iter_mut().zip(src) {
                *d -= *s;
            }
        }
    }
}

#[cfg(test)]
mod tests;
