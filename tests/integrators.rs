//! Integrators: where they fail, that failure is safe, and that they converge.

mod common;

use common::reference::talbot;
use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;
use fraccloth::history::Scheme;
use fraccloth::{Cloth, Integrator};
use fraccloth_tools::oscillator::Oscillator;
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
use nalgebra::Complex;

const SOE: Scheme = Scheme::SumOfExponentials {
    tolerance: 1e-6,
    horizon: 100.0,
    min_dt: 1e-4,
};

/// Ratio of the largest deviation from equilibrium in the last quarter of a run to that in
/// its second quarter: < 1 decaying, > 1 growing.
fn growth(cloth: &mut Cloth, o: &Oscillator, dt: f64, steps: usize) -> f64 {
    let eq = o.f / o.k;
    let (mut a, mut b) = (0.0f64, 0.0f64);
    for k in 0..steps {
        cloth.step(dt).unwrap();
        let d = (Oscillator::elongation(cloth) - eq).abs();
        if (steps / 4..steps / 2).contains(&k) {
            a = a.max(d);
        } else if k >= 3 * steps / 4 {
            b = b.max(d);
        }
    }
    b / a
}

#[test]
fn explicit_euler_is_stable_just_below_its_predicted_bound_and_fails_safely_above() {
    let o = Oscillator::default();
    let bound = o.explicit_euler_bound(); // 2 |Re p| / |p|^2 for the dominant pole p
    assert!((bound - 0.0096).abs() < 2e-4, "bound {bound}");
    let below = growth(
        &mut o.cloth(SOE, Integrator::ExplicitEuler).unwrap(),
        &o,
        0.9 * bound,
        20_000,
    );
    let above = growth(
        &mut o.cloth(SOE, Integrator::ExplicitEuler).unwrap(),
        &o,
        1.1 * bound,
        20_000,
    );
    println!("growth over a run: {below:.3} at 0.9 x bound, {above:.3} at 1.1 x bound");
    assert!(below < 0.9, "not decaying below the bound: {below}");
    assert!(above > 1.1, "not growing above the bound: {above}");

    // Above the bound, through the C ABI: the growth ends in FC_ERROR_UNSTABLE, state intact.
    let mut d = fc_cloth_desc_default();
    d.width = 2;
    d.height = 2;
    d.spacing = 0.5;
    d.total_mass = 4.0;
    d.water_density = 0.0;
    d.gravity = [1.0 / 2f64.sqrt(), -1.0 / 2f64.sqrt(), 0.0];
    d.stretch_stiffness = 0.0;
    d.bend_stiffness = 0.0;
    d.shear_stiffness = o.k;
    d.spring_damping = 0.0;
    d.viscous_drag = 0.0;
    d.history_drag = o.c;
    d.history_tolerance = 1e-6;
    d.history_horizon = 1000.0;
    d.max_speed = 1.0; // the oscillation peaks near 0.2 m/s
    let mut c = std::ptr::null_mut();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&d, &mut c), FC_OK);
        assert_eq!(fc_cloth_set_pinned(c, [0u32, 1, 2].as_ptr(), 3), FC_OK);
        let dt = 1.25 * bound;
        let mut steps = 0;
        let status = loop {
            let s = fc_cloth_step(c, dt);
            if s != FC_OK || steps > 200_000 {
                break s;
            }
            steps += 1;
        };
        assert_eq!(status, FC_ERROR_UNSTABLE, "after {steps} steps");
        let msg = std::ffi::CStr::from_ptr(fc_last_error_message())
            .to_string_lossy()
            .to_string();
        assert!(
            msg.contains("explicit Euler") && msg.contains(&format!("{dt}")),
            "{msg}"
        );
        let mut before = [0f32; 12];
        let mut after = [0f32; 12];
        fc_cloth_get_positions(c, before.as_mut_ptr(), 12);
        let t = fc_cloth_time(c);
        assert_eq!(fc_cloth_step(c, dt), FC_ERROR_UNSTABLE);
        fc_cloth_get_positions(c, after.as_mut_ptr(), 12);
        assert_eq!(before, after);
        assert_eq!(t, fc_cloth_time(c));
        fc_cloth_destroy(c);
    }
}

