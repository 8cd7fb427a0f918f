//! One streaming writer for every cache format the library writes, frame by frame.
//!
//! **A cache that failed once is poisoned.** When a frame cannot be written whole (a full
//! disk, a file-size limit), the writer cuts the partial frame off and completes the file with
//! the frames written whole (the header then counts exactly those; an OBJ sequence loses the
//! partial frame's file); if even that fails, it removes the file. Every later
//! [`CacheWriter::write_frame`] and [`CacheWriter::finish`] returns the first error, so a
//! host that keeps going never ends with a success on a corrupt file. Arguments that are
//! refused before anything is written (a wrong vertex count, a frame past an MDD's announced
//! count) do not poison.
//!
//! **A cache dropped without [`CacheWriter::finish`]** (a host that stops on an error and lets
//! it go) is finished on drop: its header counts exactly the frames written whole, or, if that
//! cannot be done, the file is removed. Only `finish` reports errors.

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::{write_obj, MddWriter, Pc2Writer};
use crate::math::Vec3;

/// Largest |start frame| a cache accepts (PC2 stores it as a float, OBJ sequences number
/// their files from it).
pub const MAX_START_FRAME: f64 = 1.0e9;
/// Frame rates a cache accepts, frames per second.
pub const FPS_RANGE: (f64, f64) = (1.0e-3, 1.0e6);

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
    Pc2 {
        writer: Pc2Writer<File>,
        path: PathBuf,
    },
    Mdd {
        writer: MddWriter,
        path: PathBuf,
    },
    Obj {
        stem: PathBuf,
        triangles: Vec<[u32; 3]>,
        next: i64,
    },
    /// Poisoned: the first error's kind and message.
    Failed(io::ErrorKind, String),
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

/// Removes a cache file that cannot be repaired; only a regular file (never a device such as
/// `/dev/full` that a host may write to).
fn discard(path: &Path) {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file()) {
        let _ = std::fs::remove_file(path);
    }
}

fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// Writes one OBJ file whole (flushed), or removes what it wrote.
fn obj_file(path: &Path, positions: &[Vec3], triangles: &[[u32; 3]]) -> io::Result<()> {
    let result = File::create(path).and_then(|f| write_obj(BufWriter::new(f), positions, triangles));
    if result.is_err() {
        discard(path);
    }
    result
}

impl CacheWriter {
    /// Opens `path` for `vertex_count` vertices. `start_frame` is the host frame of the first
    /// sample (|start_frame| <= `MAX_START_FRAME`), `fps` frames per second (within
    /// `FPS_RANGE`), `expected_frames` how many frames will be written (MDD needs it up front,
    /// at most [`super::MAX_MDD_FRAMES`]; the others ignore it). `triangles` are written into
    /// every OBJ.
    pub fn create(
        path: &Path,
        format: CacheFormat,
        vertex_count: usize,
        triangles: &[[u32; 3]],
        start_frame: f64,
        fps: f64,
        expected_frames: u32,
    ) -> io::Result<Self> {
        if !(start_frame.is_finite() && start_frame.abs() <= MAX_START_FRAME) {
            return Err(invalid(format!(
                "start_frame must be finite and within +-{MAX_START_FRAME:e}, got {start_frame}"
            )));
        }
        if !(fps >= FPS_RANGE.0 && fps <= FPS_RANGE.1) {
            return Err(invalid(format!(
                "frames per second must be within [{:e}, {:e}], got {fps}",
                FPS_RANGE.0, FPS_RANGE.1
            )));
        }
        let inner = match format {
            CacheFormat::Pc2 => Inner::Pc2 {
                writer: Pc2Writer::new(File::create(path)?, vertex_count, start_frame as f32, 1.0)?,
                path: path.to_path_buf(),
            },
            CacheFormat::Mdd => Inner::Mdd {
                writer: MddWriter::create(path, vertex_count, expected_frames, fps)?,
                path: path.to_path_buf(),
            },
            CacheFormat::ObjSequence => {
                let mut tris = Vec::new();
                tris.try_reserve_exact(triangles.len())
                    .map_err(|e| io::Error::new(io::ErrorKind::OutOfMemory, e.to_string()))?;
                tris.extend_from_slice(triangles);
                Inner::Obj {
                    stem: path.to_path_buf(),
                    triangles: tris,
                    next: start_frame.round() as i64,
                }
            }
        };
        Ok(Self { inner, vertex_count })
    }

