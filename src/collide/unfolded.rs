//! A proof that an unfolded sheet keeps its distances: up to which rest distance every pair of
//! the cloth's points is surely further apart now than self-collision's reach, so that a look
//! need not test such pairs (`self_collision.rs`).
//!
//! **When it applies.** The rest shape must be a flat convex sheet: every vertex on one plane,
//! every triangle turning the same way in it, each edge shared by at most two triangles (in
//! opposite directions), every border edge on the border of the vertices' convex hull, and the
//! triangles' areas adding up to the hull's. Then the triangles cover the hull once, so the
//! rest segment between any two points of the cloth runs through triangles of the cloth and
//! the cloth's map from rest to now is continuous along it. (A grid is always such a sheet; a
//! mesh with a hole, a slit, a notch or a curved rest shape is not, and is looked at in full.)
//!
//! **The bound.** In rest-plane coordinates each triangle `T` maps rest vectors to space by its
//! deformation gradient `F_T` (3 x 2, columns `a_T`, `b_T`). For points `p`, `q` at rest
//! distance `d` along the unit direction `u`, `x(q) - x(p)` is the integral of `F_T u` along
//! the rest segment. Take any window of the rest plane that holds the segment, the box of the
//! `a_T` and the box of the `b_T` of the triangles in it (centres `a_0`, `b_0`, half diagonals
//! `da`, `db`) and the least singular value `s` of their `F_T`. Then
//! `|F_T u - F_0 u| <= sqrt(da^2 + db^2) = e` (Cauchy-Schwarz), and by the law of cosines the
//! component of `F_T u` along `F_0 u` is `(|F_T u|^2 + |F_0 u|^2 - |F_T u - F_0 u|^2) / (2 |F_0 u|)`,
//! at least `sqrt(|F_T u|^2 - e^2)` (the arithmetic-geometric mean), so
//!
//! `|x(q) - x(p)| >= d g`, `g = sqrt(s^2 - e^2)`.
//!
//! Bending costs little here: the `b_T` of a sheet bent by an angle `phi` across the window
//! spread over an arc whose box has a half diagonal of about `phi / 2`, so `g` falls only as
//! `1 - phi^2 / 8`, where a rigid fit of the window is off by its whole sag.
//!
//! **Windows.** The rest plane is cut into square cells no smaller than any triangle's box
//! (nor than a side the cloth asks for: self-collision asks for 1.25 times the nearest tested
//! pair's rest distance, so that the first band is proved over windows of 2 cells), each cell
//! summarising the triangles whose boxes meet it, and the cells are merged two by
//! two into coarser levels. A segment of rest length `d` meets at most `floor(d / c) + 2` cells
//! of side `c` along each axis, so it lies in some window of `k x k` cells whenever
//! `d < (k - 1) c`. For windows of 2 (the finest level only), 3 and 4 cells of each level in
//! turn, the least `g` over every window bounds every pair in its band of distances: the
//! pairs from the exclusion radius up (nearer pairs are neighbours, never tested; in fact
//! from the nearest tested pair's rest distance, found once, when self-collision says it:
//! 10 mm on a 1 cm grid at 4 mm, where the exclusion is 8.8 mm and the bound at it needed 91 %
//! of a rest distance kept instead of 80 %) are certain
//! as long as each band's nearest distance times its `g` reaches the reach. The first band
//! that does not stops the proof there; a level whose windows hold the whole sheet proves it
//! for every distance.
//!
//! **A step.** The same bound holds at every instant of a step whose points move on straight
//! lines from `x0` to `x1` when each triangle's summary covers both ends: the columns of
//! `F(t) = (1 - t) F0 + t F1` lie in the boxes of both ends', and its least singular value is
//! at least `min(s0, s1) - |F1 - F0| / 2`. Proved for every distance, no pair comes within
//! reach during the step, however far its points move: self-collision's step limit is then
//! not needed (`Unfolded::out_of_reach_throughout`, `cloth/collisions.rs`).
//!
//! Nothing is kept from one look to the next but the rest shape's numbers and the working
//! lists (made when the cloth is set up, so a look allocates nothing).

