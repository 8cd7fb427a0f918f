//! How the force pass cuts a topology into tiles, decided once when the topology is built
//! (as Jolt's `SoftBodySharedSettings::Optimize` does): a topology whose springs form long runs
//! with short offsets (grids, row-ordered meshes) is walked tile by tile by
//! `forces::tiles`; any other sums its springs from a per-spring buffer.

use super::TileRuns;
use crate::parallel::TILE;

/// Largest run offset the tile path accepts: one `crate::parallel::CHUNK`, so that a spring
/// reaching into a group from before it ends in the group's first chunk (grids up to 2048
/// columns). Beyond it, the per-spring buffer path is used.
const MAX_OFFSET: usize = crate::parallel::CHUNK;

/// How the tile path cuts a topology: groups of whole chunks, each walked by one task with one
/// rolling window. Depends only on the topology, never on the thread count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileLayout {
    /// Numbers per component of the window: the largest offset plus whole tiles, at least as
    /// many particles as the offset, so sliding it copies at most one number per particle.
    pub window: usize,
    /// Particles per group, a multiple of `crate::parallel::CHUNK`.
    pub group: usize,
    /// Runs when the topology has at most [`GATHER_RUNS`] of them (a grid has eight; a few more
    /// allow a grid with holes or a row-ordered mesh), and the
    /// tiles are summed by the gathered tile walk; 0 otherwise.
    pub gather_runs: usize,
    /// Components of the gathered tile walk's force windows: three a run, four a choice run
    /// (its select bytes); 0 when not gathered.
    pub gather_components: usize,
    /// Entries before a tile in each force window of the gather path: the largest offset,
    /// rounded up to whole cache lines so that a tile's entries start on one.
    pub lead: usize,
    /// Numbers per component of each force window: `lead`, then `SLIDE_OFFSETS` largest offsets
    /// in whole tiles and `GATHER_TILES` tiles or more.
    pub force_window: usize,
    /// Particles in the window of inputs (`forces::inputs::InputWindow`): what the springs from before a
    /// group read (twice the largest offset) or what a tile's springs read (a tile and the
    /// largest offset), and `SLIDE_OFFSETS` largest offsets or `INPUT_TILES` tiles more, so that
    /// it slides once every few tiles.
    pub inputs: usize,
}

/// Tiles a force window of the gather path holds after its lead, at least: it slides (copies
/// each run's last `offset` forces to its front) once every so many tiles.
const GATHER_TILES: usize = 4;

/// Tiles the window of inputs holds beyond what one tile reads, at least: it slides once every
/// so many tiles. 1, 2 and 4 measured the same at 61 x 41 (`step_cycles`, 28.3-28.9 ns); 2 keeps
/// the window (nine component arrays) smaller than 4 and slides half as often as 1.
const INPUT_TILES: usize = 2;

/// Largest offsets both windows hold beyond what a tile reads, at least. A slide copies about
/// one largest offset of every component, so the windows slide once every eight offsets'
/// particles: an eighth of a copy of each array a particle. A grid 1001 wide (bend springs two
/// rows long, 2 002 particles) slid every 2 048 particles before and spent 3 ns of its 49 a
/// particle-step of the fractional model in the copies (`perf`); holding 8 offsets
/// instead of 1 or 4, 45-47 ns against 48-51 (`docs/benchmarks.md`). Only the windows' parts
/// near the tile are read, so the longer windows do not crowd the cache.
const SLIDE_OFFSETS: usize = 8;

/// Most entries (runs, and two a choice run) the gathered tile walk sums per particle.
pub const GATHER_RUNS: usize = 12;

impl TileLayout {
    /// The layout for `t`, or None when the tile path does not apply.
    pub(crate) fn of(tr: &TileRuns) -> Option<Self> {
        let long = tr.rest.len() >= 8 * tr.runs.len();
        if !(long && tr.max_offset <= MAX_OFFSET) {
            return None;
        }
        let chunk = crate::parallel::CHUNK;
        let tiles = tr.max_offset.div_ceil(TILE).max(1);
        let gathered = tr.gather_entries() <= GATHER_RUNS;
        // Choice runs are only made for the gathered walk (`TileRuns::gather_entries`).
        if !gathered && tr.choices.iter().any(Option::is_some) {
            return None;
        }
        Some(Self {
            // Whole cache lines per component, so each component starts on one.
            window: (tr.max_offset + tiles * TILE).next_multiple_of(8),
            // At least 8 offsets long: the springs evaluated twice at a group's start (see
            // the module's doc) are then a few percent of the group's.
            group: (8 * tr.max_offset).div_ceil(chunk).max(1) * chunk,
            gather_runs: if gathered { tr.runs.len() } else { 0 },
            gather_components: if gathered {
                (0..tr.runs.len()).map(|k| tr.components(k)).sum()
            } else {
                0
            },
            lead: tr.max_offset.next_multiple_of(8),
            force_window: tr.max_offset.next_multiple_of(8)
                + (SLIDE_OFFSETS * tr.max_offset)
                    .next_multiple_of(TILE)
                    .max(GATHER_TILES * TILE),
            inputs: ((2 * tr.max_offset).max(tr.max_offset + TILE)
                + (INPUT_TILES * TILE).max(SLIDE_OFFSETS * tr.max_offset))
            .next_multiple_of(8),
        })
    }
}
