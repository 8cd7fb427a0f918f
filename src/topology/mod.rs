//! Cloth topology: particles, springs and triangles, independent of any state.
//!
//! A [`Topology`] is what a constructor (grid today, triangle meshes later) hands to
//! the simulator: rest positions, per-particle masses, the spring list and a
//! triangle list (used for normals and rendering).

mod grid;
mod spring;

pub use grid::{grid_index, GridSpec};
pub use spring::{Spring, SpringKind};

use crate::Vec3;

/// Rest geometry and connectivity of a cloth.
#[derive(Clone, Debug)]
pub struct Topology {
    /// Rest (initial) positions, metres.
    pub rest_positions: Vec<Vec3>,
    /// Lumped particle masses, kilograms.
    pub masses: Vec<f64>,
    /// Every spring once (i < j).
    pub springs: Vec<Spring>,
    /// Triangles (counter-clockwise seen from the +normal side), vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Grid size (columns, rows) when the cloth was built from a grid.
    pub grid: Option<(u32, u32)>,
}

impl Topology {
    /// Number of particles.
    pub fn vertex_count(&self) -> usize {
        self.rest_positions.len()
    }
}
