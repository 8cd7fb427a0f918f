//! Speed against accuracy: every history scheme x integrator x time step on the fractional
//! oscillator and on the `swing` and `sphere` scenes, and every integrator x time step on the
//! underwater preset's swing, with the Pareto chart users choose from.
//!
//! `cargo run --release --example speed_accuracy` (the full run, for humans: about 15 minutes on
//! 2 cores) writes docs/speed_accuracy.csv, docs/pareto.png, docs/pareto.svg and
//! docs/ratios.txt. `-- --quick` (what CI runs: 21 x 15 cloth, short runs, a few dt) writes the
//! same files under target/.
//!
//! Errors: the oscillator against the inverse Laplace transform of its exact solution (the
//! same reference the tests use); the scenes as RMS vertex distance, at t = T/2 and T, from a
//! reference run (implicit Euler, SOE history at tolerance 1e-8, dt = 1e-4 s). SOE at 1e-8
//! stands in for `Full` in the reference because Full's O(n) per step makes 20000 steps of a
//! 2501-particle cloth impractical; the tests show SOE equals Full to its tolerance. The
//! reference is checked against the same run at 2 dt: the difference is printed.
//! Cost: wall-clock time of the stepping loop only (cloth creation excluded), one thread.

#[path = "../tests/common/reference.rs"]
mod reference;

use std::error::Error;
use std::fmt::Write as _;
use std::time::Instant;

use fraccloth::history::Scheme;
use fraccloth::{HalfDerivative, Integrator, RegularDrag, Vec3};
use fraccloth_tools::oscillator::Oscillator;
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
use nalgebra::Complex;
use plotters::coord::Shift;
use plotters::prelude::*;

fn schemes() -> Vec<Scheme> {
    let soe = |tolerance| Scheme::SumOfExponentials {
        tolerance,
        horizon: 3600.0,
        min_dt: 1e-4,
    };
    vec![
        Scheme::Truncated { u: 1 },
        Scheme::Truncated { u: 3 },
        Scheme::Truncated { u: 10 },
        Scheme::Full,
        soe(1e-2),
        Scheme::DEFAULT,
        soe(1e-6),
    ]
}

fn label(s: &Scheme) -> String {
    match *s {
        Scheme::Truncated { u } => format!("paper u={u}"),
        Scheme::Full => "full".into(),
        Scheme::SumOfExponentials { tolerance, .. } => format!("SOE {tolerance:e}"),
        Scheme::Off => "no history (underwater preset)".into(),
    }
}

#[derive(Clone, Debug)]
struct Record {
    problem: &'static str,
    scheme: Scheme,
    integrator: Integrator,
    dt: f64,
    /// Every step was accepted (no FC_ERROR_UNSTABLE); short runs can complete while growing.
    completed: bool,
    error: f64,
    wall_per_sim_s: f64,
    particle_steps_per_s: f64,
    history_bytes: usize,
    particles: usize,
}

impl Record {
    /// A record of a run that has not (yet) completed.
    fn new(problem: &'static str, scheme: Scheme, integrator: Integrator, dt: f64, particles: usize) -> Self {
        Self {
            problem,
            scheme,
            integrator,
            dt,
            completed: false,
            error: f64::NAN,
            wall_per_sim_s: f64::NAN,
            particle_steps_per_s: f64::NAN,
            history_bytes: 0,
            particles,
        }
    }

    fn is_paper(&self) -> bool {
        self.scheme == Scheme::PAPER && self.integrator == Integrator::ExplicitEuler
    }
}

struct Settings {
    quick: bool,
    width: u32,
    height: u32,
    t_end: f64,
    dts: Vec<f64>,
    ref_dt: f64,
}

fn osc_reference(o: &Oscillator, t: f64) -> f64 {
    reference::talbot(
        |s| Complex::new(o.f, 0.0) / s / (s * s * o.m + s.sqrt() * o.c + o.k),
        t,
        32,
    )
}

