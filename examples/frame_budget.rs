//! The underwater towel in a game's frame: what a frame of cloth costs and what it looks like,
//! per way of stepping, measured in one run (a benchmark: times are printed, never asserted).
//!
//! `cargo run --release --example frame_budget -- [KEY=VALUE ...]`
//!
//! Each row bakes the underwater swing (top edge swung `amp` m at `freq` Hz) for `seconds`
//! seconds, one `step` call per frame of `1/fps` s on one thread, as a game's loop does, and
//! prints the median and worst wall time of a frame's call (ms), the substeps a frame took,
//! and the look by the project's meter (half-waves, travel speed, mid ratio, hang) with each
//! descriptor's deviation from the first completed row of the same drive and frame rate (the
//! preset's symplectic Euler at its automatic step unless `ways` leaves it out). Keys:
//! `freq=0.5,1,2`, `fps=60`, `size=61x41`,
//! `jittered=1` (the irregular triangle mesh of the same size), `amp=0.04`, `seconds=12`,
//! `ways=symplectic,xpbd,xpbd_scaled,implicit_frame` (which ways of stepping; `xpbd_scaled`
//! is XPBD with the form drag smoothed over 1.15 cm instead of 1 cm, `implicit_frame` implicit
//! Euler at one step a frame, `implicit2_frame` its extrapolated, second-order form at one step
//! a frame, not in the default list: about 20 ms a frame; `tolerance=1e-2` loosens the implicit
//! solve's relative tolerance, 1e-6 by default), `substeps=8,10,15` (every way at that many equal substeps a frame
//! instead of its own step, each drive's first row the preset at its automatic step for
//! reference: what the look needs, and where a way stops being stable).

use fraccloth::{Integrator, Model, Vec3};
use fraccloth_tools::look::measure;
use fraccloth_tools::scenes::{Drive, SceneKind, SceneSpec, Variant};

/// One way of stepping: its name, integrator, whether it takes the automatic step, and the
/// form drag's smoothing length (m).
struct Way {
    name: &'static str,
    integrator: Integrator,
    auto: bool,
    scale: f64,
}

const WAYS: [Way; 5] = [
    Way {
        name: "symplectic",
        integrator: Integrator::SymplecticEuler,
        auto: true,
        scale: fraccloth::model::UNDERWATER_FORM_DRAG_SCALE,
    },
    Way {
        name: "xpbd",
        integrator: Integrator::Xpbd,
        auto: true,
        scale: fraccloth::model::UNDERWATER_FORM_DRAG_SCALE,
    },
    Way {
        name: "xpbd_scaled",
        integrator: Integrator::Xpbd,
        auto: true,
        scale: 0.0115,
    },
    Way {
        name: "implicit_frame",
        integrator: Integrator::ImplicitEuler,
        auto: false,
        scale: fraccloth::model::UNDERWATER_FORM_DRAG_SCALE,
    },
    Way {
        name: "implicit2_frame",
        integrator: Integrator::ExtrapolatedImplicit,
        auto: false,
        scale: fraccloth::model::UNDERWATER_FORM_DRAG_SCALE,
    },
];

/// What one bake gave.
struct Row {
    median_ms: f64,
    worst_ms: f64,
    substeps: f64,
    look: [f64; 3],
    hang: f64,
    status: String,
}

fn main() {
    let args = fraccloth_tools::args::Args::from_env();
    let get = |k: &str| args.get(k);
    let num = |k: &str, d: f64| args.num(k, d);
    let list = |k: &str, d: &str| -> Vec<String> {
        get(k).unwrap_or(d.into()).split(',').map(String::from).collect()
    };
    let freqs: Vec<f64> = list("freq", "0.5,1,2")
        .iter()
        .map(|f| f.parse().expect("Hz"))
        .collect();
    let fps_list: Vec<f64> = list("fps", "60")
        .iter()
        .map(|f| f.parse().expect("frames/s"))
        .collect();
    let ways = list("ways", "symplectic,xpbd,xpbd_scaled,implicit_frame");
    let (w, h) = args.size("size", (61, 41));
    let jittered = get("jittered").is_some();
    println!(
        "# {w}x{h}{}, one thread, {} s bakes; deviations against the first row of each drive and frame rate",
        if jittered { " jittered mesh" } else { " grid" },
        num("seconds", 12.0)
    );
    println!("way | freq Hz | fps | median ms | worst ms | substeps | half-waves | travel m/s | mid | hang m | deviation (half-waves, travel, mid) | status");
    let substeps: Vec<f64> = list("substeps", "0")
        .iter()
        .map(|n| n.parse().expect("substeps a frame"))
        .collect();
    for &fps in &fps_list {
        for &f in &freqs {
            let scene = |substeps: f64| Bake {
                freq: f,
                fps,
                size: (w, h),
                jittered,
                amp: num("amp", 0.04),
                seconds: num("seconds", 12.0),
                substeps,
                tolerance: num("tolerance", 0.0),
            };
            // With fixed substeps, the reference is the preset at its own step.
            let fixed = substeps.iter().any(|&n| n > 0.0);
            let mut reference: Option<[f64; 3]> = None;
            if fixed {
                let row = bake(&WAYS[0], &scene(0.0));
                reference = (row.status == "ok").then_some(row.look);
                print_row("symplectic (automatic step)", f, fps, &row, reference);
            }
            for &n in &substeps {
                for way in WAYS.iter().filter(|w| ways.iter().any(|name| name == w.name)) {
                    let row = bake(way, &scene(n));
                    // Against the first row that completed (a way refused has no look).
                    if row.status == "ok" && reference.is_none() {
                        reference = Some(row.look);
                    }
                    print_row(way.name, f, fps, &row, reference);
                }
            }
        }
    }
}

