use super::*;
use crate::topology::GridSpec;

fn grid(cols: u32, rows: u32, spacing: f64) -> Topology {
    GridSpec {
        width: cols,
        height: rows,
        spacing,
        total_mass: 0.1,
    }
    .build()
    .expect("a grid")
}

/// A fan of 13 triangles around a centre vertex and a ring, then a strip: rows of 3 to 14
/// entries, blocks of mixed widths.
fn fan() -> Topology {
    let k = 13u32;
    let mut positions = vec![Vec3::zeros()];
    for i in 0..k {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(k);
        positions.push(Vec3::new(0.02 * a.cos(), 0.02 * a.sin(), 0.0));
        positions.push(Vec3::new(
            0.035 * a.cos(),
            0.035 * a.sin(),
            0.001 * f64::from(i % 3),
        ));
    }
    let mut indices = Vec::new();
    for i in 0..k {
        let (r0, r1) = (1 + 2 * i, 1 + 2 * ((i + 1) % k));
        indices.extend([0, r0, r1]);
        indices.extend([r0, r0 + 1, r1]);
    }
    triangles(&positions, &indices)
}

/// A triangle mesh of 10 g.
fn triangles(positions: &[Vec3], indices: &[u32]) -> Topology {
    use crate::topology::{MeshMass, MeshSpec};
    MeshSpec {
        positions,
        indices,
        face_size: 3,
        mass: MeshMass::Total(0.01),
    }
    .build()
    .expect("a triangle mesh")
}

/// The scenes' jittered mesh (`crate::testing::jittered_mesh`).
fn jittered(w: u32, h: u32) -> Topology {
    crate::testing::jittered_mesh(w, h)
}

/// The blocked rows give the bits of the rows summed one by one, on a grid (rows of 7), on
/// a fan whose centre has 14 entries beside rows of 4-6, and on a jittered mesh (windowed
/// blocks), for any values (signed zeros too, and rows that sum to zero).
#[test]
fn blocked_rows_give_the_bits_of_the_rows() {
    for t in [grid(13, 9, 0.01), fan(), jittered(17, 11)] {
        let s = one_pass(&t);
        let blocks = Blocks::new(&s);
        let n = t.vertex_count();
        let widths: Vec<u32> = blocks.starts.windows(2).map(|w| w[1] - w[0]).collect();
        // Mixed values with signed zeros, and values all -0.0 but one: rows that sum to -0.0
        // beside rows that do not.
        let mut mixed: Vec<f64> = (0..n).map(|i| ((i * 7919 % 101) as f64 - 50.0) * 0.013).collect();
        mixed[1] = -0.0;
        mixed[2] = 0.0;
        let mut zeros = vec![-0.0; n];
        zeros[0] = 1.0;
        // Ones but -0.0 on one row's entries: that row sums to -0.0 while a window around it
        // reads ones where the row has no entry (on a windowed block's row, if any).
        let mut hole = vec![1.0; n];
        let row = blocks
            .window
            .iter()
            .position(|&k| k != STORED)
            .map_or(0, |b| b * LANES + 3);
        for e in s.offsets[row] as usize..s.offsets[row + 1] as usize {
            hole[s.cols[e] as usize] = -0.0;
        }
        for u in [mixed, zeros, hole] {
            let mut padded = u.clone();
            padded.resize((n + 1).next_power_of_two(), -0.0);
            let (mut by_rows, mut by_blocks) = (vec![0.0; n], vec![0.0; n]);
            s.apply(&u, &mut by_rows);
            blocks.apply(&padded, &mut by_blocks);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&by_rows), bits(&by_blocks), "widths {widths:?}");
        }
        assert!(
            widths.iter().any(|&w| w != widths[0]),
            "blocks of mixed widths: {widths:?}"
        );
        // The grid's interior blocks are shifted rows (one shape), the rest stored; the fan
        // has no shifted block; the jittered mesh's blocks away from its first and last rows
        // are windowed, none shifted.
        let shifted = blocks.shape.iter().filter(|&&k| k != STORED).count();
        let windowed = blocks.window.iter().filter(|&&k| k != STORED).count();
        let expected = if n == 13 * 9 { (4, 1) } else { (0, 0) };
        assert_eq!((shifted, blocks.shapes.len()), expected);
        if n == 17 * 11 {
            assert!(
                windowed >= 18,
                "{windowed} of {} blocks windowed",
                blocks.window.len()
            );
        }
    }
}

