//! Every D^{1/2} scheme against closed forms, with measured orders of convergence, and the
//! sum-of-exponentials scheme against the full convolution over a long run.

mod common;

use common::reference::{dawson, fresnel};
use fraccloth::history::{History, Scheme};
use fraccloth::{HalfDerivative, Vec3};

/// D^{1/2}x at t_end computed by `scheme` from velocity samples v(k h), k = 0 ..= n.
fn scheme_value(scheme: Scheme, v: &dyn Fn(f64) -> f64, h: f64, t_end: f64) -> f64 {
    let mut hist = History::new(scheme, 1).unwrap();
    let n = (t_end / h).round() as usize;
    for k in 0..n {
        hist.push(&[Vec3::new(v(k as f64 * h), 0.0, 0.0)], h);
    }
    hist.prepare();
    let mut past = [Vec3::zeros()];
    hist.past(&mut past);
    hist.current_weight() * v(n as f64 * h) + past[0].x
}

struct Case {
    name: &'static str,
    v: Box<dyn Fn(f64) -> f64>,
    exact: Box<dyn Fn(f64) -> f64>,
}

fn gamma(x: f64) -> f64 {
    libm::tgamma(x)
}

fn cases() -> Vec<Case> {
    let w = 3.0;
    let a = 2.0;
    vec![
        Case {
            name: "t",
            v: Box::new(|_| 1.0),
            exact: Box::new(|t| gamma(2.0) / gamma(1.5) * t.sqrt()),
        },
        Case {
            name: "t^2",
            v: Box::new(|t| 2.0 * t),
            exact: Box::new(|t| gamma(3.0) / gamma(2.5) * t.powf(1.5)),
        },
        Case {
            name: "t^3",
            v: Box::new(|t| 3.0 * t * t),
            exact: Box::new(|t| gamma(4.0) / gamma(3.5) * t.powf(2.5)),
        },
        Case {
            name: "sin(3t)",
            v: Box::new(move |t| w * (w * t).cos()),
            exact: Box::new(move |t| {
                let (c, s) = fresnel((2.0 * w * t / std::f64::consts::PI).sqrt());
                (2.0 * w).sqrt() * ((w * t).cos() * c + (w * t).sin() * s)
            }),
        },
        Case {
            name: "exp(-2t)",
            v: Box::new(move |t| -a * (-a * t).exp()),
            exact: Box::new(move |t| -2.0 * (a / std::f64::consts::PI).sqrt() * dawson((a * t).sqrt())),
        },
    ]
}

const STEPS: [f64; 3] = [1.0 / 64.0, 1.0 / 128.0, 1.0 / 256.0];

fn errors(scheme: Scheme, c: &Case) -> [f64; 3] {
    STEPS.map(|h| (scheme_value(scheme, &*c.v, h, 1.0) - (c.exact)(1.0)).abs())
}

fn orders(e: [f64; 3]) -> [f64; 2] {
    [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()]
}

#[test]
fn paper_eq6_converges_at_order_one_half() {
    // Untruncated (u larger than any step count) to measure the quadrature itself.
    let eq6 = Scheme::Truncated { u: 100_000 };
    for c in cases() {
        let e = errors(eq6, &c);
        let p = orders(e);
        println!(
            "Eq. 6 {:9} errors {:.3e} {:.3e} {:.3e} orders {:.3} {:.3}",
            c.name, e[0], e[1], e[2], p[0], p[1]
        );
        for q in p {
            assert!((0.4..0.65).contains(&q), "{}: order {q}", c.name);
        }
    }
    // For x = t the error is about +0.0374 sqrt(h) at every t.
    for &h in &STEPS {
        for &t in &[0.25, 1.0] {
            let err = scheme_value(eq6, &|_| 1.0, h, t) - 2.0 * (t / std::f64::consts::PI).sqrt();
            let coef = err / h.sqrt();
            assert!(
                (coef - 0.0374).abs() < 0.001,
                "h={h} t={t}: error/sqrt(h) = {coef}"
            );
        }
    }
}

#[test]
fn full_is_exact_for_quadratics_and_second_order_otherwise() {
    for c in cases() {
        let e = errors(Scheme::Full, &c);
        let p = orders(e);
        println!(
            "Full  {:9} errors {:.3e} {:.3e} {:.3e} orders {:.3} {:.3}",
            c.name, e[0], e[1], e[2], p[0], p[1]
        );
        if c.name == "t" || c.name == "t^2" {
            assert!(e.iter().all(|&x| x < 1e-13), "{}: {e:?}", c.name);
        } else {
            for q in p {
                assert!((1.85..2.2).contains(&q), "{}: order {q}", c.name);
            }
        }
    }
}