#[test]
fn implicit_runs_stiff_swing_at_frame_rate_where_explicit_fails() {
    let spec = |integrator| SceneSpec {
        width: 31,
        height: 21,
        integrator,
        scheme: Scheme::DEFAULT,
        dt: 1.0 / 24.0,
        stiffness_scale: 100.0,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
    };
    let mut explicit = spec(Integrator::ExplicitEuler).build().unwrap();
    assert!(
        explicit.run_until(10.0).is_err(),
        "explicit Euler survived dt = 1/24 with stiff springs"
    );

    for integrator in [Integrator::ImplicitEuler, Integrator::ExtrapolatedImplicit] {
        stiff_swing_stays_bounded(spec(integrator).build().unwrap(), integrator);
    }
}

/// 10 s of the stiff swing at frame rate: energy bounded, nothing flies away.
fn stiff_swing_stays_bounded(mut implicit: fraccloth_tools::scenes::Scene, integrator: Integrator) {
    // Energy relative to the start, largest magnitude in the first and in the second 5 s.
    let e0 = implicit.cloth.energy();
    let (mut first, mut second) = (0.0f64, 0.0f64);
    let mut vmax = 0.0f64;
    while implicit.cloth.time() < 10.0 - 1e-9 {
        implicit.step().unwrap();
        let e = (implicit.cloth.energy() - e0).abs();
        assert!(e.is_finite());
        if implicit.cloth.time() <= 5.0 {
            first = first.max(e);
        } else {
            second = second.max(e);
        }
        vmax = vmax.max(
            implicit
                .cloth
                .velocities()
                .iter()
                .map(|v| v.norm())
                .fold(0.0, f64::max),
        );
    }
    println!("{}, 240 steps: |E - E0| up to {first:.4e} J (0-5 s), {second:.4e} J (5-10 s); max speed {vmax:.3} m/s", integrator.name());
    // Bounded: it does not grow from the first half to the second, and nothing flies away
    // (the pins move at most 0.25 m/s).
    assert!(second <= 1.2 * first, "energy grows: {first} then {second}");
    assert!(vmax < 1.0, "max speed {vmax}");
    let s = implicit.cloth.solver_stats();
    assert!(s.iterations > 0 && s.residual <= 1e-6, "{s:?}");
}

#[test]
fn every_integrator_converges_at_its_order_on_the_oscillator() {
    let o = Oscillator::default();
    let t_end = 1.0;
    let reference = talbot(
        |s| Complex::new(o.f, 0.0) / s / (s * s * o.m + s.sqrt() * o.c + o.k),
        t_end,
        32,
    );
    let scheme = Scheme::SumOfExponentials {
        tolerance: 1e-9,
        horizon: 10.0,
        min_dt: 1e-4,
    };
    let mut finals = vec![];
    for integrator in Integrator::ALL {
        let errs: Vec<f64> = [2e-3, 1e-3, 5e-4]
            .iter()
            .map(|&dt| {
                let mut c = o.cloth(scheme, integrator).unwrap();
                while c.time() < t_end - 0.5 * dt {
                    c.step(dt).unwrap();
                }
                (Oscillator::elongation(&c) - reference).abs()
            })
            .collect();
        let p = [(errs[0] / errs[1]).log2(), (errs[1] / errs[2]).log2()];
        println!(
            "{:17} errors {:.3e} {:.3e} {:.3e} orders {:.2} {:.2}",
            integrator.name(),
            errs[0],
            errs[1],
            errs[2],
            p[0],
            p[1]
        );
        let order = f64::from(integrator.order());
        for q in p {
            assert!(
                (order - 0.2..order + 0.3).contains(&q),
                "{}: order {q}, expected {order}",
                integrator.name()
            );
        }
        finals.push(errs[2]);
    }
    assert!(finals.iter().all(|&e| e < 5e-3), "{finals:?}");
}

#[test]
fn after_an_unstable_step_a_smaller_dt_continues_from_the_intact_state() {
    // Every history scheme: SOE folds the last accepted step into its modes during the step
    // that then fails, and the retry must sum them without folding again.
    for scheme in [Scheme::PAPER, Scheme::DEFAULT, Scheme::Full] {
        retry_after_an_unstable_step(scheme);
    }
}

