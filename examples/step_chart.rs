//! "How cheap can I go and keep the look": for each integrator and step (fixed, or the
//! automatic step with one call per 30 fps frame), the underwater towel's swing (12 s) costs so
//! much wall time per simulated second and its look (half-waves, travel speed, mid ratio)
//! deviates so much from a fine-step reference (extrapolated symplectic Euler at 0.25 ms).
//!
//! `cargo run --release --example step_chart -- [SIZES, default 61x41,121x81] [OUT_DIR, default docs]`
//! Writes `OUT_DIR/step_chart.csv` and `OUT_DIR/step_chart.png`, prints a Markdown table.

use std::time::Instant;

use fraccloth::{Integrator, Vec3};
use fraccloth_tools::look::{measure, Descriptors};
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
use plotters::prelude::*;

#[derive(Clone, Copy)]
enum Step {
    Fixed(f64),
    Auto,
}

struct Row {
    size: String,
    integrator: Integrator,
    step: String,
    /// Wall time per simulated second, s.
    cost: f64,
    substeps_per_frame: f64,
    look: Option<Descriptors>,
    deviation: Option<f64>,
}

fn bake(w: u32, h: u32, integrator: Integrator, step: Step) -> (f64, f64, Option<Descriptors>) {
    let (dt, max_substep) = match step {
        Step::Fixed(dt) => (dt, 0.0),
        Step::Auto => (1.0 / 30.0, fraccloth::cloth::AUTO),
    };
    let mut scene = SceneSpec {
        width: w,
        height: h,
        integrator,
        dt,
        max_substep,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
    }
    .build()
    .expect("a scene");
    scene.cloth.set_threads(1).expect("one thread");
    let (mut frames, mut times) = (vec![scene.cloth.positions().to_vec()], vec![0.0]);
    let (mut wall, mut substeps) = (0.0, 0u64);
    for f in 1..=360 {
        let t = f as f64 / 30.0;
        let start = Instant::now();
        let done = scene.run_until(t);
        wall += start.elapsed().as_secs_f64();
        if done.is_err() {
            return (wall / t, f64::NAN, None);
        }
        substeps += u64::from(scene.cloth.step_stats().substeps);
        frames.push(scene.cloth.positions().to_vec());
        times.push(t);
    }
    let topo = scene.cloth.topology();
    let look = measure(&topo.rest_positions, &topo.triangles, &frames, &times, Vec3::y()).ok();
    let per_frame = match step {
        Step::Auto => substeps as f64 / 360.0,
        Step::Fixed(dt) => (1.0 / 30.0) / dt,
    };
    (wall / 12.0, per_frame, look.map(|l| l.descriptors))
}

