//! Arbitrary triangle or quad meshes to particles and springs.
//!
//! - **stretch** springs on every edge;
//! - **shear** springs on both diagonals of every quad;
//! - **bend** springs across every interior edge: for triangles, between the two vertices
//!   opposite the edge; for quads, at each end p of the shared edge, between p's other
//!   neighbour in one face and p's other neighbour in the other (on a regular quad grid these
//!   are exactly the grid's `(i +- 2, j)` and `(i, j +- 2)` bend springs);
//! - **masses** lumped from areas: each face gives `area / corners` of its area to every
//!   corner, times the areal density (or scaled to a total mass).
//!
//! Rejected, with the offending face or edge named: an index out of range, an index count
//! that is not a multiple of the face size, a face that repeats a vertex or has (near) zero
//! area, an edge shared by more than two faces (non-manifold), a vertex used by no face (it
//! would have no mass), and non-finite positions.

use std::collections::HashMap;

use super::{Spring, SpringKind, Topology};
use crate::error::Error;
use crate::math::Vec3;

/// Largest vertex count a mesh may have (keeps u32 indices and memory sane).
pub const MAX_MESH_VERTICES: usize = 1 << 24;

/// How the particles' masses are set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshMass {
    /// kg per m^2 of surface.
    ArealDensity(f64),
    /// The whole cloth's mass, kg, spread in proportion to the lumped areas.
    Total(f64),
}

/// A mesh to turn into a cloth.
#[derive(Clone, Debug)]
pub struct MeshSpec<'a> {
    /// Rest positions, m.
    pub positions: &'a [Vec3],
    /// Face corner indices, `face_size` per face.
    pub indices: &'a [u32],
    /// 3 (triangles) or 4 (quads, corners in order around the face).
    pub face_size: usize,
    pub mass: MeshMass,
}

/// A face is degenerate when its area is below this fraction of its longest edge squared.
const DEGENERATE_AREA: f64 = 1e-10;

impl MeshSpec<'_> {
    /// Checks the mesh and builds the topology.
    pub fn build(&self) -> Result<Topology, Error> {
        self.check()?;
        let k = self.face_size;
        let faces: Vec<&[u32]> = self.indices.chunks_exact(k).collect();
        let x = self.positions;
        let (area, triangles) = self.lumped_areas(&faces)?;
        if let Some(v) = area.iter().position(|&a| a == 0.0) {
            return Err(Error::invalid(format!(
                "vertex {v} is used by no face (it would have no mass)"
            )));
        }
        let total_area: f64 = area.iter().sum();
        let density = match self.mass {
            MeshMass::ArealDensity(d) => d,
            MeshMass::Total(m) => m / total_area,
        };
        let masses = area.iter().map(|a| a * density).collect();
        let springs = springs_of(x, &faces, k)?;
        let mut t = Topology::new(x.to_vec(), masses, springs, triangles, None);
        // The same lumping as the masses: each face gives area / corners to each corner.
        t.areas = area;
        Ok(t)
    }

    /// The face size, counts, room, finite positions and mass: what is checked before the
    /// faces are read.
    fn check(&self) -> Result<(), Error> {
        let n = self.positions.len();
        let k = self.face_size;
        if k != 3 && k != 4 {
            return Err(Error::invalid(format!(
                "face size must be 3 (triangles) or 4 (quads), got {k}"
            )));
        }
        if !(3..=MAX_MESH_VERTICES).contains(&n) {
            return Err(Error::invalid(format!(
                "a mesh needs 3 to {MAX_MESH_VERTICES} vertices, got {n}"
            )));
        }
        if self.indices.is_empty() || self.indices.len() % k != 0 {
            return Err(Error::invalid(format!(
                "index count {} is not a positive multiple of the face size {k}",
                self.indices.len()
            )));
        }
        crate::memory::ensure_available(
            (n as u64 * crate::memory::TOPOLOGY_BYTES_PER_PARTICLE)
                .saturating_add(self.indices.len() as u64 * 64),
            &format!("a mesh of {n} vertices and {} indices", self.indices.len()),
        )?;
        if let Some(i) = self
            .positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::invalid(format!("position of vertex {i} is not finite")));
        }
        match self.mass {
            MeshMass::ArealDensity(d) | MeshMass::Total(d) if !(d.is_finite() && d > 0.0) => {
                return Err(Error::invalid(format!(
                    "mass (areal density or total) must be finite and > 0, got {d}"
                )))
            }
            _ => {}
        }
        Ok(())
    }

    /// Each vertex's lumped area (each face gives area / corners to each corner) and the
    /// triangles (a quad split along its first diagonal); a face with an index out of range, a
    /// repeated corner or no area is refused.
    fn lumped_areas(&self, faces: &[&[u32]]) -> Result<(Vec<f64>, Vec<[u32; 3]>), Error> {
        let (n, k, x) = (self.positions.len(), self.face_size, self.positions);
        let mut area = vec![0.0; n];
        let mut triangles = Vec::with_capacity(faces.len() * (k - 2));
        for (f, face) in faces.iter().enumerate() {
            if let Some(&bad) = face.iter().find(|&&v| v as usize >= n) {
                return Err(Error::out_of_range(format!(
                    "face {f} {face:?}: index {bad} out of range (mesh has {n} vertices)"
                )));
            }
            for a in 0..k {
                if face[a + 1..].contains(&face[a]) {
                    return Err(Error::invalid(format!(
                        "face {f} {face:?} is degenerate: vertex {} appears twice",
                        face[a]
                    )));
                }
            }
            let tris: &[[usize; 3]] = if k == 3 {
                &[[0, 1, 2]]
            } else {
                &[[0, 1, 2], [0, 2, 3]]
            };
            let mut face_area = 0.0;
            let mut longest2: f64 = 0.0;
            for t in tris {
                let [a, b, c] = t.map(|c| face[c] as usize);
                face_area += 0.5 * (x[b] - x[a]).cross(&(x[c] - x[a])).norm();
                triangles.push(t.map(|c| face[c]));
            }
            for a in 0..k {
                let (p, q) = (face[a] as usize, face[(a + 1) % k] as usize);
                longest2 = longest2.max((x[q] - x[p]).norm_squared());
            }
            // (Written so that a NaN area is degenerate too.)
            if face_area.partial_cmp(&(DEGENERATE_AREA * longest2)) != Some(std::cmp::Ordering::Greater) {
                return Err(Error::invalid(format!(
                    "face {f} {face:?} is degenerate: area {face_area:.3e} m^2 (longest edge {:.3e} m)",
                    longest2.sqrt()
                )));
            }
            for &v in *face {
                area[v as usize] += face_area / k as f64;
            }
        }
        Ok((area, triangles))
    }
}

