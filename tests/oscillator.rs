//! The fractional oscillator m x'' + c D^{1/2}x + k x = F, built as a cloth and driven only
//! through the C ABI, against a reference from the numerical inverse Laplace transform of
//! X(s) = (F/s) / (m s^2 + c s^{1/2} + k).

mod common;

use common::reference::talbot;
use fraccloth::ffi::FcStatus::FC_OK;
use fraccloth::ffi::*;
use nalgebra::Complex;

const M: f64 = 1.0;
const C: f64 = 0.8;
const K: f64 = 25.0;
const F: f64 = 1.0;

fn reference(t: f64) -> f64 {
    talbot(
        |s| Complex::new(F, 0.0) / s / (s * s * M + s.sqrt() * C + K),
        t,
        32,
    )
}

fn undamped(t: f64) -> f64 {
    F / K * (1.0 - ((K / M).sqrt() * t).cos())
}

/// A 2 x 2 grid: vertices 0, 1, 2 pinned; vertex 3 hangs on the shear spring from vertex 0
/// only (stretch and bend constants are zero). Gravity points along that spring, no water.
/// The half-derivative term is the history drag of Eq. 4: for motion along one line,
/// `-c (D^{1/2}x . v_hat) v_hat = -c D^{1/2}x`. (Spring damping would also act through the
/// zero-stiffness stretch springs of vertex 3, since k_d is shared by all springs.)
/// x = elongation of the spring obeys the oscillator with F = m g.
fn oscillator(scheme: u32, u: u32, tolerance: f64, min_dt: f64) -> *mut FcCloth {
    let mut d = fc_cloth_desc_default();
    d.width = 2;
    d.height = 2;
    d.spacing = 0.5;
    d.total_mass = 4.0 * M;
    d.water_density = 0.0;
    let dir = [1.0 / 2f64.sqrt(), -1.0 / 2f64.sqrt(), 0.0];
    d.gravity = dir.map(|c| c * F / M);
    d.stretch_stiffness = 0.0;
    d.bend_stiffness = 0.0;
    d.shear_stiffness = K;
    d.spring_damping = 0.0;
    d.spring_damping_mode = FcSpringDamping::FC_SPRING_DAMPING_NONE as u32;
    d.viscous_drag = 0.0;
    d.history_drag = C;
    d.normal_drag = 0.0;
    d.history_scheme = scheme;
    d.history_u = u;
    d.history_tolerance = tolerance;
    d.history_horizon = 10.0;
    d.history_min_dt = min_dt;
    let mut cloth = std::ptr::null_mut();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&d, &mut cloth), FC_OK);
        assert_eq!(fc_cloth_set_pinned(cloth, [0u32, 1, 2].as_ptr(), 3), FC_OK);
    }
    cloth
}

/// Runs to each of `times` with step `dt`; returns the elongation at each.
fn run(cloth: *mut FcCloth, dt: f64, times: &[f64]) -> Vec<f64> {
    let mut out = vec![];
    let mut xyz = [0f32; 12];
    unsafe {
        assert_eq!(fc_cloth_get_positions(cloth, xyz.as_mut_ptr(), 12), FC_OK);
    }
    let rest = [xyz[9], xyz[10], xyz[11]];
    let mut n = 0u64;
    for &t in times {
        while (n as f64) * dt < t - 0.5 * dt {
            assert_eq!(unsafe { fc_cloth_step(cloth, dt) }, FC_OK);
            n += 1;
        }
        unsafe { fc_cloth_get_positions(cloth, xyz.as_mut_ptr(), 12) };
        // Elongation = displacement of vertex 3 along the spring direction.
        let dx = f64::from(xyz[9] - rest[0]);
        let dy = f64::from(xyz[10] - rest[1]);
        out.push((dx - dy) / 2f64.sqrt());
    }
    unsafe { fc_cloth_destroy(cloth) };
    out
}

const TIMES: [f64; 4] = [0.25, 0.5, 1.0, 2.0];

#[test]
fn soe_and_small_dt_match_the_laplace_reference_to_1e5() {
    let r: Vec<f64> = TIMES.iter().map(|&t| reference(t)).collect();
    let dt = 2e-6;
    let soe = run(
        oscillator(FcHistoryScheme::FC_HISTORY_SOE as u32, 3, 1e-8, dt),
        dt,
        &TIMES,
    );
    let paper = run(
        oscillator(FcHistoryScheme::FC_HISTORY_TRUNCATED as u32, 3, 1e-3, 1e-4),
        dt,
        &TIMES,
    );
    let worst_soe = soe.iter().zip(&r).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let worst_paper = paper
        .iter()
        .zip(&r)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    for (k, &t) in TIMES.iter().enumerate() {
        println!(
            "t = {t:4}: reference {:+.8} soe {:+.8} paper(u=3) {:+.8} undamped {:+.8}",
            r[k],
            soe[k],
            paper[k],
            undamped(t)
        );
    }
    println!("max error: SOE {worst_soe:.2e}, paper preset (u = 3) {worst_paper:.2e}");
    // Positions cross the ABI as f32 (~1e-8 m here), well inside the bound.
    assert!(worst_soe < 1e-5, "SOE error {worst_soe}");
    assert!(
        worst_paper > 100.0 * worst_soe,
        "the paper preset should be far less accurate"
    );
}

#[test]
fn paper_truncation_tends_to_the_undamped_oscillator_as_dt_shrinks() {
    // With u = 3 the memory spans 3 dt, so the damping vanishes like sqrt(dt).
    let t = [2.0];
    let r = reference(2.0);
    let mut last_gap = f64::INFINITY;
    for &dt in &[1e-3, 1e-4, 1e-5] {
        let x = run(
            oscillator(FcHistoryScheme::FC_HISTORY_TRUNCATED as u32, 3, 1e-3, 1e-4),
            dt,
            &t,
        )[0];
        let gap = (x - undamped(2.0)).abs();
        println!(
            "dt {dt:e}: paper x(2) = {x:+.6}, undamped {:+.6}, reference {r:+.6}",
            undamped(2.0)
        );
        assert!(gap < last_gap, "not approaching the undamped solution");
        last_gap = gap;
    }
    assert!(last_gap < (r - undamped(2.0)).abs() / 3.0);
}
