//! Meshes, colliders, soft pins and caches.
//!
//! Mesh input is checked against grids with equivalent springs: the springs a mesh should get
//! are derived here by grid index arithmetic (independently of the mesh builder's edge walk),
//! assembled into a topology with the same rest positions and masses, and both cloths are
//! stepped with the same configuration. Same springs, same rest lengths, same masses and the
//! canonical spring order mean the motions must agree to rounding; the bound below (1e-12 m)
//! is far under anything physical and would catch any missing, extra or mis-typed spring (a
//! single bend spring changes positions by ~1e-6 m within the run).

use fraccloth::forces::{Capsule, Collider, Plane};
use fraccloth::topology::{grid_index, MeshMass, MeshSpec, Spring, SpringKind, Topology};
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Vec3};

const W: u32 = 13;
const H: u32 = 9;

fn grid_positions() -> Vec<Vec3> {
    GridSpec {
        width: W,
        height: H,
        spacing: 0.02,
        total_mass: 1.0,
    }
    .build()
    .unwrap()
    .rest_positions
}

/// Quads (a, c, d, b) and their triangulation (a, c, d), (a, d, b), with a = (i, j),
/// b = (i+1, j), c = (i, j+1), d = (i+1, j+1).
fn faces(quads: bool) -> Vec<u32> {
    let mut idx = vec![];
    for j in 0..H - 1 {
        for i in 0..W - 1 {
            let a = grid_index(W, i, j);
            let (b, c, d) = (a + 1, a + W, a + W + 1);
            if quads {
                idx.extend([a, c, d, b]);
            } else {
                idx.extend([a, c, d, a, d, b]);
            }
        }
    }
    idx
}

/// The springs the mesh rules give on this grid, by index arithmetic.
fn expected_springs(quads: bool, x: &[Vec3]) -> Vec<Spring> {
    let mut s = vec![];
    let mut add = |i: i64, j: i64, kind| {
        let (i, j) = (i.min(j) as u32, i.max(j) as u32);
        s.push(Spring {
            i,
            j,
            rest: (x[j as usize] - x[i as usize]).norm(),
            kind,
        });
    };
    let (w, h) = (i64::from(W), i64::from(H));
    let at = |i: i64, j: i64| j * w + i;
    for j in 0..h {
        for i in 0..w {
            if i + 1 < w {
                add(at(i, j), at(i + 1, j), SpringKind::Stretch);
            }
            if j + 1 < h {
                add(at(i, j), at(i, j + 1), SpringKind::Stretch);
            }
            let quad = i + 1 < w && j + 1 < h;
            if quads {
                if quad {
                    add(at(i, j), at(i + 1, j + 1), SpringKind::Shear);
                    add(at(i + 1, j), at(i, j + 1), SpringKind::Shear);
                }
                // Bends across interior edges: p(i-1) to p(i+1) across the edge at column i.
                if i >= 1 && i + 1 < w {
                    add(at(i - 1, j), at(i + 1, j), SpringKind::Bend);
                }
                if j >= 1 && j + 1 < h {
                    add(at(i, j - 1), at(i, j + 1), SpringKind::Bend);
                }
            } else {
                if quad {
                    // The diagonal is an edge; the bend across it joins the other two corners.
                    add(at(i, j), at(i + 1, j + 1), SpringKind::Stretch);
                    add(at(i + 1, j), at(i, j + 1), SpringKind::Bend);
                }
                // Across the horizontal edge (i, j)-(i+1, j): (i, j-1) and (i+1, j+1).
                if i + 1 < w && j >= 1 && j + 1 < h {
                    add(at(i, j - 1), at(i + 1, j + 1), SpringKind::Bend);
                }
                // Across the vertical edge (i, j)-(i, j+1): (i-1, j) and (i+1, j+1).
                if i >= 1 && i + 1 < w && j + 1 < h {
                    add(at(i - 1, j), at(i + 1, j + 1), SpringKind::Bend);
                }
            }
        }
    }
    s
}

fn run(topology: Topology, steps: usize) -> Cloth {
    let config = ClothConfig {
        integrator: Integrator::SymplecticEuler,
        ..ClothConfig::default()
    };
    let mut c = Cloth::new(topology, config).unwrap();
    let top: Vec<u32> = (0..W).map(|i| grid_index(W, i, 0)).collect();
    c.set_pinned(&top).unwrap();
    for k in 0..steps {
        // Swing the top edge so every spring family works.
        let t = (k + 1) as f64 * 5e-4;
        let targets: Vec<Vec3> = top
            .iter()
            .map(|&i| c.topology().rest_positions[i as usize] + Vec3::new(0.0, 0.0, 0.05 * (6.0 * t).sin()))
            .collect();
        c.set_pin_targets(&top, &targets).unwrap();
        c.step(5e-4).unwrap();
    }
    c
}