/// Prints one bake's row, its look's deviations from `reference`'s (percent).
fn print_row(name: &str, f: f64, fps: f64, row: &Row, reference: Option<[f64; 3]>) {
    let base = reference.unwrap_or([f64::NAN; 3]);
    let dev = |k: usize| match row.status == "ok" {
        true => format!("{:+.1} %", 100.0 * (row.look[k] / base[k] - 1.0)),
        false => "-".to_string(),
    };
    println!(
        "{name} | {f} | {fps} | {:.3} | {:.3} | {:.2} | {:.2} | {:.3} | {:.3} | {:.3} | {}, {}, {} | {}",
        row.median_ms,
        row.worst_ms,
        row.substeps,
        row.look[0],
        row.look[1],
        row.look[2],
        row.hang,
        dev(0),
        dev(1),
        dev(2),
        row.status
    );
}

/// One bake's scene: the drive (Hz), frame rate, grid size, mesh, swing (m), length (s),
/// substeps a frame (0: the way's own) and the implicit solve's tolerance.
#[derive(Clone, Copy)]
struct Bake {
    freq: f64,
    fps: f64,
    size: (u32, u32),
    jittered: bool,
    amp: f64,
    seconds: f64,
    substeps: f64,
    /// The implicit solve's relative tolerance (0: the library's, 1e-6).
    tolerance: f64,
}

/// Bakes the swing one way and measures it.
fn bake(way: &Way, b: &Bake) -> Row {
    let Bake {
        freq,
        fps,
        size: (w, h),
        jittered,
        amp,
        seconds,
        substeps: fixed,
        ..
    } = *b;
    let mut model = Model::underwater();
    model.water.form_drag_scale = way.scale;
    let spec = SceneSpec {
        width: w,
        height: h,
        integrator: way.integrator,
        dt: 1.0 / fps,
        drive: Drive {
            amplitude: amp,
            frequency: freq,
            ramp: 0.0,
            current: Vec3::zeros(),
        },
        scheme: fraccloth::history::Scheme::DEFAULT,
        max_substep: match (fixed > 0.0, way.auto) {
            (true, _) => 1.0 / (fps * fixed),
            (false, true) => fraccloth::cloth::AUTO,
            (false, false) => 0.0,
        },
        model: Some(model),
        jittered,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
    };
    let mut scene = spec.build().expect("a scene");
    scene.cloth.set_threads(1).expect("one thread");
    if b.tolerance > 0.0 {
        let mut config = scene.cloth.config().clone();
        config.solver.tolerance = b.tolerance;
        scene.cloth.reconfigure(config).expect("a tolerance");
    }
    let topo = scene.cloth.topology().clone();
    let (mut frames, mut times) = (vec![scene.cloth.positions().to_vec()], vec![0.0]);
    let mut ms = Vec::new();
    let mut substeps = 0u64;
    let mut status = "ok".to_string();
    let count = (seconds * fps).round() as usize;
    // The meter reads 30 frames a second whatever the step's.
    let every = (fps / 30.0).round().max(1.0) as usize;
    for k in 1..=count {
        let clock = std::time::Instant::now();
        if let Err(e) = scene.step() {
            status = e.to_string();
            break;
        }
        ms.push(clock.elapsed().as_secs_f64() * 1e3);
        substeps += u64::from(scene.cloth.step_stats().substeps);
        if k % every == 0 {
            frames.push(scene.cloth.positions().to_vec());
            times.push(scene.cloth.time());
        }
    }
    ms.sort_by(f64::total_cmp);
    let (median_ms, worst_ms) = (
        ms.get(ms.len() / 2).copied().unwrap_or(0.0),
        ms.last().copied().unwrap_or(0.0),
    );
    let (look, hang) = match measure(&topo.rest_positions, &topo.triangles, &frames, &times, Vec3::y()) {
        Ok(l) => {
            let d = &l.descriptors;
            (
                [d.half_waves, d.travel_speed.unwrap_or(0.0), d.mid_ratio],
                d.hang_depth,
            )
        }
        Err(e) => {
            status = format!("{status}; meter: {e}");
            ([0.0; 3], 0.0)
        }
    };
    Row {
        median_ms,
        worst_ms,
        substeps: substeps as f64 / ms.len().max(1) as f64,
        look,
        hang,
        status,
    }
}
