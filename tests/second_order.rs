//! The second-order integrators through the C ABI against 30-digit references of the
//! fractional oscillator `m x'' + c D^{1/2}x + k x = F` (m = 1, c = 0.8, k = 25; forced from
//! rest with F = 1 N, and free from x0 = 0.1 m), with the accurate history (SOE at 1e-9):
//! maximum error over t = 0.1 .. 5 s at most 1e-6 at dt = 1e-4, observed order at least 1.9
//! from dt = 1e-2 to 1e-4. References: `tests/data/oscillator_reference.csv`, written by
//! `scripts/oscillator_reference.py` (mpmath, Talbot inversion at 60 digits).

use fraccloth::ffi::FcStatus::FC_OK;
use fraccloth::ffi::*;

const M: f64 = 1.0;
const C: f64 = 0.8;
const K: f64 = 25.0;
const F: f64 = 1.0;
const X0: f64 = 0.1;

/// (t, forced, free) rows of the reference table.
fn references() -> Vec<[f64; 3]> {
    let text = include_str!("data/oscillator_reference.csv");
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn axis() -> [f64; 3] {
    [1.0 / 2f64.sqrt(), -1.0 / 2f64.sqrt(), 0.0]
}

/// The oscillator as a 2 x 2 cloth (vertices 0-2 pinned, vertex 3 on the shear spring from
/// vertex 0; the half-derivative term is the history drag along the line), forced or free.
fn oscillator(integrator: u32, forced: bool) -> *mut FcCloth {
    let mut d = fc_cloth_desc_default();
    d.width = 2;
    d.height = 2;
    d.spacing = 0.5;
    d.total_mass = 4.0 * M;
    d.water_density = 0.0;
    let f = if forced { F } else { 0.0 };
    d.gravity = axis().map(|c| c * f / M);
    d.stretch_stiffness = 0.0;
    d.bend_stiffness = 0.0;
    d.shear_stiffness = K;
    d.spring_damping = 0.0;
    d.spring_damping_mode = FcSpringDamping::FC_SPRING_DAMPING_NONE as u32;
    d.viscous_drag = 0.0;
    d.history_drag = C;
    d.normal_drag = 0.0;
    d.history_scheme = FcHistoryScheme::FC_HISTORY_SOE as u32;
    d.history_tolerance = 1e-9;
    d.history_horizon = 10.0;
    d.history_min_dt = 1e-5;
    d.integrator = integrator;
    let mut cloth = std::ptr::null_mut();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&d, &mut cloth), FC_OK);
        assert_eq!(fc_cloth_set_pinned(cloth, [0u32, 1, 2].as_ptr(), 3), FC_OK);
        if !forced {
            // Vertex 3 displaced by x0 along the spring, exactly (double precision).
            let mut xyz = [0f64; 12];
            assert_eq!(fc_cloth_get_positions_f64(cloth, xyz.as_mut_ptr(), 12), FC_OK);
            for c in 0..3 {
                xyz[9 + c] += X0 * axis()[c];
            }
            assert_eq!(fc_cloth_set_positions_f64(cloth, xyz.as_ptr(), 12), FC_OK);
        }
    }
    cloth
}

/// Largest |x - x_ref| over the reference times, stepping with `dt` (a divisor of 0.1 s).
fn max_error(integrator: u32, forced: bool, dt: f64) -> f64 {
    let cloth = oscillator(integrator, forced);
    let mut xyz = [0f64; 12];
    let mut n = 0u64;
    let mut worst = 0.0f64;
    let rest = {
        let probe = oscillator(integrator, true);
        unsafe {
            fc_cloth_get_positions_f64(probe, xyz.as_mut_ptr(), 12);
            fc_cloth_destroy(probe);
        }
        [xyz[9], xyz[10], xyz[11]]
    };
    for [t, f, free] in references() {
        while (n as f64) * dt < t - 0.5 * dt {
            assert_eq!(unsafe { fc_cloth_step(cloth, dt) }, FC_OK);
            n += 1;
        }
        assert_eq!(
            unsafe { fc_cloth_get_positions_f64(cloth, xyz.as_mut_ptr(), 12) },
            FC_OK
        );
        let x: f64 = (0..3).map(|c| (xyz[9 + c] - rest[c]) * axis()[c]).sum();
        worst = worst.max((x - if forced { f } else { free }).abs());
    }
    unsafe { fc_cloth_destroy(cloth) };
    worst
}

