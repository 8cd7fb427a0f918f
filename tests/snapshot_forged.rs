//! A snapshot that loads can always step: forged snapshots with a valid checksum whose history
//! holds finite but absurd values are refused, naming the history; and the cross-model rule
//! (`fc_cloth_load_snapshot` in the header): a snapshot carries the state, the receiving cloth
//! keeps its own model, and the topology must be the same.

use fraccloth::history::Scheme;
use fraccloth::topology::{MeshMass, MeshSpec};
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model, Vec3};

fn grid() -> fraccloth::Topology {
    GridSpec {
        width: 6,
        height: 5,
        spacing: 0.01,
        total_mass: 0.003,
    }
    .build()
    .unwrap()
}

fn cloth(scheme: Scheme, model: Model, integrator: Integrator) -> Cloth {
    let mut c = Cloth::new(
        grid(),
        ClothConfig {
            model,
            scheme,
            integrator,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    c.set_pinned(&[0, 1, 2, 3, 4, 5]).unwrap();
    c
}

/// Rewrites the snapshot's checksum after a change to its body.
fn reseal(snap: &mut [u8]) {
    let n = snap.len();
    let crc = crc32fast::hash(&snap[..n - 4]);
    snap[n - 4..].copy_from_slice(&crc.to_le_bytes());
}

fn stepped(scheme: Scheme) -> (Cloth, Vec<u8>) {
    let mut a = cloth(scheme, Model::fractional(), Integrator::SymplecticEuler);
    for _ in 0..40 {
        a.step(5e-4).unwrap();
    }
    let snap = a.save_snapshot().unwrap();
    (a, snap)
}

/// The load is refused naming `want`, and the cloth refusing it is unchanged: a twin that
/// was never given the snapshot holds the same state, bit for bit (its own snapshot's bytes:
/// positions, velocities, pins, history, collisions), before and after both step on.
fn refused_and_unchanged(snap: &[u8], scheme: Scheme, want: &str) {
    let make = || {
        let mut c = cloth(scheme, Model::fractional(), Integrator::SymplecticEuler);
        for _ in 0..7 {
            c.step(5e-4).unwrap();
        }
        c
    };
    let (mut b, mut twin) = (make(), make());
    let err = b.load_snapshot(snap).expect_err("a forged snapshot was accepted");
    assert!(err.message.contains(want), "{}", err.message);
    assert!(
        b.save_snapshot().unwrap() == twin.save_snapshot().unwrap(),
        "the cloth changed"
    );
    for _ in 0..5 {
        b.step(5e-4).unwrap();
        twin.step(5e-4).unwrap();
    }
    assert!(
        b.save_snapshot().unwrap() == twin.save_snapshot().unwrap(),
        "the cloth steps on otherwise than its twin"
    );
}

#[test]
fn finite_but_absurd_soe_modes_are_refused_naming_the_history() {
    let (a, snap) = stepped(Scheme::DEFAULT);
    // The SOE state ends: modes (n K 3 f64), prev and newest (u64 length + 24 n bytes each), a
    // flag byte and two f64; then the (empty) strain history, the collision state (three empty
    // counts), the motion averages (two f64), the skin drag's (empty) mean and the checksum.
    let n = a.vertex_count();
    let k = a.history().mode_count();
    let end = snap.len() - 4 - 8 - 16 - 24 - 8 - 8 - 1 - 2 * (8 + 24 * n);
    for value in [1e300f64, -3e200, 1e30] {
        let mut forged = snap.clone();
        for p in (end - 8 * n * k * 3..end).step_by(8) {
            forged[p..p + 8].copy_from_slice(&value.to_le_bytes());
        }
        reseal(&mut forged);
        refused_and_unchanged(
            &forged,
            Scheme::DEFAULT,
            "half-derivative history holds values the cloth cannot step from (a trial step",
        );
    }
    // The untouched snapshot loads and steps.
    let mut b = cloth(Scheme::DEFAULT, Model::fractional(), Integrator::SymplecticEuler);
    b.load_snapshot(&snap).unwrap();
    b.step(5e-4).unwrap();
}

#[test]
fn a_full_history_whose_now_is_outside_the_cloths_life_is_refused() {
    let (_, snap) = stepped(Scheme::Full);
    for now in [-1e9, -1.0, 1e9] {
        let mut forged = snap.clone();
        // The history's last f64, before the collision state (three empty counts) and the
        // motion averages (two f64) and the skin drag's (empty) mean.
        let at = forged.len() - 4 - 8 - 16 - 24 - 8;
        forged[at..at + 8].copy_from_slice(&f64::to_le_bytes(now));
        reseal(&mut forged);
        refused_and_unchanged(&forged, Scheme::Full, "full history");
    }
}

#[test]
fn a_snapshot_carries_the_state_and_the_receiving_cloth_keeps_its_model() {
    let (a, snap) = stepped(Scheme::DEFAULT);
    // Another model (springs 1000 times stiffer) and another integrator (implicit).
    let stiff = Model {
        stretch_stiffness: 1e4,
        ..Model::fractional()
    };
    let mut b = cloth(Scheme::DEFAULT, stiff, Integrator::ImplicitEuler);
    b.load_snapshot(&snap).unwrap();
    assert_eq!(b.positions(), a.positions());
    assert_eq!(b.velocities(), a.velocities());
    assert_eq!(b.time(), a.time());
    assert_eq!(b.model().stretch_stiffness, 1e4, "the receiving cloth's model");
    assert_eq!(b.config().integrator, Integrator::ImplicitEuler);
    b.step(1.0 / 60.0).unwrap();
}

#[test]
fn a_grids_snapshot_is_refused_by_the_same_geometry_built_as_a_quad_mesh() {
    let (_, snap) = stepped(Scheme::DEFAULT);
    let g = grid();
    let w = 6u32;
    let quads: Vec<u32> = (0..4)
        .flat_map(|j| {
            (0..5).flat_map(move |i| [j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i])
        })
        .collect();
    let t = MeshSpec {
        positions: &g.rest_positions,
        indices: &quads,
        face_size: 4,
        mass: MeshMass::Total(0.003),
    }
    .build()
    .unwrap();
    let mut m = Cloth::new(
        t,
        ClothConfig {
            scheme: Scheme::DEFAULT,
            integrator: Integrator::SymplecticEuler,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    let err = m.load_snapshot(&snap).expect_err("another topology was accepted");
    assert!(err.message.contains("another cloth"), "{}", err.message);
    assert_eq!(
        m.positions()[7],
        Vec3::new(m.positions()[7].x, m.positions()[7].y, 0.0)
    );
}

/// The 6 x 5 grid (in the plane z = 0, pinned along its top row) with one large triangle
/// collider 5 cm behind it, stepped 10 ms at 1 ms.
fn with_mesh_collider() -> (Cloth, u32) {
    let mut c = cloth(Scheme::Off, Model::default(), Integrator::SymplecticEuler);
    let tri = [
        Vec3::new(-1.0, -1.0, -0.05),
        Vec3::new(1.0, -1.0, -0.05),
        Vec3::new(0.0, 1.0, -0.05),
    ];
    let id = c.add_mesh_collider(&tri, &[[0, 1, 2]], None).unwrap();
    for _ in 0..10 {
        c.step(1e-3).unwrap();
    }
    (c, id)
}

/// Where the one mesh collider's triangle list sits in a snapshot: its vertex and triangle
/// counts (3 and 1) followed by the indices 0, 1, 2.
fn mesh_triangle_at(snap: &[u8]) -> usize {
    let mut pattern = Vec::new();
    for w in [3u64, 1] {
        pattern.extend_from_slice(&w.to_le_bytes());
    }
    for i in [0u32, 1, 2] {
        pattern.extend_from_slice(&i.to_le_bytes());
    }
    let at = snap
        .windows(pattern.len())
        .position(|w| w == pattern.as_slice())
        .expect("the mesh collider's triangle is in the snapshot");
    at + 16
}

#[test]
fn a_mesh_colliders_triangle_index_out_of_range_is_a_corrupted_snapshot() {
    let (c, _) = with_mesh_collider();
    let mut snap = c.save_snapshot().unwrap();
    let at = mesh_triangle_at(&snap) + 8; // the third index
    snap[at..at + 4].copy_from_slice(&7u32.to_le_bytes());
    reseal(&mut snap);
    let (mut b, _) = with_mesh_collider();
    let before = b.save_snapshot().unwrap();
    let err = b
        .load_snapshot(&snap)
        .expect_err("a forged snapshot was accepted");
    assert_eq!(
        err.kind,
        fraccloth::ErrorKind::InvalidArgument,
        "a corrupted snapshot is an invalid argument: {}",
        err.message
    );
    assert!(err.message.contains("snapshot"), "{}", err.message);
    assert!(b.save_snapshot().unwrap() == before, "the cloth changed");
}

#[test]
fn a_snapshot_whose_mesh_collider_move_cannot_be_stepped_is_refused() {
    // The collider is told to sweep 1 m through the cloth over the next call: at 1 ms that
    // carries the cloth at 1000 m/s, past max_speed, so the next 1 ms step is refused.
    let (mut a, id) = with_mesh_collider();
    let far = [
        Vec3::new(-1.0, -1.0, 0.95),
        Vec3::new(1.0, -1.0, 0.95),
        Vec3::new(0.0, 1.0, 0.95),
    ];
    a.set_mesh_collider(id, &far, None).unwrap();
    let snap = a.save_snapshot().unwrap();
    let refused = a.clone().step(1e-3).expect_err("the sweep was stepped");
    assert_eq!(
        refused.kind,
        fraccloth::ErrorKind::Unstable,
        "{}",
        refused.message
    );
    // The load's trial step is that step: the snapshot is refused and the cloth unchanged.
    let (mut b, _) = with_mesh_collider();
    let before = b.save_snapshot().unwrap();
    let err = b
        .load_snapshot(&snap)
        .expect_err("a snapshot that cannot step was loaded");
    assert_eq!(err.kind, fraccloth::ErrorKind::InvalidArgument, "{}", err.message);
    assert!(b.save_snapshot().unwrap() == before, "the cloth changed");
    b.step(1e-3).unwrap();
    // Its collider told to stay, the same state loads and steps.
    let mut calm = a.clone();
    let tri = [
        Vec3::new(-1.0, -1.0, -0.05),
        Vec3::new(1.0, -1.0, -0.05),
        Vec3::new(0.0, 1.0, -0.05),
    ];
    calm.set_mesh_collider(id, &tri, None).unwrap();
    let mut d = with_mesh_collider().0;
    d.load_snapshot(&calm.save_snapshot().unwrap()).unwrap();
    d.step(1e-3).unwrap();
}
