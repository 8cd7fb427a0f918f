//! Reading point caches and meshes back: PC2, MDD and OBJ (the layouts in DESIGN.md
//! section 6), for the look meter and for tests. Every count in a header is checked against
//! the file's length before anything is allocated, so a damaged or hostile file gives an
//! error, never a huge allocation.

use std::io;
use std::path::Path;

use fraccloth::math::Vec3;

/// Frames read from a point cache.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CacheFrames {
    pub vertex_count: usize,
    /// `frames[k][i]`: vertex i at frame k.
    pub frames: Vec<Vec<Vec3>>,
    /// Time of each frame in seconds (MDD), or `None` (PC2 stores frame numbers).
    pub times: Option<Vec<f64>>,
    /// PC2: the first frame's number and the frames per sample.
    pub start_frame: f64,
    pub sample_rate: f64,
}

fn bad(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, msg)
}

fn frames_from(data: &[u8], frames: usize, verts: usize, big: bool) -> Vec<Vec<Vec3>> {
    let f = |b: &[u8]| {
        let a = [b[0], b[1], b[2], b[3]];
        f64::from(if big {
            f32::from_be_bytes(a)
        } else {
            f32::from_le_bytes(a)
        })
    };
    (0..frames)
        .map(|k| {
            (0..verts)
                .map(|i| {
                    let o = 12 * (k * verts + i);
                    Vec3::new(f(&data[o..]), f(&data[o + 4..]), f(&data[o + 8..]))
                })
                .collect()
        })
        .collect()
}

/// Parses a PC2 file's bytes.
pub fn parse_pc2(data: &[u8]) -> io::Result<CacheFrames> {
    if data.len() < 32 || &data[..12] != b"POINTCACHE2\0" {
        return Err(bad("not a PC2 file (no POINTCACHE2 header)".into()));
    }
    let i32_at = |o: usize| i32::from_le_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]);
    let f32_at = |o: usize| f32::from_le_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]);
    let verts = usize::try_from(i32_at(16)).map_err(|_| bad("PC2: negative vertex count".into()))?;
    let samples = usize::try_from(i32_at(28)).map_err(|_| bad("PC2: negative sample count".into()))?;
    let need = samples
        .checked_mul(verts)
        .and_then(|v| v.checked_mul(12))
        .and_then(|v| v.checked_add(32))
        .ok_or_else(|| bad("PC2: header counts overflow".into()))?;
    if data.len() != need {
        return Err(bad(format!(
            "PC2: header says {samples} samples of {verts} vertices ({need} bytes), the file has {}",
            data.len()
        )));
    }
    Ok(CacheFrames {
        vertex_count: verts,
        frames: frames_from(&data[32..], samples, verts, false),
        times: None,
        start_frame: f64::from(f32_at(20)),
        sample_rate: f64::from(f32_at(24)),
    })
}

/// Parses an MDD file's bytes.
pub fn parse_mdd(data: &[u8]) -> io::Result<CacheFrames> {
    if data.len() < 8 {
        return Err(bad("not an MDD file (shorter than its header)".into()));
    }
    let i32_at = |o: usize| i32::from_be_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]);
    let frames = usize::try_from(i32_at(0)).map_err(|_| bad("MDD: negative frame count".into()))?;
    let verts = usize::try_from(i32_at(4)).map_err(|_| bad("MDD: negative vertex count".into()))?;
    let need = frames
        .checked_mul(verts)
        .and_then(|v| v.checked_mul(12))
        .and_then(|v| v.checked_add(8 + 4 * frames))
        .ok_or_else(|| bad("MDD: header counts overflow".into()))?;
    if data.len() != need {
        return Err(bad(format!(
            "MDD: header says {frames} frames of {verts} vertices ({need} bytes), the file has {}",
            data.len()
        )));
    }
    let times = (0..frames)
        .map(|k| {
            let o = 8 + 4 * k;
            f64::from(f32::from_be_bytes([
                data[o],
                data[o + 1],
                data[o + 2],
                data[o + 3],
            ]))
        })
        .collect();
    Ok(CacheFrames {
        vertex_count: verts,
        frames: frames_from(&data[8 + 4 * frames..], frames, verts, true),
        times: Some(times),
        start_frame: 0.0,
        sample_rate: 1.0,
    })
}

/// Reads a PC2 (`.pc2`) or MDD (`.mdd`) file, chosen by its extension.
pub fn read_cache(path: &Path) -> io::Result<CacheFrames> {
    let data = std::fs::read(path)?;
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("pc2") => parse_pc2(&data),
        Some("mdd") => parse_mdd(&data),
        _ => Err(bad(format!("{}: not a .pc2 or .mdd file", path.display()))),
    }
}

/// A mesh read from OBJ: vertex positions and faces split into triangles (fans); the faces
/// as written; and the named groups (`g` and `o` lines) with the faces each holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Every face's vertex indices (0-based), in the file's order.
    pub faces: Vec<Vec<u32>>,
    /// (name, face indices) of every `g` or `o` name, in the order first seen; a face belongs
    /// to every name of the `g` line (and the `o`) before it.
    pub groups: Vec<(String, Vec<u32>)>,
}

impl ObjMesh {
    /// The vertices of the faces of group `name` (sorted, each once), or None without it.
    pub fn group_vertices(&self, name: &str) -> Option<Vec<u32>> {
        let (_, faces) = self.groups.iter().find(|(g, _)| g == name)?;
        let mut v: Vec<u32> = faces
            .iter()
            .flat_map(|&f| self.faces[f as usize].iter().copied())
            .collect();
        v.sort_unstable();
        v.dedup();
        Some(v)
    }
}