fn mesh_matches_grid_with_equivalent_springs(quads: bool) {
    let x = grid_positions();
    let idx = faces(quads);
    let mesh = MeshSpec {
        positions: &x,
        indices: &idx,
        face_size: if quads { 4 } else { 3 },
        mass: MeshMass::Total(0.1),
    }
    .build()
    .unwrap();
    let reference = Topology::new(
        x.clone(),
        mesh.masses.clone(),
        expected_springs(quads, &x),
        mesh.triangles.clone(),
        None,
    );
    let spring_set = |t: &Topology| {
        let mut v: Vec<_> = t.springs.iter().map(|s| (s.i, s.j, s.kind as u8)).collect();
        v.sort();
        v
    };
    assert_eq!(spring_set(&mesh), spring_set(&reference), "quads: {quads}");
    let (a, b) = (run(mesh, 1200), run(reference, 1200));
    let worst = a
        .positions()
        .iter()
        .zip(b.positions())
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-12, "quads: {quads}: max difference {worst:e} m");
    // And the cloth did move (so agreeing means something).
    let moved = a
        .positions()
        .iter()
        .zip(&x)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(moved > 0.01, "{moved}");
}

#[test]
fn quad_mesh_moves_as_the_grid_with_the_same_springs() {
    mesh_matches_grid_with_equivalent_springs(true);
}

#[test]
fn triangulated_grid_moves_as_the_grid_with_the_same_springs() {
    mesh_matches_grid_with_equivalent_springs(false);
}

#[test]
fn lumped_masses_follow_the_area() {
    let x = grid_positions();
    let t = MeshSpec {
        positions: &x,
        indices: &faces(false),
        face_size: 3,
        mass: MeshMass::ArealDensity(2.0),
    }
    .build()
    .unwrap();
    let area = 0.02 * 0.02 * f64::from((W - 1) * (H - 1));
    approx::assert_relative_eq!(t.masses.iter().sum::<f64>(), 2.0 * area, max_relative = 1e-12);
    // Interior vertices carry one cell's area (six triangles of half a cell, a third each).
    let interior = grid_index(W, 3, 3) as usize;
    approx::assert_relative_eq!(t.masses[interior], 2.0 * 0.02 * 0.02, max_relative = 1e-12);
}

