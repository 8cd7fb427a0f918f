use super::*;
use crate::{ClothConfig, GridSpec, Vec3};

/// A 6 x 5 cloth of `model`, symplectic Euler, its first three vertices pinned.
fn small(model: crate::Model, scheme: Scheme) -> Cloth {
    let t = GridSpec {
        width: 6,
        height: 5,
        spacing: 0.01,
        total_mass: 0.003,
    }
    .build()
    .unwrap();
    let mut c = Cloth::new(
        t,
        ClothConfig {
            model,
            scheme,
            integrator: crate::Integrator::SymplecticEuler,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    c.set_pinned(&[0, 1, 2]).unwrap();
    c
}

/// A snapshot's body (header and payload, no checksum) made whole as format `version`: its
/// version and payload length written, its checksum appended.
fn sealed(mut body: Vec<u8>, version: u32) -> Vec<u8> {
    body[8..12].copy_from_slice(&version.to_le_bytes());
    let payload = (body.len() - HEADER) as u64;
    body[16..24].copy_from_slice(&payload.to_le_bytes());
    let crc = crc32fast::hash(&body);
    body.extend_from_slice(&crc.to_le_bytes());
    body
}

fn cloth(scheme: Scheme) -> Cloth {
    let mut c = small(crate::Model::default(), scheme);
    c.pin_group(&[5], 0.5).unwrap();
    let id = c
        .add_collider(Collider::Capsule(Capsule {
            a: Vec3::new(-0.1, -0.03, 0.02),
            b: Vec3::new(0.1, -0.03, 0.02),
            radius: 0.01,
            velocity: Vec3::zeros(),
        }))
        .unwrap();
    c.set_collider_friction(id, 0.3).unwrap();
    c.set_current(Vec3::new(0.0, 0.0, 0.1)).unwrap();
    c
}

#[test]
fn restored_cloth_continues_bitwise_for_every_scheme() {
    for scheme in [Scheme::Off, Scheme::PAPER, Scheme::Full, Scheme::DEFAULT] {
        let mut a = cloth(scheme);
        for _ in 0..50 {
            a.step(5e-4).unwrap();
        }
        let snap = a.save_snapshot().unwrap();
        assert_eq!(snap.len(), a.snapshot_size());
        let mut b = cloth(scheme);
        b.load_snapshot(&snap).unwrap();
        for _ in 0..50 {
            a.step(5e-4).unwrap();
            b.step(5e-4).unwrap();
        }
        assert_eq!(a.positions(), b.positions(), "{}", scheme.name());
        assert_eq!(a.velocities(), b.velocities(), "{}", scheme.name());
        assert_eq!(a.time(), b.time());
    }
}

/// The unsteady skin drag's running mean is state: a snapshot carries it, so a cloth made
/// from it continues bitwise (left out of the load, the mean restarts from the flow and the
/// positions differ); a version-7 snapshot, without it, loads with the mean at the loaded
/// velocities relative to the water.
#[test]
fn the_skin_drags_running_mean_continues_bitwise_from_a_snapshot() {
    let make = || small(crate::Model::underwater(), Scheme::Off);
    let mut a = make();
    let rest: Vec<Vec3> = a.positions()[..3].to_vec();
    // The pins slide to and fro along the cloth's plane.
    let drive = |c: &mut Cloth, k: u32| {
        let s = Vec3::new(0.02 * (f64::from(k) * 0.01).sin(), 0.0, 0.0);
        let targets: Vec<Vec3> = rest.iter().map(|&r| r + s).collect();
        c.set_pin_targets(&[0, 1, 2], &targets).unwrap();
    };
    for k in 0..300 {
        drive(&mut a, k);
        a.step(1e-3).unwrap();
    }
    let n = a.vertex_count();
    assert_eq!(a.state.skin_mean.len(), n);
    assert!(a.state.skin_mean.iter().any(|m| m.x.abs() > 1e-4));
    let snap = a.save_snapshot().unwrap();
    let mut b = make();
    b.load_snapshot(&snap).unwrap();
    assert_eq!(b.state.skin_mean, a.state.skin_mean);
    // The same load with the mean restarted from the flow.
    let mut c = make();
    c.load_snapshot(&snap).unwrap();
    let current = c.config.model.current;
    c.state.skin_mean.clear();
    let restart = c.state.memories_for(&c.config.model).unwrap();
    c.state.change_memories(restart);
    for k in 300..400 {
        for cloth in [&mut a, &mut b, &mut c] {
            drive(cloth, k);
            cloth.step(1e-3).unwrap();
        }
    }
    assert_eq!(a.positions(), b.positions());
    assert_ne!(a.positions(), c.positions(), "the mean is state");
    // A version-7 snapshot (no mean): the mean starts from the loaded flow.
    let old = sealed(snap[..snap.len() - 4 - 8 - 24 * n].to_vec(), 7);
    let mut d = make();
    d.load_snapshot(&old).unwrap();
    let want: Vec<Vec3> = d.state.v.iter().map(|v| v - current).collect();
    assert_eq!(d.state.skin_mean, want);
    // A mean of the wrong length is refused, the cloth unchanged.
    let mut bad = snap[..snap.len() - 4 - 8 - 24 * n].to_vec();
    bad.extend_from_slice(&1u64.to_le_bytes());
    bad.extend_from_slice(&[0u8; 24]);
    let bad = sealed(bad, SNAPSHOT_VERSION);
    let before = d.save_snapshot().unwrap();
    assert!(d.load_snapshot(&bad).is_err());
    assert_eq!(d.save_snapshot().unwrap(), before);
}

/// A reconfigure that turns the unsteady skin drag off drops its mean; one that turns it
/// on starts it from the flow as it is; one that keeps it keeps the mean.
#[test]
fn reconfiguring_the_unsteady_skin_drag_drops_or_starts_its_mean() {
    let mut c = small(crate::Model::underwater(), Scheme::Off);
    for k in 0..50 {
        let s = Vec3::new(0.001 * f64::from(k), 0.0, 0.0);
        let targets: Vec<Vec3> = (0..3).map(|i| c.topology.rest_positions[i] + s).collect();
        c.set_pin_targets(&[0, 1, 2], &targets).unwrap();
        c.step(1e-3).unwrap();
    }
    let kept = c.state.skin_mean.clone();
    assert_eq!(kept.len(), c.vertex_count());
    let mut config = c.config.clone();
    config.model.current = Vec3::new(0.0, 0.0, 0.05);
    c.reconfigure(config.clone()).unwrap();
    assert_eq!(c.state.skin_mean, kept, "kept while the term stays on");
    config.model.water.skin_drag_unsteady = 0.0;
    c.reconfigure(config.clone()).unwrap();
    assert!(c.state.skin_mean.is_empty());
    config.model.water.skin_drag_unsteady = 1.0;
    c.reconfigure(config).unwrap();
    let want: Vec<Vec3> = c.state.v.iter().map(|v| v - Vec3::new(0.0, 0.0, 0.05)).collect();
    assert_eq!(c.state.skin_mean, want);
    c.step(1e-3).unwrap();
}

/// Implicit Euler's automatic step reads the motion's averages (`cloth/motion.rs`): a
/// snapshot carries them, so a cloth made from it takes the same substeps and bits.
/// With them left out of the load, the loaded cloth reads no motion and the test fails.
#[test]
fn implicit_eulers_automatic_step_continues_bitwise_from_a_snapshot() {
    let make = || {
        let mut c = cloth(Scheme::DEFAULT);
        c.config.integrator = crate::Integrator::ImplicitEuler;
        c.config.max_substep = crate::cloth::AUTO;
        c
    };
    let mut a = make();
    let rest: Vec<Vec3> = a.positions()[..3].to_vec();
    let drive = |c: &mut Cloth, k: u32| {
        let s = Vec3::new(0.01 * (f64::from(k) * 0.4).sin(), 0.0, 0.0);
        let targets: Vec<Vec3> = rest.iter().map(|&r| r + s).collect();
        c.set_pin_targets(&[0, 1, 2], &targets).unwrap();
    };
    for k in 0..20 {
        drive(&mut a, k);
        a.step(1.0 / 30.0).unwrap();
    }
    assert!(a.motion_frequency() > 0.0);
    let snap = a.save_snapshot().unwrap();
    let mut b = make();
    b.load_snapshot(&snap).unwrap();
    assert_eq!(a.motion_frequency(), b.motion_frequency());
    for k in 20..30 {
        drive(&mut a, k);
        drive(&mut b, k);
        a.step(1.0 / 30.0).unwrap();
        b.step(1.0 / 30.0).unwrap();
        assert_eq!(a.step_stats(), b.step_stats());
    }
    assert_eq!(a.positions(), b.positions());

    // A version-6 snapshot (no averages, and no skin drag mean: 8 bytes of an empty
    // list here) loads with the motion unseen.
    assert!(a.state.skin_mean.is_empty());
    let old = sealed(snap[..snap.len() - 4 - 8 - 16].to_vec(), 6);
    let mut c = make();
    c.load_snapshot(&old).unwrap();
    assert_eq!(c.motion_frequency(), 0.0);
}