fn retry_after_an_unstable_step(scheme: Scheme) {
    let spec = SceneSpec {
        width: 31,
        height: 21,
        scheme,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
    };
    let mut a = spec.build().unwrap();
    let mut b = spec.build().unwrap();
    for _ in 0..200 {
        a.step().unwrap();
        b.step().unwrap();
    }
    // Frame-rate steps explode the explicit integrator within a few steps (the first ones
    // still look sound); the step that is caught must change nothing.
    let mut accepted = 0;
    let err = loop {
        let before = (
            a.cloth.positions().to_vec(),
            a.cloth.velocities().to_vec(),
            a.cloth.time(),
        );
        match a.cloth.step(1.0 / 24.0) {
            Ok(()) => {
                accepted += 1;
                b.cloth.step(1.0 / 24.0).unwrap();
                assert!(
                    accepted < 10,
                    "{scheme:?}: explicit Euler never failed at dt = 1/24"
                );
            }
            Err(e) => {
                assert_eq!(
                    (
                        a.cloth.positions().to_vec(),
                        a.cloth.velocities().to_vec(),
                        a.cloth.time()
                    ),
                    before,
                    "{scheme:?}"
                );
                break e;
            }
        }
    };
    assert_eq!(err.kind, fraccloth::ErrorKind::Unstable);
    assert!(
        err.message.contains("explicit Euler") && err.message.contains("0.041666"),
        "{}",
        err.message
    );
    // The smaller dt that works for a calm cloth: go back to the scene's own after restoring
    // calm by hand (set the velocities to zero on both), then both runs must agree bitwise.
    let zero = vec![fraccloth::Vec3::zeros(); a.cloth.vertex_count()];
    a.cloth.set_velocities(&zero).unwrap();
    b.cloth.set_velocities(&zero).unwrap();
    // Retrying with the scene's dt continues exactly as if the failed step never happened.
    for _ in 0..200 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert_eq!(a.cloth.positions(), b.cloth.positions(), "{scheme:?}");
    assert_eq!(a.cloth.velocities(), b.cloth.velocities(), "{scheme:?}");
}

/// Largest distance between corresponding vertices (m).
fn max_distance(a: &[fraccloth::Vec3], b: &[fraccloth::Vec3]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).norm()).fold(0.0, f64::max)
}

#[test]
fn substeps_equal_manual_steps_and_restore_everything_on_failure() {
    let spec = SceneSpec {
        width: 21,
        height: 15,
        scheme: Scheme::DEFAULT,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
    };
    let mut a = spec.build().unwrap();
    let mut b = spec.build().unwrap();
    let top = a.top_row().to_vec();
    let targets: Vec<_> = top
        .iter()
        .map(|&i| a.cloth.positions()[i as usize] + fraccloth::Vec3::new(0.0, 0.0, 0.01))
        .collect();
    a.cloth.set_pin_targets(&top, &targets).unwrap();
    b.cloth.set_pin_targets(&top, &targets).unwrap();
    a.cloth.step_substeps(0.01, 20).unwrap();
    // The same by hand: 20 steps, pins moved 1/20 of the way each time.
    let start: Vec<_> = top.iter().map(|&i| b.cloth.positions()[i as usize]).collect();
    for k in 1..=20 {
        let goal: Vec<_> = start
            .iter()
            .zip(&targets)
            .map(|(s, t)| {
                if k == 20 {
                    *t
                } else {
                    s + (f64::from(k) / 20.0) * (t - s)
                }
            })
            .collect();
        b.cloth.set_pin_targets(&top, &goal).unwrap();
        b.cloth.step(0.0005).unwrap();
    }
    let max_diff = max_distance(a.cloth.positions(), b.cloth.positions());
    assert!(
        max_diff < 1e-12,
        "substeps differ from manual steps by {max_diff}"
    );
    assert_eq!(a.cloth.step_count(), 20);
    // A failing call (the last substeps explode) restores positions, velocities, history and time.
    let before = (
        a.cloth.positions().to_vec(),
        a.cloth.velocities().to_vec(),
        a.cloth.time(),
        a.cloth.step_count(),
    );
    let far: Vec<_> = targets
        .iter()
        .map(|t| t + fraccloth::Vec3::new(5.0, 0.0, 0.0))
        .collect();
    a.cloth.set_pin_targets(&top, &far).unwrap();
    let err = a.cloth.step_substeps(0.01, 4).unwrap_err();
    assert!(err.message.contains("substep"), "{}", err.message);
    assert_eq!(
        (
            a.cloth.positions().to_vec(),
            a.cloth.velocities().to_vec(),
            a.cloth.time(),
            a.cloth.step_count()
        ),
        before
    );
    // ...and the history too: continuing gives the same as the cloth that never failed.
    a.cloth.set_pin_targets(&top, &targets).unwrap();
    a.cloth.step(0.0005).unwrap();
    b.cloth.step(0.0005).unwrap();
    let d = max_distance(a.cloth.positions(), b.cloth.positions());
    assert!(d < 1e-12, "{d}");
}