#[test]
fn soe_matches_full_to_its_tolerance_and_keeps_second_order() {
    let soe = Scheme::SumOfExponentials {
        tolerance: 1e-10,
        horizon: 10.0,
        min_dt: 1e-3,
    };
    for c in cases() {
        let e = errors(soe, &c);
        let full = errors(Scheme::Full, &c);
        let p = orders(e);
        println!(
            "SOE   {:9} errors {:.3e} {:.3e} {:.3e} orders {:.3} {:.3}",
            c.name, e[0], e[1], e[2], p[0], p[1]
        );
        for k in 0..3 {
            // |SOE - Full| <= tol * integral of |v| against the kernel <= tol * max|v| * 2 sqrt(t/pi).
            assert!((e[k] - full[k]).abs() <= 1e-10 * 4.0 * 2.0 / std::f64::consts::PI.sqrt() + 1e-13);
        }
        if c.name != "t" && c.name != "t^2" {
            for q in p {
                assert!((1.85..2.2).contains(&q), "{}: order {q}", c.name);
            }
        }
    }
}

#[test]
fn truncation_turns_the_memory_into_a_damper_whose_strength_is_sqrt_h() {
    // For v = 1 the truncated operator settles at c_eff = sqrt(h) (2 sqrt(u/pi) + 0.037),
    // whatever the time, instead of growing like 2 sqrt(t/pi).
    for &u in &[1u32, 3, 10] {
        for &h in &[1e-3, 1e-4] {
            let d = scheme_value(Scheme::Truncated { u }, &|_| 1.0, h, 1.0);
            let predicted = h.sqrt() * (2.0 * (f64::from(u) / std::f64::consts::PI).sqrt() + 0.037);
            assert!(
                (d / predicted - 1.0).abs() < 0.01,
                "u={u} h={h}: {d} vs {predicted}"
            );
        }
    }
}

#[test]
fn soe_agrees_with_full_over_1e5_steps_at_constant_memory() {
    let (tol, h, steps) = (1e-6, 1e-3, 100_000usize);
    let mut soe = History::new(
        Scheme::SumOfExponentials {
            tolerance: tol,
            horizon: 200.0,
            min_dt: h,
        },
        1,
    )
    .unwrap();
    let mut full = History::new(Scheme::Full, 1).unwrap();
    let v = |t: f64| (1.3 * t).sin() + 0.5 * (0.05 * t).cos();
    let mut bytes_after_10 = 0;
    let mut checked = 0;
    let mut past = [Vec3::zeros()];
    for k in 0..steps {
        let t = k as f64 * h;
        if k == 10 {
            bytes_after_10 = soe.bytes_per_particle();
        }
        if k % 9973 == 0 || k == steps - 1 {
            soe.prepare();
            soe.past(&mut past);
            let ds = soe.current_weight() * v(t) + past[0].x;
            full.prepare();
            full.past(&mut past);
            let df = full.current_weight() * v(t) + past[0].x;
            let bound = tol * 1.5 * 2.0 * (t / std::f64::consts::PI).sqrt() + 1e-12;
            assert!(
                (ds - df).abs() <= bound,
                "step {k}: soe {ds} full {df} (bound {bound})"
            );
            checked += 1;
        }
        soe.push(&[Vec3::new(v(t), 0.0, 0.0)], h);
        full.push(&[Vec3::new(v(t), 0.0, 0.0)], h);
    }
    assert!(checked >= 10);
    // Memory, and with it the work per step (one update per mode), does not grow for SOE...
    assert_eq!(soe.bytes_per_particle(), bytes_after_10);
    assert_eq!(soe.bytes_per_particle(), (soe.mode_count() + 2) * 24);
    // ...while the full history holds every step.
    assert_eq!(full.bytes_per_particle(), steps * 24);
}

#[test]
fn soe_handles_steps_of_changing_size_exactly_like_full() {
    // Full integrates piecewise-linear velocity exactly for any step sizes; SOE must follow.
    let soe_scheme = Scheme::SumOfExponentials {
        tolerance: 1e-9,
        horizon: 10.0,
        min_dt: 1e-4,
    };
    let mut soe = History::new(soe_scheme, 1).unwrap();
    let mut full = History::new(Scheme::Full, 1).unwrap();
    let mut t = 0.0f64;
    let mut past = [Vec3::zeros()];
    for k in 0..400 {
        let h = [1e-3, 4e-3, 2.5e-4, 7e-3][k % 4];
        let v = Vec3::new((2.0 * t).sin(), 0.0, 0.0);
        soe.push(&[v], h);
        full.push(&[v], h);
        t += h;
    }
    let vn = (2.0 * t).sin();
    soe.prepare();
    soe.past(&mut past);
    let ds = soe.current_weight() * vn + past[0].x;
    full.prepare();
    full.past(&mut past);
    let df = full.current_weight() * vn + past[0].x;
    assert!((ds - df).abs() < 1e-9 * 2.0 * 2.0, "{ds} vs {df}");
}