/// A regular grid's interior rows share their weights bit for bit after `shared_rounding`,
/// which moves none by more than rounding; a jittered mesh's rows keep theirs.
#[test]
fn rows_that_differ_by_rounding_share_their_weights() {
    let bits = |r: &[(u32, f64)]| r.iter().map(|&(j, w)| (j, w.to_bits())).collect::<Vec<_>>();
    // A grid far from the origin: its face areas round differently from cell to cell.
    let mut t = grid(20, 6, 0.0137);
    for x in &mut t.rest_positions {
        *x += Vec3::new(3.1, -7.3, 0.7);
    }
    let computed = pass_rows(&t);
    let shared = shared_rounding(computed.clone());
    let interior: Vec<usize> = (0..120)
        .filter(|i| i % 20 > 0 && i % 20 < 19 && i / 20 > 0 && i / 20 < 5)
        .collect();
    let shifted = |r: &[(u32, f64)], i: usize| -> Vec<(i64, u64)> {
        r.iter()
            .map(|&(j, w)| (i64::from(j) - i as i64, w.to_bits()))
            .collect()
    };
    let first = interior[0];
    for &i in &interior {
        assert_eq!(shifted(&shared[i], i), shifted(&shared[first], first), "row {i}");
    }
    // As computed, the same rows differ in their last bits, by rounding only.
    assert!(interior
        .iter()
        .any(|&i| shifted(&computed[i], i) != shifted(&computed[first], first)));
    for (a, b) in computed.iter().flatten().zip(shared.iter().flatten()) {
        assert_eq!(a.0, b.0);
        assert!((a.1 - b.1).abs() <= ROUNDING * b.1, "{} against {}", a.1, b.1);
    }
    // A jittered mesh's rows are not moved.
    let mut j = grid(9, 7, 0.01);
    for (k, x) in j.rest_positions.iter_mut().enumerate() {
        let h = (k as u64)
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        x.x += 0.002 * ((h >> 40) as f64 / (1u64 << 24) as f64 - 0.5);
        x.y += 0.002 * ((h >> 16 & 0xff_ffff) as f64 / (1u64 << 24) as f64 - 0.5);
    }
    let computed = pass_rows(&j);
    let shared = shared_rounding(computed.clone());
    for (a, b) in computed.iter().zip(&shared) {
        assert_eq!(bits(a), bits(b));
    }
}

#[test]
fn the_transpose_is_the_transpose() {
    // <S u, g> = <u, S^T g> for any u, g, with whole and partial passes.
    let t = grid(9, 7, 0.01);
    let n = t.vertex_count();
    let w = RestWeights::new(&t, 0.023);
    assert!(w.passes >= 1 && w.partial > 0.0);
    let u: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.1).collect();
    let g: Vec<f64> = (0..n).map(|i| ((i * 13 % 7) as f64 - 3.0) * 0.3).collect();
    let (mut su, mut stg) = (u.clone(), g.clone());
    let mut b = Vec::new();
    apply(&w, false, &mut su, &mut b);
    apply(&w, true, &mut stg, &mut b);
    let lhs: f64 = su.iter().zip(&g).map(|(a, b)| a * b).sum();
    let rhs: f64 = u.iter().zip(&stg).map(|(a, b)| a * b).sum();
    assert!((lhs - rhs).abs() < 1e-12 * lhs.abs().max(1.0), "{lhs} {rhs}");
}

#[test]
fn a_uniform_field_passes_and_the_spread_matches_the_length() {
    let t = grid(41, 41, 0.01);
    let w = RestWeights::new(&t, 0.04);
    let mut b = Vec::new();
    let mut u = vec![0.3; t.vertex_count()];
    apply(&w, false, &mut u, &mut b);
    assert!(u.iter().all(|x| (x - 0.3).abs() < 1e-14));
    // A spike at the centre spreads with rms radius close to the length asked for.
    let centre = 20 * 41 + 20;
    let mut u = vec![0.0; t.vertex_count()];
    u[centre] = 1.0;
    apply(&w, false, &mut u, &mut b);
    let x = &t.rest_positions;
    let mass: f64 = u.iter().sum();
    let r2: f64 = u
        .iter()
        .zip(x)
        .map(|(ui, xi)| ui * (xi - x[centre]).norm_squared())
        .sum();
    let rms = (r2 / mass).sqrt();
    assert!((rms - 0.04).abs() < 0.004, "rms radius {rms}");
}

#[test]
fn it_only_takes_energy_out() {
    // Power of the drag against the velocities it acts on is never positive.
    let t = grid(11, 9, 0.01);
    let mut m = Model::underwater();
    m.water.form_drag_scale = 0.015;
    let x = t.rest_positions.clone();
    let mut normals = vec![Vec3::zeros(); x.len()];
    crate::forces::vertex_normals(&x, &t.triangles, &mut normals);
    let mut scratch = WideDragScratch::default();
    for seed in 0..20usize {
        let v: Vec<Vec3> = (0..x.len())
            .map(|i| {
                let s = ((i * 7919 + seed * 104729) % 1000) as f64 / 1000.0 - 0.5;
                Vec3::new(0.1 * s, -0.2 * s, s * s - 0.1)
            })
            .collect();
        let mut f = vec![Vec3::zeros(); x.len()];
        add_wide_form_drag(&m, &t, &normals, &v, &mut scratch, &mut f);
        let power: f64 = f.iter().zip(&v).map(|(f, v)| f.dot(v)).sum();
        assert!(power <= 0.0, "power {power}");
        assert!(f.iter().any(|f| f.norm() > 0.0));
    }
}