/// Parses OBJ text: `v` lines and `f` lines (1-based or negative indices, `a/b/c` forms
/// accepted; texture and normal indices ignored); other lines are skipped.
pub fn parse_obj(text: &str) -> io::Result<ObjMesh> {
    let mut mesh = ObjMesh::default();
    // The names faces now belong to (indices into `mesh.groups`): the `o` name, the `g` names.
    let (mut object, mut current): (Option<usize>, Vec<usize>) = (None, Vec::new());
    let group = |groups: &mut Vec<(String, Vec<u32>)>, name: &str| -> usize {
        match groups.iter().position(|(g, _)| g == name) {
            Some(k) => k,
            None => {
                groups.push((name.to_string(), Vec::new()));
                groups.len() - 1
            }
        }
    };
    for (n, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("o") => {
                let name: Vec<&str> = it.collect();
                object = (!name.is_empty()).then(|| group(&mut mesh.groups, &name.join(" ")));
            }
            Some("g") => {
                current = it.map(|name| group(&mut mesh.groups, name)).collect();
            }
            Some("v") => {
                let c: Vec<f64> = it
                    .take(3)
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .map_err(|e| bad(format!("OBJ line {}: {e}", n + 1)))?;
                if c.len() != 3 {
                    return Err(bad(format!("OBJ line {}: a vertex needs 3 coordinates", n + 1)));
                }
                mesh.positions.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let count = mesh.positions.len() as i64;
                let idx: Vec<u32> = it
                    .map(|tok| {
                        let v: i64 = tok
                            .split('/')
                            .next()
                            .unwrap_or("")
                            .parse()
                            .map_err(|e| bad(format!("OBJ line {}: {e}", n + 1)))?;
                        let i = if v < 0 { count + v } else { v - 1 };
                        u32::try_from(i)
                            .ok()
                            .filter(|&i| i64::from(i) < count)
                            .ok_or_else(|| bad(format!("OBJ line {}: vertex {v} does not exist", n + 1)))
                    })
                    .collect::<Result<_, _>>()?;
                if idx.len() < 3 {
                    return Err(bad(format!("OBJ line {}: a face needs 3 vertices", n + 1)));
                }
                for k in 1..idx.len() - 1 {
                    mesh.triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
                let face = mesh.faces.len() as u32;
                for &g in object.iter().chain(&current) {
                    mesh.groups[g].1.push(face);
                }
                mesh.faces.push(idx);
            }
            _ => {}
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod group_tests {
    use super::*;

    /// `g` and `o` names collect their faces; quads stay quads in `faces`.
    #[test]
    fn groups_and_faces_are_read() {
        let text = "o towel\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\ng hem top\nf 1 2 3 4\ng\nf 2 5 6 3\n";
        let m = parse_obj(text).unwrap();
        assert_eq!(m.faces, vec![vec![0, 1, 2, 3], vec![1, 4, 5, 2]]);
        assert_eq!(m.triangles.len(), 4);
        assert_eq!(m.group_vertices("hem"), Some(vec![0, 1, 2, 3]));
        assert_eq!(m.group_vertices("top"), Some(vec![0, 1, 2, 3]));
        assert_eq!(m.group_vertices("towel"), Some(vec![0, 1, 2, 3, 4, 5]));
        assert_eq!(m.group_vertices("none"), None);
    }
}

/// Reads an OBJ file.
pub fn read_obj(path: &Path) -> io::Result<ObjMesh> {
    parse_obj(&std::fs::read_to_string(path)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fraccloth::export::{write_obj, MddWriter, Pc2Writer};

    #[test]
    fn caches_and_meshes_read_back_what_was_written() {
        let frames: Vec<Vec<Vec3>> = (0..3)
            .map(|k| {
                (0..4)
                    .map(|i| Vec3::new(i as f64, k as f64 * 0.5, -1.25))
                    .collect()
            })
            .collect();
        let mut pc2 = io::Cursor::new(Vec::new());
        let mut w = Pc2Writer::new(&mut pc2, 4, 1.0, 1.0).unwrap();
        for f in &frames {
            w.write_frame(f).unwrap();
        }
        w.finish().unwrap();
        let back = parse_pc2(pc2.get_ref()).unwrap();
        assert_eq!(back.frames, frames);
        assert_eq!(back.start_frame, 1.0);
        // Truncated: refused with the counts named.
        let e = parse_pc2(&pc2.get_ref()[..40]).unwrap_err();
        assert!(e.to_string().contains("3 samples of 4 vertices"), "{e}");

        let dir = std::env::temp_dir().join(format!("fc-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.mdd");
        let mut w = MddWriter::create(&p, 4, 3, 24.0).unwrap();
        for f in &frames {
            w.write_frame(f).unwrap();
        }
        w.finish().unwrap();
        let back = read_cache(&p).unwrap();
        assert_eq!(back.frames, frames);
        assert_eq!(
            back.times.unwrap(),
            vec![0.0, f64::from(1.0f32 / 24.0), f64::from(2.0f32 / 24.0)]
        );
        std::fs::remove_dir_all(&dir).ok();

        let mut obj = vec![];
        write_obj(&mut obj, &frames[0], &[[0, 1, 2], [1, 3, 2]]).unwrap();
        let mesh = parse_obj(std::str::from_utf8(&obj).unwrap()).unwrap();
        assert_eq!(mesh.positions, frames[0]);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        let quads = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 -1/4\n").unwrap();
        assert_eq!(quads.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(parse_obj("v 0 0 0\nf 1 2 3\n").is_err());
    }
}