use crate::math::Vec3;

/// A summary of triangles' deformation gradients: the boxes of their columns `a` (0-2) and
/// `b` (3-5), lows then highs, and the least squared singular value (12). Stored in f32,
/// rounded outwards (lows and the singular value down, highs up), so a summary only ever
/// widens: the bound read from it holds for the f64 numbers.
type Span = [f32; 13];

const EMPTY: Span = [
    f32::INFINITY,
    f32::INFINITY,
    f32::INFINITY,
    f32::INFINITY,
    f32::INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NEG_INFINITY,
    f32::NEG_INFINITY,
    f32::NEG_INFINITY,
    f32::NEG_INFINITY,
    f32::NEG_INFINITY,
    f32::INFINITY,
];

#[inline(always)]
fn merge(into: &mut Span, o: &Span) {
    for k in 0..6 {
        into[k] = into[k].min(o[k]);
        into[6 + k] = into[6 + k].max(o[6 + k]);
    }
    into[12] = into[12].min(o[12]);
}

/// `g^2` of a window (see the module docs), in f64; infinite for a window with no triangle.
#[inline(always)]
fn spread_left(s: &Span) -> f64 {
    if s[12] == f32::INFINITY {
        return f64::INFINITY;
    }
    let e2: f64 = (0..6)
        .map(|k| {
            let d = f64::from(s[6 + k]) - f64::from(s[k]);
            d * d
        })
        .sum();
    f64::from(s[12]) - 0.25 * e2
}

/// An f32 not above `v` (finite): `v` lowered by more than half an f32 step before the
/// rounding cast, which moves it by at most that (a relative 2^-24; the 1e-30 covers
/// numbers near zero).
#[inline(always)]
fn down(v: f64) -> f32 {
    (v - v.abs() * (1.0 / 8_388_608.0) - 1e-30) as f32
}

/// An f32 not below `v` (finite).
#[inline(always)]
fn up(v: f64) -> f32 {
    (v + v.abs() * (1.0 / 8_388_608.0) + 1e-30) as f32
}

/// Relative tolerance of the rest shape's flatness, convexity and areas.
const TOLERANCE: f64 = 1e-9;
/// The margin a band's bound must clear the reach by (relative, squared distances).
const MARGIN: f64 = 1e-9;

/// One level's grid of cells: `real` cells a side hold triangles, padded with empty ones to at
/// least 4 (a window of 4 always fits).
#[derive(Clone, Debug, Default)]
struct Level {
    real: [usize; 2],
    padded: [usize; 2],
    cells: Vec<Span>,
}

impl Level {
    fn sized(real: [usize; 2]) -> Level {
        let padded = [real[0].max(4), real[1].max(4)];
        Level {
            real,
            padded,
            cells: Vec::new(),
        }
    }
}

/// The flat convex rest sheet's numbers, worked out once.
#[derive(Clone, Debug, Default)]
struct Sheet {
    /// The rest plane: a point of it and two unit vectors along it.
    origin: Vec3,
    axes: [Vec3; 2],
    /// Each triangle's inverse rest edge matrix in the rest plane, row-major.
    inverse: Vec<[f64; 4]>,
    /// Each triangle's cells at the finest level: first and last column, first and last row.
    cells: Vec<[u32; 4]>,
    /// The finest cells' side, m.
    side: f64,
    levels: Vec<Level>,
}

/// The certificate's rest numbers and working lists; `None` inside when the rest shape is not
/// a flat convex sheet (see the module docs).
#[derive(Clone, Debug, Default)]
pub(super) struct Unfolded {
    sheet: Option<Sheet>,
    /// The least rest distance of the pairs self-collision tests (`neighbours::nearest_tested`;
    /// 0 before it is told): the proof starts there, not at the exclusion under it.
    first: f64,
    /// Windows of the level being worked on: the last size's and the next's.
    windows: [Vec<Span>; 2],
}

