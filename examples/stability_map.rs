//! Stability map: for each integrator x history scheme, the largest stable time step on
//! (a) the fractional oscillator m x'' + c D^{1/2}x + k x = F over a range of stiffness k and
//! (b) the `swing` scene (31 x 21, fractional) and (c) the underwater preset's swing (31 x 21:
//! added mass, entrained water, form drag) over a range of spring stiffness scales.
//!
//! `cargo run --release --example stability_map` writes docs/stability.csv,
//! docs/stability.png and docs/stability.svg. `-- --quick` runs a reduced sweep.
//!
//! Stability test: (a) the run must not fail and the largest deviation from equilibrium in
//! the last quarter of the run must be smaller than in the second quarter (a decaying
//! response); (b) 2 s of the scene must run without a step being refused (non-finite state
//! or a speed above 100 m/s) and end with every speed below 5 m/s. The largest stable dt is
//! found by bisection in log(dt); (b) is capped at frame rate, 1/24 s.

use std::error::Error;
use std::fmt::Write as _;

use fraccloth::history::Scheme;
use fraccloth::{Cloth, Integrator};
use fraccloth_tools::oscillator::Oscillator;
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
use plotters::coord::Shift;
use plotters::prelude::*;

const SOE_DEFAULT: Scheme = Scheme::DEFAULT;
const SOE_FINE: Scheme = Scheme::SumOfExponentials {
    tolerance: 1e-6,
    horizon: 3600.0,
    min_dt: 1e-5,
};

fn oscillator_stable(o: &Oscillator, scheme: Scheme, integrator: Integrator, dt: f64) -> bool {
    let Ok(mut cloth) = o.cloth(scheme, integrator) else {
        return false;
    };
    // At least 20 periods of the undamped oscillator (or 400 steps).
    let period = std::f64::consts::TAU / (o.k / o.m).sqrt();
    let cap = if scheme == Scheme::Full { 8_000.0 } else { 40_000.0 };
    let steps = (20.0 * period / dt).clamp(400.0, cap) as usize;
    // Bounded: the response decays, or what is left is below 1 % of the static deflection
    // (an SOE kernel of tolerance 1e-3 leaves a tail that wiggles at that level).
    growth(&mut cloth, o, dt, steps).is_some_and(|(early, late)| late < early || late < 1e-2 * o.f / o.k)
}

/// Largest deviation from equilibrium in the second and in the last quarter of the run.
fn growth(cloth: &mut Cloth, o: &Oscillator, dt: f64, steps: usize) -> Option<(f64, f64)> {
    let eq = o.f / o.k;
    let (mut a, mut b) = (0.0f64, 0.0f64);
    for k in 0..steps {
        cloth.step(dt).ok()?;
        let d = (Oscillator::elongation(cloth) - eq).abs();
        if (steps / 4..steps / 2).contains(&k) {
            a = a.max(d);
        } else if k >= 3 * steps / 4 {
            b = b.max(d);
        }
    }
    Some((a, b))
}

fn swing_stable(variant: Variant, scale: f64, scheme: Scheme, integrator: Integrator, dt: f64) -> bool {
    let spec = SceneSpec {
        width: 31,
        height: 21,
        scheme,
        integrator,
        dt,
        stiffness_scale: scale,
        ..SceneSpec::paper(SceneKind::Swing, variant)
    };
    let Ok(mut scene) = spec.build() else { return false };
    let t_end = 2.0f64.max(50.0 * dt);
    scene.run_until(t_end).is_ok() && scene.cloth.velocities().iter().all(|v| v.norm() < 5.0)
}

/// Largest dt in [lo, hi] with `stable(dt)`, by bisection in log(dt). Returns hi if hi is stable.
fn largest_stable(lo: f64, hi: f64, iterations: u32, stable: impl Fn(f64) -> bool) -> f64 {
    if stable(hi) {
        return hi;
    }
    if !stable(lo) {
        return f64::NAN;
    }
    let (mut a, mut b) = (lo.ln(), hi.ln());
    for _ in 0..iterations {
        let m = 0.5 * (a + b);
        if stable(m.exp()) {
            a = m;
        } else {
            b = m;
        }
    }
    a.exp()
}

struct Row {
    /// Smallest dt tried: NaN in `dt` means unstable even there.
    lowest: f64,
    problem: &'static str,
    integrator: Integrator,
    scheme: Scheme,
    stiffness: f64,
    dt: f64,
}

fn scheme_label(s: Scheme) -> String {
    match s {
        Scheme::Truncated { u } => format!("paper Eq.6 u={u}"),
        Scheme::Full => "full".into(),
        Scheme::SumOfExponentials { tolerance, .. } => format!("SOE {tolerance:e}"),
        Scheme::Off => "preset, no history".into(),
    }
}

