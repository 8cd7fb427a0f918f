//! Springs grouped into runs: consecutive springs `(i, i + offset)`, `(i + 1, i + 1 + offset)`,
//! ... of one family. A run's end points are contiguous in memory, so the spring pass loads
//! them as plain slices (no index loads, no gathers) and the compiler vectorises it.
//!
//! `order_into_runs` sorts a spring list by (family, offset, first vertex); a grid then falls
//! into long runs (a whole vertical family is one run) and any mesh whose vertices are
//! numbered in rows (most are) into fairly long ones. A spring that fits no run is a run of
//! one: the layout is never wrong, only less fast.

use super::choice::{self, Choice, ChoiceRun};
use super::Spring;

/// `len` springs starting at spring index `first_spring`; spring `first_spring + t` joins
/// vertex `first_vertex + t` to vertex `first_vertex + t + offset`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpringRun {
    pub first_spring: u32,
    pub first_vertex: u32,
    pub offset: u32,
    pub len: u32,
    /// The family of the run's springs (`SpringKind as u8`).
    pub kind: u8,
    /// A second family sharing the run (tile runs only, [`TileRuns`]): its springs' slots hold
    /// their rest lengths negated. None: every spring of the run is of `kind`.
    pub second: Option<u8>,
}

/// Calls `f(run, lo, hi)` for every run overlapping the springs `first .. end`, in order, with
/// `lo .. hi` the overlap (spring indices). `runs` must be in spring order, as built here.
pub fn for_each_piece(
    runs: &[SpringRun],
    first: usize,
    end: usize,
    mut f: impl FnMut(&SpringRun, usize, usize),
) {
    let start = runs.partition_point(|r| (r.first_spring + r.len) as usize <= first);
    for run in &runs[start..] {
        let (a, b) = (run.first_spring as usize, (run.first_spring + run.len) as usize);
        if a >= end {
            break;
        }
        f(run, a.max(first), b.min(end));
    }
}

/// Sorts `springs` (each with i < j) by (kind, j - i, i) and returns the runs.
pub fn order_into_runs(springs: &mut [Spring]) -> Vec<SpringRun> {
    springs.sort_by_key(|s| (s.kind as u8, s.j - s.i, s.i));
    runs_by(springs, |s| (s.kind as u8, None))
}

/// The runs of `springs`, sorted so that springs of one class (`class`: a family, and a second
/// family sharing its runs) and offset follow each other by first vertex.
fn runs_by(springs: &[Spring], class: impl Fn(&Spring) -> (u8, Option<u8>)) -> Vec<SpringRun> {
    let mut runs: Vec<SpringRun> = Vec::new();
    for (k, s) in springs.iter().enumerate() {
        let offset = s.j - s.i;
        let (kind, second) = class(s);
        if let Some(r) = runs.last_mut() {
            if (r.kind, r.second) == (kind, second) && r.offset == offset && r.first_vertex + r.len == s.i {
                r.len += 1;
                continue;
            }
        }
        runs.push(SpringRun {
            first_spring: k as u32,
            first_vertex: s.i,
            offset,
            len: 1,
            kind,
            second,
        });
    }
    runs
}

/// The springs in the order of runs in which the two families at an offset that exactly two
/// families have, never both at one first vertex, share their runs, and those runs, when there
/// is such an offset. An irregular triangle mesh numbered in rows has them: a cell's two
/// diagonals are one edge (a stretch spring) and one bend spring across it, at the same
/// offset, in cells that alternate at random; as two families they are two half-empty runs at
/// each diagonal offset, as one, one full run.
fn mixed_order(springs: &[Spring]) -> Option<(Vec<Spring>, Vec<SpringRun>)> {
    use std::collections::{BTreeMap, HashSet};
    let mut families: BTreeMap<u32, u8> = BTreeMap::new();
    for s in springs {
        *families.entry(s.j - s.i).or_default() |= 1 << (s.kind as u8);
    }
    let mut shared: BTreeMap<u32, (u8, u8)> = families
        .into_iter()
        .filter(|(_, bits)| bits.count_ones() == 2)
        .map(|(offset, bits)| {
            let a = bits.trailing_zeros() as u8;
            let b = (bits & (bits - 1)).trailing_zeros() as u8;
            (offset, (a, b))
        })
        .collect();
    // Two springs of one offset at one first vertex cannot share a run's slot.
    let mut seen = HashSet::new();
    for s in springs {
        let offset = s.j - s.i;
        if shared.contains_key(&offset) && !seen.insert((offset, s.i)) {
            shared.remove(&offset);
        }
    }
    if shared.is_empty() {
        return None;
    }
    let class = |s: &Spring| match shared.get(&(s.j - s.i)) {
        Some(&(a, b)) => (a, Some(b)),
        None => (s.kind as u8, None),
    };
    let mut sorted = springs.to_vec();
    sorted.sort_by_key(|s| (class(s), s.j - s.i, s.i));
    let runs = runs_by(&sorted, class);
    Some((sorted, runs))
}

