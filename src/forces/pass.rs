//! The force pass: every particle's total force, tile by tile.
//!
//! For each tile of [`TILE`] consecutive particles, the springs' sums are formed (by the tile
//! walk of [`super::tiles`] on grids and row-ordered meshes, from per-spring forces otherwise;
//! the strategy is fixed when the topology is built, [`crate::topology::Topology::tiled`]), then
//! every per-particle term that is on ([`super::terms::TERMS`]) adds to them, and the tile's
//! totals go to a sink while they are in L1 cache: an explicit integrator steps them there; the
//! implicit one needs a whole force array, which [`total_forces`] writes from the tiles.

use super::inputs::{InputWindow, Sources, TileState};
use super::normals;
use super::springs::{self, spring_rate, SpringRate};
use super::terms::{self, Context, Tile};
use super::tiles::{self, TILE};
use super::{body_acceleration, Collider};
use crate::math::Vec3;
use crate::model::Model;
use crate::parallel;
use crate::soa::Soa3;
use crate::topology::Topology;

/// Everything the forces read at one instant.
pub struct ForceInput<'a> {
    pub model: &'a Model,
    pub topology: &'a Topology,
    /// Positions, m.
    pub x: &'a [Vec3],
    /// Velocities, m/s.
    pub v: &'a [Vec3],
    /// D^{1/2}x of every particle (of the displacement relative to the water), m s^{-1/2};
    /// ignored when the model uses no fractional term.
    pub half_derivative: &'a [Vec3],
    /// Colliders present this step.
    pub colliders: &'a [Collider],
    /// Forces of the whole-cloth passes evaluated before this one (N, one per particle): the
    /// pair elements with a pass of their own (`elements.rs`) and the carried
    /// water's turning forces (`inertia.rs`); empty when the model has neither.
    pub prior_forces: &'a [Vec3],
    /// The current-rate weight w0 of each memory's D^{1/2} this step (what the implicit
    /// integrator treats as damping).
    pub weights: super::Weights,
    /// The running mean of the relative velocity the unsteady skin drag acts against (m/s,
    /// one per particle); empty when the model has none.
    pub skin_mean: &'a [Vec3],
}

/// Scratch buffers the force pass reuses (no allocation in a step).
#[derive(Clone, Debug, Default)]
pub struct ForceScratch {
    normals: Vec<Vec3>,
    /// Whether `normals` are already those of the coming pass's positions
    /// ([`ForceScratch::normals_ahead`]); the pass consumes the flag.
    normals_ready: bool,
    faces: Vec<Vec3>,
    springs: Soa3,
    spring_inputs: springs::SpringScratch,
    windows: crate::aligned::AlignedF64,
    /// What an [`Ahead`] first pass wrote, while the walk reads it: each task's window, then
    /// the bands where tasks meet (velocities, then D^{1/2}x, in each).
    ahead: crate::aligned::AlignedVec3,
}

impl ForceScratch {
    /// The component arrays the spring pass of an untiled topology reads, positions and damping
    /// rate (see [`spring_rate`]), sized for `n` particles: for a caller that fills them in a
    /// pass of its own ([`SpringInputs::Filled`]).
    pub(crate) fn spring_arrays(&mut self, n: usize) -> (&mut Soa3, &mut Soa3) {
        let s = &mut self.spring_inputs;
        s.x.resize(n);
        s.q.resize(n);
        (&mut s.x, &mut s.q)
    }

    /// Vertex normals of the last pass (empty when no term read them).
    pub(crate) fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// The vertex normals at `x`, computed now for a whole-cloth pass before the force pass,
    /// which then reads them instead of computing them again (once a step). Not computed
    /// again when an earlier pass of the same step wrote them ([`Self::normals_to_write`]).
    pub(crate) fn normals_ahead(&mut self, x: &[Vec3], topology: &crate::topology::Topology) -> &[Vec3] {
        if !self.normals_ready || self.normals.len() != x.len() {
            compute_normals(x, topology, self);
            self.normals_ready = true;
        }
        &self.normals
    }

    /// The buffer for the vertex normals of the coming pass's positions, `n` of them, for a
    /// pass before it that computes them anyway ([`crate::forces::turning_forces`]); the
    /// caller must fill every one, with the bits of [`super::vertex_normals_with`].
    pub(crate) fn normals_to_write(&mut self, n: usize) -> &mut [Vec3] {
        self.normals.resize(n, Vec3::zeros());
        self.normals_ready = true;
        &mut self.normals
    }
}

