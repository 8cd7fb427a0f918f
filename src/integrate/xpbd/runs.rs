//! [`super::project`]'s pass over links that come as runs (`crate::topology::SpringRun`: link
//! `t` of a run joins particle `i0 + t` to `i0 + t + offset`), on component arrays.
//!
//! Two links of a run share a particle only when their first ends are `offset` apart, so a
//! run's links split into two phases, blocks of `offset` consecutive links taken every other
//! block: no two links of a phase share a particle. A block's first ends are `i0 .. i0 + len`
//! and its second ends `i0 + offset ..`, `len <= offset`: two contiguous, disjoint slices of each
//! array, so the block's links are projected as one vector loop without gathers or scatters.
//! On a grid a vertical or diagonal run's blocks are whole rows. The order (run after run, a
//! run's first phase then its second) is Gauss-Seidel across phases and runs, as the batches
//! of [`super::Batches`] are; every link takes the scalar step's operations in its order (no
//! fused multiply-add), so every vector width gives the same bits.

use super::Compliance;

/// A block of consecutive links: first ends `i0 .. i0 + len`, second ends `offset` further,
/// `len <= offset`; rest lengths from `rest` (m) in the plan's list; its family's index. With
/// `groups > 0` (offsets 1 and 2, whose blocks are one or two links), a whole phase instead:
/// `groups` blocks of `offset` links, block `q` from `i0 + 2 offset q`, their rest lengths
/// consecutive from `rest`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Block {
    i0: usize,
    offset: usize,
    len: usize,
    rest: usize,
    family: u8,
    groups: usize,
}

/// The links of a cloth as blocks, in the order a pass projects them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunPlan {
    n: usize,
    blocks: Vec<Block>,
    rest: Vec<f64>,
}

/// A run of links for [`RunPlan::of`]: one link per rest length (m), the first from particle
/// `i0`, each second end `offset` further (`offset >= 1`), and the links' family index.
pub struct Run<'a> {
    pub i0: usize,
    pub offset: usize,
    pub rest: &'a [f64],
    pub family: u8,
}

impl RunPlan {
    /// Orders `runs` of particles below `n` into blocks; `None` when a run reaches past `n`,
    /// has a zero offset, or the room cannot be had.
    pub fn of<'a>(runs: impl Iterator<Item = Run<'a>>, n: usize) -> Option<RunPlan> {
        let mut plan = RunPlan {
            n,
            ..RunPlan::default()
        };
        for run in runs {
            let len = run.rest.len();
            let end = run.i0.checked_add(len)?.checked_add(run.offset)?;
            if run.offset == 0 || (len > 0 && end > n) {
                return None;
            }
            let first = plan.rest.len();
            plan.rest.try_reserve(len).ok()?;
            plan.rest.extend_from_slice(run.rest);
            let o = run.offset;
            for phase in 0..2 {
                let mut at = phase * o;
                // Offsets 1 and 2: the phase's whole blocks as one strided item, their rest
                // lengths copied after the run's in that order; the last block, if short, alone.
                let whole = if o <= 2 {
                    len.saturating_sub(at) / (2 * o) + usize::from(len.saturating_sub(at) % (2 * o) >= o)
                } else {
                    0
                };
                if whole > 0 {
                    let from = plan.rest.len();
                    plan.rest.try_reserve(whole * o).ok()?;
                    for q in 0..whole {
                        let d = at + 2 * o * q;
                        plan.rest.extend_from_slice(&run.rest[d..d + o]);
                    }
                    plan.blocks.try_reserve(1).ok()?;
                    plan.blocks.push(Block {
                        i0: run.i0 + at,
                        offset: o,
                        len: whole * o,
                        rest: from,
                        family: run.family,
                        groups: whole,
                    });
                    at += 2 * o * whole;
                }
                while at < len {
                    let l = o.min(len - at);
                    plan.blocks.try_reserve(1).ok()?;
                    plan.blocks.push(Block {
                        i0: run.i0 + at,
                        offset: o,
                        len: l,
                        rest: first + at,
                        family: run.family,
                        groups: 0,
                    });
                    at += 2 * o;
                }
            }
        }
        Some(plan)
    }

    /// How many links.
    pub fn len(&self) -> usize {
        self.blocks.iter().map(|b| b.len).sum()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }
}