/// Largest gap (missing springs) between two runs of one family and offset that [`TileRuns`]
/// pads over when joining them all would pad too much (see [`MAX_PADDED`]).
const MAX_GAP: u32 = 4;

/// [`TileRuns`] joins every run of one family and offset into one, padding the gaps, when that
/// leaves at most this many slots per spring: an irregular mesh (random diagonals) then walks in
/// as few runs as a grid (`docs/benchmarks.md`: 2.3x the grid's cost per particle-step before,
/// about 1.5x after), while a mesh whose runs lie far apart is not padded without bound.
const MAX_PADDED: usize = 3;

/// The rest length a padding slot holds: NaN, so the force pass can tell padding from springs
/// by the rest lengths it reads anyway (a spring's is a finite number, negated for a run's
/// second family).
pub const PAD_REST: f64 = f64::NAN;

/// The runs again, with runs of the same family and offset that are separated by a few missing
/// springs joined into one by padding slots (a grid's rows break every horizontal, shear and
/// bend run at the row end: padding makes each family one run). A slot is a real spring or
/// padding (listed in `pads`, rest NaN): the force pass evaluates padding like a spring and then
/// sets its force to zero, so it reads nothing per slot to tell them apart.
/// Where two families share an offset (an irregular mesh's diagonals), they may share its runs
/// ([`SpringRun::second`]), when that takes fewer slots: the second family's slots hold their
/// rest lengths negated, and the force pass takes each slot's constants by that sign.
/// `SpringRun::first_spring` indexes slots here. Used by the tiled force pass, where fewer,
/// longer runs mean fewer, longer vector loops.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TileRuns {
    pub runs: Vec<SpringRun>,
    /// Rest length of each slot, m: negated for a run's second family, [`PAD_REST`] (NaN) for
    /// padding.
    pub rest: Vec<f64>,
    /// The padding slots, ascending.
    pub pads: Vec<u32>,
    /// Per run: the rest length every spring of it has, when they all have the same one (a
    /// regular grid's families), so the force pass need not read `rest` for it.
    pub uniform_rest: Vec<Option<f64>>,
    /// Per run: whether padding is more than a sixteenth of its slots, so that the force pass
    /// sets padding to no force by a mask over the rest lengths rather than from `pads`.
    pub many_pads: Vec<bool>,
    /// Per run: the shifts of its ends when it is a choice run (bend springs indexed by the
    /// edge they cross, `super::choice`): then `first_vertex + t` is slot t's key, `offset` the
    /// largest shift, and `select` says which shift each end takes. Only the gathered tile walk
    /// is given choice runs ([`TileRuns::gather_entries`]).
    pub choices: Vec<Option<Choice>>,
    /// The choice runs' slots' select bytes (they are the last runs, so their slots are the
    /// last, from `select_from` on): bit 0 set when the slot's first end is at its run's
    /// `a[1]`, bit 1 when its second is at `b[1]`. Empty without choice runs.
    pub select: Vec<u8>,
    /// The first choice slot (the slot count when there is none).
    pub select_from: usize,
    /// Runs touching each chunk of vertices.
    pub chunk_runs: super::Adjacency,
    /// Largest offset of any run.
    pub max_offset: usize,
}

