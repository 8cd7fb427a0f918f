//! The look descriptors on synthetic displacement fields with known answers.

use fraccloth::look::{bump_count, describe, half_amplitude_distance, travel_speed};

#[test]
fn bumps_are_runs_of_one_sign_above_the_threshold() {
    assert_eq!(bump_count(&[0.0, 0.01, 0.02, 0.01], 0.005), 1);
    assert_eq!(bump_count(&[0.01, 0.02, -0.01, -0.03, 0.02], 0.005), 3);
    // Small wiggles below the threshold do not count, and do not split a bump.
    assert_eq!(bump_count(&[0.01, 0.001, -0.002, 0.02, 0.01], 0.005), 1);
    assert_eq!(bump_count(&[0.001, -0.001], 0.005), 0);
    // A sampled sine with 2.5 periods over the column has 5 half-waves.
    let p: Vec<f64> = (0..200)
        .map(|j| (std::f64::consts::TAU * 2.5 * j as f64 / 200.0 + 0.1).sin())
        .collect();
    assert_eq!(bump_count(&p, 0.05), 5);
}

#[test]
fn half_amplitude_distance_of_an_exponential_envelope() {
    // env(j) = exp(-j s / L): halves after L ln 2.
    let (s, l) = (0.01, 0.1);
    let env: Vec<f64> = (0..100).map(|j| (-(j as f64) * s / l).exp()).collect();
    let d = half_amplitude_distance(&env, s).unwrap();
    assert!((d - l * 2f64.ln()).abs() <= s, "{d}");
    // An envelope that never halves: None.
    assert_eq!(half_amplitude_distance(&[1.0, 0.9, 0.8, 0.7], s), None);
}

#[test]
fn travel_speed_of_a_travelling_wave() {
    // d = A sin(k y - w t) with y = j s: speed w / k.
    let (s, dt, k, w) = (0.01, 1.0 / 30.0, 20.0, 3.0);
    let field: Vec<Vec<f64>> = (0..300)
        .map(|t| {
            (0..41)
                .map(|j| (k * j as f64 * s - w * t as f64 * dt).sin())
                .collect()
        })
        .collect();
    let v = travel_speed(&field, 10, 30, dt, s, 60).unwrap();
    // Resolution is one frame of lag: 0.2 m over about 1.33 s = 40 frames.
    assert!((v - w / k).abs() < 0.01, "{v} vs {}", w / k);
    let look = describe(&field, s, dt, 0.05);
    assert!((look.travel_speed.unwrap() - w / k).abs() < 0.01);
    // 41 rows of 0.01 m = 0.4 m = 2.55 half-wavelengths (pi / 20 = 0.157 m): 3 or 4 runs per
    // frame, counting the partial ones at the ends; 3.55 on average.
    assert!((look.mean_bumps - 3.55).abs() < 0.05, "{}", look.mean_bumps);
    assert_eq!(look.half_amplitude_distance, None);
    assert!((look.max_displacement - 1.0).abs() < 1e-3);
}