/// Who copies an untiled topology's spring inputs into component arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringInputs {
    /// The caller did ([`ForceScratch::spring_arrays`]; ignored on tiled topologies).
    Filled,
    /// The pass does.
    Copy,
}

/// The step's first pass over the particles, run by the force pass itself just ahead of the
/// particles its tile walk reads: on a cloth larger than the cache, the walk then reads what
/// the first pass wrote from cache instead of memory. For a step whose passes between the two
/// read none of it (no water carried, no pair elements, no contacts), on a tiled topology
/// ([`Topology::tiled`]; the caller runs the first pass itself on others).
///
/// What it writes that the force pass reads, the step's velocities and the half-derivatives
/// D^{1/2}x (in place of [`ForceInput::v`] and [`ForceInput::half_derivative`], which are then
/// empty), the force pass keeps only while its walk reads them: in a window of each task's
/// particles that slides with the walk, and a band where two tasks meet. Written to arrays
/// of the whole cloth, they would be written back to memory and read from it again (as a
/// line's write begins with reading it) only to be dropped after the step.
pub struct Ahead<'a> {
    /// The first pass over a range of particles, writing their velocities and D^{1/2}x into
    /// the two slices (as long as the range): every particle once, in ranges that start on
    /// multiples of [`TILE`] and end on one or at the last particle, never two overlapping
    /// ones at a time (what the force pass asks of it).
    pub run: &'a FirstPassInto<'a>,
}

/// The first pass over a range of particles, writing their velocities and D^{1/2}x into the
/// two slices ([`Ahead::run`]).
pub type FirstPassInto<'f> = dyn Fn(std::ops::Range<usize>, &mut [Vec3], &mut [Vec3]) + Sync + 'f;

