//! `fraccloth`: bakes a built-in underwater cloth scene to a PC2 point cache plus
//! an OBJ rest mesh that Blender, Maya or 3ds Max can load (Mesh Cache modifier).
//!
//! With no arguments it bakes the paper's fractional `swing` scene (61 x 41) into `out/`.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use fraccloth::export::{write_obj, Pc2Writer};
use fraccloth::history::Scheme;
use fraccloth::scenes::{SceneKind, SceneSpec, Variant, DEFAULT_DT};
use fraccloth::{HalfDerivative, Integrator};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser, Debug)]
#[command(
    version,
    about = "Bake an underwater cloth scene to a PC2 point cache and an OBJ rest mesh"
)]
struct Args {
    /// Scene: swing, sway or sphere.
    #[arg(long, default_value = "swing")]
    scene: String,
    /// Model: fractional, regular (normal drag), regular-viscous, regular-viscous-normal.
    #[arg(long, default_value = "fractional")]
    variant: String,
    /// Grid size as COLUMNSxROWS (the paper uses 61x41 and 31x21).
    #[arg(long, default_value = "61x41")]
    size: String,
    /// Simulated seconds.
    #[arg(long, default_value_t = 8.0)]
    seconds: f64,
    /// Frames per second written to the cache.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Time step, seconds.
    #[arg(long, default_value_t = DEFAULT_DT)]
    dt: f64,
    /// Integrator: explicit (the paper's Eq. 7), symplectic, implicit (stable at frame rate).
    #[arg(long, default_value = "explicit")]
    integrator: String,
    /// How D^{1/2} is evaluated: soe (accurate, constant cost; the default), paper (Eq. 6 with
    /// the last --u states), full (exact convolution, cost grows with time), off.
    #[arg(long, default_value = "soe")]
    history: String,
    /// History length u for --history paper.
    #[arg(long, default_value_t = 3)]
    u: u32,
    /// Relative kernel tolerance for --history soe.
    #[arg(long, default_value_t = fraccloth::history::DEFAULT_SOE_TOLERANCE)]
    tolerance: f64,
    /// Output directory.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size {s:?} is not COLUMNSxROWS"))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("size {s:?}: {e}"));
    Ok((p(w)?, p(h)?))
}

fn run(args: Args) -> Result<(), String> {
    let kind = SceneKind::from_name(&args.scene)
        .ok_or_else(|| format!("unknown scene {:?} (swing, sway, sphere)", args.scene))?;
    let variant = Variant::from_name(&args.variant).ok_or_else(|| {
        format!(
            "unknown variant {:?} (fractional, regular, regular-viscous, regular-viscous-normal)",
            args.variant
        )
    })?;
    let (width, height) = parse_size(&args.size)?;
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.fps.is_finite() && args.fps > 0.0) {
        return Err("--seconds and --fps must be positive".into());
    }
    let scheme = match args.history.as_str() {
        "soe" => Scheme::SumOfExponentials {
            tolerance: args.tolerance,
            horizon: fraccloth::history::DEFAULT_SOE_HORIZON.max(2.0 * args.seconds),
            min_dt: fraccloth::history::DEFAULT_SOE_MIN_DT.min(args.dt),
        },
        "paper" => Scheme::Truncated { u: args.u },
        "full" => Scheme::Full,
        "off" => Scheme::Off,
        other => return Err(format!("unknown history {other:?} (soe, paper, full, off)")),
    };
    let integrator = Integrator::ALL
        .into_iter()
        .find(|i| i.key() == args.integrator)
        .ok_or_else(|| {
            format!(
                "unknown integrator {:?} (explicit, symplectic, implicit)",
                args.integrator
            )
        })?;
    let spec = SceneSpec {
        width,
        height,
        dt: args.dt,
        scheme,
        integrator,
        ..SceneSpec::paper(kind, variant)
    };
    let mut scene = spec.build().map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let stem = format!("{}-{}", kind.name(), variant.name());
    let pc2_path = args.out.join(format!("{stem}.pc2"));
    let obj_path = args.out.join(format!("{stem}.obj"));
    let topo = scene.cloth.topology().clone();
    let obj = File::create(&obj_path).map_err(|e| format!("{}: {e}", obj_path.display()))?;
    write_obj(BufWriter::new(obj), &topo.rest_positions, &topo.triangles).map_err(|e| e.to_string())?;
    let pc2 = File::create(&pc2_path).map_err(|e| format!("{}: {e}", pc2_path.display()))?;
    let mut cache =
        Pc2Writer::new(BufWriter::new(pc2), topo.vertex_count(), 1.0, 1.0).map_err(|e| e.to_string())?;

    let frames = (args.seconds * args.fps).round() as u64;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(frames)
    };
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames, {elapsed_precise} (eta {eta})")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    bar.set_message(format!("baking {stem}"));
    let started = Instant::now();
    cache
        .write_frame(scene.cloth.positions())
        .map_err(|e| e.to_string())?;
    for f in 1..=frames {
        scene
            .run_until(f as f64 / args.fps)
            .map_err(|e| format!("frame {f}: {e}"))?;
        cache
            .write_frame(scene.cloth.positions())
            .map_err(|e| e.to_string())?;
        bar.inc(1);
    }
    cache.finish().map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    let steps = scene.cloth.step_count();
    let n = topo.vertex_count();
    let summary = format!(
        "scene        {}\nvariant      {}\ngrid         {} x {} ({} vertices, {} springs)\nhistory      {} ({} modes, {} bytes/particle)\nintegrator   {}\ndt           {} s\nsimulated    {:.3} s in {} steps\nframes       {} at {} fps (+ frame 0)\nwall time    {:.3} s ({:.2} M particle-steps/s)\npoint cache  {}\nrest mesh    {}\n",
        kind.name(),
        variant.name(),
        width,
        height,
        n,
        topo.springs.len(),
        if scene.cloth.history().is_off() { Scheme::Off.name() } else { spec.scheme.name() },
        scene.cloth.history().mode_count(),
        scene.cloth.history().bytes_per_particle(),
        spec.integrator.name(),
        spec.dt,
        scene.cloth.time(),
        steps,
        frames,
        args.fps,
        wall,
        (steps as f64 * n as f64) / wall / 1e6,
        pc2_path.display(),
        obj_path.display(),
    );
    print!("{summary}");
    std::fs::write(args.out.join(format!("{stem}.txt")), summary).map_err(|e| e.to_string())?;
    Ok(())
}

fn main() {
    if let Err(e) = run(Args::parse()) {
        eprintln!("fraccloth: {e}");
        std::process::exit(1);
    }
}
