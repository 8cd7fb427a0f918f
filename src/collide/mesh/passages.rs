//! A mesh collider's passages: where the cloth would pass through the mesh over a step (the
//! continuous check, `ccd.rs`).

use super::*;

impl MeshCollider {
    /// The cloth's passages through this mesh over a step (continuous check, `ccd.rs`): the
    /// cloth moving from `x0` to `x1` and the mesh from fraction `f0` to `f1` of the call, each
    /// cloth vertex against its candidate triangles, each cloth triangle against its candidate
    /// mesh vertices and each cloth edge against its candidate active edges. Each passage is
    /// appended to `out` as the cloth vertices it takes and the mesh's displacement there over
    /// the step (the mean of the mesh element's vertices'), which carries them.
    #[allow(clippy::too_many_arguments)] // the cloth's arrays, the step's ends and the tolerance
    pub(crate) fn passages(
        &self,
        x0: &[Vec3],
        x1: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        f0: f64,
        f1: f64,
        tolerance: f64,
        out: &mut Vec<MeshPassage>,
    ) {
        let c = &self.cache;
        // A closed mesh has an inside: a vertex found there is being pushed out, and its way
        // out through the surface is not stopped (nor are its triangles' and edges').
        let inside = |i: u32| self.closed && c.inside.get(i as usize).copied().unwrap_or(false);
        let path = |i: u32| (x0[i as usize], x1[i as usize]);
        let mesh_path = |m: u32| (self.at(m, f0), self.at(m, f1));
        let carry = |ms: &[u32]| {
            ms.iter()
                .fold(Vec3::zeros(), |s, &m| s + (self.at(m, f1) - self.at(m, f0)))
                / ms.len() as f64
        };
        // Swept boxes first: a passage needs the two elements' boxes over the step to meet.
        let swept = |ps: &[(Vec3, Vec3)]| Aabb::of(ps.iter().flat_map(|p| [&p.0, &p.1])).inflated(tolerance);
        // No part of the mesh moves farther than this in the step.
        let travel = (f1 - f0).abs() * self.travel + tolerance;
        for &i in &c.with_vertex {
            let pi = path(i);
            // A vertex farther from the mesh (where it starts, from where the mesh ends) than
            // both can move in the step meets none of its triangles.
            let reach = (pi.1 - pi.0).norm() + travel;
            if c.distance.get(i as usize).is_none_or(|&d| d > reach) {
                continue;
            }
            let own = swept(&[pi]);
            for &t in &c.vertex[i as usize] {
                let [a, b, m] = self.triangles[t as usize];
                let p: Path = [mesh_path(a), mesh_path(b), mesh_path(m), pi];
                if !own.overlaps(&swept(&p[..3])) {
                    continue;
                }
                // Through a closed mesh's face from behind it (the faces wind outwards): on
                // its way out.
                if self.closed && start_sign(&p) < 0 {
                    continue;
                }
                if vertex_passes_triangle(&p, tolerance).is_some() {
                    out.push(MeshPassage {
                        cloth: [i, i, i],
                        carry: carry(&[a, b, m]),
                    });
                }
            }
        }
        for &t in &c.with_triangle {
            let tri = cloth_triangles[t as usize];
            if tri.iter().any(|&i| inside(i)) {
                continue;
            }
            let corners = tri.map(path);
            let own = swept(&corners);
            for &m in &c.triangle[t as usize] {
                let q = mesh_path(m);
                if !own.overlaps(&swept(&[q])) {
                    continue;
                }
                let p: Path = [corners[0], corners[1], corners[2], q];
                if vertex_passes_triangle(&p, tolerance).is_some() {
                    out.push(MeshPassage {
                        cloth: tri,
                        carry: carry(&[m]),
                    });
                }
            }
        }
        for &e in &c.with_edge {
            let [i0, i1] = c.cloth_edges[e as usize];
            if inside(i0) || inside(i1) {
                continue;
            }
            let ends = [path(i0), path(i1)];
            let own = swept(&ends);
            for &m in &c.edge[e as usize] {
                let [j0, j1] = self.edges[m as usize];
                let other = [mesh_path(j0), mesh_path(j1)];
                if !own.overlaps(&swept(&other)) {
                    continue;
                }
                let p: Path = [ends[0], ends[1], other[0], other[1]];
                if edge_passes_edge(&p, tolerance).is_some() {
                    out.push(MeshPassage {
                        cloth: [i0, i1, i1],
                        carry: carry(&[j0, j1]),
                    });
                }
            }
        }
    }
}
