//! Bend springs indexed by the edge they cross: a triangle mesh's "choice runs".
//!
//! A bend spring joins the two vertices opposite an edge `(u, w)`. In a mesh numbered in rows
//! whose cells are split along random diagonals (what a DCC tool's triangulation of a quad
//! grid gives), the opposite vertices of the edges of one direction `w - u` lie at one of two
//! places on each side (left of a vertical edge: `u - 1` or `u + columns - 1`), chosen by the
//! diagonals. Indexed by their first vertex, those springs scatter over up to four offsets,
//! each a run mostly of padding. Indexed by the edge they cross, they are one dense run whose
//! every slot reads its first end at one of two shifts from the slot's key and its second at
//! one of two others: a [`Choice`], with a per-slot byte saying which ([`ChoiceRun::select`]).
//!
//! Found here from the triangles, for the springs the padded runs hold least densely; used
//! only by the gathered tile walk (`forces::tiles`).

use super::Spring;
use std::collections::HashMap;

/// The shifts from a slot's key of a choice run's two ends: the first end is at `key + a[s & 1]`
/// and the second at `key + b[(s >> 1) & 1]`, `s` the slot's select byte. Every shift is at
/// least 0 and one of them is 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Choice {
    pub a: [u32; 2],
    pub b: [u32; 2],
}

impl Choice {
    /// The largest shift: how far past its key a slot reads.
    pub fn reach(&self) -> u32 {
        self.a[0].max(self.a[1]).max(self.b[0]).max(self.b[1])
    }
}

/// One choice run before it is laid out: keys `first_key ..= first_key + slots.len() - 1`,
/// each slot a spring (its rest length and select byte) or padding.
#[derive(Clone, Debug, PartialEq)]
pub struct ChoiceRun {
    pub first_key: u32,
    pub choice: Choice,
    /// Per key: the spring's rest length and select byte, or None (padding).
    pub slots: Vec<Option<(f64, u8)>>,
    /// The family of its springs (`SpringKind as u8`).
    pub kind: u8,
}

/// The choice runs of the springs `candidates` (indices into `springs`) of one family `kind`,
/// and the candidates they hold; candidates that fit none (no crossed edge found, more than two
/// places a side, a direction whose runs would be sparse) are left out of both.
pub fn choice_runs(
    n: usize,
    springs: &[Spring],
    candidates: &[usize],
    kind: u8,
    triangles: &[[u32; 3]],
) -> (Vec<ChoiceRun>, Vec<usize>) {
    // Each triangle edge with the triangle's third vertex, sorted by edge: an interior edge's
    // two entries are then side by side (sorting, not hashing: a million-vertex mesh has six
    // million entries).
    let key = |p: u32, q: u32| (u64::from(p.min(q)) << 32) | u64::from(p.max(q));
    let mut sides: Vec<(u64, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |a| (key(t[a], t[(a + 1) % 3]), t[(a + 2) % 3])))
        .collect();
    sides.sort_unstable();
    // (the spring across the edge, the edge), for each edge of exactly two triangles (as the
    // mesh's bend springs were made), sorted by spring then edge.
    let mut crossed: Vec<(u64, u64)> = sides
        .chunk_by(|a, b| a.0 == b.0)
        .filter_map(|e| match e {
            [(edge, p), (_, q)] => Some((key(*p, *q), *edge)),
            _ => None,
        })
        .collect();
    drop(sides);
    crossed.sort_unstable();
    // A spring across two edges (three vertices in a line: the mesh made it once) is indexed
    // by the first of them; the other edge has no spring of its own.
    crossed.dedup_by_key(|c| c.0);
    // By direction: (edge's first vertex, spring index, its ends relative to it).
    let mut groups: HashMap<u32, Vec<(u32, usize, [i64; 2])>> = HashMap::new();
    for &s in candidates {
        let sp = &springs[s];
        let Ok(at) = crossed.binary_search_by_key(&key(sp.i, sp.j), |c| c.0) else {
            continue;
        };
        let (u, w) = ((crossed[at].1 >> 32) as u32, crossed[at].1 as u32);
        let rel = [i64::from(sp.i) - i64::from(u), i64::from(sp.j) - i64::from(u)];
        groups.entry(w - u).or_default().push((u, s, rel));
    }
    let mut directions: Vec<u32> = groups.keys().copied().collect();
    directions.sort_unstable();
    let (mut runs, mut taken) = (Vec::new(), Vec::new());
    for d in directions {
        let mut group = groups.remove(&d).unwrap_or_default();
        group.sort_unstable_by_key(|g| g.0);
        if let Some((run, held)) = run_of(n, springs, &group, kind) {
            taken.extend(held);
            runs.push(run);
        }
    }
    taken.sort_unstable();
    (runs, taken)
}