/// The springs of a manifold mesh of `k`-cornered faces at rest positions `x`: a stretch
/// spring on every edge, a bend spring across every edge two faces share (between the
/// opposite corners of triangles; between each end's other neighbours in quads) and, in
/// quads, shear springs on both diagonals; each spring once.
fn springs_of(x: &[Vec3], faces: &[&[u32]], k: usize) -> Result<Vec<Spring>, Error> {
    // Edges: (min, max) -> the faces using it and, per face, the corner position of the edge.
    let mut edges: HashMap<(u32, u32), Vec<(usize, usize)>> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for a in 0..k {
            let (p, q) = (face[a], face[(a + 1) % k]);
            edges.entry((p.min(q), p.max(q))).or_default().push((f, a));
        }
    }
    let mut edge_list: Vec<_> = edges.into_iter().collect();
    edge_list.sort_unstable_by_key(|(e, _)| *e);
    let mut springs = Vec::new();
    let mut push = |i: u32, j: u32, kind: SpringKind| {
        if i != j {
            let (i, j) = (i.min(j), i.max(j));
            springs.push(Spring {
                i,
                j,
                rest: (x[j as usize] - x[i as usize]).norm(),
                kind,
            });
        }
    };
    for ((p, q), users) in &edge_list {
        if users.len() > 2 {
            let list: Vec<usize> = users.iter().map(|u| u.0).collect();
            return Err(Error::invalid(format!(
                "edge ({p}, {q}) is shared by {} faces {list:?}: the mesh is not manifold",
                users.len()
            )));
        }
        push(*p, *q, SpringKind::Stretch);
        if let [(f, a), (g, b)] = users[..] {
            let (ff, gg) = (faces[f], faces[g]);
            if k == 3 {
                push(ff[(a + 2) % 3], gg[(b + 2) % 3], SpringKind::Bend);
            } else {
                // At each end of the shared edge, the end's other neighbour in each face.
                for end in [*p, *q] {
                    let other = |face: &[u32], c: usize| {
                        // c: corner index of the edge start; the edge is (c, c+1).
                        if face[c] == end {
                            face[(c + 3) % 4]
                        } else {
                            face[(c + 2) % 4]
                        }
                    };
                    push(other(ff, a), other(gg, b), SpringKind::Bend);
                }
            }
        }
    }
    if k == 4 {
        for face in faces {
            push(face[0], face[2], SpringKind::Shear);
            push(face[1], face[3], SpringKind::Shear);
        }
    }
    // A spring listed twice (e.g. a quad diagonal that is also a bend) is kept once.
    springs.sort_by_key(|s| (s.i, s.j, s.kind as u8));
    springs.dedup_by(|a, b| a.i == b.i && a.j == b.j && a.kind == b.kind);
    Ok(springs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::ErrorKind;

    fn quad_grid(w: u32, h: u32) -> (Vec<Vec3>, Vec<u32>) {
        let mut x = vec![];
        for j in 0..h {
            for i in 0..w {
                x.push(Vec3::new(f64::from(i) * 0.1, -f64::from(j) * 0.1, 0.0));
            }
        }
        let mut idx = vec![];
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let a = j * w + i;
                idx.extend([a, a + w, a + w + 1, a + 1]);
            }
        }
        (x, idx)
    }

    /// A mesh's spacing (what `Model::bend_reference_spacing` compares with) is its grid's for
    /// a quad grid, and for a grid of triangles with its vertices moved in the plane.
    #[test]
    fn a_grid_mesh_has_its_grids_spacing() {
        let (x, idx) = quad_grid(7, 5);
        let quads = MeshSpec {
            positions: &x,
            indices: &idx,
            face_size: 4,
            mass: MeshMass::ArealDensity(1.0),
        }
        .build()
        .unwrap();
        assert!((quads.spacing - 0.1).abs() < 1e-12, "{}", quads.spacing);
        // Triangles, every interior vertex moved: the same total area, the same spacing.
        let moved: Vec<Vec3> = x
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let (i, j) = (k % 7, k / 7);
                let inside = i > 0 && i < 6 && j > 0 && j < 4;
                p + if inside {
                    Vec3::new(0.01 * (k % 3) as f64, -0.01 * (k % 2) as f64, 0.0)
                } else {
                    Vec3::zeros()
                }
            })
            .collect();
        let tris: Vec<u32> = idx
            .chunks(4)
            .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
            .collect();
        let t = MeshSpec {
            positions: &moved,
            indices: &tris,
            face_size: 3,
            mass: MeshMass::ArealDensity(1.0),
        }
        .build()
        .unwrap();
        assert!((t.spacing - 0.1).abs() < 1e-12, "{}", t.spacing);
    }

    #[test]
    fn two_triangles_give_five_edges_one_bend_and_lumped_masses() {
        let x = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let t = MeshSpec {
            positions: &x,
            indices: &[0, 1, 2, 2, 1, 3],
            face_size: 3,
            mass: MeshMass::ArealDensity(3.0),
        }
        .build()
        .unwrap();
        let count = |k| t.springs.iter().filter(|s| s.kind == k).count();
        assert_eq!(count(SpringKind::Stretch), 5);
        assert_eq!(count(SpringKind::Bend), 1);
        assert!(t
            .springs
            .iter()
            .any(|s| (s.i, s.j, s.kind) == (0, 3, SpringKind::Bend)));
        // Each triangle has area 1/2: vertices 1 and 2 touch both, 0 and 3 one.
        assert_eq!(t.masses, vec![0.5, 1.0, 1.0, 0.5]);
    }

    #[test]
    fn quad_grid_gets_the_grid_springs_but_the_diagonal_bends() {
        let (w, h) = (5u32, 4u32);
        let (x, idx) = quad_grid(w, h);
        let t = MeshSpec {
            positions: &x,
            indices: &idx,
            face_size: 4,
            mass: MeshMass::Total(1.0),
        }
        .build()
        .unwrap();
        let g = crate::topology::GridSpec {
            width: w,
            height: h,
            spacing: 0.1,
            total_mass: 1.0,
        }
        .build()
        .unwrap();
        let set = |s: &[Spring], skip_diagonal_bends: bool| {
            let mut v: Vec<_> = s
                .iter()
                .filter(|s| {
                    let d = s.j - s.i;
                    !(skip_diagonal_bends && s.kind == SpringKind::Bend && d != 2 && d != 2 * w)
                })
                .map(|s| (s.i, s.j, s.kind as u8))
                .collect();
            v.sort();
            v
        };
        assert_eq!(set(&t.springs, false), set(&g.springs, true));
        approx::assert_relative_eq!(t.masses.iter().sum::<f64>(), 1.0, max_relative = 1e-12);
    }

    fn err(positions: &[Vec3], indices: &[u32], face_size: usize) -> Error {
        MeshSpec {
            positions,
            indices,
            face_size,
            mass: MeshMass::ArealDensity(1.0),
        }
        .build()
        .unwrap_err()
    }

    #[test]
    fn bad_meshes_are_rejected_with_the_culprit_named() {
        let x = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.5, 0.5, 1.0),
        ];
        let e = err(&x, &[0, 1, 7], 3);
        assert_eq!(e.kind, ErrorKind::OutOfRange);
        assert!(e.message.contains("index 7"), "{}", e.message);
        let e = err(&x, &[0, 1, 2, 0], 3);
        assert!(e.message.contains("multiple"), "{}", e.message);
        let e = err(&x, &[0, 1, 2, 0, 1, 3], 3);
        assert!(
            e.message.contains("face 1") && e.message.contains("degenerate"),
            "{}",
            e.message
        );
        let e = err(&x, &[0, 0, 2], 3);
        assert!(e.message.contains("appears twice"), "{}", e.message);
        let e = err(&x, &[0, 1, 2, 1, 0, 4, 0, 1, 5, 1, 3, 2], 3);
        assert!(e.message.contains("not manifold"), "{}", e.message);
        let e = err(&x, &[0, 1, 2, 1, 0, 4, 0, 1, 5], 3);
        assert!(e.message.contains("vertex 3 is used by no face"), "{}", e.message);
        let e = err(&x, &[0, 1, 2], 5);
        assert!(e.message.contains("face size"), "{}", e.message);
    }
}