    /// The first error, again, if the cache failed earlier.
    fn poisoned(&self) -> io::Result<()> {
        match &self.inner {
            Inner::Failed(kind, msg) => Err(io::Error::new(
                *kind,
                format!("the cache failed earlier and holds only its complete frames: {msg}"),
            )),
            _ => Ok(()),
        }
    }

    /// Records `e` as the cache's failure, repairs the file as the module docs say, and
    /// returns `e`.
    fn poison(&mut self, e: io::Error) -> io::Error {
        let inner = std::mem::replace(&mut self.inner, Inner::Failed(e.kind(), e.to_string()));
        match inner {
            Inner::Pc2 { writer, path } => {
                let keep = writer.complete_len();
                let count = writer.frames_written();
                let repair = |mut f: File| -> io::Result<()> {
                    f.set_len(keep)?;
                    f.seek(SeekFrom::Start(28))?;
                    f.write_all(&(count as i32).to_le_bytes())?;
                    f.sync_all()
                };
                if writer.finish().and_then(repair).is_err() {
                    discard(&path);
                }
            }
            Inner::Mdd { writer, path } => {
                if writer.finish_truncated().is_err() {
                    discard(&path);
                }
            }
            Inner::Obj { .. } | Inner::Failed(..) => {}
        }
        e
    }

    /// Vertices per frame.
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Appends one frame of positions. After a failure that may have written part of a frame,
    /// the cache is poisoned (module docs).
    pub fn write_frame(&mut self, positions: &[Vec3]) -> io::Result<()> {
        self.poisoned()?;
        if positions.len() != self.vertex_count {
            return Err(invalid(format!(
                "expected {} vertices, got {}",
                self.vertex_count,
                positions.len()
            )));
        }
        let result = match &mut self.inner {
            Inner::Pc2 { writer, .. } => writer.write_frame(positions),
            Inner::Mdd { writer, .. } => writer.write_frame(positions),
            Inner::Obj {
                stem,
                triangles,
                next,
            } => obj_file(&sequence_path(stem, *next), positions, triangles).map(|()| *next += 1),
            Inner::Failed(..) => Ok(()),
        };
        match result {
            Err(e) if e.kind() != io::ErrorKind::InvalidInput => Err(self.poison(e)),
            other => other,
        }
    }

    /// Completes the file (patches counts, flushes to disk) and closes it; a poisoned cache
    /// returns its first error.
    pub fn finish(mut self) -> io::Result<()> {
        self.poisoned()?;
        match std::mem::replace(
            &mut self.inner,
            Inner::Failed(io::ErrorKind::Other, String::new()),
        ) {
            Inner::Pc2 { writer, path } => writer.finish().and_then(|f| f.sync_all()).inspect_err(|_| {
                discard(&path);
            }),
            Inner::Mdd { writer, path } => writer.finish().inspect_err(|_| {
                discard(&path);
            }),
            Inner::Obj { .. } | Inner::Failed(..) => Ok(()),
        }
    }
}

impl Drop for CacheWriter {
    /// Finishes a cache that was not finished (module docs); errors remove the file.
    fn drop(&mut self) {
        match std::mem::replace(
            &mut self.inner,
            Inner::Failed(io::ErrorKind::Other, String::new()),
        ) {
            Inner::Pc2 { writer, path } => {
                if writer.finish().and_then(|f| f.sync_all()).is_err() {
                    discard(&path);
                }
            }
            Inner::Mdd { writer, path } => {
                if writer.finish().is_err() {
                    discard(&path);
                }
            }
            Inner::Obj { .. } | Inner::Failed(..) => {}
        }
    }
}
