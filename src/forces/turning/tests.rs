use super::*;
use crate::forces::inertia::{carried, carried_past, Inertia, CARRIED_FULL, CARRIED_SPAN};
use crate::forces::patch::{patch_turning, PATCH_BLOCK};

/// A crumpled, moving patch: positions, velocities, and a model with normal added mass.
fn patch() -> (Topology, Vec<Vec3>, Vec<Vec3>, Model) {
    let (t, x, v) = crate::testing::crumpled_grid(4, 3, 3);
    let mut m = Model::fractional();
    m.water.added_mass = 30.0;
    (t, x, v, m)
}

/// Each vertex's inertia at positions `x`.
fn inertias(t: &Topology, m: &Model, x: &[Vec3]) -> Vec<Inertia> {
    let (mut n, mut p) = (vec![Vec3::zeros(); x.len()], vec![0.0; x.len()]);
    patch_normals(x, t, &mut n, &mut p);
    (0..x.len())
        .map(|i| Inertia::of(m, 0.0, t.areas[i], n[i], p[i]))
        .collect()
}

/// Asserts that `got` are Lagrange's terms of the water's kinetic energy at `x`, `v`.
fn assert_lagranges(got: &[Vec3], t: &Topology, m: &Model, x: &[Vec3], v: &[Vec3]) {
    check::lagranges_terms(
        got,
        x,
        v,
        |y| water_energy(t, m, y, v),
        |y, j| inertias(t, m, y)[j].apply(&v[j]),
    );
}

/// The water's kinetic energy.
fn water_energy(t: &Topology, m: &Model, x: &[Vec3], v: &[Vec3]) -> f64 {
    inertias(t, m, x)
        .iter()
        .zip(v)
        .map(|(i, v)| i.kinetic_energy(v))
        .sum()
}

#[test]
fn turning_forces_are_lagranges_terms() {
    let (t, x, v, m) = patch();
    let (got, projected, normals) = check::turning_of(&m, &t, &x, &v, None);
    // The normals are the force pass's, bit for bit (it reads these instead).
    let mut want_normals = vec![Vec3::zeros(); x.len()];
    crate::forces::normals::vertex_normals(&x, &t.triangles, &mut want_normals);
    assert_eq!(normals, want_normals);
    // The ratios are the patches' own, 1 at rest.
    let (mut n, mut p) = (vec![Vec3::zeros(); x.len()], vec![0.0; x.len()]);
    patch_normals(&x, &t, &mut n, &mut p);
    assert!(
        projected.iter().zip(&p).all(|(a, b)| (a - b).abs() < 1e-14),
        "{projected:?} {p:?}"
    );
    let mut rest = vec![0.0; x.len()];
    patch_normals(&t.rest_positions, &t, &mut n, &mut rest);
    assert!(rest.iter().all(|r| (r - 1.0).abs() < 1e-12), "{rest:?}");
    assert_lagranges(&got, &t, &m, &x, &v);
    // Nothing without normal added mass.
    let (none, _, _) = check::turning_of(&Model::fractional(), &t, &x, &v, None);
    assert!(none.iter().all(|f| *f == Vec3::zeros()));
}

/// Stretched past [`CARRIED_FULL`], where the water a patch carries saturates
/// ([`carried`]), the turning forces are still Lagrange's terms of the kinetic energy the
/// mass matrix gives: mildly stretched (most patches just past the bound) and far (each
/// carrying nearly `CARRIED_FULL + CARRIED_SPAN`).
#[test]
fn turning_forces_of_a_stretched_patch_are_lagranges_terms() {
    let (t, x, v, m) = patch();
    for stretch in [1.12, 1.6] {
        let y: Vec<Vec3> = x.iter().map(|p| stretch * p).collect();
        let (got, projected, _) = check::turning_of(&m, &t, &y, &v, None);
        let over = projected.iter().filter(|p| *p * *p > CARRIED_FULL).count();
        assert!(
            over * 2 > y.len(),
            "{stretch}: {over} of {} patches past the bound",
            y.len()
        );
        assert_lagranges(&got, &t, &m, &y, &v);
    }
}

