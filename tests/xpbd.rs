//! The XPBD integrator (`Integrator::Xpbd`, `FC_INTEGRATOR_XPBD`) on the underwater towel:
//! the substeps its automatic step takes, the slow swing's look against symplectic Euler's by
//! the project's meter, the hang at rest, a refused call, and the scenes at its limits.

use fraccloth::forces::{Collider, Sphere};
use fraccloth::topology::grid_index;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model, Vec3};
use fraccloth_tools::look::measure;
use fraccloth_tools::scenes::{Drive, SceneKind, SceneSpec, Variant};

/// The underwater swing (4 cm at `freq` Hz) baked for `seconds` at 60 Hz frames with the
/// automatic step: (half-waves, travel speed, mid ratio), the hang depth, and the substeps a
/// frame took on average.
fn swing(integrator: Integrator, freq: f64, seconds: f64, jittered: bool) -> ([f64; 3], f64, f64) {
    let spec = SceneSpec {
        integrator,
        dt: 1.0 / 60.0,
        max_substep: fraccloth::cloth::AUTO,
        drive: Drive {
            amplitude: 0.04,
            frequency: freq,
            ramp: 0.0,
            current: Vec3::zeros(),
        },
        model: Some(Model::underwater()),
        jittered,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
    };
    let mut scene = spec.build().unwrap();
    let topo = scene.cloth.topology().clone();
    let (mut frames, mut times) = (vec![scene.cloth.positions().to_vec()], vec![0.0]);
    let mut substeps = 0u64;
    let count = (seconds * 60.0) as usize;
    for k in 1..=count {
        scene.step().unwrap();
        substeps += u64::from(scene.cloth.step_stats().substeps);
        if k % 2 == 0 {
            frames.push(scene.cloth.positions().to_vec());
            times.push(scene.cloth.time());
        }
    }
    let look = measure(&topo.rest_positions, &topo.triangles, &frames, &times, Vec3::y()).unwrap();
    let d = look.descriptors;
    (
        [d.half_waves, d.travel_speed.unwrap_or(0.0), d.mid_ratio],
        d.hang_depth,
        substeps as f64 / count as f64,
    )
}

#[test]
fn a_frame_takes_three_substeps_and_the_slow_swing_keeps_its_look() {
    let (reference, _, explicit_substeps) = swing(Integrator::SymplecticEuler, 0.5, 12.0, false);
    let (look, hang, substeps) = swing(Integrator::Xpbd, 0.5, 12.0, false);
    // Symplectic Euler's stable step is set by the stretch springs; XPBD's by the bend springs
    // and the water.
    assert!(
        explicit_substeps > 12.0 && substeps <= 3.5,
        "{explicit_substeps} {substeps}"
    );
    for k in 0..3 {
        let deviation = look[k] / reference[k] - 1.0;
        assert!(
            deviation.abs() < 0.05,
            "descriptor {k}: {look:?} against {reference:?}"
        );
    }
    // The towel is 0.40 m long; it hangs at least 0.9 of it while swung.
    assert!(hang > 0.36 && hang < 0.41, "hang {hang}");
}

#[test]
fn the_jittered_mesh_takes_the_same_few_substeps() {
    let (look, hang, substeps) = swing(Integrator::Xpbd, 1.0, 3.0, true);
    assert!(substeps <= 4.0, "{substeps}");
    assert!(
        look.iter().all(|d| d.is_finite()) && hang > 0.3,
        "{look:?} {hang}"
    );
}

/// A 31 x 21 cloth of `model` (1 cm, 1 kg/m^2) hanging from its top row, with the automatic
/// step.
fn pinned(model: Model, integrator: Integrator) -> Cloth {
    let (w, h) = (31u32, 21u32);
    let t = GridSpec {
        width: w,
        height: h,
        spacing: 0.01,
        total_mass: 1e-4 * f64::from(w * h),
    }
    .build()
    .unwrap();
    let config = ClothConfig {
        model,
        integrator,
        max_substep: fraccloth::cloth::AUTO,
        ..ClothConfig::default()
    };
    let mut c = Cloth::new(t, config).unwrap();
    let top: Vec<u32> = (0..w).map(|i| grid_index(w, i, 0)).collect();
    c.set_pinned(&top).unwrap();
    c
}