impl Unfolded {
    /// The certificate for rest positions `rest` and `triangles`: none (every look in full)
    /// when the rest shape is not a flat convex sheet, or when its lists cannot be allocated.
    pub(super) fn new(rest: &[Vec3], triangles: &[[u32; 3]]) -> Unfolded {
        let sheet = Sheet::of(rest, triangles);
        let mut windows = [Vec::new(), Vec::new()];
        if let Some(s) = &sheet {
            let most = s.levels.first().map_or(0, |l| l.padded[0] * l.padded[1]);
            if windows.iter_mut().any(|w| w.try_reserve_exact(most).is_err()) {
                return Unfolded::default();
            }
        }
        Unfolded {
            sheet,
            windows,
            first: 0.0,
        }
    }

    /// Whether the rest shape qualified.
    pub(super) fn applies(&self) -> bool {
        self.sheet.is_some()
    }

    /// Tells the proof that no pair self-collision tests is nearer than `first` at rest, and
    /// cuts its cells again, at least `min_side` a side (no larger a count than before: the
    /// working lists keep their room). No proof when the cells cannot be allocated.
    pub(super) fn set_first(&mut self, first: f64, min_side: f64, rest: &[Vec3], triangles: &[[u32; 3]]) {
        self.first = first;
        if let Some(sheet) = &mut self.sheet {
            if min_side > sheet.side && sheet.celled(rest, triangles, min_side).is_none() {
                self.sheet = None;
            }
        }
    }

    /// The rest distance below which every pair of points at least `excluded` apart at rest
    /// (and at least the distance [`Unfolded::set_first`] gave) is surely at least `reach`
    /// apart at positions `x`: `excluded` when nothing is proved, infinite when every such
    /// pair is.
    pub(super) fn certified_below(
        &mut self,
        x: &[Vec3],
        triangles: &[[u32; 3]],
        reach: f64,
        excluded: f64,
    ) -> f64 {
        self.certified_with(triangles, reach, excluded, |t, m| gradient(x, t, m))
    }

    /// Whether every pair of points at least `excluded` apart at rest (and at least the
    /// distance [`Unfolded::set_first`] gave) is surely at least `reach` apart at every instant
    /// of a step that moves each point on a straight line from `x0` to `x1` (module docs, "A
    /// step"): then no such pair can meet within it, however long it is.
    pub(super) fn out_of_reach_throughout(
        &mut self,
        x0: &[Vec3],
        x1: &[Vec3],
        triangles: &[[u32; 3]],
        reach: f64,
        excluded: f64,
    ) -> bool {
        self.sheet.is_some()
            && self.certified_with(triangles, reach, excluded, |t, m| swept_gradient(x0, x1, t, m))
                == f64::INFINITY
    }

