//! Wavefront OBJ of a triangle mesh (the rest mesh, or one frame).

use std::io::{self, Write};

use crate::math::Vec3;

/// Writes `v x y z` lines then 1-based `f a b c` lines, and flushes: a write that fails only
/// when the buffer drains (a full disk) is an error, not a silently short file.
pub fn write_obj<W: Write>(mut out: W, positions: &[Vec3], triangles: &[[u32; 3]]) -> io::Result<()> {
    writeln!(
        out,
        "# fraccloth mesh: {} vertices, {} triangles",
        positions.len(),
        triangles.len()
    )?;
    for p in positions {
        writeln!(out, "v {} {} {}", p.x as f32, p.y as f32, p.z as f32)?;
    }
    for t in triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    out.flush()
}