impl TileRuns {
    /// Pads `runs` (from `order_into_runs` on `springs`) for `n` vertices: every run of a family
    /// and offset joined into one when the padding stays within `MAX_PADDED` slots a spring,
    /// else only over gaps of at most `MAX_GAP`. Two families sharing an offset share its runs
    /// when that takes fewer slots. A triangle mesh's bend springs that the padded runs hold
    /// sparsely become choice runs (`super::choice`) when that takes fewer slots and the walk
    /// stays gathered.
    pub fn new(n: usize, springs: &[Spring], runs: &[SpringRun], triangles: &[[u32; 3]]) -> Self {
        let best = Self::best(n, springs, runs);
        best.with_choices(n, springs, triangles).unwrap_or(best)
    }

    /// Entries the gathered tile walk sums per particle: one per run, two per choice run (its
    /// first ends' two shifts, each with its second ends' one).
    pub fn gather_entries(&self) -> usize {
        self.choices.iter().map(|c| if c.is_some() { 2 } else { 1 }).sum()
    }

    /// Arrays in run `k`'s force window of the gathered tile walk: the force's three
    /// components, and for a choice run its keys' select bytes (as the bits of numbers).
    pub fn components(&self, k: usize) -> usize {
        if self.choices[k].is_some() {
            4
        } else {
            3
        }
    }

    /// The runs again with the sparsely held springs of a family in choice runs, when that
    /// costs less (a choice slot reads twice the places, counted as 3/2 of a slot) and leaves
    /// at most [`super::GATHER_RUNS`] entries to gather; None when it would not.
    fn with_choices(&self, n: usize, springs: &[Spring], triangles: &[[u32; 3]]) -> Option<Self> {
        if triangles.is_empty() {
            return None;
        }
        // The springs of a family and offset whose plain run is mostly padding.
        let sparse: std::collections::HashSet<(u8, u32)> = self
            .runs
            .iter()
            .zip(&self.many_pads)
            .filter(|(r, &many)| many && r.second.is_none())
            .map(|(r, _)| (r.kind, r.offset))
            .collect();
        if sparse.is_empty() {
            return None;
        }
        let (candidates, kinds): (Vec<usize>, Vec<u8>) = springs
            .iter()
            .enumerate()
            .filter(|(_, s)| sparse.contains(&(s.kind as u8, s.j - s.i)))
            .map(|(k, s)| (k, s.kind as u8))
            .unzip();
        let mut families: Vec<u8> = kinds.clone();
        families.sort_unstable();
        families.dedup();
        let (mut found, mut taken) = (Vec::new(), Vec::new());
        for kind in families {
            let of_kind: Vec<usize> = candidates
                .iter()
                .zip(&kinds)
                .filter(|(_, &k)| k == kind)
                .map(|(&s, _)| s)
                .collect();
            let (runs, held) = choice::choice_runs(n, springs, &of_kind, kind, triangles);
            found.extend(runs);
            taken.extend(held);
        }
        if found.is_empty() {
            return None;
        }
        taken.sort_unstable();
        let mut others: Vec<Spring> = springs
            .iter()
            .enumerate()
            .filter(|(k, _)| taken.binary_search(k).is_err())
            .map(|(_, s)| *s)
            .collect();
        let runs = order_into_runs(&mut others);
        let mut t = Self::best(n, &others, &runs);
        for run in &found {
            t.push_choice(run);
        }
        t.finish(n);
        let cost = |t: &Self| -> usize {
            let choice: usize = t
                .runs
                .iter()
                .zip(&t.choices)
                .filter(|(_, c)| c.is_some())
                .map(|(r, _)| r.len as usize)
                .sum();
            2 * t.rest.len() + choice
        };
        (t.gather_entries() <= super::GATHER_RUNS && cost(&t) < cost(self)).then_some(t)
    }

    /// The select bytes of the choice slots `slots`.
    pub fn select_of(&self, slots: std::ops::Range<usize>) -> &[u8] {
        &self.select[slots.start - self.select_from..slots.end - self.select_from]
    }