fn colour(i: Integrator) -> RGBColor {
    match i {
        Integrator::ExplicitEuler => RGBColor(214, 39, 40),
        Integrator::SymplecticEuler => RGBColor(31, 119, 180),
        Integrator::ImplicitEuler => RGBColor(44, 160, 44),
        Integrator::ExtrapolatedSymplectic => RGBColor(148, 103, 189),
        Integrator::ExtrapolatedImplicit => RGBColor(255, 127, 14),
        Integrator::Xpbd => RGBColor(23, 190, 207),
    }
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    rows: &[Row],
    schemes: &[Scheme],
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let panels = root.split_evenly((1, 3));
    for (panel, (problem, xdesc)) in panels.iter().zip([
        ("oscillator", "spring constant k (N/m), m = 1 kg, c = 0.8"),
        ("swing", "stiffness scale of the swing cloth (1 = 10 N/m stretch)"),
        ("underwater", "stiffness scale of the underwater preset's springs"),
    ]) {
        let mine: Vec<&Row> = rows
            .iter()
            .filter(|r| r.problem == problem && r.dt.is_finite())
            .collect();
        let xs = mine.iter().map(|r| r.stiffness);
        let (xmin, xmax) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
        let mut chart = ChartBuilder::on(panel)
            .caption(
                match problem {
                    "oscillator" => "largest stable dt: fractional oscillator (top: 1 s, every dt tried)",
                    "swing" => "largest stable dt: fractional swing 31 x 21 (top: frame rate, 1/24 s)",
                    _ => "largest stable dt: underwater preset's swing 31 x 21 (top: 1/24 s)",
                },
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((xmin / 1.5..xmax * 1.5).log_scale(), (1e-5f64..3.0).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(xdesc)
            .y_desc("dt (s)")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        for integrator in Integrator::ALL {
            for (si, &scheme) in schemes.iter().enumerate() {
                let pts: Vec<(f64, f64)> = mine
                    .iter()
                    .filter(|r| r.integrator == integrator && r.scheme == scheme)
                    .map(|r| (r.stiffness, r.dt))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let c = colour(integrator);
                let style = ShapeStyle {
                    color: c.to_rgba(),
                    filled: si % 2 == 0,
                    stroke_width: 2,
                };
                chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(1)))?;
                let label = format!("{} / {}", integrator.key(), scheme_label(scheme));
                let marker = move |(x, y): (f64, f64)| -> DynElement<DB, (f64, f64)> {
                    match si {
                        0 => Circle::new((x, y), 5, style).into_dyn(),
                        1 => TriangleMarker::new((x, y), 6, style).into_dyn(),
                        2 => Cross::new((x, y), 5, style).into_dyn(),
                        4 => Circle::new((x, y), 3, style).into_dyn(),
                        _ => Rectangle::new([(x, y), (x, y)], style).into_dyn(),
                    }
                };
                chart
                    .draw_series(pts.iter().map(|&p| marker(p)))?
                    .label(label)
                    .legend(move |(x, y)| {
                        let glyph = ["\u{25cf}", "\u{25b2}", "\u{2715}", "\u{25a0}", "\u{2022}"][si.min(4)];
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(-10, 0), (10, 0)], c.stroke_width(1))
                            + Text::new(glyph, (-5, -7), ("sans-serif", 14).into_font().color(&c))
                    });
            }
        }
        if problem == "oscillator" {
            let ks: Vec<f64> = mine.iter().map(|r| r.stiffness).collect();
            let bound = |k: f64, f: fn(&Oscillator) -> f64| {
                f(&Oscillator {
                    k,
                    ..Oscillator::default()
                })
            };
            let explicit: Vec<(f64, f64)> = ks
                .iter()
                .map(|&k| (k, bound(k, Oscillator::explicit_euler_bound)))
                .collect();
            let symplectic: Vec<(f64, f64)> = ks
                .iter()
                .map(|&k| (k, bound(k, Oscillator::symplectic_bound)))
                .collect();
            chart
                .draw_series(DashedLineSeries::new(explicit, 6, 4, BLACK.stroke_width(1)))?
                .label("analytic: 2|Re p|/|p|^2 (explicit, full memory)")
                .legend(|(x, y)| PathElement::new(vec![(x - 8, y), (x + 8, y)], BLACK));
            chart
                .draw_series(DashedLineSeries::new(
                    symplectic,
                    2,
                    4,
                    RGBColor(120, 120, 120).stroke_width(1),
                ))?
                .label("analytic: 2/omega (symplectic, undamped)")
                .legend(|(x, y)| PathElement::new(vec![(x - 8, y), (x + 8, y)], RGBColor(120, 120, 120)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()?;
    }
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let quick = std::env::args().any(|a| a == "--quick");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    // The quick sweep is a smoke run: it writes under target/, the full one into docs/.
    let out = if quick {
        root.join("target")
    } else {
        root.join("docs")
    };
    let stiffness: &[f64] = if quick {
        &[25.0, 400.0]
    } else {
        &[6.25, 25.0, 100.0, 400.0, 1600.0]
    };
    let scales: &[f64] = if quick { &[1.0, 100.0] } else { &[1.0, 10.0, 100.0] };
    let osc_schemes = [Scheme::PAPER, Scheme::Full, SOE_DEFAULT, SOE_FINE];
    let swing_schemes = [Scheme::PAPER, SOE_DEFAULT];
    let iters = if quick { 8 } else { 14 };
    let mut rows = vec![];
    for &k in stiffness {
        let o = Oscillator {
            k,
            ..Oscillator::default()
        };
        let period = std::f64::consts::TAU / (o.k / o.m).sqrt();
        for integrator in Integrator::ALL {
            for scheme in osc_schemes {
                // The second-order integrators with the default history only.
                if integrator.is_extrapolated() && scheme != SOE_DEFAULT {
                    continue;
                }
                let dt = largest_stable(period / 2000.0, 1.0, iters, |dt| {
                    oscillator_stable(&o, scheme, integrator, dt)
                });
                println!(
                    "oscillator k={k:7} {:10} {:16} largest stable dt {dt:.4e}",
                    integrator.key(),
                    scheme_label(scheme)
                );
                rows.push(Row {
                    lowest: period / 2000.0,
                    problem: "oscillator",
                    integrator,
                    scheme,
                    stiffness: k,
                    dt,
                });
            }
        }
    }
    // The paper's fractional swing with two history schemes, and the underwater preset's swing
    // (added mass, entrained water, form drag; no half-derivative term, so no history).
    let swings = [
        ("swing", Variant::Fractional, swing_schemes.to_vec()),
        ("underwater", Variant::Underwater, vec![Scheme::Off]),
    ];
    for (problem, variant, schemes) in &swings {
        for &scale in scales {
            for integrator in Integrator::ALL {
                for &scheme in schemes {
                    if integrator.is_extrapolated() && scheme == Scheme::PAPER {
                        continue;
                    }
                    let dt = largest_stable(1e-5, 1.0 / 24.0, iters.min(10), |dt| {
                        swing_stable(*variant, scale, scheme, integrator, dt)
                    });
                    println!(
                        "{problem} scale={scale:5} {:10} {:16} largest stable dt {dt:.4e}",
                        integrator.key(),
                        scheme_label(scheme)
                    );
                    rows.push(Row {
                        lowest: 1e-5,
                        problem,
                        integrator,
                        scheme,
                        stiffness: scale,
                        dt,
                    });
                }
            }
        }
    }
    let mut csv = String::from("problem,integrator,scheme,stiffness,largest_stable_dt,smallest_dt_tried,analytic_explicit_bound,analytic_symplectic_bound\n");
    for r in &rows {
        let (e, s) = if r.problem == "oscillator" {
            let o = Oscillator {
                k: r.stiffness,
                ..Oscillator::default()
            };
            (
                format!("{:.6e}", o.explicit_euler_bound()),
                format!("{:.6e}", o.symplectic_bound()),
            )
        } else {
            (String::new(), String::new())
        };
        writeln!(
            csv,
            "{},{},{},{},{:.6e},{:.6e},{e},{s}",
            r.problem,
            r.integrator.key(),
            scheme_label(r.scheme),
            r.stiffness,
            r.dt,
            r.lowest
        )?;
    }
    let suffix = if quick { "-quick" } else { "" };
    std::fs::write(out.join(format!("stability{suffix}.csv")), csv)?;
    let mut all: Vec<Scheme> = osc_schemes.to_vec();
    all.push(Scheme::Off);
    draw(
        BitMapBackend::new(&out.join(format!("stability{suffix}.png")), (2100, 620)).into_drawing_area(),
        &rows,
        &all,
    )?;
    draw(
        SVGBackend::new(&out.join(format!("stability{suffix}.svg")), (2100, 620)).into_drawing_area(),
        &rows,
        &all,
    )?;
    println!("wrote {}/stability{suffix}.csv, .png, .svg", out.display());
    Ok(())
}
