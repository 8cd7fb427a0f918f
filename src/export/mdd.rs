//! MDD point cache (LightWave; read by Blender's Mesh Cache modifier, Maya, 3ds Max),
//! big-endian: `i32 frame_count`, `i32 vertex_count`, `f32 times[frame_count]` (seconds),
//! then frame_count x vertex_count x `f32[3]`.
//!
//! The frame times come before the frames, so [`MddWriter`] is told how many frames to
//! expect: it writes the header and times, then streams frames. If fewer frames arrive, the
//! file is compacted in place on finish (header and times rewritten, frames moved down in
//! blocks), so a long bake never sits in memory either way.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::Path;

use crate::math::Vec3;

/// At most this many frames may be announced: the frame times come first, and are written
/// when the file is opened (4 bytes each: 4 MB here).
pub const MAX_MDD_FRAMES: u32 = 1_000_000;

/// Streaming MDD writer to a file.
pub struct MddWriter {
    out: File,
    vertex_count: usize,
    expected: u32,
    written: u32,
    fps: f64,
}

fn too_many(what: &str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, format!("too many {what} for MDD"))
}

/// The header and frame times, in one buffer.
fn header(frames: u32, vertex_count: usize, fps: f64) -> io::Result<Vec<u8>> {
    if frames > MAX_MDD_FRAMES {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("an MDD cache holds at most {MAX_MDD_FRAMES} frames, {frames} were announced"),
        ));
    }
    let frames_i = i32::try_from(frames).map_err(|_| too_many("frames"))?;
    let verts = i32::try_from(vertex_count).map_err(|_| too_many("vertices"))?;
    let mut out = Vec::new();
    out.try_reserve_exact(8 + 4 * frames as usize)
        .map_err(|e| io::Error::new(io::ErrorKind::OutOfMemory, e.to_string()))?;
    out.extend_from_slice(&frames_i.to_be_bytes());
    out.extend_from_slice(&verts.to_be_bytes());
    for k in 0..frames {
        let t = (f64::from(k) / fps) as f32;
        if !t.is_finite() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("frame {k} at {fps} fps has no finite time in seconds"),
            ));
        }
        out.extend_from_slice(&t.to_be_bytes());
    }
    Ok(out)
}

impl MddWriter {
    /// Writes the header for `expected_frames` frames at `fps` frames per second (the time of
    /// frame k is k / fps seconds).
    pub fn create(path: &Path, vertex_count: usize, expected_frames: u32, fps: f64) -> io::Result<Self> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "fps must be > 0"));
        }
        // Read access too: compaction reads frames back.
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)?;
        let head = header(expected_frames, vertex_count, fps)?;
        let mut out = file;
        out.write_all(&head)?;
        Ok(Self {
            out,
            vertex_count,
            expected: expected_frames,
            written: 0,
            fps,
        })
    }

    /// Appends one frame; more frames than announced is an error.
    pub fn write_frame(&mut self, positions: &[Vec3]) -> io::Result<()> {
        if positions.len() != self.vertex_count {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "wrong vertex count"));
        }
        if self.written == self.expected {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("the MDD cache was opened for {} frames", self.expected),
            ));
        }
        self.out.write_all(&super::encode_frame(positions, true)?)?;
        self.written += 1;
        Ok(())
    }

    /// Frames completely written so far.
    pub fn frames_written(&self) -> u32 {
        self.written
    }

    /// After a failed write: cuts a partial frame off the end, then completes the file with
    /// the frames that were written whole (as [`MddWriter::finish`] does).
    pub fn finish_truncated(self) -> io::Result<()> {
        let end = 8 + 4 * u64::from(self.expected) + 12 * self.vertex_count as u64 * u64::from(self.written);
        self.out.set_len(end)?;
        self.finish()
    }

    /// Flushes; if fewer frames than announced were written, compacts the file so its header
    /// tells the truth.
    pub fn finish(self) -> io::Result<()> {
        let mut file = self.out;
        if self.written < self.expected {
            let frame_bytes = 12 * self.vertex_count as u64;
            let old_start = 8 + 4 * u64::from(self.expected);
            let new_start = 8 + 4 * u64::from(self.written);
            let total = frame_bytes * u64::from(self.written);
            let mut block = vec![0u8; 1 << 20];
            let mut moved = 0u64;
            while moved < total {
                let n = (total - moved).min(block.len() as u64) as usize;
                file.seek(SeekFrom::Start(old_start + moved))?;
                file.read_exact(&mut block[..n])?;
                file.seek(SeekFrom::Start(new_start + moved))?;
                file.write_all(&block[..n])?;
                moved += n as u64;
            }
            file.seek(SeekFrom::Start(0))?;
            file.write_all(&header(self.written, self.vertex_count, self.fps)?)?;
            file.set_len(new_start + total)?;
        }
        file.flush()?;
        file.sync_all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(path: &std::path::Path) -> Vec<u8> {
        std::fs::read(path).unwrap()
    }

    #[test]
    fn layout_and_compaction() {
        let dir = std::env::temp_dir().join(format!("fc_mdd_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let frames = [
            [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 0.25)],
            [Vec3::zeros(), Vec3::new(4.0, 5.0, 6.0)],
        ];
        for expected in [2u32, 5] {
            let path = dir.join(format!("t{expected}.mdd"));
            let mut w = MddWriter::create(&path, 2, expected, 24.0).unwrap();
            for f in &frames {
                w.write_frame(f).unwrap();
            }
            if expected == 2 {
                assert!(w.write_frame(&frames[0]).is_err());
            }
            w.finish().unwrap();
            let b = read(&path);
            let i32_at = |o: usize| i32::from_be_bytes(b[o..o + 4].try_into().unwrap());
            let f32_at = |o: usize| f32::from_be_bytes(b[o..o + 4].try_into().unwrap());
            assert_eq!((i32_at(0), i32_at(4)), (2, 2));
            assert_eq!((f32_at(8), f32_at(12)), (0.0, 1.0 / 24.0));
            assert_eq!(b.len(), 8 + 2 * 4 + 2 * 2 * 12);
            assert_eq!(f32_at(16 + 4), 2.0);
            assert_eq!(f32_at(16 + 24 + 12 + 8), 6.0);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