fn check_second_order(integrator: u32) {
    for forced in [true, false] {
        let e: Vec<f64> = [1e-2, 1e-3, 1e-4]
            .iter()
            .map(|&dt| max_error(integrator, forced, dt))
            .collect();
        let order = (e[0] / e[2]).log10() / 2.0;
        let case = if forced { "forced" } else { "free" };
        println!("integrator {integrator} {case}: max error {:.3e} {:.3e} {:.3e} at dt 1e-2, 1e-3, 1e-4; order {order:.3}", e[0], e[1], e[2]);
        assert!(
            e[2] <= 1e-6,
            "integrator {integrator} {case}: {:e} at dt = 1e-4",
            e[2]
        );
        assert!(order >= 1.9, "integrator {integrator} {case}: order {order}");
        assert!(
            (e[0] / e[1]).log10() >= 1.9 && (e[1] / e[2]).log10() >= 1.9,
            "{e:?}"
        );
    }
}

#[test]
fn extrapolated_symplectic_euler_is_second_order_on_the_fractional_oscillator() {
    check_second_order(FcIntegrator::FC_INTEGRATOR_EXTRAPOLATED_SYMPLECTIC as u32);
}

#[test]
fn extrapolated_implicit_euler_is_second_order_on_the_fractional_oscillator() {
    check_second_order(FcIntegrator::FC_INTEGRATOR_EXTRAPOLATED_IMPLICIT as u32);
}

#[test]
fn the_first_order_integrators_measure_first_order_against_the_same_references() {
    // The harness can tell: symplectic Euler's order is about 1 here.
    let e: Vec<f64> = [1e-2, 1e-3]
        .iter()
        .map(|&dt| max_error(FcIntegrator::FC_INTEGRATOR_SYMPLECTIC_EULER as u32, true, dt))
        .collect();
    let order = (e[0] / e[1]).log10();
    assert!((0.8..1.2).contains(&order), "order {order} ({e:?})");
}

