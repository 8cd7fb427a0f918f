use fraccloth::history::Scheme;
use fraccloth::oscillator::Oscillator;
use fraccloth::{Cloth, Integrator, Vec3};

#[allow(dead_code)]
fn step_extrap(c: &mut Cloth, h: f64) {
    let snap = c.save_snapshot().unwrap();
    c.step(h).unwrap();
    let (xa, va) = (c.positions().to_vec(), c.velocities().to_vec());
    c.load_snapshot(&snap).unwrap();
    c.step_substeps(h, 2).unwrap();
    let x: Vec<Vec3> = c.positions().iter().zip(&xa).map(|(b, a)| 2.0 * b - a).collect();
    let v: Vec<Vec3> = c.velocities().iter().zip(&va).map(|(b, a)| 2.0 * b - a).collect();
    c.set_positions(&x).unwrap();
    c.set_velocities(&v).unwrap();
}

fn main() {
    let text = std::fs::read_to_string("tests/data/oscillator_reference.csv").unwrap();
    let refs: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let p: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (p[0], p[1])
        })
        .collect();
    let o = Oscillator::default();
    let tol: f64 = std::env::var("TOL")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1e-9);
    for integrator in [
        Integrator::ExtrapolatedSymplectic,
        Integrator::ExtrapolatedImplicit,
    ] {
        for scheme in [Scheme::SumOfExponentials {
            tolerance: tol,
            horizon: 3600.0,
            min_dt: 1e-5,
        }] {
            let mut prev = None;
            for dt in [1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4] {
                let mut c = o.cloth(scheme, integrator).unwrap();
                let mut err = 0.0f64;
                let mut worst_t = 0.0;
                for &(t, x) in &refs {
                    while c.time() < t - 0.5 * dt {
                        c.step(dt).unwrap();
                    }
                    let e = (Oscillator::elongation(&c) - x).abs();
                    if e > err {
                        err = e;
                        worst_t = t;
                    }
                }
                let order = prev.map(|(pd, pe): (f64, f64)| (pe / err).ln() / (pd / dt).ln());
                println!(
                    "{integrator:?} {} dt {dt:e}: max err {err:.3e} at {worst_t} order {order:?}",
                    scheme.name()
                );
                prev = Some((dt, err));
            }
        }
    }
}
