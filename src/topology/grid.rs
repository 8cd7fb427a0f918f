//! Quad grid of W x H particles with the Choi & Ko spring layout (paper, section 4).
//!
//! Vertex (column `i`, row `j`) has index `j * width + i`; row 0 is the top edge.
//! The cloth hangs in the x-y plane at rest: x grows with the column, y falls with
//! the row (y is up), the grid is centred on x = 0 with its top edge at y = 0.

use super::{Spring, SpringKind, Topology};
use crate::{Error, Vec3};

/// Grid index of column `i`, row `j`.
pub fn grid_index(width: u32, i: u32, j: u32) -> u32 {
    j * width + i
}

/// What a grid cloth is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    /// Columns (>= 2).
    pub width: u32,
    /// Rows (>= 2).
    pub height: u32,
    /// Distance between neighbouring particles, metres (> 0).
    pub spacing: f64,
    /// Mass of the whole cloth, kilograms (> 0); spread equally over particles, as in the paper.
    pub total_mass: f64,
}

/// Largest particle count a grid may have (keeps u32 indices and memory sane).
pub const MAX_GRID_VERTICES: u64 = 1 << 24;

impl GridSpec {
    /// Checks the spec and builds the topology.
    pub fn build(&self) -> Result<Topology, Error> {
        let (w, h) = (self.width, self.height);
        if w < 2 || h < 2 {
            return Err(Error::invalid(format!(
                "grid must be at least 2 x 2 particles, got {w} x {h}"
            )));
        }
        if u64::from(w) * u64::from(h) > MAX_GRID_VERTICES {
            return Err(Error::invalid(format!(
                "grid {w} x {h} has more than {MAX_GRID_VERTICES} particles"
            )));
        }
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(Error::invalid(format!(
                "spacing must be finite and > 0, got {}",
                self.spacing
            )));
        }
        if !(self.total_mass.is_finite() && self.total_mass > 0.0) {
            return Err(Error::invalid(format!(
                "total mass must be finite and > 0, got {}",
                self.total_mass
            )));
        }
        let n = (w * h) as usize;
        crate::memory::ensure_available(
            n as u64 * crate::memory::TOPOLOGY_BYTES_PER_PARTICLE,
            &format!("a {w} x {h} grid"),
        )?;
        let s = self.spacing;
        let x0 = -0.5 * s * f64::from(w - 1);
        let mut rest_positions = Vec::with_capacity(n);
        for j in 0..h {
            for i in 0..w {
                rest_positions.push(Vec3::new(x0 + s * f64::from(i), -s * f64::from(j), 0.0));
            }
        }
        let mut springs = Vec::new();
        // Offsets (di, dj) with di, dj >= 0 or di > 0 / dj < 0 so each pair is listed once.
        let families: [(SpringKind, &[(i64, i64)]); 3] = [
            (SpringKind::Stretch, &[(1, 0), (0, 1)]),
            (SpringKind::Shear, &[(1, 1), (1, -1)]),
            (SpringKind::Bend, &[(2, 0), (0, 2), (2, 2), (2, -2)]),
        ];
        for (kind, offsets) in families {
            for j in 0..i64::from(h) {
                for i in 0..i64::from(w) {
                    for &(di, dj) in offsets {
                        let (ni, nj) = (i + di, j + dj);
                        if ni < 0 || nj < 0 || ni >= i64::from(w) || nj >= i64::from(h) {
                            continue;
                        }
                        let a = (j * i64::from(w) + i) as u32;
                        let b = (nj * i64::from(w) + ni) as u32;
                        // The nominal length, the same bits for every spring of a family (the
                        // difference of the rest positions can differ from it by an ulp), so
                        // the force pass can treat a family's rest length as one number.
                        let rest = s * ((di * di + dj * dj) as f64).sqrt();
                        springs.push(Spring {
                            i: a.min(b),
                            j: a.max(b),
                            rest,
                            kind,
                        });
                    }
                }
            }
        }
        let mut triangles = Vec::with_capacity(2 * ((w - 1) * (h - 1)) as usize);
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let a = grid_index(w, i, j);
                let b = grid_index(w, i + 1, j);
                let c = grid_index(w, i, j + 1);
                let d = grid_index(w, i + 1, j + 1);
                // Counter-clockwise seen from +z (x right, y up, rows go down).
                triangles.push([a, c, b]);
                triangles.push([b, c, d]);
            }
        }
        let mut t = Topology::new(
            rest_positions,
            vec![self.total_mass / n as f64; n],
            springs,
            triangles,
            Some((w, h)),
        );
        t.spacing = s;
        // Each cell gives a quarter of its area to each corner: s^2 inside, half on an edge,
        // a quarter at a corner.
        for j in 0..h {
            for i in 0..w {
                let edges = u32::from(i == 0 || i == w - 1) + u32::from(j == 0 || j == h - 1);
                t.areas[(j * w + i) as usize] = s * s / f64::from(1u32 << edges);
            }
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    fn spec(w: u32, h: u32) -> GridSpec {
        GridSpec {
            width: w,
            height: h,
            spacing: 0.1,
            total_mass: 1.0,
        }
    }

    #[test]
    fn spring_counts_match_choi_ko_layout() {
        let (w, h) = (7u32, 5u32);
        let t = spec(w, h).build().unwrap();
        let count = |k| t.springs.iter().filter(|s| s.kind == k).count() as u32;
        assert_eq!(count(SpringKind::Stretch), (w - 1) * h + w * (h - 1));
        assert_eq!(count(SpringKind::Shear), 2 * (w - 1) * (h - 1));
        assert_eq!(
            count(SpringKind::Bend),
            (w - 2) * h + w * (h - 2) + 2 * (w - 2) * (h - 2)
        );
        let unique: HashSet<(u32, u32)> = t.springs.iter().map(|s| (s.i, s.j)).collect();
        assert_eq!(unique.len(), t.springs.len(), "a spring is listed twice");
    }

    #[test]
    fn interior_particle_has_the_sixteen_neighbours_of_the_paper() {
        let (w, h) = (9u32, 9u32);
        let t = spec(w, h).build().unwrap();
        let p = grid_index(w, 4, 4);
        let mut neighbours: Vec<(i64, i64)> = t
            .springs
            .iter()
            .filter_map(|s| {
                let o = if s.i == p {
                    s.j
                } else if s.j == p {
                    s.i
                } else {
                    return None;
                };
                Some((i64::from(o % w) - 4, i64::from(o / w) - 4))
            })
            .collect();
        neighbours.sort();
        let mut expected = vec![];
        for (di, dj) in [(1, 0), (0, 1), (1, 1), (1, -1), (2, 0), (0, 2), (2, 2), (2, -2)] {
            expected.push((di, dj));
            expected.push((-di, -dj));
        }
        expected.sort();
        assert_eq!(neighbours, expected);
    }

    #[test]
    fn rejects_bad_specs() {
        assert!(spec(1, 5).build().is_err());
        assert!(spec(5, 1).build().is_err());
        let mut s = spec(3, 3);
        s.spacing = f64::NAN;
        assert!(s.build().is_err());
        s.spacing = 0.1;
        s.total_mass = -1.0;
        assert!(s.build().is_err());
    }

    #[test]
    fn rest_lengths_and_masses() {
        let t = spec(3, 3).build().unwrap();
        for s in &t.springs {
            let d = (t.rest_positions[s.i as usize] - t.rest_positions[s.j as usize]).norm();
            assert!((d - s.rest).abs() < 1e-15);
        }
        let m: f64 = t.masses.iter().sum();
        assert!((m - 1.0).abs() < 1e-12);
        assert_eq!(t.triangles.len(), 8);
    }
}
