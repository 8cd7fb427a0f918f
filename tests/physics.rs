//! Physics checks of the paper's model (issue: fractional cloth core).

use fraccloth::forces::body_force;
use fraccloth::history::Scheme;
use fraccloth::{Cloth, ClothConfig, GridSpec, Model, RegularDrag, SpringDamping, Vec3};
use fraccloth_tools::scenes::{sphere_at, SceneKind, SceneSpec, Variant};

fn free_particles(model: Model) -> Cloth {
    // 2 x 2 grid with every spring switched off: four independent particles.
    let topology = GridSpec {
        width: 2,
        height: 2,
        spacing: 0.01,
        total_mass: 4.0e-4,
    }
    .build()
    .unwrap();
    Cloth::new(
        topology,
        ClothConfig {
            model,
            ..ClothConfig::default()
        },
    )
    .unwrap()
}

#[test]
fn sinking_particle_reaches_the_terminal_velocity_of_buoyancy_and_viscous_drag() {
    let model = Model {
        stretch_stiffness: 0.0,
        shear_stiffness: 0.0,
        bend_stiffness: 0.0,
        spring_damping_mode: SpringDamping::None,
        history_drag: 0.0,
        viscous_drag: 1.0e-3,
        ..Model::fractional()
    };
    let mut cloth = free_particles(model);
    let m = cloth.topology().masses[0];
    let terminal = body_force(&model, m) / model.viscous_drag;
    // Independent of the code under test: (1 - rho_w / rho_c) m g / k_vd.
    let expected_y = (1.0 - 1000.0 / 1100.0) * m * -9.81 / 1.0e-3;
    assert!((terminal.y - expected_y).abs() < 1e-12);
    let tau = m / model.viscous_drag;
    let dt = tau / 200.0;
    let mut t = 0.0;
    while t < tau - 0.5 * dt {
        cloth.step(dt).unwrap();
        t += dt;
    }
    // After one time constant: 1 - 1/e of the way (first-order method, small dt).
    let v1 = cloth.velocities()[0].y / expected_y;
    assert!((v1 - (1.0 - (-1f64).exp())).abs() < 5e-3, "v(tau)/v_term = {v1}");
    while t < 15.0 * tau {
        cloth.step(dt).unwrap();
        t += dt;
    }
    for v in cloth.velocities() {
        assert!(
            (v.y / expected_y - 1.0).abs() < 1e-5,
            "v = {v:?}, terminal {expected_y}"
        );
        assert!(v.x.abs() < 1e-15 && v.z.abs() < 1e-15);
    }
}

#[test]
fn pinned_vertices_sit_exactly_on_their_targets_after_every_step() {
    let mut scene = SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
        .build()
        .unwrap();
    let top = scene.top_row().to_vec();
    let rest: Vec<Vec3> = top.iter().map(|&i| scene.cloth.positions()[i as usize]).collect();
    for _ in 0..400 {
        scene.step().unwrap();
        let t = scene.cloth.time();
        let off = fraccloth_tools::scenes::top_offset(SceneKind::Swing, Variant::Fractional, t);
        for (k, &i) in top.iter().enumerate() {
            assert_eq!(scene.cloth.positions()[i as usize], rest[k] + off, "t = {t}");
        }
    }
    // And through explicit targets: move one pin off the swing; it lands exactly there.
    let target = scene.cloth.positions()[top[3] as usize] + Vec3::new(1.25e-3, -0.5e-3, 0.75e-3);
    scene.cloth.set_pin_targets(&[top[3]], &[target]).unwrap();
    scene.cloth.step(5e-4).unwrap();
    assert_eq!(scene.cloth.positions()[top[3] as usize], target);
}

fn kick(cloth: &mut Cloth) {
    let v: Vec<Vec3> = (0..cloth.vertex_count())
        .map(|i| Vec3::new(0.02, 0.0, 0.15 * ((i % 7) as f64 - 3.0) / 3.0))
        .collect();
    cloth.set_velocities(&v).unwrap();
}

#[test]
fn energy_of_an_unforced_damped_cloth_decreases() {
    for variant in [
        Variant::Regular(RegularDrag::ViscousAndNormal),
        Variant::Regular(RegularDrag::Viscous),
        Variant::Regular(RegularDrag::Normal),
    ] {
        let mut spec = SceneSpec::paper(SceneKind::Swing, variant);
        spec.width = 31;
        spec.height = 21;
        let mut scene = spec.build().unwrap();
        let cloth = &mut scene.cloth; // pins stay where they are: no forcing
        kick(cloth);
        let mut last = cloth.energy();
        let first = last;
        for _ in 0..200 {
            for _ in 0..10 {
                cloth.step(spec.dt).unwrap();
            }
            let e = cloth.energy();
            assert!(
                e <= last + 1e-12 * last.abs(),
                "{}: energy rose {last} -> {e}",
                variant.name()
            );
            last = e;
        }
        assert!(last < first, "{}", variant.name());
    }
    // The fractional cloth too, sampled every 100 steps (its damping has memory, so it
    // is not asserted step by step).
    let mut spec = SceneSpec::paper(SceneKind::Swing, Variant::Fractional);
    spec.width = 31;
    spec.height = 21;
    let mut scene = spec.build().unwrap();
    kick(&mut scene.cloth);
    let mut last = scene.cloth.energy();
    for _ in 0..20 {
        for _ in 0..100 {
            scene.cloth.step(spec.dt).unwrap();
        }
        let e = scene.cloth.energy();
        assert!(e < last, "fractional: energy rose {last} -> {e}");
        last = e;
    }
}