    /// Appends a choice run's slots (after every other run's).
    fn push_choice(&mut self, run: &ChoiceRun) {
        if self.select.is_empty() {
            self.select_from = self.rest.len();
        }
        self.runs.push(SpringRun {
            first_spring: self.rest.len() as u32,
            first_vertex: run.first_key,
            offset: run.choice.reach(),
            len: run.slots.len() as u32,
            kind: run.kind,
            second: None,
        });
        self.choices.resize(self.runs.len() - 1, None);
        self.choices.push(Some(run.choice));
        for slot in &run.slots {
            match *slot {
                Some((rest, select)) => {
                    self.rest.push(rest);
                    self.select.push(select);
                }
                None => {
                    self.pads.push(self.rest.len() as u32);
                    self.rest.push(PAD_REST);
                    self.select.push(0);
                }
            }
        }
    }

    /// The plain runs or the runs two families share, whichever takes fewer slots.
    fn best(n: usize, springs: &[Spring], runs: &[SpringRun]) -> Self {
        let plain = Self::bounded(n, springs, runs);
        match mixed_order(springs) {
            Some((sorted, mixed_runs)) => {
                let mixed = Self::bounded(n, &sorted, &mixed_runs);
                if mixed.rest.len() < plain.rest.len() {
                    mixed
                } else {
                    plain
                }
            }
            None => plain,
        }
    }

    /// [`TileRuns::new`] for one order of the springs.
    fn bounded(n: usize, springs: &[Spring], runs: &[SpringRun]) -> Self {
        let joined = Self::padded(n, springs, runs, u32::MAX);
        if joined.rest.len() <= MAX_PADDED * springs.len().max(1) {
            return joined;
        }
        Self::padded(n, springs, runs, MAX_GAP)
    }

    /// `runs` joined over gaps of at most `max_gap` missing springs.
    fn padded(n: usize, springs: &[Spring], runs: &[SpringRun], max_gap: u32) -> Self {
        let mut t = Self::default();
        for r in runs {
            let gap = t.runs.last().and_then(|last| {
                let end = last.first_vertex + last.len;
                let same = (last.kind, last.second, last.offset) == (r.kind, r.second, r.offset);
                (same && r.first_vertex >= end && r.first_vertex - end <= max_gap)
                    .then(|| r.first_vertex - end)
            });
            match (gap, t.runs.last_mut()) {
                (Some(gap), Some(last)) => {
                    for _ in 0..gap {
                        t.pads.push(t.rest.len() as u32);
                        t.rest.push(PAD_REST);
                    }
                    last.len += gap + r.len;
                }
                _ => t.runs.push(SpringRun {
                    first_spring: t.rest.len() as u32,
                    len: r.len,
                    ..*r
                }),
            }
            for s in &springs[r.first_spring as usize..(r.first_spring + r.len) as usize] {
                let second = r.second == Some(s.kind as u8);
                t.rest.push(if second { -s.rest } else { s.rest });
            }
        }
        t.finish(n);
        t
    }

    /// What follows from the runs and slots: which runs have one rest length or many pads,
    /// the runs of each chunk, the largest offset; the lists' spare capacity dropped.
    fn finish(&mut self, n: usize) {
        let t = self;
        t.choices.resize(t.runs.len(), None);
        if t.select.is_empty() {
            t.select_from = t.rest.len();
        }
        t.uniform_rest = t
            .runs
            .iter()
            .zip(&t.choices)
            .map(|(r, c)| if c.is_some() { None } else { t.uniform(r) })
            .collect();
        t.many_pads = t
            .runs
            .iter()
            .map(|r| {
                let slots = r.first_spring as usize..(r.first_spring + r.len) as usize;
                16 * t.pads_in(slots).count() > r.len as usize
            })
            .collect();
        // Built by pushes: drop the spare capacity (these live as long as the cloth).
        t.rest.shrink_to_fit();
        t.pads.shrink_to_fit();
        t.runs.shrink_to_fit();
        t.select.shrink_to_fit();
        t.choices.shrink_to_fit();
        t.chunk_runs = super::Adjacency::chunk_runs(n, &t.runs);
        t.max_offset = t.runs.iter().map(|r| r.offset as usize).max().unwrap_or(0);
    }

