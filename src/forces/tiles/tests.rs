use super::super::{total_forces, ForceInput, ForceScratch};
use crate::math::Vec3;
use crate::model::Model;
use crate::topology::{GridSpec, Topology};

/// Spring forces the plain way: every spring once, f64 square root and division, scattered.
fn reference(m: &Model, t: &Topology, x: &[Vec3], q: &[Vec3]) -> Vec<Vec3> {
    let mut f = vec![Vec3::zeros(); x.len()];
    for s in &t.springs {
        let (i, j) = (s.i as usize, s.j as usize);
        let l = x[i] - x[j];
        let len = l.norm();
        let dir = l / len;
        let mag = -m.stiffness(s.kind, t.spacing) * (len - s.rest)
            - m.spring_damping_of(s.kind) * (q[i] - q[j]).dot(&dir);
        f[i] += mag * dir;
        f[j] -= mag * dir;
    }
    f
}

#[test]
fn tiled_and_buffered_spring_sums_match_the_plain_sum_across_chunks() {
    // 101 x 101 = 10 201 particles: three chunks, so the prologue across chunk boundaries runs.
    let t = GridSpec {
        width: 101,
        height: 101,
        spacing: 0.01,
        total_mass: 1.0,
    }
    .build()
    .unwrap();
    let n = t.vertex_count();
    assert!(t.tiled.is_some());
    let mut buffered = t.clone();
    buffered.tiled = None;
    // Deterministic pseudo-random displacements and rates.
    let mut rnd = crate::testing::numbers(12345);
    let x: Vec<Vec3> = t
        .rest_positions
        .iter()
        .map(|p| p + 0.002 * Vec3::new(rnd(), rnd(), rnd()))
        .collect();
    let q: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
    // Springs only: no gravity, no drag.
    let mut m = Model::fractional();
    m.gravity = Vec3::zeros();
    m.viscous_drag = 0.0;
    m.history_drag = 0.0;
    // A damping of its own for each family: a run two families share takes each slot's.
    m.spring_damping_scale = [1.0, 0.5, 0.25];
    // Rest lengths that differ within a family (as a mesh's do): the tiled pass reads them
    // per slot instead of one number per run.
    let mut springs = t.springs.clone();
    for s in springs.iter_mut().step_by(7) {
        s.rest *= 1.01;
    }
    let varied = Topology::new(
        t.rest_positions.clone(),
        t.masses.clone(),
        springs,
        t.triangles.clone(),
        t.grid,
    );
    assert!(varied.tile_runs.uniform_rest.iter().all(|r| r.is_none()));
    assert!(t.tile_runs.uniform_rest.iter().all(|r| r.is_some()));
    // 1500 columns: offsets up to 3000, so the window slides by several tiles, groups span
    // several chunks and a tile's runs come from its own chunk.
    let wide = GridSpec {
        width: 1500,
        height: 20,
        spacing: 0.01,
        total_mass: 1.0,
    }
    .build()
    .unwrap();
    let layout = wide.tiled.unwrap();
    assert!(layout.window > 4 * super::TILE && layout.group > crate::parallel::CHUNK);
    assert!(wide.vertex_count() > layout.group);
    let x_wide: Vec<Vec3> = wide
        .rest_positions
        .iter()
        .map(|p| p + 0.002 * Vec3::new(rnd(), rnd(), rnd()))
        .collect();
    let q_wide: Vec<Vec3> = (0..wide.vertex_count())
        .map(|_| Vec3::new(rnd(), rnd(), rnd()))
        .collect();
    // The grid `t` with only the springs `keep` accepts.
    let keeping = |keep: &dyn Fn(&crate::topology::Spring) -> bool| {
        let springs = t.springs.iter().filter(|s| keep(s)).copied().collect();
        Topology::new(
            t.rest_positions.clone(),
            t.masses.clone(),
            springs,
            t.triangles.clone(),
            t.grid,
        )
    };
    // Gaps of six springs in every family at four places: padded, each family and offset
    // one run again, gathered.
    let holes = keeping(&|s| !(1..=4).any(|k| (2000 * k..2000 * k + 6).contains(&s.i)));
    assert_eq!(holes.tile_runs.runs.len(), t.tile_runs.runs.len());
    // One gap in the horizontal stretch family only, inside a tile: padded over, so a
    // tile's run has padding slots in its middle.
    let gap = keeping(&|s| !(s.j == s.i + 1 && (3000..3006).contains(&s.i)));
    assert_eq!(gap.tile_runs.runs.len(), t.tile_runs.runs.len());
    assert!(gap.tile_runs.pads.len() >= 6);
    // Six more offsets (bend springs reaching 3 to 8 columns along a row): 14 runs, too many
    // for the gather path, so the window-of-sums path runs.
    let mut more = t.springs.clone();
    let w = t.grid.map_or(0, |g| g.0);
    for k in 3..=8u32 {
        for i in 0..n as u32 {
            if i % w + k < w {
                let rest = (t.rest_positions[(i + k) as usize] - t.rest_positions[i as usize]).norm();
                more.push(crate::topology::Spring {
                    i,
                    j: i + k,
                    rest,
                    kind: crate::topology::SpringKind::Bend,
                });
            }
        }
    }
    let many = Topology::new(
        t.rest_positions.clone(),
        t.masses.clone(),
        more,
        t.triangles.clone(),
        t.grid,
    );
    assert_eq!(many.tile_runs.runs.len(), t.tile_runs.runs.len() + 6);
    let gathered = |t: &Topology| t.tiled.is_some_and(|l| l.gather_runs > 0);
    assert!(gathered(&gap) && gathered(&holes));
    assert!(many.tiled.is_some() && !gathered(&many));
    assert!(gathered(&t) && gathered(&varied) && gathered(&wide));
    // The scenes' jittered mesh: its diagonals' stretch and bend springs share runs.
    let jittered = crate::testing::jittered_mesh(101, 101);
    let two = jittered
        .tile_runs
        .runs
        .iter()
        .filter(|r| r.second.is_some())
        .count();
    assert!(two >= 2, "runs of two families: {two}");
    assert!(gathered(&jittered));
    // Its bend springs across the rows' and the columns' edges: one choice run each.
    let choices = jittered.tile_runs.choices.iter().filter(|c| c.is_some()).count();
    assert_eq!(choices, 2);
    let x_jittered: Vec<Vec3> = jittered
        .rest_positions
        .iter()
        .map(|p| p + 0.002 * Vec3::new(rnd(), rnd(), rnd()))
        .collect();
    // The same shape a hundred trillion times smaller: every squared length under the
    // fast inverse length's range, so each slice is done again by the exact pass (the
    // choice runs pick their places for it too).
    let x_tiny: Vec<Vec3> = x_jittered.iter().map(|p| 1e-14 * p).collect();
    // A second-family spring of rest length 0 (its slot holds -0.0): still the second's.
    let shared = jittered
        .tile_runs
        .runs
        .iter()
        .find(|r| r.second.is_some())
        .copied();
    let shared = shared.expect("a shared run");
    let mut springs = jittered.springs.clone();
    let zeroed = springs
        .iter_mut()
        .find(|s| s.j - s.i == shared.offset && Some(s.kind as u8) == shared.second)
        .expect("a spring of the second family");
    zeroed.rest = 0.0;
    let zero_rest = Topology::new(
        jittered.rest_positions.clone(),
        jittered.masses.clone(),
        springs,
        jittered.triangles.clone(),
        jittered.grid,
    );
    assert!(zero_rest
        .tile_runs
        .rest
        .iter()
        .any(|r| *r == 0.0 && r.is_sign_negative()));
    for (topology, x, q) in [
        (&jittered, &x_jittered, &q),
        (&jittered, &x_tiny, &q),
        (&zero_rest, &x_jittered, &q),
        (&t, &x, &q),
        (&buffered, &x, &q),
        (&varied, &x, &q),
        (&wide, &x_wide, &q_wide),
        (&holes, &x, &q),
        (&gap, &x, &q),
        (&many, &x, &q),
    ] {
        let n = topology.vertex_count();
        let want = reference(&m, topology, x, q);
        let input = ForceInput {
            model: &m,
            topology,
            x,
            v: q,
            half_derivative: q,
            colliders: &[],
            prior_forces: &[],
            weights: Default::default(),
            skin_mean: &[],
        };
        let mut f = vec![Vec3::zeros(); n];
        total_forces(&input, &mut ForceScratch::default(), &mut f);
        let scale = want.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for (p, (a, b)) in f.iter().zip(&want).enumerate() {
            assert!((a - b).norm() <= 1e-12 * scale, "particle {p}: {a} vs {b}");
        }
    }
}