/// A tile's total forces and state as component arrays, each `[x, y, z]` of one length.
pub struct TileTotals<'a> {
    /// The tile's first particle.
    pub p0: usize,
    /// Total force (N).
    pub force: [&'a [f64]; 3],
    /// Positions (m) and velocities (m/s) of [`ForceInput`].
    pub x: [&'a [f64]; 3],
    pub v: [&'a [f64]; 3],
    /// Unit vertex normals, when some term or the added mass reads them.
    pub normals: Option<&'a [Vec3]>,
}

/// Writes the total force on every particle into `f` (N), copying the spring inputs itself.
pub fn total_forces(input: &ForceInput<'_>, scratch: &mut ForceScratch, f: &mut [Vec3]) {
    total_forces_with(input, scratch, SpringInputs::Copy, f);
}

/// [`total_forces`], saying who copied the spring inputs.
pub fn total_forces_with(
    input: &ForceInput<'_>,
    scratch: &mut ForceScratch,
    inputs: SpringInputs,
    f: &mut [Vec3],
) {
    let out = parallel::Disjoint::new(f);
    for_each_tile(input, scratch, inputs, |t| {
        // SAFETY: tiles are disjoint, each is handed to this closure once.
        let out = unsafe { out.range(t.p0..t.p0 + t.force[0].len()) };
        for (k, o) in out.iter_mut().enumerate() {
            *o = Vec3::new(t.force[0][k], t.force[1][k], t.force[2][k]);
        }
    });
}

/// Evaluates the total force on every particle, tile by tile, and hands each tile's totals
/// and state to `sink` once (at most [`TILE`] particles, all in one `parallel::CHUNK`).
/// Tiles of different chunks may be handed over on different threads, in any order; the
/// forces do not depend on the thread count.
pub fn for_each_tile<S>(input: &ForceInput<'_>, scratch: &mut ForceScratch, inputs: SpringInputs, sink: S)
where
    S: Fn(TileTotals<'_>) + Sync,
{
    for_each_tile_ahead(input, scratch, inputs, None, sink);
}

/// [`for_each_tile`], running the step's first pass (`ahead`) as it goes when given one (on a
/// tiled topology only).
pub fn for_each_tile_ahead<S>(
    input: &ForceInput<'_>,
    scratch: &mut ForceScratch,
    inputs: SpringInputs,
    ahead: Option<&Ahead<'_>>,
    sink: S,
) where
    S: Fn(TileTotals<'_>) + Sync,
{
    let m = input.model;
    let reads = terms::reads(m, !input.colliders.is_empty());
    if reads.normals && !std::mem::take(&mut scratch.normals_ready) {
        compute_normals(input.x, input.topology, scratch);
    }
    scratch.normals_ready = false;
    let normals = reads.normals.then_some(&scratch.normals[..]);
    let context = Context {
        model: m,
        gravity: body_acceleration(m),
        colliders: input.colliders,
    };
    let (masses, areas) = (&input.topology.masses, &input.topology.areas);
    let half = (!input.half_derivative.is_empty() || ahead.is_some()).then_some(input.half_derivative);
    let finish = |p0: usize, s: [&mut [f64]; 3], state: &TileState<'_>| {
        let len = s[0].len();
        let Some(v) = state.v else {
            unreachable!("the pass keeps every tile's velocities");
        };
        let tile = Tile {
            x: state.x,
            v,
            half: state.half,
            normals: normals.map(|n| &n[p0..p0 + len]),
            masses: &masses[p0..p0 + len],
            areas: &areas[p0..p0 + len],
            skin_mean: input.skin_mean.get(p0..p0 + len),
        };
        let [fx, fy, fz] = s;
        if let Some(prior) = input.prior_forces.get(p0..p0 + len) {
            for (k, f) in prior.iter().enumerate() {
                (fx[k], fy[k], fz[k]) = (fx[k] + f.x, fy[k] + f.y, fz[k] + f.z);
            }
        }
        terms::add_all(&context, &tile, [&mut *fx, &mut *fy, &mut *fz]);
        sink(TileTotals {
            p0,
            force: [fx, fy, fz],
            x: state.x,
            v,
            normals: tile.normals,
        });
    };
    let sources = Sources {
        x: input.x,
        v: Some(input.v),
        half: if reads.half_derivative || spring_rate(m) == SpringRate::HalfDerivative {
            half
        } else {
            None
        },
        rate: spring_rate(m),
        base: 0,
    };
    let ForceScratch {
        spring_inputs,
        springs,
        windows,
        ahead: ahead_room,
        ..
    } = scratch;
    spring_sums(
        input,
        spring_inputs,
        springs,
        (windows, ahead_room),
        inputs,
        sources,
        ahead,
        finish,
    );
}

/// Computes the vertex normals at `x` into `scratch`.
fn compute_normals(x: &[Vec3], t: &crate::topology::Topology, scratch: &mut ForceScratch) {
    let n = x.len();
    scratch.normals.resize(n, Vec3::zeros());
    scratch.faces.resize(t.triangles.len(), Vec3::zeros());
    normals::vertex_normals_with(
        x,
        &t.triangles,
        &t.vertex_triangles,
        parallel::worth_it(n),
        &mut scratch.faces,
        &mut scratch.normals,
    );
}

/// Walks the particles tile by tile: sums each tile's spring forces and calls
/// `finish(p0, sums, state)` with them (component arrays, which the finisher adds to) and the
/// tile's state as component arrays (`sources`, from the tile walk's window on a tiled topology,
/// gathered from the step's arrays otherwise). With `ahead`, the velocities and
/// half-derivatives of `sources` are those `ahead` writes: on a tiled topology it runs first
/// on the particles around where the tasks meet, then each task runs it on its own particles
/// a group ahead of its walk.
#[allow(clippy::too_many_arguments)] // the pass's scratch buffers, borrowed apart from its normals
fn spring_sums<T>(
    input: &ForceInput<'_>,
    spring_inputs: &mut springs::SpringScratch,
    spring_buffer: &mut Soa3,
    (windows, ahead_room): (&mut crate::aligned::AlignedF64, &mut crate::aligned::AlignedVec3),
    inputs: SpringInputs,
    sources: Sources<'_>,
    ahead: Option<&Ahead<'_>>,
    finish: T,
) where
    T: Fn(usize, [&mut [f64]; 3], &TileState<'_>) + Sync,
{
    let t = input.topology;
    let n = input.x.len();
    let par = parallel::worth_it(n);
    let layout = t.tiled.as_ref();
    let fill = inputs == SpringInputs::Copy && layout.is_none();
    let params = springs::params(input, par, spring_inputs, fill);
    assert!(
        sources.rate != SpringRate::HalfDerivative || sources.half.is_some(),
        "fractional spring damping needs the half-derivatives (ForceInput::half_derivative)"
    );
    if let Some(layout) = layout {
        spring_sums_tiled(
            input,
            &params,
            layout,
            (windows, ahead_room),
            sources,
            ahead,
            finish,
        );
    } else {
        debug_assert!(ahead.is_none(), "the first pass runs inside tile walks only");
        spring_sums_untiled(t, &params, par, spring_buffer, &sources, finish);
    }
}

/// [`spring_sums`] on a tiled topology (`layout`): the groups of tiles cut into [`Tasks`], each
/// with its window, and with `ahead` the first pass run into windows that slide with the walk.
fn spring_sums_tiled<T>(
    input: &ForceInput<'_>,
    params: &springs::Params<'_>,
    layout: &crate::topology::TileLayout,
    (windows, ahead_room): (&mut crate::aligned::AlignedF64, &mut crate::aligned::AlignedVec3),
    sources: Sources<'_>,
    ahead: Option<&Ahead<'_>>,
    finish: T,
) where
    T: Fn(usize, [&mut [f64]; 3], &TileState<'_>) + Sync,
{
    let t = input.topology;
    let n = input.x.len();
    let par = parallel::worth_it(n);
    let tk = Tasks::new(n, layout.group, par, t.tile_runs.max_offset);
    let (tasks, band, max_offset) = (tk.count, tk.band, t.tile_runs.max_offset);
    let w = tiles::scratch(layout);
    windows.resize(w * tasks);
    // The first pass's velocities and D^{1/2}x: a window of `room` particles a task (the
    // group it walks, the springs' reach either side, a tile of rounding, [`LINED`]), and
    // the bands.
    let room = (layout.group + 2 * max_offset + 2 * TILE + LINED)
        .min(n)
        .next_multiple_of(LINED);
    let (task_room, band_room) = if ahead.is_some() {
        (2 * room, 4 * band)
    } else {
        (0, 0)
    };
    ahead_room.resize(tasks * task_room + tasks.saturating_sub(1) * band_room);
    let (task_rooms, band_rooms) = ahead_room.split_at_mut(tasks * task_room);
    if let Some(a) = ahead {
        tk.run_bands(a, band_rooms, band_room);
    }
    let band_rooms = &*band_rooms;
    // The band where tasks k - 1 and k meet: its particles and its two parts.
    let band_of = |k: usize| {
        let b = &band_rooms[(k - 1) * band_room..k * band_room];
        let (bv, bh) = b.split_at(2 * band);
        (tk.band(k), bv, bh)
    };
    let task_rooms = parallel::Disjoint::new(task_rooms);
    parallel::chunks(par, &mut windows[..w * tasks], w, |first, window| {
        let (sums, buf) = window.split_at_mut(tiles::sums_scratch(layout));
        let k = first / w;
        let done = tk.own(k).start;
        // SAFETY: each task takes its own part.
        let mine = unsafe { task_rooms.range(k * task_room..(k + 1) * task_room) };
        let (wv, wh) = mine.split_at_mut(task_room / 2);
        let mut win = AheadWindow {
            v: wv,
            h: wh,
            lo: 0,
            hi: 0,
            done,
            room,
        };
        for g in tk.groups(k) {
            let c0 = g * layout.group;
            let len = layout.group.min(n - c0);
            let finish = |p0: usize, sums: [&mut [f64]; 3], w: &InputWindow<'_>| {
                let len = sums[0].len();
                finish(p0, sums, &w.tile(p0, p0 + len))
            };
            let start = c0.saturating_sub(max_offset);
            let end = (c0 + len + max_offset).min(n);
            let sources = match ahead {
                None => sources,
                Some(a) => {
                    // The first pass over this task's particles up to what the group's
                    // springs read, a tile at a time; the bands' particles (run before
                    // the tasks) copied in.
                    let own = tk.own(k);
                    let target = end.max(end.next_multiple_of(TILE).min(own.end));
                    win.reach(a, own, start, target, |at| band_of(if at { k } else { k + 1 }));
                    let (v, h) = win.held(start..end);
                    Sources {
                        x: &input.x[start..end],
                        v: Some(v),
                        half: sources.half.map(|_| h),
                        base: start,
                        ..sources
                    }
                }
            };
            let mut window = InputWindow::new(sources, buf, start);
            if layout.gather_runs > 0 {
                tiles::spring_forces_gathered(params, t, layout, c0, len, sums, &mut window, finish);
            } else {
                tiles::spring_forces(params, t, c0, len, sums, &mut window, finish);
            }
        }
        debug_assert!(ahead.is_none() || win.done == tk.own(k).end);
    });
}

/// [`spring_sums`] on a topology the force pass cannot walk in tiles: every spring's force
/// into `spring_buffer`, then each tile's sums gathered along the adjacency, its state
/// gathered from `sources`.
fn spring_sums_untiled<T>(
    t: &Topology,
    params: &springs::Params<'_>,
    par: bool,
    spring_buffer: &mut Soa3,
    sources: &Sources<'_>,
    finish: T,
) where
    T: Fn(usize, [&mut [f64]; 3], &TileState<'_>) + Sync,
{
    let n = t.vertex_count();
    springs::compute(params, &t.spring_runs, par, spring_buffer);
    let spring_force = spring_buffer.slices();
    parallel::for_chunks(par, n, parallel::CHUNK, |first, len| {
        let mut acc = [[0.0; TILE]; 3];
        let mut state = [[0.0; TILE]; 9];
        for p0 in (first..first + len).step_by(TILE) {
            let m = TILE.min(first + len - p0);
            super::assemble::add_spring_forces(t, p0, m, spring_force, &mut acc);
            let gathered = gather(sources, p0, m, &mut state);
            let [ax, ay, az] = &mut acc;
            finish(p0, [&mut ax[..m], &mut ay[..m], &mut az[..m]], &gathered);
        }
    });
}

/// How a tiled walk of `n` particles is cut into tasks, one window each: task k walks the
/// contiguous groups `k * groups / count .. (k + 1) * groups / count` (which task walks a group
/// does not change its sums). Tasks of as near equal work as whole groups allow, in order: the
/// pool halves the list of tasks between its threads, so each thread gets the groups of one
/// half (interleaved groups gave one thread of two 6 of 201 x 201's 10 groups and the other 4).
#[derive(Clone, Copy)]
struct Tasks {
    n: usize,
    groups: usize,
    count: usize,
    group: usize,
    /// The band around a task's first particle that reads across two tasks.
    band: usize,
}

impl Tasks {
    fn new(n: usize, group: usize, par: bool, max_offset: usize) -> Self {
        let groups = n.div_ceil(group);
        let count = if par {
            groups.min(2 * rayon::current_num_threads())
        } else {
            1
        };
        let band = max_offset.next_multiple_of(TILE);
        Tasks {
            n,
            groups,
            count,
            group,
            band,
        }
    }

    /// Task k's groups.
    fn groups(&self, k: usize) -> std::ops::Range<usize> {
        k * self.groups / self.count..(k + 1) * self.groups / self.count
    }

    /// Task k's first particle.
    fn start(&self, k: usize) -> usize {
        ((k * self.groups / self.count) * self.group).min(self.n)
    }

    /// Where task k's own run of the first pass begins and ends: the bands are run first,
    /// before the tasks (tasks are at least a group, eight offsets, long).
    fn own(&self, k: usize) -> std::ops::Range<usize> {
        let lo = if k == 0 {
            0
        } else {
            (self.start(k) + self.band).min(self.n)
        };
        let hi = if k + 1 == self.count {
            self.n
        } else {
            self.start(k + 1).saturating_sub(self.band)
        };
        lo..hi.max(lo)
    }

    /// The first pass over the bands where tasks meet, into `rooms` (`room` each: the
    /// velocities, then the half-derivatives), before the tasks run.
    fn run_bands(&self, a: &Ahead<'_>, rooms: &mut [Vec3], room: usize) {
        for (k, b) in (1..self.count).zip(rooms.chunks_mut(room)) {
            let r = self.band(k);
            let (bv, bh) = b.split_at_mut(2 * self.band);
            (a.run)(r.clone(), &mut bv[..r.len()], &mut bh[..r.len()]);
        }
    }

    /// The particles of the band where tasks k - 1 and k meet.
    fn band(&self, k: usize) -> std::ops::Range<usize> {
        let c = self.start(k);
        c.saturating_sub(self.band)..(c + self.band).min(self.n)
    }
}

/// A task's window of the first pass's velocities and D^{1/2}x ([`Ahead`]): particles
/// `lo .. hi` at `v[0..]`, `h[0..]`, at most `room`, slid along the task's walk; `done` the
/// end of what the task has run of its own particles.
struct AheadWindow<'w> {
    v: &'w mut [Vec3],
    h: &'w mut [Vec3],
    lo: usize,
    hi: usize,
    done: usize,
    room: usize,
}

/// Windows start on a particle a multiple of this from the first, so each particle sits at the
/// same place in its cache line as in an array of the whole cloth (the walk's loads split no
/// more lines than they did there).
const LINED: usize = 8;

impl AheadWindow<'_> {
    /// Makes the window hold particles `start .. target`: slid to `start` when it would not
    /// hold them (never on a cloth it holds whole), then grown by the first pass over the
    /// task's `own` particles and by copies of the bands' (`band(true)` the band the task
    /// starts in, `band(false)` the one it ends in: its particles and their two parts).
    fn reach<'b>(
        &mut self,
        a: &Ahead<'_>,
        own: std::ops::Range<usize>,
        start: usize,
        target: usize,
        band: impl Fn(bool) -> (std::ops::Range<usize>, &'b [Vec3], &'b [Vec3]),
    ) {
        let (wv, wh) = (&mut *self.v, &mut *self.h);
        let (lo, hi) = (&mut self.lo, &mut self.hi);
        if *hi <= start {
            (*lo, *hi) = (start - start % LINED, start - start % LINED);
        } else if target - *lo > self.room {
            let from = start - start % LINED;
            wv.copy_within(from - *lo..*hi - *lo, 0);
            wh.copy_within(from - *lo..*hi - *lo, 0);
            *lo = from;
        }
        while *hi < target {
            let next = if own.contains(hi) {
                debug_assert_eq!(*hi, self.done);
                let e = target.next_multiple_of(TILE).min(own.end);
                (a.run)(*hi..e, &mut wv[*hi - *lo..e - *lo], &mut wh[*hi - *lo..e - *lo]);
                self.done = e;
                e
            } else {
                let (b, bv, bh) = band(*hi < own.start);
                let e = target.min(b.end);
                wv[*hi - *lo..e - *lo].copy_from_slice(&bv[*hi - b.start..e - b.start]);
                wh[*hi - *lo..e - *lo].copy_from_slice(&bh[*hi - b.start..e - b.start]);
                e
            };
            debug_assert!(next > *hi, "the window did not grow");
            if next <= *hi {
                break;
            }
            *hi = next;
        }
    }

    /// The velocities and D^{1/2}x of particles `r`, which the window holds.
    fn held(&self, r: std::ops::Range<usize>) -> (&[Vec3], &[Vec3]) {
        let (a, b) = (r.start - self.lo, r.end - self.lo);
        (&self.v[a..b], &self.h[a..b])
    }
}

/// The state of particles `p0 .. p0 + m` as component arrays, copied into `buf`.
fn gather<'b>(s: &Sources<'_>, p0: usize, m: usize, buf: &'b mut [[f64; TILE]; 9]) -> TileState<'b> {
    let [x0, x1, x2, v0, v1, v2, h0, h1, h2] = buf;
    super::inputs::transpose_widest(&s.x[p0..p0 + m], [&mut x0[..m], &mut x1[..m], &mut x2[..m]]);
    if let Some(v) = s.v {
        super::inputs::transpose_widest(&v[p0..p0 + m], [&mut v0[..m], &mut v1[..m], &mut v2[..m]]);
    }
    if let Some(h) = s.half {
        super::inputs::transpose_widest(&h[p0..p0 + m], [&mut h0[..m], &mut h1[..m], &mut h2[..m]]);
    }
    TileState {
        x: [&x0[..m], &x1[..m], &x2[..m]],
        v: s.v.map(|_| [&v0[..m], &v1[..m], &v2[..m]]),
        half: s.half.map(|_| [&h0[..m], &h1[..m], &h2[..m]]),
    }
}
