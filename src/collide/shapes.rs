//! Closed triangle meshes of simple solids, outward-facing (counter-clockwise seen from
//! outside): the colliders of the built-in scenes and of the tests.

use crate::math::Vec3;

/// A mesh: vertices and triangles.
pub type Mesh = (Vec<Vec3>, Vec<[u32; 3]>);

/// A UV sphere of `radius` around `centre`, `slices` around and `stacks` from pole to pole.
pub fn uv_sphere(centre: Vec3, radius: f64, slices: u32, stacks: u32) -> Mesh {
    let (slices, stacks) = (slices.max(3), stacks.max(2));
    let mut x = vec![centre + Vec3::new(0.0, radius, 0.0)];
    for j in 1..stacks {
        let th = std::f64::consts::PI * f64::from(j) / f64::from(stacks);
        for i in 0..slices {
            let ph = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(slices);
            x.push(centre + radius * Vec3::new(th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin()));
        }
    }
    x.push(centre - Vec3::new(0.0, radius, 0.0));
    let bottom = x.len() as u32 - 1;
    let ring = |j: u32, i: u32| 1 + (j - 1) * slices + i % slices;
    let mut t = Vec::new();
    for i in 0..slices {
        t.push([0, ring(1, i), ring(1, i + 1)]);
        t.push([bottom, ring(stacks - 1, i + 1), ring(stacks - 1, i)]);
    }
    for j in 1..stacks - 1 {
        for i in 0..slices {
            let (a, b, c, d) = (ring(j, i), ring(j, i + 1), ring(j + 1, i), ring(j + 1, i + 1));
            t.push([a, c, d]);
            t.push([a, d, b]);
        }
    }
    (x, t)
}

/// A torus around the y axis through `centre`: ring radius `major`, tube radius `minor`.
pub fn torus(centre: Vec3, major: f64, minor: f64, around: u32, tube: u32) -> Mesh {
    let (around, tube) = (around.max(3), tube.max(3));
    let mut x = Vec::new();
    for i in 0..around {
        let ph = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(around);
        let (c, s) = (ph.cos(), ph.sin());
        for j in 0..tube {
            let th = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(tube);
            let r = major + minor * th.cos();
            x.push(centre + Vec3::new(r * c, minor * th.sin(), r * s));
        }
    }
    let id = |i: u32, j: u32| (i % around) * tube + j % tube;
    let mut t = Vec::new();
    for i in 0..around {
        for j in 0..tube {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
            t.push([a, c, d]);
            t.push([a, d, b]);
        }
    }
    (x, t)
}

/// A square bar from `a` to `b` with half-width `half`, cut into `segments` along its length.
pub fn bar(a: Vec3, b: Vec3, half: f64, segments: u32) -> Mesh {
    let segments = segments.max(1);
    let axis = (b - a).try_normalize(0.0).unwrap_or(Vec3::x());
    let helper = if axis.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    let u = axis.cross(&helper).normalize() * half;
    let w = axis.cross(&u).normalize() * half;
    let corners = [u + w, -u + w, -u - w, u - w];
    let mut x = Vec::new();
    for s in 0..=segments {
        let p = a + (b - a) * (f64::from(s) / f64::from(segments));
        x.extend(corners.iter().map(|c| p + c));
    }
    let id = |s: u32, k: u32| s * 4 + k % 4;
    let mut t = Vec::new();
    for s in 0..segments {
        for k in 0..4 {
            let (p, q, r, o) = (id(s, k), id(s, k + 1), id(s + 1, k), id(s + 1, k + 1));
            t.push([p, q, o]);
            t.push([p, o, r]);
        }
    }
    // End caps.
    t.push([id(0, 0), id(0, 3), id(0, 2)]);
    t.push([id(0, 0), id(0, 2), id(0, 1)]);
    let e = segments;
    t.push([id(e, 0), id(e, 1), id(e, 2)]);
    t.push([id(e, 0), id(e, 2), id(e, 3)]);
    (x, t)
}

/// Signed volume of a closed mesh (positive when it faces outward).
pub fn volume(mesh: &Mesh) -> f64 {
    mesh.1
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.0[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every solid faces outward and has about its volume (facets sag inside the true one).
    #[test]
    fn solids_face_outward_with_their_volume() {
        let pi = std::f64::consts::PI;
        let s = volume(&uv_sphere(Vec3::new(0.1, 0.2, 0.3), 0.5, 48, 24));
        assert!((s / (4.0 / 3.0 * pi * 0.125) - 1.0).abs() < 0.02, "{s}");
        let t = volume(&torus(Vec3::zeros(), 0.4, 0.1, 64, 32));
        assert!((t / (2.0 * pi * pi * 0.4 * 0.01) - 1.0).abs() < 0.02, "{t}");
        let b = volume(&bar(Vec3::zeros(), Vec3::new(0.0, 0.0, 2.0), 0.01, 3));
        assert!((b / (2.0 * 0.02 * 0.02) - 1.0).abs() < 1e-9, "{b}");
    }
}