    /// The rest length shared by every spring (not padding) of `run`, if there is one (never
    /// for a run of two families).
    fn uniform(&self, run: &SpringRun) -> Option<f64> {
        if run.second.is_some() {
            return None;
        }
        let slots = run.first_spring as usize..(run.first_spring + run.len) as usize;
        let mut pads = self.pads_in(slots.clone()).peekable();
        let mut shared: Option<f64> = None;
        for slot in slots {
            if pads.next_if_eq(&slot).is_some() {
                continue;
            }
            let r = self.rest[slot];
            match shared {
                None => shared = Some(r),
                Some(s) if s.to_bits() == r.to_bits() => {}
                Some(_) => return None,
            }
        }
        shared
    }

    /// The padding slots among `slots`.
    pub fn pads_in(&self, slots: std::ops::Range<usize>) -> impl Iterator<Item = usize> + '_ {
        let first = self.pads.partition_point(|&q| (q as usize) < slots.start);
        self.pads[first..]
            .iter()
            .map(|&q| q as usize)
            .take_while(move |&q| q < slots.end)
    }
}

#[cfg(test)]
mod tests {
    use crate::topology::{GridSpec, Topology};

    /// Runs of one family and offset are joined into one when the padding stays bounded, and
    /// only over short gaps when joining would pad more than `MAX_PADDED` slots a spring.
    #[test]
    fn runs_are_joined_when_the_padding_stays_bounded() {
        let t = grid_7x5();
        let keep = |keep: &dyn Fn(&crate::topology::Spring) -> bool| {
            let springs: Vec<_> = t.springs.iter().filter(|s| keep(s)).copied().collect();
            Topology::new(
                t.rest_positions.clone(),
                t.masses.clone(),
                springs,
                t.triangles.clone(),
                t.grid,
            )
        };
        // A gap of three rows in every family: joined (padding within bounds).
        let gapped = keep(&|s| !(7..28).contains(&s.i));
        assert_eq!(gapped.tile_runs.runs.len(), t.tile_runs.runs.len());
        assert!(!gapped.tile_runs.pads.is_empty());
        // Only the first and last stretch spring along x: joining would pad 27 slots for two
        // springs, so they stay two runs.
        let sparse = keep(&|s| s.j == s.i + 1 && (s.i == 0 || s.i == 32));
        assert_eq!(sparse.tile_runs.runs.len(), 2);
        assert!(sparse.tile_runs.pads.is_empty());
    }

    fn grid_7x5() -> Topology {
        GridSpec {
            width: 7,
            height: 5,
            spacing: 0.1,
            total_mass: 1.0,
        }
        .build()
        .unwrap()
    }

    #[test]
    fn runs_describe_every_spring_exactly() {
        let t = grid_7x5();
        let mut covered = 0;
        for r in &t.spring_runs {
            for k in 0..r.len {
                let s = &t.springs[(r.first_spring + k) as usize];
                assert_eq!(s.i, r.first_vertex + k);
                assert_eq!(s.j, s.i + r.offset);
                assert_eq!(s.kind, t.springs[r.first_spring as usize].kind);
            }
            assert_eq!(r.first_spring as usize, covered);
            covered += r.len as usize;
        }
        assert_eq!(covered, t.springs.len());
        // The vertical stretch family is one run over all rows but the last.
        assert!(t.spring_runs.iter().any(|r| r.offset == 7 && r.len == 7 * 4));
    }