    /// [`Unfolded::certified_below`] with each triangle's summary given by `span`.
    fn certified_with(
        &mut self,
        triangles: &[[u32; 3]],
        reach: f64,
        excluded: f64,
        span: impl Fn(&[u32; 3], &[f64; 4]) -> Option<Span>,
    ) -> f64 {
        let Some(sheet) = &mut self.sheet else {
            return excluded;
        };
        if sheet.inverse.len() != triangles.len() || reach.is_nan() || reach <= 0.0 {
            return excluded;
        }
        // The finest cells.
        let level0 = &mut sheet.levels[0];
        level0.cells.clear();
        level0.cells.resize(level0.padded[0] * level0.padded[1], EMPTY);
        let stride = level0.padded[0];
        for ((t, m), c) in triangles.iter().zip(&sheet.inverse).zip(&sheet.cells) {
            let Some(span) = span(t, m) else {
                return excluded;
            };
            for row in c[2]..=c[3] {
                for col in c[0]..=c[1] {
                    merge(&mut level0.cells[row as usize * stride + col as usize], &span);
                }
            }
        }
        let reach2 = reach * reach * (1.0 + MARGIN);
        // The whole sheet's summary bounds every window's: from the distance where it proves
        // a band, it proves every band after.
        let whole = spread_left(&level0.cells.iter().fold(EMPTY, |mut s, c| {
            merge(&mut s, c);
            s
        }));
        let all_from = if whole > 0.0 {
            (reach2 / whole).sqrt()
        } else {
            f64::INFINITY
        };
        // No pair tested is nearer at rest than `first`: the bands start there.
        let start = excluded.max(self.first);
        let mut below = start;
        let mut side = sheet.side;
        for l in 0..sheet.levels.len() {
            if below >= all_from {
                return f64::INFINITY;
            }
            if l > 0 {
                let (finer, coarser) = sheet.levels.split_at_mut(l);
                coarsen(&finer[l - 1], &mut coarser[0]);
            }
            let level = &sheet.levels[l];
            let [w0, w1] = &mut self.windows;
            // Windows of 2 (the finest level's band only), 3 and 4 cells, each from the last
            // (2 from the cells).
            for k in 2..=4usize {
                let upto = band_end(k, side);
                let band = !(k == 2 && l > 0) && upto > below;
                if band && below >= all_from {
                    return f64::INFINITY;
                }
                let (dims, out) = if k == 2 {
                    windows_of(&level.cells, level.padded, &level.cells, level.padded, 2, w0)
                } else if k == 3 {
                    windows_of(&level.cells, level.padded, w0, dims_of(level.padded, 2), 3, w1)
                } else {
                    windows_of(&level.cells, level.padded, w1, dims_of(level.padded, 3), 4, w0)
                };
                debug_assert_eq!(dims, dims_of(level.padded, k));
                if !band {
                    continue;
                }
                let g2 = out.iter().map(spread_left).fold(f64::INFINITY, f64::min);
                if !(g2 > 0.0 && below * below * g2 >= reach2) {
                    // Nothing proved past what the rest shape says.
                    return if below == start { excluded } else { below };
                }
                below = upto;
            }
            if level.real[0] <= 4 && level.real[1] <= 4 {
                // The windows of 4 held the whole sheet.
                return f64::INFINITY;
            }
            side *= 2.0;
        }
        below
    }
}

/// The rest distance below which every segment lies in some window of `k` cells of side
/// `side`: a segment of length `d` meets at most `floor(d / side) + 2` cells along an axis.
fn band_end(k: usize, side: f64) -> f64 {
    (k - 1) as f64 * side
}

/// Dimensions of the windows of `k` cells over a grid of `padded` cells.
fn dims_of(padded: [usize; 2], k: usize) -> [usize; 2] {
    [padded[0] + 1 - k, padded[1] + 1 - k]
}

/// The windows of `k` cells of `cells` (a grid of `padded`), from those of `k - 1` (`prev`, of
/// `prev_dims`: the cells themselves for `k = 2`), into `out`: each is the last size's window
/// at its corner and the one diagonally next to it, with the two corner cells neither covers.
fn windows_of<'a>(
    cells: &[Span],
    padded: [usize; 2],
    prev: &[Span],
    prev_dims: [usize; 2],
    k: usize,
    out: &'a mut Vec<Span>,
) -> ([usize; 2], &'a [Span]) {
    let dims = dims_of(padded, k);
    out.clear();
    for j in 0..dims[1] {
        for i in 0..dims[0] {
            let mut s = prev[j * prev_dims[0] + i];
            merge(&mut s, &prev[(j + 1) * prev_dims[0] + i + 1]);
            merge(&mut s, &cells[j * padded[0] + i + k - 1]);
            merge(&mut s, &cells[(j + k - 1) * padded[0] + i]);
            out.push(s);
        }
    }
    (dims, out)
}

/// The next level's cells, each the merge of the four below it.
fn coarsen(finer: &Level, coarser: &mut Level) {
    coarser.cells.clear();
    coarser.cells.resize(coarser.padded[0] * coarser.padded[1], EMPTY);
    for j in 0..coarser.real[1] {
        for i in 0..coarser.real[0] {
            let out = &mut coarser.cells[j * coarser.padded[0] + i];
            for (dj, di) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                let (fi, fj) = (2 * i + di, 2 * j + dj);
                if fi < finer.real[0] && fj < finer.real[1] {
                    merge(out, &finer.cells[fj * finer.padded[0] + fi]);
                }
            }
        }
    }
}