/// The choice run of one direction's springs (sorted by crossed edge), when their ends fall at
/// two places a side and the run is dense (at most two slots a spring), and the springs it
/// holds: those whose slot reads, at every shift, a vertex of the `n` (a slot loads both places
/// of each side).
fn run_of(
    n: usize,
    springs: &[Spring],
    group: &[(u32, usize, [i64; 2])],
    kind: u8,
) -> Option<(ChoiceRun, Vec<usize>)> {
    // Two-colour the relative places: a spring's two ends are on opposite sides.
    let mut places: Vec<i64> = group.iter().flat_map(|g| g.2).collect();
    places.sort_unstable();
    places.dedup();
    if places.len() > 4 {
        return None;
    }
    let index = |o: i64| places.iter().position(|&p| p == o).unwrap_or(0);
    let mut side: [Option<bool>; 4] = [None; 4];
    // Colour until nothing changes (at most four places, so a few sweeps).
    for _ in 0..4 {
        for g in group {
            let (x, y) = (index(g.2[0]), index(g.2[1]));
            match (side[x], side[y]) {
                (Some(a), Some(b)) if a == b => return None,
                (Some(a), None) => side[y] = Some(!a),
                (None, Some(b)) => side[x] = Some(!b),
                (None, None) if side.iter().all(Option::is_none) => {
                    side[x] = Some(false);
                    side[y] = Some(true);
                }
                _ => {}
            }
        }
    }
    let of_side = |s: bool| -> Vec<i64> {
        (0..places.len())
            .filter(|&k| side[k] == Some(s))
            .map(|k| places[k])
            .collect()
    };
    let (left, right) = (of_side(false), of_side(true));
    if left.is_empty() || right.is_empty() || left.len() > 2 || right.len() > 2 {
        return None;
    }
    if left.len() + right.len() != places.len() {
        return None;
    }
    let low = places[0];
    let pair = |v: &[i64]| -> [u32; 2] {
        let (p, q) = (v[0] - low, *v.last().unwrap_or(&v[0]) - low);
        [p as u32, q as u32]
    };
    let choice = Choice {
        a: pair(&left),
        b: pair(&right),
    };
    // The springs whose slot reads inside the cloth at every shift.
    let reach = i64::from(choice.reach());
    let inside = |u: u32| {
        let key = i64::from(u) + low;
        key >= 0 && key + reach < n as i64
    };
    let held: Vec<&(u32, usize, [i64; 2])> = group.iter().filter(|g| inside(g.0)).collect();
    let first_edge = held.first()?.0;
    let last_edge = held.last()?.0;
    let first_key = u32::try_from(i64::from(first_edge) + low).ok()?;
    let len = (last_edge - first_edge) as usize + 1;
    if len > 2 * held.len() {
        return None;
    }
    let mut slots = vec![None; len];
    for &&(u, s, rel) in &held {
        // The spring's end on the first side, then on the second.
        let (first, second) = if left.contains(&rel[0]) {
            (rel[0], rel[1])
        } else {
            (rel[1], rel[0])
        };
        let pick = |v: &[i64], o: i64| u8::from(v.len() == 2 && v[1] == o);
        let select = pick(&left, first) | (pick(&right, second) << 1);
        let slot = &mut slots[(u - first_edge) as usize];
        if slot.is_some() {
            return None;
        }
        *slot = Some((springs[s].rest, select));
    }
    let run = ChoiceRun {
        first_key,
        choice,
        slots,
        kind,
    };
    Some((run, held.iter().map(|g| g.1).collect()))
}