/// Deepest penetration (m, > 0 inside) allowed for the sphere scene: half the 1 cm
/// spacing. The penalty force only starts inside the 1 cm collision margin.
const SPHERE_TOLERANCE: f64 = 0.005;

#[test]
fn no_particle_ends_inside_the_sphere() {
    for variant in [Variant::Fractional, Variant::Regular(RegularDrag::Normal)] {
        let mut scene = SceneSpec::paper(SceneKind::Sphere, variant).build().unwrap();
        let mut deepest = f64::NEG_INFINITY;
        let mut touched = 0usize;
        while scene.cloth.time() < 3.0 {
            scene.step().unwrap();
            let s = sphere_at(scene.cloth.time());
            for p in scene.cloth.positions() {
                let depth = s.radius - (p - s.center).norm();
                deepest = deepest.max(depth);
                if depth > -0.01 {
                    touched += 1;
                }
            }
        }
        assert!(touched > 1000, "the sphere never met the cloth");
        assert!(
            deepest < SPHERE_TOLERANCE,
            "{}: a particle is {deepest} m inside the sphere",
            variant.name()
        );
    }
}

fn rms_difference(a: &[Vec3], b: &[Vec3]) -> f64 {
    (a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum::<f64>() / a.len() as f64).sqrt()
}

#[test]
fn fractional_and_regular_swing_differ_measurably() {
    let run = |variant| {
        let mut s = SceneSpec::paper(SceneKind::Swing, variant).build().unwrap();
        s.run_until(3.0).unwrap();
        s.cloth.positions().to_vec()
    };
    let frac = run(Variant::Fractional);
    let reg = run(Variant::Regular(RegularDrag::Normal));
    let d = rms_difference(&frac, &reg);
    assert!(d > 5e-3, "RMS difference only {d} m");
    // And the memory itself matters: u = 1 against the paper's u = 3.
    let mut short = SceneSpec::paper(SceneKind::Swing, Variant::Fractional);
    short.scheme = Scheme::Truncated { u: 1 };
    let mut s = short.build().unwrap();
    s.run_until(3.0).unwrap();
    let d1 = rms_difference(&frac, s.cloth.positions());
    assert!(d1 > 1e-4, "u = 1 and u = 3 differ by only {d1} m");
}

#[test]
fn a_cloth_without_fractional_terms_keeps_no_history() {
    let s = SceneSpec::paper(SceneKind::Swing, Variant::Regular(RegularDrag::Normal))
        .build()
        .unwrap();
    assert!(s.cloth.history().is_off());
    let f = SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
        .build()
        .unwrap();
    assert!(!f.cloth.history().is_off());
}

/// Spring damping per family: scales (0, 0, 0) damp nothing (the same forces as no damping),
/// (1, 1, 1) is the common value, and one family can be damped alone.
#[test]
fn spring_damping_can_be_set_per_family() {
    use fraccloth::forces::{total_forces, ForceInput, ForceScratch};
    let t = fraccloth::GridSpec {
        width: 6,
        height: 5,
        spacing: 0.01,
        total_mass: 0.01,
    }
    .build()
    .unwrap();
    let n = t.vertex_count();
    let x: Vec<Vec3> = t
        .rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| p + 1e-3 * Vec3::new((i as f64).sin(), 0.0, (i as f64 * 0.7).cos()))
        .collect();
    let v: Vec<Vec3> = (0..n)
        .map(|i| Vec3::new((i as f64 * 1.3).cos(), (i as f64).sin(), 0.2))
        .collect();
    let forces = |scale: [f64; 3], damping: f64| {
        let model = Model {
            spring_damping: damping,
            spring_damping_mode: SpringDamping::Velocity,
            spring_damping_scale: scale,
            ..Model::fractional()
        };
        let mut f = vec![Vec3::zeros(); n];
        let input = ForceInput {
            model: &model,
            topology: &t,
            x: &x,
            v: &v,
            half_derivative: &[],
            colliders: &[],
            prior_forces: &[],
            weights: Default::default(),
            skin_mean: &[],
        };
        total_forces(&input, &mut ForceScratch::default(), &mut f);
        f
    };
    let undamped = forces([1.0; 3], 0.0);
    assert_eq!(forces([0.0; 3], 0.1), undamped);
    let all = forces([1.0; 3], 0.1);
    let bend_only = forces([0.0, 0.0, 1.0], 0.1);
    let stretch_only = forces([1.0, 0.0, 0.0], 0.1);
    assert_ne!(bend_only, undamped);
    assert_ne!(bend_only, all);
    // Damping is linear in the velocities: the families' parts add up to the whole.
    let shear_only = forces([0.0, 1.0, 0.0], 0.1);
    for i in 0..n {
        let sum =
            (bend_only[i] - undamped[i]) + (stretch_only[i] - undamped[i]) + (shear_only[i] - undamped[i]);
        assert!((sum - (all[i] - undamped[i])).norm() < 1e-12, "{i}");
    }
}