/// Triangle `t`'s deformation gradient at `x` as a one-triangle summary; `None` when it is
/// not finite.
#[inline]
fn gradient(x: &[Vec3], t: &[u32; 3], m: &[f64; 4]) -> Option<Span> {
    let (a, b, s2) = columns(x, t, m)?;
    let all = [a.x, a.y, a.z, b.x, b.y, b.z, s2];
    if !all.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut span = EMPTY;
    for k in 0..6 {
        span[k] = down(all[k]);
        span[6 + k] = up(all[k]);
    }
    span[12] = down(s2);
    Some(span)
}

/// A triangle's deformation gradient's columns `a`, `b` at `x` (`m` its inverse rest edge
/// matrix) and a bound under its least squared singular value.
#[inline(always)]
fn columns(x: &[Vec3], t: &[u32; 3], m: &[f64; 4]) -> Option<(Vec3, Vec3, f64)> {
    let x0 = x.get(t[0] as usize)?;
    let d1 = x.get(t[1] as usize)? - x0;
    let d2 = x.get(t[2] as usize)? - x0;
    let a = d1 * m[0] + d2 * m[2];
    let b = d1 * m[1] + d2 * m[3];
    let (aa, bb, ab) = (a.dot(&a), b.dot(&b), a.dot(&b));
    let s2 = 0.5 * ((aa + bb) - ((aa - bb) * (aa - bb) + 4.0 * ab * ab).sqrt());
    // Rounding of the root's argument: a relative 1e-12 of the trace taken off.
    Some((a, b, s2 - 1e-12 * (aa + bb)))
}

/// A triangle's summary over a step from `x0` to `x1` along straight lines: its gradient is
/// `F(t) = (1 - t) F0 + t F1`, whose columns lie in the boxes of both ends' and whose least
/// singular value is at least `max(s0 - t D, s1 - (1 - t) D)` (Weyl; `D` the spectral norm of
/// `F1 - F0`, bounded by its Frobenius norm), so at least `min(s0, s1) - D / 2`.
fn swept_gradient(x0: &[Vec3], x1: &[Vec3], t: &[u32; 3], m: &[f64; 4]) -> Option<Span> {
    let (a0, b0, s0) = columns(x0, t, m)?;
    let (a1, b1, s1) = columns(x1, t, m)?;
    let d = ((a1 - a0).norm_squared() + (b1 - b0).norm_squared()).sqrt();
    let low = s0.max(0.0).sqrt().min(s1.max(0.0).sqrt()) - 0.5 * d;
    // No bound left (an inverted or collapsed instant may lie within): a negative square,
    // which fails any window holding the triangle. Rounded down by a relative 1e-12.
    let s2 = if low > 0.0 {
        low * low * (1.0 - 1e-12)
    } else {
        -1.0
    };
    let all = [
        a0.x, a0.y, a0.z, b0.x, b0.y, b0.z, a1.x, a1.y, a1.z, b1.x, b1.y, b1.z, s2,
    ];
    if !all.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut span = EMPTY;
    for k in 0..6 {
        span[k] = down(all[k].min(all[6 + k]));
        span[6 + k] = up(all[k].max(all[6 + k]));
    }
    span[12] = down(s2);
    Some(span)
}