fn run_oscillator(set: &Settings, scheme: Scheme, integrator: Integrator, dt: f64) -> Record {
    let o = Oscillator::default();
    let times = [0.5, 1.0, 1.5, 2.0];
    let mut rec = Record::new("oscillator", scheme, integrator, dt, 4);
    if scheme == Scheme::Full && 2.0 / dt > 40_000.0 {
        return rec; // O(n^2) overall: skipped, recorded as not run
    }
    let Ok(mut c) = o.cloth(scheme, integrator) else {
        return rec;
    };
    let start = Instant::now();
    let mut err = 0.0f64;
    for &t in &times {
        while c.time() < t - 0.5 * dt {
            if c.step(dt).is_err() {
                return rec;
            }
        }
        err = err.max((Oscillator::elongation(&c) - osc_reference(&o, t)).abs());
    }
    let wall = start.elapsed().as_secs_f64();
    let _ = set;
    rec.completed = err.is_finite();
    rec.error = err;
    rec.wall_per_sim_s = wall / c.time();
    rec.particle_steps_per_s = 4.0 * c.step_count() as f64 / wall;
    rec.history_bytes = c.history().bytes_per_particle();
    rec
}

/// One scene of the chart: which scene, which model, which history schemes it is run with.
struct SceneProblem {
    name: &'static str,
    kind: SceneKind,
    variant: Variant,
    /// History schemes to run (the underwater preset has no half-derivative term: `Off`).
    schemes: Vec<Scheme>,
    /// History scheme of the reference run.
    reference: Scheme,
}

fn scene_spec(
    set: &Settings,
    p: &SceneProblem,
    scheme: Scheme,
    integrator: Integrator,
    dt: f64,
) -> SceneSpec {
    SceneSpec {
        width: set.width,
        height: set.height,
        scheme,
        integrator,
        dt,
        ..SceneSpec::paper(p.kind, p.variant)
    }
}

/// Positions at t_end / 2 and t_end, or None if a step was refused. Also the stepping wall time.
fn run_scene(spec: SceneSpec, t_end: f64) -> Option<(Vec<Vec3>, f64, u64, usize)> {
    let mut s = spec.build().ok()?;
    let start = Instant::now();
    s.run_until(0.5 * t_end).ok()?;
    let mut snap = s.cloth.positions().to_vec();
    s.run_until(t_end).ok()?;
    let wall = start.elapsed().as_secs_f64();
    snap.extend_from_slice(s.cloth.positions());
    Some((
        snap,
        wall,
        s.cloth.step_count(),
        s.cloth.history().bytes_per_particle(),
    ))
}

fn rms(a: &[Vec3], b: &[Vec3]) -> f64 {
    (a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum::<f64>() / a.len() as f64).sqrt()
}

