//! [`Topology`]: the rest geometry and connectivity of a cloth, assembled once from what a
//! constructor (grid, mesh) hands over, with everything the step reads of it laid out.

use super::runs;
use super::{Adjacency, Spring, SpringRun, TileLayout, TileRuns};
use crate::math::Vec3;

/// Rest geometry and connectivity of a cloth.
#[derive(Clone, Debug)]
pub struct Topology {
    /// Rest (initial) positions, metres.
    pub rest_positions: Vec<Vec3>,
    /// Lumped particle masses, kilograms.
    pub masses: Vec<f64>,
    /// Lumped particle areas, m^2: what per-unit-area coefficients multiply, so the motion
    /// does not change with resolution. Each face gives its area over its corner count to every
    /// corner (grids: a quarter of each cell; meshes: as their masses are lumped).
    pub areas: Vec<f64>,
    /// Every spring once (i < j), ordered into [`SpringRun`]s.
    pub springs: Vec<Spring>,
    /// The springs as runs of consecutive vertices (see [`SpringRun`]).
    pub spring_runs: Vec<SpringRun>,
    /// Rest length of each spring (a copy laid out for the spring pass), m.
    pub spring_rest: Vec<f64>,
    /// Family of each spring (`SpringKind as u8`).
    pub spring_kinds: Vec<u8>,
    /// Triangles (counter-clockwise seen from the +normal side), vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// One over the length of each vertex's patch normal at rest: `1 / |N_i|`, `N_i` the sum
    /// of its triangles' normals each twice its area (0 where that sum vanishes). A patch's
    /// area vector relative to its rest area is `N_i(x) * patch_scale[i]`
    /// (`forces::patch_normals`).
    pub patch_scale: Vec<f64>,
    /// Grid size (columns, rows) when the cloth was built from a grid.
    pub grid: Option<(u32, u32)>,
    /// `(columns, rows)` when the triangles are those [`crate::topology::GridSpec`] makes of
    /// such a grid (every cell `(i, j)` split into `[a, c, b]` and `[b, c, d]`, `a = (i, j)`,
    /// `b = (i + 1, j)`, `c = (i, j + 1)`, `d = (i + 1, j + 1)`, cell after cell, row after
    /// row): then a pass may find a vertex's faces from its place in the grid.
    pub(crate) grid_faces: Option<(usize, usize)>,
    /// The cloth's spacing, m: a grid's own; for a mesh the side of a square of two of its
    /// triangles' mean rest area (a grid's spacing for a triangulated grid, jittered or not;
    /// 0 without triangles). What `Model::bend_reference_spacing` compares with.
    pub spacing: f64,
    /// Springs touching each vertex (see [`Adjacency::springs`]).
    pub vertex_springs: Adjacency,
    /// Triangles touching each vertex.
    pub vertex_triangles: Adjacency,
    /// Spring runs touching each chunk of vertices (see [`Adjacency::chunk_runs`]).
    pub chunk_runs: Adjacency,
    /// The runs joined over small gaps, for the tiled force pass (see [`TileRuns`]).
    pub tile_runs: TileRuns,
    /// How the force pass walks this topology: tile by tile (`Some`), or from a per-spring
    /// buffer (`None`); decided here, once.
    pub tiled: Option<TileLayout>,
}

/// `grid` as `(columns, rows)` when the cloth's `n` vertices are its and `triangles` are the
/// ones [`crate::topology::GridSpec`] makes of it ([`Topology::grid_faces`]).
fn grid_faces((w, h): (u32, u32), n: usize, triangles: &[[u32; 3]]) -> Option<(usize, usize)> {
    let (w, h) = (w as usize, h as usize);
    if w < 2 || h < 2 || w.checked_mul(h) != Some(n) || triangles.len() != 2 * (w - 1) * (h - 1) {
        return None;
    }
    let cells = (0..h - 1).flat_map(|j| (0..w - 1).map(move |i| (i, j)));
    let expected = cells.flat_map(|(i, j)| {
        let at = |i: usize, j: usize| (j * w + i) as u32;
        let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
        [[a, c, b], [b, c, d]]
    });
    expected.eq(triangles.iter().copied()).then_some((w, h))
}