/// The largest relative deviation of half-waves, travel speed and mid ratio.
fn deviation(a: &Descriptors, reference: &Descriptors) -> f64 {
    let rel = |x: f64, r: f64| ((x - r) / r).abs();
    rel(a.half_waves, reference.half_waves)
        .max(rel(
            a.travel_speed.unwrap_or(0.0),
            reference.travel_speed.unwrap_or(1.0),
        ))
        .max(rel(a.mid_ratio, reference.mid_ratio))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sizes = std::env::args().nth(1).unwrap_or("61x41,121x81".into());
    let out = std::path::PathBuf::from(std::env::args().nth(2).unwrap_or("docs".into()));
    let cases: Vec<(Integrator, Step)> = vec![
        (Integrator::SymplecticEuler, Step::Fixed(2.5e-4)),
        (Integrator::SymplecticEuler, Step::Fixed(5e-4)),
        (Integrator::SymplecticEuler, Step::Fixed(1e-3)),
        (Integrator::SymplecticEuler, Step::Auto),
        (Integrator::ExtrapolatedSymplectic, Step::Fixed(5e-4)),
        (Integrator::ExtrapolatedSymplectic, Step::Auto),
        (Integrator::ExplicitEuler, Step::Fixed(2.5e-4)),
        (Integrator::ExplicitEuler, Step::Auto),
        (Integrator::ImplicitEuler, Step::Fixed(1.0 / 240.0)),
        (Integrator::ImplicitEuler, Step::Fixed(1.0 / 120.0)),
        (Integrator::ImplicitEuler, Step::Fixed(1.0 / 30.0)),
        (Integrator::ImplicitEuler, Step::Auto),
        (Integrator::ExtrapolatedImplicit, Step::Fixed(1.0 / 120.0)),
        (Integrator::ExtrapolatedImplicit, Step::Auto),
        (Integrator::Xpbd, Step::Fixed(1.0 / 120.0)),
        (Integrator::Xpbd, Step::Auto),
    ];
    let mut rows = vec![];
    for size in sizes.split(',') {
        let (w, h) = size.split_once('x').expect("WxH");
        let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
        // The reference: second order at a quarter of a millisecond.
        let (_, _, reference) = bake(w, h, Integrator::ExtrapolatedSymplectic, Step::Fixed(2.5e-4));
        let reference = reference.expect("the reference measures");
        for &(integrator, step) in &cases {
            let (cost, per_frame, look) = bake(w, h, integrator, step);
            let deviation = look.as_ref().map(|l| deviation(l, &reference));
            let step_name = match step {
                Step::Fixed(dt) => format!("{:.3} ms", dt * 1e3),
                Step::Auto => "auto".into(),
            };
            eprintln!("{size} {} {step_name}: {cost:.3} s/s, {per_frame:.1} substeps/frame, deviation {deviation:?}", integrator.key());
            rows.push(Row {
                size: size.into(),
                integrator,
                step: step_name,
                cost,
                substeps_per_frame: per_frame,
                look,
                deviation,
            });
        }
    }
    println!("| size | integrator | step | substeps per 30 fps frame | wall s per simulated s | half-waves | travel (m/s) | mid ratio | look deviation |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut csv =
        String::from("size,integrator,step,substeps_per_frame,cost,half_waves,travel,mid_ratio,deviation\n");
    for r in &rows {
        let (hw, tr, mid) = r.look.as_ref().map_or((f64::NAN, f64::NAN, f64::NAN), |l| {
            (l.half_waves, l.travel_speed.unwrap_or(f64::NAN), l.mid_ratio)
        });
        let dev = r
            .deviation
            .map_or("refused".to_string(), |d| format!("{:.1} %", 100.0 * d));
        println!(
            "| {} | {} | {} | {:.1} | {:.3} | {hw:.2} | {tr:.3} | {mid:.3} | {dev} |",
            r.size,
            r.integrator.key(),
            r.step,
            r.substeps_per_frame,
            r.cost
        );
        csv += &format!(
            "{},{},{},{:.3},{:.5},{hw:.4},{tr:.4},{mid:.4},{}\n",
            r.size,
            r.integrator.key(),
            r.step,
            r.substeps_per_frame,
            r.cost,
            r.deviation.map_or(f64::NAN, |d| d)
        );
    }
    std::fs::create_dir_all(&out)?;
    std::fs::write(out.join("step_chart.csv"), csv)?;
    // The chart: cost against deviation, one panel per size, the automatic step ringed.
    let png = out.join("step_chart.png");
    let root = BitMapBackend::new(&png, (1400, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let sizes: Vec<String> = rows.iter().map(|r| r.size.clone()).fold(vec![], |mut v, s| {
        if !v.contains(&s) {
            v.push(s);
        }
        v
    });
    let panels = root.split_evenly((1, sizes.len()));
    for (panel, size) in panels.iter().zip(&sizes) {
        let mine: Vec<&Row> = rows
            .iter()
            .filter(|r| &r.size == size && r.deviation.is_some())
            .collect();
        let (x0, x1) = mine.iter().fold((f64::INFINITY, 0.0f64), |(a, b), r| {
            (a.min(r.cost), b.max(r.cost))
        });
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("underwater swing {size}: look against cost"),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d((x0 / 1.5..x1 * 1.5).log_scale(), (1e-4..1.0f64).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("wall time per simulated second (s), one thread")
            .y_desc("look deviation from the reference")
            .x_label_formatter(&|v| format!("{v:.2}"))
            .y_label_formatter(&|v| format!("{:.2} %", 100.0 * v))
            .draw()?;
        for r in &mine {
            let d = r.deviation.unwrap_or(1.0).max(1.1e-4);
            let c = Palette99::pick(
                Integrator::ALL
                    .iter()
                    .position(|i| *i == r.integrator)
                    .unwrap_or(0),
            )
            .to_rgba();
            chart.draw_series(std::iter::once(Circle::new((r.cost, d), 5, c.filled())))?;
            if r.step == "auto" {
                chart.draw_series(std::iter::once(Circle::new(
                    (r.cost, d),
                    10,
                    BLACK.stroke_width(2),
                )))?;
            }
            chart.draw_series(std::iter::once(Text::new(
                format!("{} {}", r.integrator.key(), r.step),
                (r.cost, d),
                ("sans-serif", 12).into_font().color(&c),
            )))?;
        }
        // The 3 % line.
        chart.draw_series(LineSeries::new(
            vec![(x0 / 1.5, 0.03), (x1 * 1.5, 0.03)],
            RED.stroke_width(1),
        ))?;
    }
    root.present()?;
    eprintln!("wrote {} and step_chart.csv", png.display());
    Ok(())
}