/// The water a patch carries: its squared ratio up to the bound, then the same value and
/// slope there, growing ever more slowly, never past `CARRIED_FULL + CARRIED_SPAN`; and
/// `carried_past`'s `h` and `dh/dq` are `f / q` and its derivative.
#[test]
fn the_water_a_stretched_patch_carries_saturates() {
    assert_eq!(carried(0.25), 0.25);
    assert_eq!(carried(CARRIED_FULL), CARRIED_FULL);
    assert!(carried(1e12) <= CARRIED_FULL + CARRIED_SPAN);
    let e = 1e-7;
    let slope = (carried(CARRIED_FULL + e) - carried(CARRIED_FULL)) / e;
    assert!((slope - 1.0).abs() < 1e-6, "{slope}");
    let mut last = CARRIED_FULL;
    for q in [0.1, 0.5, 1.0, 3.0, 100.0, 1e4].map(|d| CARRIED_FULL + d) {
        let f = carried(q);
        assert!(f > last && f < CARRIED_FULL + CARRIED_SPAN && f < q, "{q}: {f}");
        last = f;
        let (h, hq) = carried_past(q);
        assert!((h - f / q).abs() < 1e-15 * (1.0 + h));
        let d = 1e-6 * q;
        let want = (carried(q + d) / (q + d) - carried(q - d) / (q - d)) / (2.0 * d);
        assert!((hq - want).abs() < 1e-6 * want.abs(), "{q}: {hq} against {want}");
    }
}

/// A `w x h` sheet as a triangle mesh with random diagonals, its vertices in the grid's
/// order or scrambled, crumpled and moving.
fn mesh(w: u32, h: u32, scrambled: bool) -> (Topology, Vec<Vec3>, Vec<Vec3>) {
    let n = (w * h) as usize;
    let order: Vec<u32> = (0..n as u32)
        .map(|k| if scrambled { (k * 37) % n as u32 } else { k })
        .collect();
    let mut r = crate::testing::numbers(11);
    let mut rest = vec![Vec3::zeros(); n];
    for j in 0..h {
        for i in 0..w {
            rest[order[(j * w + i) as usize] as usize] = Vec3::new(0.01 * i as f64, -0.01 * j as f64, 0.0);
        }
    }
    let mut indices = Vec::new();
    for j in 0..h - 1 {
        for i in 0..w - 1 {
            let at = |i: u32, j: u32| order[(j * w + i) as usize];
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if r() < 0.0 {
                indices.extend([a, d, b, b, d, c]);
            } else {
                indices.extend([a, d, c, a, c, b]);
            }
        }
    }
    let t = crate::topology::MeshSpec {
        positions: &rest,
        indices: &indices,
        face_size: 3,
        mass: crate::topology::MeshMass::ArealDensity(1.0),
    }
    .build()
    .expect("a valid mesh");
    let x = rest
        .iter()
        .map(|p| p + 0.004 * Vec3::new(r(), r(), 2.0 * r()))
        .collect();
    let v = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
    (t, x, v)
}