impl Topology {
    /// Assembles a topology: orders the springs into runs and builds the per-vertex adjacency.
    /// Every spring must have i < j. Indices must be in range (the
    /// constructors check their input before calling this).
    pub fn new(
        mut rest_positions: Vec<Vec3>,
        masses: Vec<f64>,
        mut springs: Vec<Spring>,
        mut triangles: Vec<[u32; 3]>,
        grid: Option<(u32, u32)>,
    ) -> Self {
        let n = rest_positions.len();
        // The constructors build these by pushes: drop the spare capacity, they live as long
        // as the cloth.
        springs.shrink_to_fit();
        triangles.shrink_to_fit();
        rest_positions.shrink_to_fit();
        let mut spring_runs = runs::order_into_runs(&mut springs);
        spring_runs.shrink_to_fit();
        let mut areas = vec![0.0; n];
        for tri in &triangles {
            let [a, b, c] = tri.map(|i| i as usize);
            let third = (rest_positions[b] - rest_positions[a])
                .cross(&(rest_positions[c] - rest_positions[a]))
                .norm()
                / 6.0;
            for i in [a, b, c] {
                areas[i] += third;
            }
        }
        let mut patch = vec![Vec3::zeros(); n];
        for tri in &triangles {
            let [a, b, c] = tri.map(|i| i as usize);
            let face =
                (rest_positions[b] - rest_positions[a]).cross(&(rest_positions[c] - rest_positions[a]));
            for i in [a, b, c] {
                patch[i] += face;
            }
        }
        let spacing = if triangles.is_empty() {
            0.0
        } else {
            (2.0 * areas.iter().sum::<f64>() / triangles.len() as f64).sqrt()
        };
        let patch_scale = patch
            .iter()
            .map(|p| if p.norm() > 0.0 { 1.0 / p.norm() } else { 0.0 })
            .collect();
        let mut t = Self {
            areas,
            patch_scale,
            spring_rest: springs.iter().map(|s| s.rest).collect(),
            spring_kinds: springs.iter().map(|s| s.kind as u8).collect(),
            vertex_springs: Adjacency::springs(n, &springs),
            chunk_runs: Adjacency::chunk_runs(n, &spring_runs),
            tile_runs: TileRuns::new(n, &springs, &spring_runs, &triangles),
            tiled: None,
            spring_runs,
            vertex_triangles: Adjacency::triangles(n, &triangles),
            rest_positions,
            masses,
            springs,
            grid_faces: grid.and_then(|g| grid_faces(g, n, &triangles)),
            triangles,
            grid,
            spacing,
        };
        t.tiled = TileLayout::of(&t.tile_runs);
        t
    }

    /// Number of particles.
    pub fn vertex_count(&self) -> usize {
        self.rest_positions.len()
    }

    /// The cloth's width: the smaller of its two extents in its own plane at rest, m. The plane
    /// is the rest shape's principal plane (its two largest principal axes), so a cloth modelled
    /// in any orientation gives the same width. What `Water::added_mass_coefficient`
    /// multiplies. 0 for fewer than two particles.
    pub fn width(&self) -> f64 {
        let p = &self.rest_positions;
        if p.len() < 2 {
            return 0.0;
        }
        let centre = p.iter().sum::<Vec3>() / p.len() as f64;
        let covariance = p
            .iter()
            .map(|q| (q - centre) * (q - centre).transpose())
            .sum::<nalgebra::Matrix3<f64>>();
        let eigen = nalgebra::SymmetricEigen::new(covariance);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        let extent = |axis: usize| {
            let e = eigen.eigenvectors.column(order[axis]).into_owned();
            let (lo, hi) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                let s = (q - centre).dot(&e);
                (lo.min(s), hi.max(s))
            });
            hi - lo
        };
        extent(0).min(extent(1))
    }

    /// Whether the springs form runs long enough (8 springs on average) that the force pass
    /// adds them run by run rather than gathering them vertex by vertex.
    pub fn long_runs(&self) -> bool {
        self.springs.len() >= 8 * self.spring_runs.len()
    }
}
