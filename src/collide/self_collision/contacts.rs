//! Self-collision's contacts: each remembered pair within the thickness a contact element, its
//! side learnt, kept or forgotten on the way.

use super::*;

/// The contact of vertex `p` with triangle `tri` at `x` (signed distance, direction, the
/// triangle's weights), its remembered side `s` learnt or forgotten on the way; `None` when
/// the pair is apart or its direction is not defined.
#[inline]
fn vertex_triangle_contact(
    x: &[Vec3],
    p: u32,
    tri: &[u32; 3],
    s: &mut i8,
    thickness: f64,
    reach: f64,
) -> Option<(f64, Vec3, [f64; 3])> {
    let (d, w, r) = vertex_triangle(x, p, tri);
    let [a, b, c] = tri.map(|i| x[i as usize]);
    let interior = w.iter().all(|&wk| wk > 0.0);
    let normal = (b - a).cross(&(c - a)).try_normalize(0.0)?;
    if d >= thickness {
        // Apart. Over the face on the other side of the remembered one, within the
        // reach: it went through (a step moves a pair at most one thickness closer, so
        // it cannot be past the reach already) and is pushed back. Else nothing
        // crossed and the side is learnt afresh (a triangle that turned over).
        let now = side(r.dot(&normal));
        if !interior {
            // Beside the face it may go round the triangle's border: forgotten.
            *s = 0;
            return None;
        }
        if settled_apart(s, now, d, reach) {
            return None;
        }
    }
    if *s == 0 && interior {
        // First over the triangle's face: the side it comes from is known now.
        *s = side(r.dot(&normal));
    }
    let side_n = f64::from(*s) * normal;
    let (dist, dir) = if interior && r.dot(&side_n) <= 0.0 {
        (-d, side_n)
    } else if interior && *s != 0 {
        (r.dot(&side_n), side_n)
    } else if d > 1e-12 {
        (d, r / d)
    } else {
        return None;
    };
    Some((dist, dir, w))
}

/// The contact of edges `ee` and `ff` at `x` (signed distance, direction, the parameters of
/// the closest points), their remembered side `s` learnt or forgotten on the way; `None` when
/// they are apart, past an end, or their direction is not defined.
#[inline]
fn edge_edge_contact(
    x: &[Vec3],
    ee: &[u32; 2],
    ff: &[u32; 2],
    s: &mut i8,
    thickness: f64,
    reach: f64,
) -> Option<(f64, Vec3, f64, f64)> {
    let (d, a, b, r, n) = edge_edge(x, ee, ff);
    if !(a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0) {
        if d >= thickness {
            // Apart and past an end: it may go round the edge's end, forgotten.
            *s = 0;
        }
        return None;
    }
    // The side is kept relative to e x f, which means something only while the edges
    // are not near parallel (and flips as they turn through parallel).
    let lengths =
        (x[ee[1] as usize] - x[ee[0] as usize]).norm() * (x[ff[1] as usize] - x[ff[0] as usize]).norm();
    let n_len = n.norm();
    let conditioned = n_len > PARALLEL_SINE * lengths;
    if d >= thickness {
        // Apart: as for a vertex and a triangle, on the other side within the reach
        // they went through each other; else the side is learnt afresh (edges that
        // turned). Turning through parallel flips `e x f` without crossing, so near
        // parallel the side is forgotten.
        if !conditioned {
            *s = 0;
            return None;
        }
        let now = side(r.dot(&n));
        if settled_apart(s, now, d, reach) {
            return None;
        }
    }
    let (dist, dir) = if conditioned {
        let n = n / n_len;
        if *s == 0 {
            *s = side(r.dot(&n));
        }
        let side_n = f64::from(*s) * n;
        if r.dot(&side_n) <= 0.0 {
            (-d, side_n)
        } else {
            (d, r / d)
        }
    } else if d > 1e-12 {
        // Near parallel: pushed apart along the line between them (the vertex-triangle
        // pairs of their triangles keep the sides).
        (d, r / d)
    } else {
        return None;
    };
    Some((dist, dir, a, b))
}

/// For a pair apart (past the thickness) at distance `d`, now on side `now` of its remembered
/// side `s`: whether it is settled there, its side learnt afresh (unknown before, the same,
/// or past the `reach`, where no step from a contact can have brought it). Else it went
/// through and is to be pushed back.
fn settled_apart(s: &mut i8, now: i8, d: f64, reach: f64) -> bool {
    let settled = *s == 0 || now == *s || d >= reach;
    if settled {
        *s = now;
    }
    settled
}

impl SelfCollision {
    /// The contacts of the cloth (positions `x`, velocities unused here, rest positions `rest`)
    /// with itself at thickness `thickness`, appended to `out`, after [`SelfCollision::prepare`]
    /// at that thickness. Looks the pairs up again when the cloth has deformed enough. Every
    /// list it grows (the pairs, the look's working lists, `out`) is asked of the allocator
    /// fallibly and kept for the next call: an out-of-memory error, not an abort, when memory
    /// runs out, and no allocation once the lists have grown to what the shapes need.
    pub fn contacts(
        &mut self,
        x: &[Vec3],
        rest: &[Vec3],
        triangles: &[[u32; 3]],
        thickness: f64,
        friction: f64,
        out: &mut Vec<Contact>,
    ) -> Result<(), Error> {
        let skin = SKIN * thickness;
        let reach = thickness + skin;
        if self.deformed(x, skin) {
            self.look(x, rest, triangles, reach, EXCLUDED * thickness)?;
        }
        // At most one contact a pair: room for all of them, so the pushes never allocate.
        let pairs = self.vertex_triangle.len() + self.edge_edge.len();
        out.try_reserve(pairs).map_err(|_| {
            Error::out_of_memory(format!("self-collision: {pairs} contacts cannot be allocated"))
        })?;
        let cap = 2.0 * thickness;
        // A contact between four vertices at signed distance `dist` along `dir`, if within the
        // thickness.
        let push = |out: &mut Vec<Contact>, idx: [u32; 4], coef: [f64; 4], dist: f64, dir: Vec3| {
            if dist < thickness {
                out.push(Contact {
                    idx,
                    coef,
                    len: 4,
                    dir,
                    depth: (thickness - dist).min(cap),
                    surface_velocity: Vec3::zeros(),
                    friction,
                    scale: 1.0,
                });
            }
        };
        for (p, t, s) in self.vertex_triangle.iter_mut().map(|q| (q.0, q.1, &mut q.2)) {
            let tri = &triangles[t as usize];
            if let Some((dist, dir, w)) = vertex_triangle_contact(x, p, tri, s, thickness, reach) {
                push(
                    out,
                    [p, tri[0], tri[1], tri[2]],
                    [1.0, -w[0], -w[1], -w[2]],
                    dist,
                    dir,
                );
            }
        }
        for (e, f, s) in self.edge_edge.iter_mut().map(|p| (p.0, p.1, &mut p.2)) {
            let (ee, ff) = (&self.edges[e as usize], &self.edges[f as usize]);
            if let Some((dist, dir, a, b)) = edge_edge_contact(x, ee, ff, s, thickness, reach) {
                push(
                    out,
                    [ee[0], ee[1], ff[0], ff[1]],
                    [1.0 - a, a, -(1.0 - b), -b],
                    dist,
                    dir,
                );
            }
        }
        Ok(())
    }
}