/// The chunked wavefront gives the one-thread passes' bits for every chunk size, on one
/// thread and on the pool, whatever the vertex order (border vertices, far corners).
#[test]
fn chunks_and_wavefront_keep_the_bits() {
    // 61 x 41 has 4 800 faces: more than one wave (`WAVE`) in the larger chunks.
    for (w, h, scrambled) in [
        (23, 17, false),
        (23, 17, true),
        (5, 4, false),
        (61, 41, false),
        (61, 41, true),
    ] {
        let (t, x, v) = mesh(w, h, scrambled);
        let n = x.len();
        let prior: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f64, -0.5, 0.25)).collect();
        let run = |chunk: Option<(usize, bool)>| {
            let mut s = TurningScratch::default();
            let (mut p, mut nr, mut out) = (vec![0.0; n], vec![Vec3::zeros(); n], prior.clone());
            for _ in 0..2 {
                out.clone_from(&prior);
                match chunk {
                    None => turning_serial(8.0, &t, &x, &v, &mut s, &mut p, &mut nr, &mut out, None),
                    Some((c, par)) => {
                        turning_chunked(8.0, &t, &x, &v, &mut s, c, par, &mut p, &mut nr, &mut out)
                    }
                }
            }
            (out, p, nr)
        };
        let want = run(None);
        assert!(want.0.iter().zip(&prior).all(|(a, b)| a != b));
        for chunk in [n, n / 3 + 1, 50, 7, 1] {
            for par in [false, true] {
                let got = run(Some((chunk, par)));
                let same = |a: &[Vec3], b: &[Vec3]| {
                    a.iter()
                        .zip(b)
                        .all(|(a, b)| (0..3).all(|k| a[k].to_bits() == b[k].to_bits()))
                };
                assert!(same(&got.0, &want.0), "forces, {w}x{h} {scrambled} chunk {chunk}");
                assert!(
                    same(&got.2, &want.2),
                    "normals, {w}x{h} {scrambled} chunk {chunk}"
                );
                assert!(
                    got.1.iter().zip(&want.1).all(|(a, b)| a.to_bits() == b.to_bits()),
                    "ratios, {w}x{h} {scrambled} chunk {chunk}"
                );
            }
        }
    }
}

/// The blocks of [`patch_range`] give [`patch_turning`]'s bits, vertex by vertex, for
/// ranges of every length round the block size, with some patches folded flat (zero sums).
#[test]
fn patch_blocks_keep_the_bits() {
    let mut r = crate::testing::numbers(5);
    let mut v3 = || Vec3::new(r(), r(), r());
    for m in 0..=2 * PATCH_BLOCK + 3 {
        let sums: Vec<Vec3> = (0..m)
            .map(|i| match i % 5 {
                2 => Vec3::zeros(),
                // Patches stretched past the carried water's bound.
                0 | 3 => 3.0 * v3(),
                _ => v3(),
            })
            .collect();
        let (rates, v, o): (Vec<Vec3>, Vec<Vec3>, Vec<Vec3>) = (
            (0..m).map(|_| v3()).collect(),
            (0..m).map(|_| v3()).collect(),
            (0..m).map(|_| v3()).collect(),
        );
        let scale: Vec<f64> = (0..m).map(|i| 1.5 + sums[i].x).collect();
        let areas: Vec<f64> = (0..m).map(|i| 2.0 + rates[i].y).collect();
        let (mut go, mut gp, mut gn, mut gw) = (
            o.clone(),
            vec![0.0; m],
            vec![Vec3::zeros(); m],
            vec![Vec3::zeros(); m],
        );
        let out = PatchOut {
            o: &mut go,
            projected: &mut gp,
            normals: &mut gn,
            w: &mut gw,
        };
        patch_range(8.0, &areas, &scale, &sums, &rates, &v, out);
        // Both sides of the carried water's bound among the patches.
        let past = gp.iter().filter(|p| *p * *p > CARRIED_FULL).count();
        assert!(
            m < 8 || (past > 0 && past < m),
            "range {m}: {past} past the bound"
        );
        for i in 0..m {
            let (mut o1, mut p1, mut n1) = (o[i], 0.0, Vec3::zeros());
            let w1 = patch_turning(
                sums[i],
                rates[i],
                scale[i],
                8.0 * areas[i],
                &v[i],
                &mut o1,
                &mut p1,
                &mut n1,
            );
            let bits = |a: &Vec3| a.map(f64::to_bits);
            assert_eq!(bits(&go[i]), bits(&o1), "force, range {m} vertex {i}");
            assert_eq!(bits(&gn[i]), bits(&n1), "normal, range {m} vertex {i}");
            assert_eq!(bits(&gw[i]), bits(&w1), "w, range {m} vertex {i}");
            assert_eq!(gp[i].to_bits(), p1.to_bits(), "ratio, range {m} vertex {i}");
        }
    }
}
