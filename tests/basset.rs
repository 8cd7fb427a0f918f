//! The Basset problem: a sphere released from rest in a still fluid, with Stokes drag,
//! added mass and the Basset history force. In dimensionless form (time in units of
//! a^2 (2 rho_p + rho_f) / (9 mu), velocity in units of the terminal velocity):
//!
//!   u' + beta D^{1/2} u + u = 1,  u(0) = 0,  beta = 3 / sqrt(2 rho_p / rho_f + 1).
//!
//! Closed form (from the Laplace transform U = 1 / (s (s + beta s^{1/2} + 1))): with
//! lambda_{1,2} the roots of lambda^2 + beta lambda + 1 = 0 and
//! E_i = exp(lambda_i^2 s) erfc(-lambda_i sqrt(s)),
//! u(s) = [(E_1 - 1)/lambda_1 - (E_2 - 1)/lambda_2] / (lambda_1 - lambda_2).
//! For a particle twice as dense as the fluid the roots are complex.

mod common;

use common::reference::{erfcx_complex, talbot};
use fraccloth::history::{History, Scheme};
use fraccloth::{HalfDerivative, Vec3};
use nalgebra::Complex;

type C64 = Complex<f64>;

fn beta() -> f64 {
    3.0 / (2.0 * 2.0 + 1.0f64).sqrt() // rho_p / rho_f = 2
}

fn closed_form(s: f64) -> f64 {
    let b = beta();
    let disc = C64::new(b * b - 4.0, 0.0).sqrt();
    let l1 = (C64::new(-b, 0.0) + disc) / 2.0;
    let l2 = (C64::new(-b, 0.0) - disc) / 2.0;
    let e = |l: C64| erfcx_complex(-l * s.sqrt());
    let u = ((e(l1) - 1.0) / l1 - (e(l2) - 1.0) / l2) / (l1 - l2);
    assert!(u.im.abs() < 1e-12, "imaginary part {}", u.im);
    u.re
}

/// Solves the equation with a history scheme: D^{1/2}u_n = w0 u'_n + H_n, with the w0
/// term taken implicitly, `u'_n = (1 - u_n - beta H_n) / (1 + beta w0)`, then
/// `u_{n+1} = u_n + h u'_n`.
fn solve(scheme: Scheme, h: f64, times: &[f64]) -> Vec<f64> {
    let mut hist = History::new(scheme, 1).unwrap();
    let b = beta();
    let (mut u, mut n) = (0.0, 0u64);
    let mut past = [Vec3::zeros()];
    let mut out = vec![];
    for &t in times {
        while (n as f64) * h < t - 0.5 * h {
            hist.prepare();
            hist.past(&mut past);
            let du = (1.0 - u - b * past[0].x) / (1.0 + b * hist.current_weight());
            hist.push(&[Vec3::new(du, 0.0, 0.0)], h);
            u += h * du;
            n += 1;
        }
        out.push(u);
    }
    out
}

const TIMES: [f64; 4] = [0.5, 1.0, 2.0, 5.0];

#[test]
fn closed_form_agrees_with_the_inverse_laplace_transform() {
    let b = beta();
    for &s in &TIMES {
        let inv = talbot(|p| C64::new(1.0, 0.0) / (p * (p + p.sqrt() * b + 1.0)), s, 32);
        assert!(
            (closed_form(s) - inv).abs() < 1e-9,
            "s={s}: {} vs {inv}",
            closed_form(s)
        );
    }
}

#[test]
fn history_schemes_reproduce_the_basset_solution() {
    let exact: Vec<f64> = TIMES.iter().map(|&s| closed_form(s)).collect();
    let soe = Scheme::SumOfExponentials {
        tolerance: 1e-8,
        horizon: 10.0,
        min_dt: 1e-4,
    };
    let mut last = f64::INFINITY;
    for &h in &[4e-3, 2e-3, 1e-3] {
        let full = solve(Scheme::Full, h, &TIMES);
        let soe_u = solve(soe, h, &TIMES);
        let paper = solve(Scheme::PAPER, h, &TIMES);
        let err = |x: &[f64]| {
            x.iter()
                .zip(&exact)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        };
        let (ef, es, ep) = (err(&full), err(&soe_u), err(&paper));
        println!("h = {h:e}: max error Full {ef:.3e}, SOE {es:.3e}, paper (u = 3) {ep:.3e}");
        assert!((es - ef).abs() < 1e-6, "SOE and Full disagree");
        // First order overall (the outer Euler step), errors halve with h.
        assert!(ef < 0.6 * last, "error did not shrink: {ef} after {last}");
        last = ef;
        // Truncating the memory misses the slow t^{-1/2} approach to terminal velocity.
        assert!(ep > 10.0 * ef, "paper {ep} vs full {ef}");
    }
    assert!(last < 2e-3, "Full error at h = 1e-3: {last}");
}