/// The particles on component arrays for a pass: positions (moved), positions where the
/// substep began, and the inverse mass `W = w I - u u^T` (all zero: held).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    pub x: [Vec<f64>; 3],
    pub start: [Vec<f64>; 3],
    pub w: Vec<f64>,
    pub u: [Vec<f64>; 3],
}

impl Particles {
    /// Sizes every array for `n` particles; `None` when the room cannot be had.
    pub fn ready(&mut self, n: usize) -> Option<()> {
        let all = [&mut self.x, &mut self.start, &mut self.u];
        for a in all.into_iter().flatten().chain([&mut self.w]) {
            a.try_reserve_exact(n.saturating_sub(a.len())).ok()?;
            a.resize(n, 0.0);
        }
        Some(())
    }
}

/// `a`'s `n` entries from `i` and from `j` (`i + n <= j`), apart.
#[inline(always)]
fn split(a: &mut [f64], i: usize, j: usize, n: usize) -> (&mut [f64], &mut [f64]) {
    let (lo, hi) = a.split_at_mut(j);
    (&mut lo[i..i + n], &mut hi[..n])
}

/// One pass over `plan`'s links on `p` (sized for the plan's particles: panics otherwise).
pub fn project(plan: &RunPlan, params: &[Compliance; 3], p: &mut Particles) {
    assert!(
        p.w.len() >= plan.n,
        "the particles' arrays are shorter than the plan's"
    );
    project_widest(plan, params, p);
}

crate::simd_dispatch! { fn project_widest(plan: &RunPlan, params: &[Compliance; 3], p: &mut Particles) => project_blocks }

/// Every block in order, each a vector loop.
#[inline(always)]
fn project_blocks(plan: &RunPlan, params: &[Compliance; 3], p: &mut Particles) {
    for b in &plan.blocks {
        let c = params[usize::from(b.family)];
        match (b.groups > 0, b.offset) {
            (true, 1) => strided::<1>(b, &plan.rest, c, p),
            (true, 2) => strided::<2>(b, &plan.rest, c, p),
            _ => block(b, &plan.rest, c, p),
        }
    }
}

/// One block of consecutive links: two contiguous slices of each array.
#[inline(always)]
fn block(b: &Block, rest: &[f64], c: Compliance, p: &mut Particles) {
    let Particles { x, start, w, u } = p;
    let [x0, x1, x2] = x;
    let (n, i, j) = (b.len, b.i0, b.i0 + b.offset);
    let rest = &rest[b.rest..b.rest + n];
    // `n <= offset`: the first ends end where the second ends may begin.
    let ((ax, bx), (ay, by), (az, bz)) = (split(x0, i, j, n), split(x1, i, j, n), split(x2, i, j, n));
    let (si, sj) = (
        start.each_ref().map(|a| &a[i..i + n]),
        start.each_ref().map(|a| &a[j..j + n]),
    );
    let (ui, uj) = (
        u.each_ref().map(|a| &a[i..i + n]),
        u.each_ref().map(|a| &a[j..j + n]),
    );
    let (wi, wj) = (&w[i..i + n], &w[j..j + n]);
    for t in 0..n {
        let (xi, xj) = ([ax[t], ay[t], az[t]], [bx[t], by[t], bz[t]]);
        let s = ([si[0][t], si[1][t], si[2][t]], [sj[0][t], sj[1][t], sj[2][t]]);
        let ua = [ui[0][t], ui[1][t], ui[2][t]];
        let ub = [uj[0][t], uj[1][t], uj[2][t]];
        let (ni, nj) = super::link_update(xi, xj, s, (wi[t], ua), (wj[t], ub), c, rest[t]);
        (ax[t], ay[t], az[t]) = (ni[0], ni[1], ni[2]);
        (bx[t], by[t], bz[t]) = (nj[0], nj[1], nj[2]);
    }
}

