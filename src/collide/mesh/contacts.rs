//! A mesh collider's contacts with the cloth: vertex against triangle, mesh vertex against
//! cloth triangle, mesh edge against cloth edge (the module docs of `mesh.rs`, "Contacts").

use super::*;

impl MeshCollider {
    /// The contacts of the cloth (positions `x`, triangles `cloth_triangles`) with this mesh at
    /// fraction `f` of the call, appended to `out`: penetration `margin - d`, at most
    /// `max_depth` (a vertex deep inside is pushed out at a bounded rate).
    #[allow(clippy::too_many_arguments)] // the cloth's arrays and the contact's three lengths
    pub(crate) fn contacts(
        &mut self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        f: f64,
        margin: f64,
        skin: f64,
        max_depth: f64,
        out: &mut Vec<Contact>,
    ) -> Result<(), Full> {
        if let Err(why) = self.refresh_candidates(x, cloth_triangles, margin, skin) {
            self.cache.stale = true;
            return Err(why);
        }
        let c = &mut self.cache;
        c.nearest.resize(x.len(), NONE);
        for &i in &c.touched {
            c.touching[i as usize] = false;
            c.inside[i as usize] = false;
        }
        c.touched.clear();
        c.touching.resize(x.len(), false);
        c.inside.resize(x.len(), false);
        c.distance.resize(x.len(), f64::INFINITY);
        self.vertex_contacts(x, f, margin, max_depth, out);
        self.triangle_contacts(x, cloth_triangles, f, margin, max_depth, out);
        self.edge_contacts(x, f, margin, max_depth, out);
        Ok(())
    }

    /// Each cloth vertex at `x` against its nearest candidate triangle (the mesh at fraction
    /// `f` of the call): a contact within `margin` (depth at most `max_depth`), and what the
    /// other contacts and the continuous check read of it (touching, inside, distance).
    fn vertex_contacts(&mut self, x: &[Vec3], f: f64, margin: f64, max_depth: f64, out: &mut Vec<Contact>) {
        let friction = self.friction;
        for &i in &self.cache.with_vertex {
            let i = i as usize;
            let cands = &self.cache.vertex[i];
            let p = &x[i];
            let mut best: Option<(f64, u32, [f64; 3], Vec3)> = None;
            // The last nearest first; then only triangles whose swept box is not farther than
            // the best so far (the box holds the triangle at every fraction of the call).
            // Nearest by unsigned distance, the lower index among equals (a point on an edge
            // two triangles share is as near to both: the contact does not depend on the
            // order they are tried in); the side only for the nearest.
            let hint = self.cache.nearest.get(i).copied().filter(|t| cands.contains(t));
            for &t in hint.iter().chain(cands.iter().filter(|&&t| Some(t) != hint)) {
                if let Some(b) = &best {
                    if self.tri_boxes[t as usize].distance2(p) > b.0 * b.0 {
                        continue;
                    }
                }
                let (d, w, r) = self.nearest_on(t, f, p);
                if best.is_none_or(|b| d < b.0 || (d == b.0 && t < b.1)) {
                    best = Some((d, t, w, r));
                }
            }
            if let (Some(b), Some(slot)) = (&best, self.cache.nearest.get_mut(i)) {
                *slot = b.1;
            }
            if let Some(slot) = self.cache.distance.get_mut(i) {
                *slot = best.as_ref().map_or(f64::INFINITY, |b| b.0);
            }
            if let Some((d, t, w, r)) = best {
                let (d, dir) = self.signed(t, d, w, &r);
                if d < margin {
                    self.cache.touching[i] = true;
                    self.cache.inside[i] = d < 0.0;
                    self.cache.touched.push(i as u32);
                    out.push(Contact {
                        idx: [i as u32, 0, 0, 0],
                        coef: [1.0, 0.0, 0.0, 0.0],
                        len: 1,
                        dir,
                        depth: (margin - d).min(max_depth),
                        surface_velocity: self.surface_velocity(t, w),
                        friction,
                        scale: 1.0,
                    });
                }
            }
        }
    }

    /// Each mesh vertex against its candidate cloth triangles, where no corner of the triangle
    /// touches the mesh already.
    fn triangle_contacts(
        &self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        f: f64,
        margin: f64,
        max_depth: f64,
        out: &mut Vec<Contact>,
    ) {
        let friction = self.friction;
        for &t in &self.cache.with_triangle {
            let cands = &self.cache.triangle[t as usize];
            let tri = cloth_triangles[t as usize];
            // Where a corner touches the mesh already, its vertex contact holds the triangle:
            // a finely tessellated mesh under the cloth would otherwise push each triangle once
            // per mesh vertex under it, a stiffness that grows with the mesh's resolution.
            if tri.iter().any(|&i| self.cache.touching[i as usize]) {
                continue;
            }
            let [a, b, c] = tri.map(|i| x[i as usize]);
            let near = Aabb::of([&a, &b, &c]).inflated(margin);
            for &m in cands {
                let q = self.at(m, f);
                if !near.contains(&q) {
                    continue;
                }
                let w = closest_on_triangle(&q, &a, &b, &c);
                // Only where the mesh vertex faces the triangle's inside: at an edge or a corner
                // the neighbouring triangle or the vertex contact takes it.
                if w.iter().any(|&wk| wk <= 0.0) {
                    continue;
                }
                let r = w[0] * a + w[1] * b + w[2] * c - q;
                let d = r.norm();
                if d >= margin || d <= 1e-12 {
                    continue;
                }
                out.push(Contact {
                    idx: [tri[0], tri[1], tri[2], 0],
                    coef: [w[0], w[1], w[2], 0.0],
                    len: 3,
                    dir: r / d,
                    depth: (margin - d).min(max_depth),
                    surface_velocity: self.velocity[m as usize],
                    friction,
                    scale: 1.0,
                });
            }
        }
    }

    /// Mesh edge against cloth edge, where the nearest points are inside both edges (at an
    /// end, a vertex contact above takes it) and neither cloth vertex touches the mesh
    /// already: edge contacts catch what the vertices miss (a thin collider between them),
    /// and do not double the push where the cloth lies on the mesh.
    fn edge_contacts(&self, x: &[Vec3], f: f64, margin: f64, max_depth: f64, out: &mut Vec<Contact>) {
        let friction = self.friction;
        for &e in &self.cache.with_edge {
            let cands = &self.cache.edge[e as usize];
            let [i0, i1] = self.cache.cloth_edges[e as usize];
            if self.cache.touching[i0 as usize] || self.cache.touching[i1 as usize] {
                continue;
            }
            let (p0, p1) = (x[i0 as usize], x[i1 as usize]);
            for &m in cands {
                let [j0, j1] = self.edges[m as usize];
                let (q0, q1) = (self.at(j0, f), self.at(j1, f));
                let (s, t) = closest_on_segments(&p0, &p1, &q0, &q1);
                if !(s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) {
                    continue;
                }
                let r = (p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0));
                let d = r.norm();
                if d >= margin || d <= 1e-12 {
                    continue;
                }
                let (v0, v1) = (self.velocity[j0 as usize], self.velocity[j1 as usize]);
                out.push(Contact {
                    idx: [i0, i1, 0, 0],
                    coef: [1.0 - s, s, 0.0, 0.0],
                    len: 2,
                    dir: r / d,
                    depth: (margin - d).min(max_depth),
                    surface_velocity: v0 + t * (v1 - v0),
                    friction,
                    scale: 1.0,
                });
            }
        }
    }
}