    #[test]
    fn padded_runs_hold_every_spring_once_and_pad_only_gaps() {
        let t = grid_7x5();
        let p = &t.tile_runs;
        // A grid's eight families (stretch and bend along rows and columns, the two shear
        // diagonals, the two skip-one bend diagonals) become eight runs.
        assert_eq!(p.runs.len(), 8);
        let mut seen = vec![0; t.springs.len()];
        for r in &p.runs {
            let slots = r.first_spring as usize..(r.first_spring + r.len) as usize;
            let pads: Vec<usize> = p.pads_in(slots.clone()).collect();
            for (k, slot) in slots.enumerate() {
                let (i, j) = (r.first_vertex + k as u32, r.first_vertex + k as u32 + r.offset);
                let found = t.springs.iter().position(|s| s.i == i && s.j == j);
                match found {
                    Some(s) => {
                        assert!(!pads.contains(&slot));
                        assert_eq!(p.rest[slot], t.springs[s].rest);
                        assert_eq!(r.kind, t.springs[s].kind as u8);
                        seen[s] += 1;
                    }
                    None => assert!(pads.contains(&slot) && p.rest[slot].is_nan()),
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        assert_eq!(p.max_offset, 16);
        // A regular grid: each family has one rest length.
        assert!(p.uniform_rest.iter().all(|r| r.is_some()));
    }

    /// A triangle mesh with random diagonals: its bend springs across the rows' and the
    /// columns' edges become two choice runs, and every spring is held once, by a plain run's
    /// slot or by a choice slot whose selected places are its two ends.
    #[test]
    fn choice_runs_and_plain_runs_hold_every_spring_once() {
        let t = crate::testing::jittered_mesh(23, 17);
        let p = &t.tile_runs;
        let choices: Vec<_> = p.choices.iter().flatten().collect();
        assert_eq!(choices.len(), 2);
        assert_eq!(p.select_from + p.select.len(), p.rest.len());
        let mut seen = vec![0; t.springs.len()];
        let find = |a: u32, b: u32| {
            let (i, j) = (a.min(b), a.max(b));
            t.springs.iter().position(|s| s.i == i && s.j == j)
        };
        for (r, choice) in p.runs.iter().zip(&p.choices) {
            let slots = r.first_spring as usize..(r.first_spring + r.len) as usize;
            let pads: Vec<usize> = p.pads_in(slots.clone()).collect();
            for (k, slot) in slots.enumerate() {
                let key = r.first_vertex + k as u32;
                let (i, j) = match choice {
                    None => (key, key + r.offset),
                    Some(c) => {
                        let sel = p.select_of(slot..slot + 1)[0];
                        let (i, j) = (
                            key + c.a[(sel & 1) as usize],
                            key + c.b[((sel >> 1) & 1) as usize],
                        );
                        // Every place a slot loads is a vertex of the mesh.
                        assert!((key + c.reach()) < t.vertex_count() as u32);
                        (i, j)
                    }
                };
                if pads.contains(&slot) {
                    assert!(p.rest[slot].is_nan());
                    continue;
                }
                let s = find(i, j).expect("a slot's ends are a spring's");
                let same_family =
                    r.kind == t.springs[s].kind as u8 || r.second == Some(t.springs[s].kind as u8);
                assert!(same_family);
                assert_eq!(p.rest[slot].abs(), t.springs[s].rest);
                seen[s] += 1;
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        // No pad-heavy run is left: the choice runs took the scattered bend springs.
        assert!(p
            .many_pads
            .iter()
            .zip(&p.choices)
            .all(|(&many, c)| !many || c.is_some()));
        // A grid has none (its bend springs are in dense runs already).
        assert!(grid_7x5().tile_runs.choices.iter().all(Option::is_none));
        assert!(grid_7x5().tile_runs.select.is_empty());
    }

    #[test]
    fn a_run_with_two_rest_lengths_has_no_uniform_one() {
        let mut t = grid_7x5();
        // Stretch one spring of the first family: the topology is rebuilt from the springs.
        t.springs[0].rest *= 1.5;
        let p = super::TileRuns::new(t.vertex_count(), &t.springs, &t.spring_runs, &t.triangles);
        let kind = t.springs[0].kind as u8;
        let (with, without): (Vec<_>, Vec<_>) = p
            .runs
            .iter()
            .zip(&p.uniform_rest)
            .partition(|(r, _)| r.kind == kind && r.first_vertex == 0);
        assert!(with.iter().any(|(_, u)| u.is_none()));
        assert!(without.iter().all(|(_, u)| u.is_some()));
    }
}