/// The underwater cloth of [`pinned`] with a sphere under it and self-collision on, stepped
/// `seconds` in 60 Hz frames.
fn hanging(integrator: Integrator, seconds: f64) -> Cloth {
    let mut model = Model::underwater();
    model.self_collision_relative = 0.4;
    let mut c = pinned(model, integrator);
    c.add_collider(Collider::Sphere(Sphere {
        center: Vec3::new(0.15, -0.3, 0.05),
        radius: 0.06,
        velocity: Vec3::zeros(),
    }))
    .unwrap();
    for _ in 0..(seconds * 60.0) as usize {
        c.step(1.0 / 60.0).unwrap();
    }
    c
}

#[test]
fn it_hangs_where_symplectic_euler_hangs_with_colliders_and_self_collision() {
    let (a, b) = (
        hanging(Integrator::SymplecticEuler, 4.0),
        hanging(Integrator::Xpbd, 4.0),
    );
    let low = |c: &Cloth| c.positions().iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    // The constraints' rest is the springs' rest: the same hang within a millimetre.
    assert!((low(&a) - low(&b)).abs() < 1e-3, "{} {}", low(&a), low(&b));
    assert!(b.positions().iter().all(|p| p.iter().all(|c| c.is_finite())));
}

#[test]
fn a_refused_call_leaves_the_cloth_as_it_was() {
    let mut c = hanging(Integrator::Xpbd, 0.2);
    let before = (c.positions().to_vec(), c.velocities().to_vec(), c.time());
    // A pin jumped 1 m in one fixed step of a frame: too fast for the speed limit.
    let mut config = c.config().clone();
    config.max_substep = 0.0;
    config.max_speed = 1.0;
    c.reconfigure(config).unwrap();
    let top: Vec<u32> = (0..31).collect();
    let targets: Vec<Vec3> = top
        .iter()
        .map(|&i| c.positions()[i as usize] + Vec3::new(0.0, 0.0, 1.0))
        .collect();
    c.set_pin_targets(&top, &targets).unwrap();
    let err = c.step(1.0 / 60.0).unwrap_err();
    assert!(err.to_string().contains("XPBD"), "{err}");
    assert_eq!(
        (c.positions().to_vec(), c.velocities().to_vec(), c.time()),
        before
    );
}

#[test]
fn a_current_presses_it_on_a_mesh_wall_it_does_not_pass() {
    let (explicit, front) = (
        pressed_on_a_wall(Integrator::SymplecticEuler),
        pressed_on_a_wall(Integrator::Xpbd),
    );
    let z = 0.03;
    // Pressed on the wall (the current alone would carry the free edge far past it) and not
    // through it, where symplectic Euler keeps it.
    assert!(front > z - 0.02 && front < z, "front {front}");
    assert!((front - explicit).abs() < 2e-3, "{front} against {explicit}");
}

/// How far the cloth reaches along a 0.3 m/s current towards a mesh wall 3 cm in front of it.
fn pressed_on_a_wall(integrator: Integrator) -> f64 {
    let mut model = Model::underwater();
    model.current = Vec3::new(0.0, 0.0, 0.3);
    let mut c = pinned(model, integrator);
    // A wall of two triangles 3 cm in front of the cloth, across the current.
    let z = 0.03;
    let wall = [
        Vec3::new(-0.5, 0.05, z),
        Vec3::new(0.5, 0.05, z),
        Vec3::new(0.5, -0.4, z),
        Vec3::new(-0.5, -0.4, z),
    ];
    c.add_mesh_collider(&wall, &[[0, 1, 2], [0, 2, 3]], None).unwrap();
    for _ in 0..120 {
        c.step(1.0 / 60.0).unwrap();
    }
    c.positions()
        .iter()
        .map(|p| p.z)
        .fold(f64::NEG_INFINITY, f64::max)
}