/// The border edges of `triangles` (those in one triangle), or `None` unless each edge is in
/// at most two triangles, in opposite directions (or its list cannot be allocated).
fn border_edges(triangles: &[[u32; 3]]) -> Option<Vec<(u32, u32)>> {
    let mut directed: Vec<(u32, u32, bool)> = Vec::new();
    directed.try_reserve_exact(3 * triangles.len()).ok()?;
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            directed.push((a.min(b), a.max(b), a < b));
        }
    }
    directed.sort_unstable();
    let mut border = Vec::new();
    let mut k = 0;
    while k < directed.len() {
        let mut end = k + 1;
        while end < directed.len() && directed[end].0 == directed[k].0 && directed[end].1 == directed[k].1 {
            end += 1;
        }
        match end - k {
            1 => border.push((directed[k].0, directed[k].1)),
            2 if directed[k].2 != directed[k + 1].2 => {}
            _ => return None,
        }
        k = end;
    }
    Some(border)
}

impl Sheet {
    /// The sheet's numbers, or `None` when the rest shape is not a flat convex sheet or its
    /// lists cannot be allocated.
    fn of(rest: &[Vec3], triangles: &[[u32; 3]]) -> Option<Sheet> {
        if triangles.is_empty() || triangles.iter().flatten().any(|&v| v as usize >= rest.len()) {
            return None;
        }
        // The plane: the triangles' summed area vector (Newell's normal).
        let corner = |t: &[u32; 3], k: usize| rest[t[k] as usize];
        let normal: Vec3 = triangles
            .iter()
            .map(|t| (corner(t, 1) - corner(t, 0)).cross(&(corner(t, 2) - corner(t, 0))))
            .sum();
        let n = normal.try_normalize(0.0)?;
        let first = corner(&triangles[0], 0);
        let extent = triangles
            .iter()
            .flatten()
            .map(|&v| (rest[v as usize] - first).norm())
            .fold(0.0, f64::max);
        if !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let tol = TOLERANCE * extent;
        if triangles
            .iter()
            .flatten()
            .any(|&v| (rest[v as usize] - first).dot(&n).abs() > tol)
        {
            return None;
        }
        let e1 = (corner(&triangles[0], 1) - first - n * (corner(&triangles[0], 1) - first).dot(&n))
            .try_normalize(0.0)?;
        let e2 = n.cross(&e1);
        let flat = |v: u32| {
            let r = rest[v as usize] - first;
            [r.dot(&e1), r.dot(&e2)]
        };
        // Every triangle turning the same way, its inverse edge matrix, its area.
        let mut inverse = Vec::new();
        inverse.try_reserve_exact(triangles.len()).ok()?;
        let mut area = 0.0;
        for t in triangles {
            let [p, q, r] = t.map(flat);
            let (m00, m01, m10, m11) = (q[0] - p[0], r[0] - p[0], q[1] - p[1], r[1] - p[1]);
            let det = m00 * m11 - m01 * m10;
            if det.is_nan() || det <= tol * tol {
                return None;
            }
            area += 0.5 * det;
            inverse.push([m11 / det, -m01 / det, -m10 / det, m00 / det]);
        }
        let border = border_edges(triangles)?;
        // The hull: its area is the triangles', and every border edge lies on its border.
        let mut used = Vec::new();
        used.try_reserve_exact(rest.len()).ok()?;
        used.resize(rest.len(), false);
        triangles.iter().flatten().for_each(|&v| used[v as usize] = true);
        let mut points: Vec<[f64; 2]> = Vec::new();
        points
            .try_reserve_exact(used.iter().filter(|&&u| u).count())
            .ok()?;
        points.extend((0..rest.len() as u32).filter(|&v| used[v as usize]).map(flat));
        let hull = convex_hull(&mut points);
        let hull_area = polygon_area(&hull);
        if hull.len() < 3 || (hull_area - area).abs() > TOLERANCE * hull_area {
            return None;
        }
        let on_border = |p: [f64; 2]| {
            (0..hull.len()).any(|i| segment_distance(p, hull[i], hull[(i + 1) % hull.len()]) <= tol)
        };
        for &(a, b) in &border {
            let (p, q) = (flat(a), flat(b));
            let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
            if !(on_border(p) && on_border(q) && on_border(mid)) {
                return None;
            }
        }
        let mut sheet = Sheet {
            origin: first,
            axes: [e1, e2],
            inverse,
            cells: Vec::new(),
            side: 0.0,
            levels: Vec::new(),
        };
        sheet.celled(rest, triangles, 0.0)?;
        Some(sheet)
    }