#[test]
fn velocities_and_positions_round_trip_exactly_in_double_and_are_checked() {
    let cloth = oscillator(FcIntegrator::FC_INTEGRATOR_EXTRAPOLATED_IMPLICIT as u32, true);
    let v: Vec<f64> = (0..12).map(|k| 0.1 + f64::from(k) * 1e-9).collect();
    let mut back = [0f64; 12];
    let mut back32 = [0f32; 12];
    unsafe {
        assert_eq!(fc_cloth_set_velocities_f64(cloth, v.as_ptr(), 12), FC_OK);
        assert_eq!(fc_cloth_get_velocities_f64(cloth, back.as_mut_ptr(), 12), FC_OK);
        assert_eq!(&back[..], &v[..]);
        let v32: Vec<f32> = v.iter().map(|&x| x as f32).collect();
        assert_eq!(fc_cloth_set_velocities(cloth, v32.as_ptr(), 12), FC_OK);
        assert_eq!(fc_cloth_get_velocities(cloth, back32.as_mut_ptr(), 12), FC_OK);
        assert_eq!(&back32[..], &v32[..]);
        // Wrong counts, NULL and non-finite values are refused and change nothing.
        assert_eq!(
            fc_cloth_set_velocities_f64(cloth, v.as_ptr(), 9),
            FcStatus::FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            fc_cloth_get_positions_f64(cloth, std::ptr::null_mut(), 12),
            FcStatus::FC_ERROR_NULL_ARGUMENT
        );
        let mut bad = v.clone();
        bad[4] = f64::NAN;
        assert_eq!(
            fc_cloth_set_velocities_f64(cloth, bad.as_ptr(), 12),
            FcStatus::FC_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(fc_cloth_get_velocities(cloth, back32.as_mut_ptr(), 12), FC_OK);
        assert_eq!(&back32[..], &v32[..]);
        fc_cloth_destroy(cloth);
    }
}

/// RMS distance between two states of the same cloth, m.
fn rms(a: &[fraccloth::Vec3], b: &[fraccloth::Vec3]) -> f64 {
    (a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum::<f64>() / a.len() as f64).sqrt()
}

/// The paper's swing cloth (21 x 15) with its fractional springs, tilted and swung at the top
/// (5 cm, 1 Hz) for 0.5 s, no drags: the RMS differences between runs at dt = 8e-4, 4e-4 and
/// 2e-4 s. `smooth`: the pins start at rest (z = 2.5 cm (1 - cos 2 pi t)); otherwise they jump
/// to their full speed at t = 0 (z = 5 cm sin 2 pi t), a kink no integrator follows at second
/// order.
fn swung_differences(integrator: fraccloth::Integrator, smooth: bool) -> (f64, f64) {
    use fraccloth::history::Scheme;
    use fraccloth::{Cloth, ClothConfig, Vec3};
    use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
    let run = |dt: f64| -> Vec<Vec3> {
        let spec = SceneSpec {
            width: 21,
            height: 15,
            scheme: Scheme::SumOfExponentials {
                tolerance: 1e-8,
                horizon: 100.0,
                min_dt: 1e-5,
            },
            integrator,
            dt,
            ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
        };
        let s = spec.build().unwrap();
        let mut model = *s.cloth.model();
        model.history_drag = 0.0;
        model.viscous_drag = 0.0;
        let config = ClothConfig {
            model,
            ..s.cloth.config().clone()
        };
        let top = s.cloth.pinned().to_vec();
        let mut c = Cloth::new(s.cloth.topology().clone(), config).unwrap();
        c.set_pinned(&top).unwrap();
        let mut x = c.positions().to_vec();
        for p in x.iter_mut() {
            p.z += 0.3 * p.y;
        }
        c.set_positions(&x).unwrap();
        let rest: Vec<Vec3> = top.iter().map(|&i| c.positions()[i as usize]).collect();
        for k in 0..(0.5 / dt).round() as usize {
            let phase = std::f64::consts::TAU * (k + 1) as f64 * dt;
            let z = if smooth {
                0.025 * (1.0 - phase.cos())
            } else {
                0.05 * phase.sin()
            };
            let targets: Vec<Vec3> = rest.iter().map(|p| p + Vec3::new(0.0, 0.0, z)).collect();
            c.set_pin_targets(&top, &targets).unwrap();
            c.step(dt).unwrap();
        }
        c.positions().to_vec()
    };
    let x: Vec<Vec<Vec3>> = [8e-4, 4e-4, 2e-4].iter().map(|&dt| run(dt)).collect();
    let (d0, d1) = (rms(&x[0], &x[1]), rms(&x[1], &x[2]));
    println!(
        "swung cloth ({}), {}: differences {d0:.3e} {d1:.3e}, ratio {:.2}",
        if smooth { "smooth start" } else { "sudden start" },
        integrator.name(),
        d0 / d1
    );
    (d0, d1)
}

#[test]
fn extrapolated_implicit_euler_converges_at_second_order_on_a_swung_cloth() {
    // Differences shrink about 4x per halving (measured 3.5), where first-order integrators
    // shrink them 2x. The history records the pins' velocity at the start of each step and the
    // half steps' pins move on a parabola, or the ratio falls to 2 (docs/accuracy.md).
    let (d0, d1) = swung_differences(fraccloth::Integrator::ExtrapolatedImplicit, false);
    assert!(d0 / d1 > 3.0, "ratio {}", d0 / d1);
}

#[test]
fn extrapolated_symplectic_euler_converges_at_second_order_on_a_swung_cloth() {
    // Measured ratio 4.05 with the pins started smoothly (2.6 before hard pins kept their
    // secant and the first half step's history sample became (S_prev + 2 S_1) / 3,
    // docs/accuracy.md); about 1.9 with the sudden start, whose kink the history remembers.
    let (d0, d1) = swung_differences(fraccloth::Integrator::ExtrapolatedSymplectic, true);
    assert!(d0 / d1 > 3.6, "ratio {}", d0 / d1);
    let (s0, s1) = swung_differences(fraccloth::Integrator::SymplecticEuler, true);
    assert!(
        s0 / s1 < 2.5,
        "symplectic Euler is first order here: ratio {}",
        s0 / s1
    );
}

#[test]
fn extrapolated_symplectic_euler_converges_at_second_order_on_the_underwater_swing() {
    // The underwater preset (no history) swung with its sudden start at 31 x 21 for 1 s: the
    // pins' velocity error after the kink must die out (measured ratios 4.01, 4.00; a mid goal
    // read from the extrapolated velocity instead kept it alive: 1.85).
    use fraccloth::history::Scheme;
    use fraccloth::Vec3;
    use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
    let run = |dt: f64| -> Vec<Vec3> {
        let spec = SceneSpec {
            width: 31,
            height: 21,
            scheme: Scheme::Off,
            integrator: fraccloth::Integrator::ExtrapolatedSymplectic,
            dt,
            ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
        };
        let mut s = spec.build().unwrap();
        s.run_until(1.0).unwrap();
        s.cloth.positions().to_vec()
    };
    let x: Vec<Vec<Vec3>> = [2e-3, 1e-3, 5e-4].iter().map(|&dt| run(dt)).collect();
    let (d0, d1) = (rms(&x[0], &x[1]), rms(&x[1], &x[2]));
    println!(
        "underwater swing, extrapolated symplectic: differences {d0:.3e} {d1:.3e}, ratio {:.2}",
        d0 / d1
    );
    assert!(d0 / d1 > 3.6, "ratio {}", d0 / d1);
}