/// The speed check sees every particle the step moves: one pushed hard by a collider is
/// refused, a pinned one moved too fast is refused, and a pinned one that the collider pushes
/// is not (its pin overrides the push). The explicit integrators check as they integrate,
/// tile by tile, then re-check the pins; this pins down that they refuse exactly what the
/// plain check after the step refuses.
#[test]
fn the_speed_check_covers_pins_and_ignores_what_pins_override() {
    use fraccloth::forces::Sphere;
    use fraccloth::{ClothConfig, ErrorKind, GridSpec, Vec3};
    for integrator in Integrator::ALL {
        let make = |pinned: &[u32], sphere: bool| {
            let topology = GridSpec {
                width: 5,
                height: 5,
                spacing: 0.1,
                total_mass: 0.025, // 1 g per particle
            }
            .build()
            .unwrap();
            let mut config = ClothConfig {
                integrator,
                max_speed: 0.1,
                ..ClothConfig::default()
            };
            config.model.gravity = Vec3::zeros();
            let mut cloth = Cloth::new(topology, config).unwrap();
            cloth.set_pinned(pinned).unwrap();
            // A small sphere 1 cm in front of vertex 0 only: ~0.75 N on 1 g, so 0.75 m/s
            // after 1 ms if vertex 0 is free.
            let x0 = cloth.positions()[0];
            if sphere {
                cloth
                    .add_sphere(Sphere {
                        center: x0 + Vec3::new(0.0, 0.0, 0.01),
                        radius: 0.02,
                        velocity: Vec3::zeros(),
                    })
                    .unwrap();
            }
            cloth
        };
        let name = integrator.name();
        // Free: the push is too fast.
        let mut free = make(&[1, 2, 3, 4], true);
        let before = free.positions().to_vec();
        let e = free.step(1e-3).unwrap_err();
        assert_eq!(e.kind, ErrorKind::Unstable, "{name}: {}", e.message);
        assert!(e.message.contains("vertex 0"), "{name}: {}", e.message);
        assert_eq!(free.positions(), &before[..], "{name}");
        // Pinned: the pin holds it, nothing moves too fast.
        let mut held = make(&[0, 1, 2, 3, 4], true);
        held.step(1e-3)
            .unwrap_or_else(|e| panic!("{name}: {}", e.message));
        assert_eq!(held.positions()[0], before[0], "{name}");
        // A pin sent 1 m in 1 ms (1000 m/s) is refused, and nothing changes.
        let target = before[2] + Vec3::new(1.0, 0.0, 0.0);
        held.set_pin_targets(&[2], &[target]).unwrap();
        let now = held.positions().to_vec();
        let e = held.step(1e-3).unwrap_err();
        assert_eq!(e.kind, ErrorKind::Unstable, "{name}: {}", e.message);
        assert!(e.message.contains("vertex 2"), "{name}: {}", e.message);
        assert_eq!(held.positions(), &now[..], "{name}");
        // A soft pin (weight 1/2) sent 1 m in 1 ms, nothing else moving: the particle
        // integrates from rest (sound) and only the pin's pull, applied after, makes it too
        // fast (500 m/s).
        let mut soft = make(&[0, 1, 3, 4], false);
        soft.pin_group(&[2], 0.5).unwrap();
        soft.set_pin_targets(&[2], &[target]).unwrap();
        let e = soft.step(1e-3).unwrap_err();
        assert_eq!(e.kind, ErrorKind::Unstable, "{name}: {}", e.message);
        assert!(e.message.contains("vertex 2"), "{name}: {}", e.message);
        assert_eq!(soft.positions(), &before[..], "{name}");
    }
}
