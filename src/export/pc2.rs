//! PC2 point cache (Blender Mesh Cache, Maya, 3ds Max), little-endian:
//! `char[12] "POINTCACHE2\0"`, `i32 version = 1`, `i32 vertex_count`,
//! `f32 start_frame`, `f32 sample_rate`, `i32 sample_count`, then
//! sample_count x vertex_count x `f32[3]`.
//!
//! [`Pc2Writer`] streams frame by frame and patches the sample count on finish,
//! so a long bake never sits in memory.

use std::io::{self, Seek, SeekFrom, Write};

use crate::math::Vec3;

/// Streaming PC2 writer.
pub struct Pc2Writer<W: Write + Seek> {
    out: W,
    vertex_count: usize,
    samples: u32,
}

const SAMPLE_COUNT_OFFSET: u64 = 12 + 4 + 4 + 4 + 4;

impl<W: Write + Seek> Pc2Writer<W> {
    /// Writes the header. `sample_rate` is in frames per sample (1 for one sample a frame).
    pub fn new(mut out: W, vertex_count: usize, start_frame: f32, sample_rate: f32) -> io::Result<Self> {
        let count = i32::try_from(vertex_count)
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "too many vertices for PC2"))?;
        out.write_all(b"POINTCACHE2\0")?;
        out.write_all(&1i32.to_le_bytes())?;
        out.write_all(&count.to_le_bytes())?;
        out.write_all(&start_frame.to_le_bytes())?;
        out.write_all(&sample_rate.to_le_bytes())?;
        out.write_all(&0i32.to_le_bytes())?;
        Ok(Self {
            out,
            vertex_count,
            samples: 0,
        })
    }

    /// Appends one frame.
    pub fn write_frame(&mut self, positions: &[Vec3]) -> io::Result<()> {
        if positions.len() != self.vertex_count {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "wrong vertex count"));
        }
        self.out.write_all(&super::encode_frame(positions, false)?)?;
        self.samples += 1;
        Ok(())
    }

    /// Frames completely written so far.
    pub fn frames_written(&self) -> u32 {
        self.samples
    }

    /// Bytes of the header and of the frames completely written so far.
    pub fn complete_len(&self) -> u64 {
        SAMPLE_COUNT_OFFSET + 4 + 12 * self.vertex_count as u64 * u64::from(self.samples)
    }

    /// Patches the sample count and returns the writer.
    pub fn finish(mut self) -> io::Result<W> {
        let end = self.out.stream_position()?;
        self.out.seek(SeekFrom::Start(SAMPLE_COUNT_OFFSET))?;
        self.out.write_all(&(self.samples as i32).to_le_bytes())?;
        self.out.seek(SeekFrom::Start(end))?;
        self.out.flush()?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn layout_round_trips() {
        let mut w = Pc2Writer::new(Cursor::new(Vec::new()), 2, 1.0, 1.0).unwrap();
        w.write_frame(&[Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 0.25)])
            .unwrap();
        w.write_frame(&[Vec3::zeros(), Vec3::new(4.0, 5.0, 6.0)]).unwrap();
        let bytes = w.finish().unwrap().into_inner();
        assert_eq!(&bytes[..12], b"POINTCACHE2\0");
        let i32_at = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        assert_eq!(i32_at(12), 1);
        assert_eq!(i32_at(16), 2);
        assert_eq!(f32_at(20), 1.0);
        assert_eq!(i32_at(28), 2);
        assert_eq!(bytes.len(), 32 + 2 * 2 * 12);
        assert_eq!(f32_at(32 + 12 + 4), 0.5);
        assert_eq!(f32_at(32 + 24 + 12 + 8), 6.0);
    }
}