    /// The rest plane's coordinates of `p`.
    fn flat(&self, p: &Vec3) -> [f64; 2] {
        let r = p - self.origin;
        [r.dot(&self.axes[0]), r.dot(&self.axes[1])]
    }

    /// Cuts the rest plane into cells at least `min_side` a side (and no smaller than any
    /// triangle's box) and sizes the levels; `None` when the lists cannot be allocated or the
    /// sheet is not worth the cells.
    fn celled(&mut self, rest: &[Vec3], triangles: &[[u32; 3]], min_side: f64) -> Option<()> {
        let flat = |v: u32| self.flat(&rest[v as usize]);
        // Cells no smaller than any triangle's box, over the hull's box.
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut side: f64 = 0.0;
        for t in triangles {
            let c = t.map(flat);
            for axis in 0..2 {
                let (a, b) = (
                    c.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min),
                    c.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max),
                );
                side = side.max(b - a);
                lo[axis] = lo[axis].min(a);
                hi[axis] = hi[axis].max(b);
            }
        }
        let side = side.max(min_side) * (1.0 + 1e-6);
        let real = [0, 1].map(|axis| ((hi[axis] - lo[axis]) / side).floor() as usize + 1);
        // A sheet whose box is mostly empty (a thin diagonal strip) is not worth the cells.
        if real[0].saturating_mul(real[1]) > 2 * triangles.len() + 64 {
            return None;
        }
        let cell_of = |u: f64, axis: usize| {
            let f = (u - lo[axis]) / side;
            f.floor().clamp(0.0, (real[axis] - 1) as f64) as u32
        };
        let mut cells = Vec::new();
        cells.try_reserve_exact(triangles.len()).ok()?;
        let pad = 1e-7 * side;
        for t in triangles {
            let c = t.map(flat);
            let range = |axis: usize| {
                let a = c.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
                let b = c.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
                (cell_of(a - pad, axis), cell_of(b + pad, axis))
            };
            let ((c0, c1), (r0, r1)) = (range(0), range(1));
            cells.push([c0, c1, r0, r1]);
        }
        // The levels, each half the last a side, down to one whose windows of 4 hold it all.
        let mut levels = vec![Level::sized(real)];
        while levels.last().is_some_and(|l| l.real[0] > 4 || l.real[1] > 4) {
            let r = levels.last().map_or([1, 1], |l| l.real);
            levels.push(Level::sized([r[0].div_ceil(2), r[1].div_ceil(2)]));
        }
        for l in &mut levels {
            l.cells.try_reserve_exact(l.padded[0] * l.padded[1]).ok()?;
        }
        self.cells = cells;
        self.side = side;
        self.levels = levels;
        Some(())
    }
}

/// The convex hull of `points` (reordered), counter-clockwise, without points on its edges
/// (Andrew's monotone chain).
fn convex_hull(points: &mut [[f64; 2]]) -> Vec<[f64; 2]> {
    points.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross =
        |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let chain = |ordered: &mut dyn Iterator<Item = &[f64; 2]>| {
        let mut out: Vec<[f64; 2]> = Vec::new();
        for &p in ordered {
            while out.len() >= 2 && cross(out[out.len() - 2], out[out.len() - 1], p) <= 0.0 {
                out.pop();
            }
            out.push(p);
        }
        // Its last point is the other chain's first.
        out.pop();
        out
    };
    let mut hull = chain(&mut points.iter());
    hull.extend(chain(&mut points.iter().rev()));
    hull
}

/// The area of a counter-clockwise polygon.
fn polygon_area(p: &[[f64; 2]]) -> f64 {
    0.5 * (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
}

/// The distance from `p` to the segment from `a` to `b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let s = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p[0] - a[0] - s * dx).powi(2) + (p[1] - a[1] - s * dy).powi(2)).sqrt()
}

#[cfg(test)]
mod tests;
