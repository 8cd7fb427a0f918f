//! One streaming writer for every cache format the library writes, frame by frame.

use std::fs::File;
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};

use super::{write_obj, MddWriter, Pc2Writer};
use crate::Vec3;

/// Cache file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheFormat {
    /// PC2, little-endian (Blender Mesh Cache, Maya, 3ds Max).
    Pc2,
    /// MDD, big-endian.
    Mdd,
    /// One OBJ per frame: `name.obj` becomes `name_0001.obj`, `name_0002.obj`, ... numbered
    /// from the start frame.
    ObjSequence,
}

enum Inner {
    Pc2(Pc2Writer<BufWriter<File>>),
    Mdd(MddWriter),
    Obj {
        stem: PathBuf,
        triangles: Vec<[u32; 3]>,
        next: i64,
    },
}

/// A cache being written.
pub struct CacheWriter {
    inner: Inner,
    vertex_count: usize,
}

/// `dir/name.obj` and frame 7 -> `dir/name_0007.obj`.
pub fn sequence_path(path: &Path, frame: i64) -> PathBuf {
    let stem = path.with_extension("");
    let mut name = stem.into_os_string();
    name.push(format!("_{frame:04}.obj"));
    PathBuf::from(name)
}

impl CacheWriter {
    /// Opens `path` for `vertex_count` vertices. `start_frame` is the host frame of the first
    /// sample, `fps` frames per second, `expected_frames` how many frames will be written (MDD
    /// needs it up front; the others ignore it). `triangles` are written into every OBJ.
    pub fn create(
        path: &Path,
        format: CacheFormat,
        vertex_count: usize,
        triangles: &[[u32; 3]],
        start_frame: f64,
        fps: f64,
        expected_frames: u32,
    ) -> io::Result<Self> {
        if !(start_frame.is_finite() && fps.is_finite() && fps > 0.0) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("start_frame must be finite and fps > 0, got {start_frame} and {fps}"),
            ));
        }
        let inner = match format {
            CacheFormat::Pc2 => Inner::Pc2(Pc2Writer::new(
                BufWriter::new(File::create(path)?),
                vertex_count,
                start_frame as f32,
                1.0,
            )?),
            CacheFormat::Mdd => Inner::Mdd(MddWriter::create(path, vertex_count, expected_frames, fps)?),
            CacheFormat::ObjSequence => Inner::Obj {
                stem: path.to_path_buf(),
                triangles: triangles.to_vec(),
                next: start_frame.round() as i64,
            },
        };
        Ok(Self { inner, vertex_count })
    }

    /// Appends one frame of positions.
    pub fn write_frame(&mut self, positions: &[Vec3]) -> io::Result<()> {
        if positions.len() != self.vertex_count {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("expected {} vertices, got {}", self.vertex_count, positions.len()),
            ));
        }
        match &mut self.inner {
            Inner::Pc2(w) => w.write_frame(positions),
            Inner::Mdd(w) => w.write_frame(positions),
            Inner::Obj {
                stem,
                triangles,
                next,
            } => {
                let file = BufWriter::new(File::create(sequence_path(stem, *next))?);
                write_obj(file, positions, triangles)?;
                *next += 1;
                Ok(())
            }
        }
    }

    /// Completes the file (patches counts) and closes it.
    pub fn finish(self) -> io::Result<()> {
        match self.inner {
            Inner::Pc2(w) => w.finish().map(drop),
            Inner::Mdd(w) => w.finish(),
            Inner::Obj { .. } => Ok(()),
        }
    }
}