fn ratios(set: &Settings, records: &[Record], out: &mut String) -> Result<(), Box<dyn Error>> {
    let small = |scheme, steps: usize, every: &[usize]| -> Vec<f64> {
        // Time per step around given step counts, on an 11 x 11 cloth, explicit, dt = 1e-4 s.
        let spec = SceneSpec {
            width: 11,
            height: 11,
            scheme,
            dt: 1e-4,
            ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
        };
        let mut s = spec.build().expect("scene");
        let mut res = vec![];
        let window = 2000;
        let mut k = 0usize;
        for &mark in every {
            while k + window / 2 < mark {
                s.step().expect("step");
                k += 1;
            }
            let t0 = Instant::now();
            for _ in 0..window {
                s.step().expect("step");
                k += 1;
            }
            res.push(t0.elapsed().as_secs_f64() / window as f64);
        }
        let _ = steps;
        res
    };
    // 1. Fractional (SOE default) against regular, same mesh, integrator and dt.
    let ratio_t = if set.quick { 0.5 } else { 2.0 };
    writeln!(
        out,
        "== fractional (SOE 1e-3) and the underwater preset vs regular (damped springs, normal drag): same {}x{} mesh, {ratio_t} s of swing",
        set.width, set.height
    )?;
    for integrator in [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::ImplicitEuler,
    ] {
        let dt = if integrator == Integrator::ImplicitEuler {
            1.0 / 60.0
        } else {
            5e-4
        };
        let mut walls = vec![];
        for variant in [
            Variant::Fractional,
            Variant::Regular(RegularDrag::Normal),
            Variant::Underwater,
        ] {
            let spec = SceneSpec {
                width: set.width,
                height: set.height,
                scheme: Scheme::DEFAULT,
                integrator,
                dt,
                ..SceneSpec::paper(SceneKind::Swing, variant)
            };
            let (_, wall, _, _) = run_scene(spec, ratio_t).ok_or("run failed")?;
            walls.push(wall);
        }
        writeln!(
            out,
            "{:17} dt {:.2e}: fractional {:.3} s, regular {:.3} s, ratio {:.2}x (target <= 1.3x); \
             underwater preset {:.3} s, ratio to regular {:.2}x (target <= 1.3x)",
            integrator.name(),
            dt,
            walls[0],
            walls[1],
            walls[0] / walls[1],
            walls[2],
            walls[2] / walls[1]
        )?;
    }
    // 2. Equal error on swing.
    writeln!(out, "\n== swing at equal error (1 mm RMS)")?;
    let swing: Vec<&Record> = records
        .iter()
        .filter(|r| r.problem == "swing" && r.completed)
        .collect();
    let within: Vec<&&Record> = swing.iter().filter(|r| r.error <= 1e-3).collect();
    let fastest = within
        .iter()
        .min_by(|a, b| a.wall_per_sim_s.total_cmp(&b.wall_per_sim_s));
    let paper: Vec<&&Record> = swing.iter().filter(|r| r.is_paper()).collect();
    let paper_within = paper
        .iter()
        .filter(|r| r.error <= 1e-3)
        .min_by(|a, b| a.wall_per_sim_s.total_cmp(&b.wall_per_sim_s));
    match fastest {
        Some(f) => writeln!(
            out,
            "fastest within 1 mm: {} / {} / dt {:.2e}: error {:.2e} m, {:.3} s per simulated s",
            label(&f.scheme),
            f.integrator.name(),
            f.dt,
            f.error,
            f.wall_per_sim_s
        )?,
        None => writeln!(out, "no configuration reached 1 mm")?,
    }
    // First- against second-order integrators, in this run.
    let cheapest = |order: u32| {
        within
            .iter()
            .filter(|r| r.integrator.order() == order)
            .min_by(|a, b| a.wall_per_sim_s.total_cmp(&b.wall_per_sim_s))
    };
    for order in [1, 2] {
        if let Some(f) = cheapest(order) {
            writeln!(
                out,
                "cheapest within 1 mm, order {order}: {} / {} / dt {:.2e}: error {:.2e} m, {:.3} s per simulated s",
                label(&f.scheme),
                f.integrator.name(),
                f.dt,
                f.error,
                f.wall_per_sim_s
            )?;
        }
    }
    if let (Some(a), Some(b)) = (cheapest(1), cheapest(2)) {
        writeln!(
            out,
            "second order against first, within 1 mm: {:.2}x cheaper (target >= 3x)",
            a.wall_per_sim_s / b.wall_per_sim_s
        )?;
    }
    match (paper_within, fastest) {
        (Some(p), Some(f)) => writeln!(
            out,
            "paper (u=3, explicit) within 1 mm: dt {:.2e}, {:.3} s per simulated s: fastest is {:.1}x faster (target >= 10x)",
            p.dt,
            p.wall_per_sim_s,
            p.wall_per_sim_s / f.wall_per_sim_s
        )?,
        _ => {
            let best = paper.iter().map(|r| r.error).fold(f64::INFINITY, f64::min);
            writeln!(out, "the paper's configuration (u=3, explicit Euler) never reaches 1 mm: its best error is {best:.2e} m")?;
        }
    }
    // 3. The underwater preset at equal error: the cheapest run of each integrator within 1 mm.
    writeln!(out, "\n== underwater preset at equal error (1 mm RMS)")?;
    for integrator in Integrator::ALL {
        let best = records
            .iter()
            .filter(|r| {
                r.problem == "underwater" && r.completed && r.integrator == integrator && r.error <= 1e-3
            })
            .min_by(|a, b| a.wall_per_sim_s.total_cmp(&b.wall_per_sim_s));
        match best {
            Some(r) => writeln!(
                out,
                "{}: dt {:.2e}, error {:.2e} m, {:.3} s per simulated s",
                integrator.name(),
                r.dt,
                r.error,
                r.wall_per_sim_s
            )?,
            None => writeln!(out, "{}: no step tried reaches 1 mm", integrator.name())?,
        }
    }
    // 3. SOE per-step cost at step 1e3 against 1e6 (1e5 in quick mode).
    let far = if set.quick { 100_000 } else { 1_000_000 };
    let soe = small(Scheme::DEFAULT, far, &[1_000, far]);
    writeln!(
        out,
        "\n== SOE (1e-3) per-step cost, 11x11 cloth: {:.3} us at step 1e3, {:.3} us at step {:.0e}: ratio {:.3} (target within 10 %)",
        soe[0] * 1e6,
        soe[1] * 1e6,
        far as f64,
        soe[1] / soe[0]
    )?;
    // 4. Full history cost growth.
    let marks = if set.quick {
        vec![1_000, 4_000]
    } else {
        vec![1_000, 4_000, 16_000]
    };
    let full = small(Scheme::Full, 0, &marks);
    write!(out, "== Full history per-step cost, 11x11 cloth:")?;
    for (m, t) in marks.iter().zip(&full) {
        write!(out, " {:.1} us at step {m};", t * 1e6)?;
    }
    writeln!(
        out,
        " growth {:.1}x over {:.0}x more steps",
        full[full.len() - 1] / full[0],
        marks[marks.len() - 1] as f64 / marks[0] as f64
    )?;
    Ok(())
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

const GLYPHS: [&str; 8] = [
    "\u{25cf}", "\u{25b2}", "\u{25bc}", "\u{25a0}", "\u{25c6}", "\u{2715}", "\u{2605}", "\u{271a}",
];

fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut front: Vec<(f64, f64)> = vec![];
    for q in p {
        if front.last().is_none_or(|l| q.1 < l.1) {
            front.push(q);
        }
    }
    front
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    records: &[Record],
    problems: &[&str],
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let mut all = schemes();
    all.push(Scheme::Off);
    let panels = root.split_evenly((1, problems.len()));
    for (panel, &problem) in panels.iter().zip(problems) {
        let mine: Vec<&Record> = records
            .iter()
            .filter(|r| r.problem == problem && r.completed && r.error > 0.0)
            .collect();
        if mine.is_empty() {
            continue;
        }
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
        for r in &mine {
            x0 = x0.min(r.wall_per_sim_s);
            x1 = x1.max(r.wall_per_sim_s);
            y0 = y0.min(r.error);
            y1 = y1.max(r.error);
        }
        let unit = if problem == "oscillator" {
            "max |x - x_ref| (m)"
        } else {
            "RMS vertex error (m)"
        };
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("{problem}: error against cost"), ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x0 / 2.0..x1 * 2.0).log_scale(), (y0 / 3.0..y1 * 3.0).log_scale())?;
        chart
            .configure_mesh()
            .x_labels(6)
            .y_labels(8)
            .x_desc("wall time per simulated second (s), one thread")
            .y_desc(unit)
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        let front = pareto(
            &mine
                .iter()
                .map(|r| (r.wall_per_sim_s, r.error))
                .collect::<Vec<_>>(),
        );
        chart
            .draw_series(LineSeries::new(front, BLACK.stroke_width(2)))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x - 10, y), (x + 10, y)], BLACK.stroke_width(2)));
        for (si, scheme) in all.iter().enumerate() {
            for integrator in Integrator::ALL {
                let c = colour(integrator);
                let pts: Vec<&&Record> = mine
                    .iter()
                    .filter(|r| r.scheme == *scheme && r.integrator == integrator)
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let font =
                    ("sans-serif", 15)
                        .into_font()
                        .color(&c)
                        .pos(plotters::style::text_anchor::Pos::new(
                            plotters::style::text_anchor::HPos::Center,
                            plotters::style::text_anchor::VPos::Center,
                        ));
                chart.draw_series(
                    pts.iter()
                        .map(|r| Text::new(GLYPHS[si], (r.wall_per_sim_s, r.error), font.clone())),
                )?;
            }
        }
        // The paper's configuration, ringed.
        chart
            .draw_series(
                mine.iter()
                    .filter(|r| r.is_paper())
                    .map(|r| Circle::new((r.wall_per_sim_s, r.error), 11, BLACK.stroke_width(2))),
            )?
            .label("paper: Eq. 6 u=3 + explicit Euler")
            .legend(|(x, y)| Circle::new((x, y), 6, BLACK.stroke_width(2)));
        for (si, scheme) in all.iter().enumerate() {
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                .label(label(scheme))
                .legend(move |(x, y)| Text::new(GLYPHS[si], (x - 5, y - 8), ("sans-serif", 15).into_font()));
        }
        for integrator in Integrator::ALL {
            let c = colour(integrator);
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                .label(integrator.name())
                .legend(move |(x, y)| Rectangle::new([(x - 8, y - 5), (x + 8, y + 5)], c.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
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
    let set = if quick {
        Settings {
            quick,
            width: 21,
            height: 15,
            t_end: 0.5,
            dts: vec![1e-3, 1.0 / 60.0],
            ref_dt: 2.5e-4,
        }
    } else {
        Settings {
            quick,
            width: 61,
            height: 41,
            t_end: 2.0,
            dts: vec![1e-4, 3e-4, 1e-3, 2e-3, 3e-3, 1e-2, 1.0 / 24.0],
            ref_dt: 2e-4,
        }
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let out_dir = if quick {
        root.join("target")
    } else {
        root.join("docs")
    };
    let mut records = vec![];
    let mut log = String::new();
    // Oscillator.
    for scheme in schemes() {
        for integrator in Integrator::ALL {
            for &dt in &set.dts {
                let r = run_oscillator(&set, scheme, integrator, dt);
                println!(
                    "oscillator {:10} {:17} dt {dt:.2e}: completed {} error {:.3e}",
                    label(&scheme),
                    integrator.name(),
                    r.completed,
                    r.error
                );
                records.push(r);
            }
        }
    }
    // Scenes.
    let fine = Scheme::SumOfExponentials {
        tolerance: 1e-8,
        horizon: 3600.0,
        min_dt: 1e-5,
    };
    let problems = [
        SceneProblem {
            name: "swing",
            kind: SceneKind::Swing,
            variant: Variant::Fractional,
            schemes: schemes(),
            reference: fine,
        },
        SceneProblem {
            name: "sphere",
            kind: SceneKind::Sphere,
            variant: Variant::Fractional,
            schemes: schemes(),
            reference: fine,
        },
        // The underwater preset (added mass, form drag, entrained water; no half-derivative).
        SceneProblem {
            name: "underwater",
            kind: SceneKind::Swing,
            variant: Variant::Underwater,
            schemes: vec![Scheme::Off],
            reference: Scheme::Off,
        },
    ];
    for p in &problems {
        // Reference: extrapolated implicit Euler (second order) with the SOE history at 1e-8 (no
        // history for the underwater preset), Richardson-extrapolated from dt and 2 dt (second
        // order in time: (4 x(dt) - x(2 dt)) / 3 cancels the leading error). Its uncertainty is
        // estimated by the same extrapolation one level coarser (2 dt and 4 dt).
        let ref_scheme = p.reference;
        let run_ref = |dt: f64| -> Result<Vec<Vec3>, Box<dyn Error>> {
            Ok(run_scene(
                scene_spec(&set, p, ref_scheme, Integrator::ExtrapolatedImplicit, dt),
                set.t_end,
            )
            .ok_or("reference run failed")?
            .0)
        };
        let (x1, x2, x4) = (
            run_ref(set.ref_dt)?,
            run_ref(2.0 * set.ref_dt)?,
            run_ref(4.0 * set.ref_dt)?,
        );
        let extrapolate = |a: &[Vec3], b: &[Vec3]| -> Vec<Vec3> {
            a.iter().zip(b).map(|(p, q)| (4.0 * p - q) / 3.0).collect()
        };
        let reference = extrapolate(&x1, &x2);
        let coarse = extrapolate(&x2, &x4);
        let line = format!(
            "{} reference (extrapolated implicit, {}, Richardson from dt {:.1e} and {:.1e}): plain runs differ by {:.3e} m; \
             extrapolated reference differs from the one at 2x coarser steps by {:.3e} m",
            p.name,
            label(&ref_scheme),
            set.ref_dt,
            2.0 * set.ref_dt,
            rms(&x1, &x2),
            rms(&reference, &coarse)
        );
        println!("{line}");
        writeln!(log, "{line}")?;
        let n = (set.width * set.height) as usize;
        for &scheme in &p.schemes {
            for integrator in Integrator::ALL {
                for &dt in &set.dts {
                    let steps = set.t_end / dt;
                    let mut rec = Record::new(p.name, scheme, integrator, dt, n);
                    // The second-order integrators (three first-order steps each) with the
                    // accurate histories only, and not at the smallest step.
                    let second_order_skip = integrator.is_extrapolated()
                        && (!matches!(scheme, Scheme::SumOfExponentials { .. } | Scheme::Off)
                            || scheme == schemes()[4]
                            || (dt < 2e-4 && !set.quick));
                    if second_order_skip {
                        continue;
                    }
                    let skip = scheme == Scheme::Full && steps > 2_000.0;
                    if !skip {
                        if let Some((pos, wall, count, bytes)) =
                            run_scene(scene_spec(&set, p, scheme, integrator, dt), set.t_end)
                        {
                            rec.completed = true;
                            rec.error = rms(&pos, &reference);
                            rec.wall_per_sim_s = wall / set.t_end;
                            rec.particle_steps_per_s = (n as f64) * count as f64 / wall;
                            rec.history_bytes = bytes;
                        }
                    }
                    println!(
                        "{} {:10} {:17} dt {dt:.2e}: {} error {:.3e} m, {:.3e} s/sim-s",
                        p.name,
                        label(&scheme),
                        integrator.name(),
                        if skip {
                            "skipped (Full, too many steps)"
                        } else if rec.completed {
                            "completed"
                        } else {
                            "UNSTABLE (a step was refused)"
                        },
                        rec.error,
                        rec.wall_per_sim_s
                    );
                    records.push(rec);
                }
            }
        }
    }
    let mut csv = String::from(
        "problem,scheme,integrator,dt,completed,error_m,wall_s_per_simulated_s,particle_steps_per_s,history_bytes_per_particle,particles\n",
    );
    for r in &records {
        writeln!(
            csv,
            "{},{},{},{:.6e},{},{:.6e},{:.6e},{:.6e},{},{}",
            r.problem,
            label(&r.scheme),
            r.integrator.key(),
            r.dt,
            r.completed,
            r.error,
            r.wall_per_sim_s,
            r.particle_steps_per_s,
            r.history_bytes,
            r.particles
        )?;
    }
    std::fs::write(out_dir.join("speed_accuracy.csv"), csv)?;
    let mut text = log;
    ratios(&set, &records, &mut text)?;
    print!("{text}");
    std::fs::write(out_dir.join("ratios.txt"), &text)?;
    let problems = ["oscillator", "swing", "sphere", "underwater"];
    draw(
        BitMapBackend::new(&out_dir.join("pareto.png"), (2400, 640)).into_drawing_area(),
        &records,
        &problems,
    )?;
    draw(
        SVGBackend::new(&out_dir.join("pareto.svg"), (2400, 640)).into_drawing_area(),
        &records,
        &problems,
    )?;
    println!(
        "wrote {}/speed_accuracy.csv, ratios.txt, pareto.png, pareto.svg",
        out_dir.display()
    );
    Ok(())
}