/// A phase of a run of offset `O` as one loop: `groups` blocks of `O` links, block `q`'s
/// first ends from `i0 + 2 O q`, so that link `r` of block `q` joins `i0 + 2 O q + r` to `O`
/// further. Each group of `2 O` particles is read and written whole.
#[inline(always)]
fn strided<const O: usize>(b: &Block, rest: &[f64], c: Compliance, p: &mut Particles) {
    let Particles { x, start, w, u } = p;
    let span = 2 * O * b.groups;
    let (i0, rest) = (b.i0, &rest[b.rest..b.rest + O * b.groups]);
    let [x0, x1, x2] = x.each_mut().map(|a| &mut a[i0..i0 + span]);
    let s = start.each_ref().map(|a| &a[i0..i0 + span]);
    let uu = u.each_ref().map(|a| &a[i0..i0 + span]);
    let w = &w[i0..i0 + span];
    for q in 0..b.groups {
        for r in 0..O {
            let (i, j) = (2 * O * q + r, 2 * O * q + r + O);
            let (xi, xj) = ([x0[i], x1[i], x2[i]], [x0[j], x1[j], x2[j]]);
            let ends = ([s[0][i], s[1][i], s[2][i]], [s[0][j], s[1][j], s[2][j]]);
            let ua = [uu[0][i], uu[1][i], uu[2][i]];
            let ub = [uu[0][j], uu[1][j], uu[2][j]];
            let (ni, nj) = super::link_update(xi, xj, ends, (w[i], ua), (w[j], ub), c, rest[O * q + r]);
            (x0[i], x1[i], x2[i]) = (ni[0], ni[1], ni[2]);
            (x0[j], x1[j], x2[j]) = (nj[0], nj[1], nj[2]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{link_update, Compliance};
    use super::*;

    /// A `w` x `h` grid's runs as a cloth lists them, `(first end, offset, links, family)`:
    /// stretch along rows (offset 1) and down the columns (w), shear both ways (w + 1 from a
    /// row's first column, w - 1 from its second), bend along rows (2) and columns (2 w).
    fn grid_runs(w: usize, h: usize) -> Vec<(usize, usize, usize, u8)> {
        let mut runs = Vec::new();
        for r in 0..h {
            runs.push((r * w, 1, w - 1, 0));
            runs.push((r * w, 2, w - 2, 2));
        }
        for r in 0..h - 1 {
            runs.push((r * w, w + 1, w - 1, 1));
            runs.push((r * w + 1, w - 1, w - 1, 1));
        }
        runs.push((0, w, (h - 1) * w, 0));
        runs.push((0, 2 * w, (h - 2) * w, 2));
        runs
    }

    fn plan_of(w: usize, h: usize) -> (RunPlan, Vec<(usize, usize, u8, f64)>) {
        let runs = grid_runs(w, h);
        let rests: Vec<Vec<f64>> = runs
            .iter()
            .map(|&(i0, _, len, _)| (0..len).map(|t| 0.01 + 1e-4 * ((i0 + t) % 7) as f64).collect())
            .collect();
        let plan = RunPlan::of(
            runs.iter()
                .zip(&rests)
                .map(|(&(i0, offset, _, family), rest)| Run {
                    i0,
                    offset,
                    rest,
                    family,
                }),
            w * h,
        )
        .unwrap();
        // Every link in the plan's order: (i, j, family, rest).
        let mut links = Vec::new();
        for b in &plan.blocks {
            let o = b.offset;
            for k in 0..b.len {
                let d = if b.groups > 0 { 2 * o * (k / o) + k % o } else { k };
                links.push((b.i0 + d, b.i0 + d + o, b.family, plan.rest[b.rest + k]));
            }
        }
        (plan, links)
    }

    #[test]
    fn every_link_once_and_no_phase_touches_a_particle_twice() {
        let (w, h) = (9, 6);
        let (plan, links) = plan_of(w, h);
        let want: usize = grid_runs(w, h).iter().map(|r| r.2).sum();
        assert_eq!(plan.len(), want);
        let mut seen = std::collections::HashSet::new();
        for l in &links {
            assert!(l.1 < w * h);
            assert!(seen.insert((l.0, l.1)), "link {l:?} twice");
        }
        assert_eq!(seen.len(), want);
        // A block's (or strided phase's) links share no particle.
        for b in &plan.blocks {
            let mut touched = std::collections::HashSet::new();
            for k in 0..b.len {
                let d = if b.groups > 0 {
                    2 * b.offset * (k / b.offset) + k % b.offset
                } else {
                    k
                };
                assert!(touched.insert(b.i0 + d) && touched.insert(b.i0 + d + b.offset));
            }
        }
        // A run reaching past the particles is refused.
        let bad = [0.01; 3];
        let run = Run {
            i0: 5,
            offset: 4,
            rest: &bad,
            family: 0,
        };
        assert!(RunPlan::of([run].into_iter(), 11).is_none());
    }

    #[test]
    fn the_pass_gives_the_bits_of_its_links_one_by_one() {
        // Short rows, and rows of many blocks in their strided phases.
        for (w, h) in [(9, 6), (37, 5)] {
            pass_against_links(w, h);
        }
    }

    fn pass_against_links(w: usize, h: usize) {
        let n = w * h;
        let (plan, links) = plan_of(w, h);
        let mut p = Particles::default();
        p.ready(n).unwrap();
        // Positions off their rest, some held (w = 0), water along a tilted normal.
        let jiggle = |i: usize, c: usize| ((i * 7 + c * 3) % 11) as f64 * 1e-4;
        for i in 0..n {
            let (col, row) = ((i % w) as f64, (i / w) as f64);
            let at = [0.01 * col, -0.01 * row, 0.0];
            for c in 0..3 {
                p.start[c][i] = at[c];
                p.x[c][i] = at[c] + jiggle(i, c);
            }
            p.w[i] = if i < w { 0.0 } else { 1e4 };
            if i >= w {
                let u = (1e4f64 * 0.8).sqrt();
                (p.u[0][i], p.u[1][i], p.u[2][i]) = (0.0, 0.6 * u, 0.8 * u);
            }
        }
        let params = [
            Compliance::of(10.0, 0.003, 1.0 / 180.0),
            Compliance::of(10.0, 0.003, 1.0 / 180.0),
            Compliance::of(0.0, 0.003, 1.0 / 180.0),
        ];
        let mut one = p.clone();
        project(&plan, &params, &mut p);
        let get = |a: &[Vec<f64>; 3], i: usize| [a[0][i], a[1][i], a[2][i]];
        for &(i, j, family, rest) in &links {
            let (ni, nj) = link_update(
                get(&one.x, i),
                get(&one.x, j),
                (get(&one.start, i), get(&one.start, j)),
                (one.w[i], get(&one.u, i)),
                (one.w[j], get(&one.u, j)),
                params[usize::from(family)],
                rest,
            );
            for c in 0..3 {
                (one.x[c][i], one.x[c][j]) = (ni[c], nj[c]);
            }
        }
        for c in 0..3 {
            for i in 0..n {
                assert_eq!(p.x[c][i].to_bits(), one.x[c][i].to_bits(), "particle {i}");
            }
        }
        // It moved something, and nothing held.
        assert!((0..n).any(|i| p.x[2][i] != p.start[2][i] + jiggle(i, 2)));
        assert!((0..w).all(|i| p.x[0][i] == p.start[0][i] + jiggle(i, 0)));
    }
}