/// A free cloth (no pins) above a collider, falling under its weight in water for `seconds`.
fn drop_onto(collider: Collider, friction: f64, seconds: f64) -> Cloth {
    let topology = GridSpec {
        width: 11,
        height: 11,
        spacing: 0.01,
        total_mass: 0.0121,
    }
    .build()
    .unwrap();
    let mut c = Cloth::new(
        topology,
        ClothConfig {
            integrator: Integrator::SymplecticEuler,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    // Lay the cloth flat (x-z plane) 3 cm above y = 0.
    let flat: Vec<Vec3> = c.positions().iter().map(|p| Vec3::new(p.x, 0.03, p.y)).collect();
    c.set_positions(&flat).unwrap();
    let id = c.add_collider(collider).unwrap();
    c.set_collider_friction(id, friction).unwrap();
    let steps = (seconds / 5e-4) as usize;
    for _ in 0..steps {
        c.step(5e-4).unwrap();
    }
    c
}

#[test]
fn plane_holds_the_cloth_and_friction_stops_sliding() {
    let flat = Collider::Plane(Plane {
        point: Vec3::zeros(),
        normal: Vec3::new(0.0, 2.0, 0.0), // any length: normalised
        velocity: Vec3::zeros(),
    });
    let c = drop_onto(flat, 0.0, 3.0);
    let lowest = c.positions().iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    assert!(lowest > -0.005, "cloth sank {lowest} m into the plane");
    assert!(lowest < 0.02, "cloth never reached the plane: {lowest}");
    // A tilted plane (20 degrees): without friction the cloth slides down, with enough it stays.
    let tilt = 20f64.to_radians();
    let tilted = Collider::Plane(Plane {
        point: Vec3::zeros(),
        normal: Vec3::new(tilt.sin(), tilt.cos(), 0.0),
        velocity: Vec3::zeros(),
    });
    let centre = |c: &Cloth| c.positions().iter().sum::<Vec3>() / c.vertex_count() as f64;
    let slid = centre(&drop_onto(tilted, 0.0, 3.0)).x;
    let held = centre(&drop_onto(tilted, 1.0, 3.0)).x;
    assert!(slid > 0.01, "frictionless cloth slid only {slid} m");
    assert!(
        held.abs() < 0.25 * slid,
        "with friction 1 it slid {held} m (frictionless {slid} m)"
    );
}

#[test]
fn capsule_keeps_the_cloth_out() {
    let capsule = Collider::Capsule(Capsule {
        a: Vec3::new(-0.1, -0.02, -0.05),
        b: Vec3::new(0.1, -0.02, -0.05),
        radius: 0.02,
        velocity: Vec3::zeros(),
    });
    let c = drop_onto(capsule, 0.0, 2.0);
    let inside = c
        .positions()
        .iter()
        .map(|p| match capsule.probe(p).0 {
            d if d < 0.0 => -d,
            _ => 0.0,
        })
        .fold(0.0, f64::max);
    assert!(inside < 0.005, "deepest penetration {inside} m");
    // It draped over: the middle rests on the capsule, the edges hang lower.
    let mid = c.positions()[grid_index(11, 5, 5) as usize].y;
    let edge = c.positions()[grid_index(11, 5, 0) as usize].y;
    assert!(mid > edge + 0.01, "mid {mid}, edge {edge}");
}

#[test]
fn moving_plane_pushes_the_cloth() {
    // A floor rising at 5 cm/s, moved by the host each step with its velocity given.
    let topology = GridSpec {
        width: 5,
        height: 5,
        spacing: 0.01,
        total_mass: 0.0025,
    }
    .build()
    .unwrap();
    let mut c = Cloth::new(topology, ClothConfig::default()).unwrap();
    let flat: Vec<Vec3> = c.positions().iter().map(|p| Vec3::new(p.x, 0.0, p.y)).collect();
    c.set_positions(&flat).unwrap();
    let plane = |t: f64| {
        Collider::Plane(Plane {
            point: Vec3::new(0.0, -0.02 + 0.05 * t, 0.0),
            normal: Vec3::y(),
            velocity: Vec3::new(0.0, 0.05, 0.0),
        })
    };
    let id = c.add_collider(plane(0.0)).unwrap();
    for _ in 0..4000 {
        c.set_collider(id, plane(c.time())).unwrap();
        c.step(5e-4).unwrap();
    }
    let floor = -0.02 + 0.05 * c.time();
    let lowest = c.positions().iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    assert!(lowest > floor - 0.005, "cloth at {lowest} below floor {floor}");
}

#[test]
fn soft_pins_sit_between_free_and_pinned() {
    let build = || {
        let t = GridSpec {
            width: 5,
            height: 5,
            spacing: 0.01,
            total_mass: 0.0025,
        }
        .build()
        .unwrap();
        let mut c = Cloth::new(t, ClothConfig::default()).unwrap();
        // A current pushes the hanging cloth sideways, so a free corner travels far.
        c.set_current(Vec3::new(0.0, 0.0, 0.3)).unwrap();
        c
    };
    let corner = grid_index(5, 4, 4);
    let drop_of = |weight: f64| {
        let mut c = build();
        c.pin_group(&(0..5).collect::<Vec<u32>>(), 1.0).unwrap();
        if weight > 0.0 {
            c.pin_group(&[corner], weight).unwrap();
        }
        let rest = c.positions()[corner as usize];
        for _ in 0..2000 {
            c.step(5e-4).unwrap();
        }
        (rest - c.positions()[corner as usize]).norm()
    };
    let (free, soft, full) = (drop_of(0.0), drop_of(0.02), drop_of(1.0));
    assert_eq!(full, 0.0);
    assert!(free > 0.01, "{free}");
    assert!(soft > 0.0 && soft < 0.5 * free, "free {free}, soft {soft}");
    // Weights for every vertex at once; out-of-range weights are refused.
    let mut c = build();
    let mut w = vec![0.0; 25];
    w[0] = 1.0;
    w[1] = 0.5;
    c.set_pin_weights(&w).unwrap();
    assert_eq!(c.pinned(), &[0, 1]);
    w[2] = 1.5;
    assert!(c.set_pin_weights(&w).is_err());
    assert_eq!(c.pinned(), &[0, 1]);
}
