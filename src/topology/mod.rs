//! Cloth topology: particles, springs and triangles, independent of any state.
//!
//! A [`Topology`] is what a constructor (grid today, triangle meshes later) hands to
//! the simulator: rest positions, per-particle masses, the spring list and a
//! triangle list (used for normals and rendering).

mod adjacency;
mod assemble;
mod choice;
mod grid;
mod mesh;
mod runs;
mod spring;
mod tiling;

pub use adjacency::Adjacency;
pub use assemble::Topology;
pub use choice::Choice;
pub use grid::{grid_index, GridSpec};
pub use mesh::{MeshMass, MeshSpec, MAX_MESH_VERTICES};
pub use runs::{for_each_piece, SpringRun, TileRuns, PAD_REST};
pub use spring::{Spring, SpringKind};
pub use tiling::{TileLayout, GATHER_RUNS};
