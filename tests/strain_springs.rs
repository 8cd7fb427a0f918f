//! The rotation-invariant fractional spring (`SpringDamping::FractionalStrain`,
//! `src/forces/strain.rs`) against the paper's Eq. 5: the same on a straight line, unlike it
//! when the cloth turns.

use fraccloth::history::Scheme;
use fraccloth::model::SpringDamping;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model, Vec3};
use fraccloth_tools::oscillator::{axis, Oscillator};

/// The fractional oscillator `m x'' + c D^{1/2}x + k x = F` built from one diagonal spring
/// whose damping is `mode` (the other springs neither pull nor damp): particle 3 moves on the
/// spring's line.
fn line_oscillator(mode: SpringDamping, scheme: Scheme, integrator: Integrator) -> Cloth {
    let o = Oscillator::default();
    let topology = GridSpec {
        width: 2,
        height: 2,
        spacing: 0.5,
        total_mass: 4.0 * o.m,
    }
    .build()
    .unwrap();
    let model = Model {
        water_density: 0.0,
        gravity: axis() * (o.f / o.m),
        stretch_stiffness: 0.0,
        bend_stiffness: 0.0,
        shear_stiffness: o.k,
        spring_damping: o.c,
        spring_damping_mode: mode,
        spring_damping_scale: [0.0, 1.0, 0.0],
        viscous_drag: 0.0,
        history_drag: 0.0,
        normal_drag: 0.0,
        ..Model::fractional()
    };
    let mut cloth = Cloth::new(
        topology,
        ClothConfig {
            model,
            scheme,
            integrator,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    cloth.set_pinned(&[0, 1, 2]).unwrap();
    cloth
}

#[test]
fn on_a_straight_line_the_strain_element_is_eq5() {
    // On a fixed line, D^{1/2}(x_i - x_j) . l_hat = D^{1/2}|l| = D^{1/2}(|l| - r): the two
    // elements are one, so every integrator and scheme gives the same motion, to rounding.
    for scheme in [Scheme::Truncated { u: 3 }, Scheme::Full, Scheme::DEFAULT] {
        for integrator in Integrator::ALL {
            let mut a = line_oscillator(SpringDamping::Fractional, scheme, integrator);
            let mut b = line_oscillator(SpringDamping::FractionalStrain, scheme, integrator);
            let mut largest = 0.0f64;
            for _ in 0..2000 {
                a.step(1e-3).unwrap();
                b.step(1e-3).unwrap();
                largest = largest.max(Oscillator::elongation(&a).abs());
                let d = Oscillator::elongation(&a) - Oscillator::elongation(&b);
                assert!(d.abs() < 1e-12, "{scheme:?} {integrator:?} at {}: {d}", a.time());
            }
            // Not trivially equal: the spring moved (static deflection F/k = 0.04 m) and is damped.
            assert!(largest > 0.04, "{largest}");
        }
    }
}

#[test]
fn the_strain_element_follows_the_fractional_oscillators_closed_form() {
    // The exact response, by inverse Laplace transform (tests/common/reference.rs), at t = 1 s
    // and 2 s: first-order integrators at dt = 1e-4 land within 2e-4 of it.
    #[path = "common/reference.rs"]
    mod reference;
    let o = Oscillator::default();
    let exact = |t: f64| {
        reference::talbot(
            |s| nalgebra::Complex::new(o.f, 0.0) / s / (s * s * o.m + s.sqrt() * o.c + o.k),
            t,
            32,
        )
    };
    let mut c = line_oscillator(
        SpringDamping::FractionalStrain,
        Scheme::Full,
        Integrator::SymplecticEuler,
    );
    for t in [1.0, 2.0] {
        while c.time() < t - 0.5e-4 {
            c.step(1e-4).unwrap();
        }
        let (got, want) = (Oscillator::elongation(&c), exact(t));
        assert!((got - want).abs() < 2e-4, "t = {t}: {got} vs {want}");
    }
}

/// A free square cloth (no gravity, no water, no drag) spun in its own plane at `omega`
/// rad/s about its centre; returns the largest relative change of a spring's length over
/// `t_end` seconds.
fn spin(mode: SpringDamping, spring_damping: f64, omega: f64, t_end: f64) -> f64 {
    let topology = GridSpec {
        width: 11,
        height: 11,
        spacing: 0.02,
        total_mass: 0.04,
    }
    .build()
    .unwrap();
    let model = Model {
        water_density: 0.0,
        gravity: Vec3::zeros(),
        spring_damping,
        spring_damping_mode: mode,
        viscous_drag: 0.0,
        history_drag: 0.0,
        normal_drag: 0.0,
        ..Model::fractional()
    };
    let mut cloth = Cloth::new(
        topology,
        ClothConfig {
            model,
            scheme: Scheme::DEFAULT,
            integrator: Integrator::SymplecticEuler,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    let x = cloth.positions().to_vec();
    let centre = x.iter().sum::<Vec3>() / x.len() as f64;
    let w = Vec3::new(0.0, 0.0, omega);
    let v: Vec<Vec3> = x.iter().map(|p| w.cross(&(p - centre))).collect();
    cloth.set_velocities(&v).unwrap();
    let springs = cloth.topology().springs.clone();
    let mut worst = 0.0f64;
    while cloth.time() < t_end {
        cloth.step(2e-4).unwrap();
        let x = cloth.positions();
        for s in &springs {
            let len = (x[s.i as usize] - x[s.j as usize]).norm();
            worst = worst.max((len / s.rest - 1.0).abs());
        }
    }
    worst
}

#[test]
fn a_spinning_cloth_keeps_its_shape_with_the_strain_element_and_not_with_eq5() {
    // A quarter turn a second for 2 s. Undamped, the springs stretch only by the centrifugal
    // load; the strain element damps only changes of length, so it stretches them no more.
    // Eq. 5 remembers where each end was: once the cloth has turned, that memory projected on
    // the springs' new directions pushes along them, though no length changed.
    let omega = std::f64::consts::FRAC_PI_2;
    let undamped = spin(SpringDamping::None, 0.0, omega, 2.0);
    let strain = spin(SpringDamping::FractionalStrain, 0.35, omega, 2.0);
    let eq5 = spin(SpringDamping::Fractional, 0.35, omega, 2.0);
    println!("largest relative spring length change: undamped {undamped:.3e}, strain {strain:.3e}, Eq. 5 {eq5:.3e}");
    assert!(
        strain <= 1.05 * undamped,
        "strain {strain} vs undamped {undamped}"
    );
    assert!(eq5 > 10.0 * undamped, "Eq. 5 {eq5} vs undamped {undamped}");
}

#[test]
fn a_snapshot_of_a_cloth_with_strain_springs_resumes_bit_for_bit() {
    let make = || {
        let mut c = line_oscillator(
            SpringDamping::FractionalStrain,
            Scheme::DEFAULT,
            Integrator::ImplicitEuler,
        );
        for _ in 0..50 {
            c.step(1e-3).unwrap();
        }
        c
    };
    let mut a = make();
    let bytes = a.save_snapshot().unwrap();
    assert_eq!(bytes.len(), a.snapshot_size());
    let mut b = line_oscillator(
        SpringDamping::FractionalStrain,
        Scheme::DEFAULT,
        Integrator::ImplicitEuler,
    );
    b.load_snapshot(&bytes).unwrap();
    for _ in 0..100 {
        a.step(1e-3).unwrap();
        b.step(1e-3).unwrap();
    }
    assert_eq!(a.positions(), b.positions());
    // A cloth without a history per spring refuses it with a message.
    let mut c = line_oscillator(
        SpringDamping::Fractional,
        Scheme::DEFAULT,
        Integrator::ImplicitEuler,
    );
    let e = c.load_snapshot(&bytes).unwrap_err();
    assert!(e.message.contains("history"), "{}", e.message);
}
