//! Helpers for the unit tests.

/// Deterministic pseudo-random numbers in [-0.5, 0.5) (a 64-bit linear congruential generator),
/// the same sequence on every machine for a given seed.
pub(crate) fn numbers(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// A `cols` x `rows` grid of `h` spacing in the xy plane, each quad cut along the diagonal
/// from its first corner: (rest positions, triangles).
pub(crate) fn flat_grid(cols: u32, rows: u32, h: f64) -> (Vec<crate::math::Vec3>, Vec<[u32; 3]>) {
    let rest = (0..rows)
        .flat_map(|j| (0..cols).map(move |i| crate::math::Vec3::new(f64::from(i) * h, f64::from(j) * h, 0.0)))
        .collect();
    let at = |i: u32, j: u32| j * cols + i;
    let mut triangles = Vec::new();
    for j in 0..rows - 1 {
        for i in 0..cols - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (rest, triangles)
}

/// A `width x height` grid of 0.1 m spacing (0.2 kg) with every vertex moved up to 1.5 cm
/// (seeded by `seed`) and random velocities: a crumpled, moving patch.
pub(crate) fn crumpled_grid(
    width: u32,
    height: u32,
    seed: u64,
) -> (crate::Topology, Vec<crate::Vec3>, Vec<crate::Vec3>) {
    use crate::Vec3;
    let t = crate::GridSpec {
        width,
        height,
        spacing: 0.1,
        total_mass: 0.2,
    }
    .build()
    .expect("a valid grid");
    let mut r = numbers(seed);
    let x = t
        .rest_positions
        .iter()
        .map(|p| p + 0.03 * Vec3::new(r(), r(), r()))
        .collect();
    let v = (0..t.vertex_count()).map(|_| Vec3::new(r(), r(), r())).collect();
    (t, x, v)
}

/// A `w x h` grid of 1 cm numbered in rows, its cells split along random diagonals and its
/// inner vertices moved up to 15 % of the spacing: rows of 4 to 9 entries within a 3 x 3
/// neighbourhood, no two alike (the scenes' jittered mesh).
pub(crate) fn jittered_mesh(w: u32, h: u32) -> crate::Topology {
    let mut r = numbers(11);
    let positions: Vec<crate::Vec3> = (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            let inner = i > 0 && j > 0 && i + 1 < w && j + 1 < h;
            let jitter = if inner {
                0.0015 * crate::Vec3::new(r(), r(), 0.0)
            } else {
                crate::Vec3::zeros()
            };
            crate::Vec3::new(0.01 * f64::from(i), 0.01 * f64::from(j), 0.0) + jitter
        })
        .collect();
    let mut indices = Vec::new();
    for j in 0..h - 1 {
        for i in 0..w - 1 {
            let (a, b, c, d) = (j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i);
            if r() < 0.0 {
                indices.extend([a, d, b, b, d, c]);
            } else {
                indices.extend([a, d, c, a, c, b]);
            }
        }
    }
    crate::topology::MeshSpec {
        positions: &positions,
        indices: &indices,
        face_size: 3,
        mass: crate::topology::MeshMass::Total(0.01),
    }
    .build()
    .expect("a triangle mesh")
}

/// Where point `p` of a flat sheet in the xy plane goes when the sheet beyond `x = x0` is folded
/// back over itself round a half circle of radius `r`: the halves `2 r` apart.
pub(crate) fn folded_over(p: &crate::math::Vec3, x0: f64, r: f64) -> crate::math::Vec3 {
    use crate::math::Vec3;
    let s = p.x - x0;
    if s <= 0.0 {
        *p
    } else if s <= std::f64::consts::PI * r {
        let a = s / r;
        Vec3::new(x0 + r * a.sin(), p.y, r * (1.0 - a.cos()))
    } else {
        Vec3::new(x0 - (s - std::f64::consts::PI * r), p.y, 2.0 * r)
    }
}
