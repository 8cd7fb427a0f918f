//! `fraccloth`: bakes a built-in underwater cloth scene to a PC2 point cache plus an OBJ rest
//! mesh that Blender, Maya or 3ds Max can load (Mesh Cache modifier), with preview pictures: a
//! contact sheet (PNG) and an animated GIF. `--compare` bakes one scene with the paper's three
//! regular models, its fractional preset and the accurate default side by side, and measures
//! the look of each (`fraccloth::look`).
//!
//! With no arguments it bakes the fractional `swing` scene (61 x 41, 8 s) into `out/`.

use std::fmt::Write as _;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Parser;
use fraccloth::export::{write_obj, CacheFormat, CacheWriter};
use fraccloth::history::Scheme;
use fraccloth::look::{describe, Look};
use fraccloth::render::{contact_sheet, render_frame, save_png, Camera, GifWriter, Scene3d};
use fraccloth::scenes::{Scene, SceneKind, SceneSpec, Variant, DEFAULT_DT};
use fraccloth::{HalfDerivative, Integrator, RegularDrag};
use indicatif::{ProgressBar, ProgressStyle};
use tiny_skia::Pixmap;

#[derive(Parser, Debug)]
#[command(
    version,
    about = "Bake an underwater cloth scene to PC2 and MDD point caches, an OBJ rest mesh and preview pictures"
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
    /// Skip the preview pictures.
    #[arg(long)]
    no_preview: bool,
    /// Bake the scene with five models side by side (three regular, the paper's fractional
    /// preset, the accurate default) into one comparison sheet, and measure their look.
    #[arg(long)]
    compare: bool,
    /// Also write every frame as an OBJ (NAME_0001.obj, ...).
    #[arg(long)]
    obj_frames: bool,
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

fn scheme_from(args: &Args) -> Result<Scheme, String> {
    Ok(match args.history.as_str() {
        "soe" => Scheme::SumOfExponentials {
            tolerance: args.tolerance,
            horizon: fraccloth::history::DEFAULT_SOE_HORIZON.max(2.0 * args.seconds),
            min_dt: fraccloth::history::DEFAULT_SOE_MIN_DT.min(args.dt),
        },
        "paper" => Scheme::Truncated { u: args.u },
        "full" => Scheme::Full,
        "off" => Scheme::Off,
        other => return Err(format!("unknown history {other:?} (soe, paper, full, off)")),
    })
}

fn spec_from(args: &Args, variant: Variant, scheme: Scheme) -> Result<SceneSpec, String> {
    let kind = SceneKind::from_name(&args.scene)
        .ok_or_else(|| format!("unknown scene {:?} (swing, sway, sphere)", args.scene))?;
    let (width, height) = parse_size(&args.size)?;
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.fps.is_finite() && args.fps > 0.0) {
        return Err("--seconds and --fps must be positive".into());
    }
    let integrator = Integrator::ALL
        .into_iter()
        .find(|i| i.key() == args.integrator)
        .ok_or_else(|| {
            format!(
                "unknown integrator {:?} (explicit, symplectic, implicit)",
                args.integrator
            )
        })?;
    Ok(SceneSpec {
        width,
        height,
        dt: args.dt,
        scheme,
        integrator,
        ..SceneSpec::paper(kind, variant)
    })
}

/// The fixed camera of a scene.
fn camera_for(scene: &Scene, width: u32, height: u32) -> Camera {
    Camera::for_rest_shape(&scene.cloth.topology().rest_positions, width, height)
}

fn picture(scene: &Scene, camera: &Camera) -> Result<Pixmap, String> {
    let mut pix = Pixmap::new(camera.width, camera.height).ok_or("bad picture size")?;
    let spheres = Scene3d::spheres_of(scene.cloth.colliders().iter().copied());
    let s3 = Scene3d {
        positions: scene.cloth.positions(),
        triangles: &scene.cloth.topology().triangles,
        spheres: &spheres,
    };
    render_frame(&s3, camera, &mut pix);
    Ok(pix)
}

fn progress(quiet: bool, len: u64, msg: String) -> Result<ProgressBar, String> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(len)
    };
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames, {elapsed_precise} (eta {eta})")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    bar.set_message(msg);
    Ok(bar)
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> String + '_ {
    move |e| format!("{}: {e}", path.display())
}

fn bake(args: &Args) -> Result<(), String> {
    let variant = Variant::from_name(&args.variant).ok_or_else(|| {
        format!(
            "unknown variant {:?} (fractional, regular, regular-viscous, regular-viscous-normal)",
            args.variant
        )
    })?;
    let spec = spec_from(args, variant, scheme_from(args)?)?;
    let mut scene = spec.build().map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&args.out).map_err(io(&args.out))?;
    let stem = format!("{}-{}", spec.kind.name(), variant.name());
    let path = |ext: &str| args.out.join(format!("{stem}{ext}"));
    let topo = scene.cloth.topology().clone();
    let obj_path = path(".obj");
    write_obj(
        BufWriter::new(File::create(&obj_path).map_err(io(&obj_path))?),
        &topo.rest_positions,
        &topo.triangles,
    )
    .map_err(io(&obj_path))?;
    let frames = (args.seconds * args.fps).round() as u64;
    let (pc2_path, mdd_path, seq_path) = (path(".pc2"), path(".mdd"), path(".obj"));
    let mut formats = vec![(CacheFormat::Pc2, &pc2_path), (CacheFormat::Mdd, &mdd_path)];
    if args.obj_frames {
        formats.push((CacheFormat::ObjSequence, &seq_path));
    }
    // Frame 0 is the first sample: host frame 1, as Blender counts.
    let mut caches = formats
        .into_iter()
        .map(|(format, p)| {
            let expected = u32::try_from(frames + 1).map_err(|_| "too many frames".to_string())?;
            CacheWriter::create(
                p,
                format,
                topo.vertex_count(),
                &topo.triangles,
                1.0,
                args.fps,
                expected,
            )
            .map(|w| (w, p))
            .map_err(io(p))
        })
        .collect::<Result<Vec<_>, String>>()?;

    let preview = !args.no_preview;
    let (sheet_cam, gif_cam) = (camera_for(&scene, 320, 240), camera_for(&scene, 400, 300));
    let gif_every = (args.fps / 15.0).round().max(1.0) as u64;
    let (gif_path, sheet_path) = (path(".gif"), path("-sheet.png"));
    let mut gif = if preview {
        Some(GifWriter::create(&gif_path, 400, 300, gif_every as f64 / args.fps).map_err(io(&gif_path))?)
    } else {
        None
    };
    let sheet_frames: Vec<u64> = (0..8).map(|k| (k * frames) / 7).collect();
    let mut sheet_cells = vec![];
    let mut render_time = 0.0;
    let bar = progress(args.quiet, frames, format!("baking {stem}"))?;
    let started = Instant::now();
    for f in 0..=frames {
        if f > 0 {
            scene
                .run_until(f as f64 / args.fps)
                .map_err(|e| format!("frame {f}: {e}"))?;
            bar.inc(1);
        }
        for (cache, p) in caches.iter_mut() {
            cache.write_frame(scene.cloth.positions()).map_err(io(p))?;
        }
        let t0 = Instant::now();
        if let Some(g) = gif.as_mut() {
            if f % gif_every == 0 {
                g.push(&picture(&scene, &gif_cam)?).map_err(io(&gif_path))?;
            }
        }
        if preview && sheet_frames.contains(&f) {
            sheet_cells.push(picture(&scene, &sheet_cam)?);
        }
        render_time += t0.elapsed().as_secs_f64();
    }
    for (cache, p) in caches {
        cache.finish().map_err(io(p))?;
    }
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64() - render_time;
    if preview {
        let labels: Vec<String> = sheet_frames
            .iter()
            .map(|&f| format!("t={:.2}s", f as f64 / args.fps))
            .collect();
        // Two rows of four, each cell labelled with its time.
        for (cell, label) in sheet_cells.iter_mut().zip(&labels) {
            fraccloth::render::draw_label(cell, label, 6, 6, 2);
        }
        let rows: Vec<Vec<Pixmap>> = sheet_cells.chunks(4).map(|c| c.to_vec()).collect();
        let sheet = contact_sheet(&rows, &[], &[]).ok_or("empty sheet")?;
        save_png(&sheet, &sheet_path).map_err(io(&sheet_path))?;
    }
    let steps = scene.cloth.step_count();
    let n = topo.vertex_count();
    let history = &scene.cloth.history();
    let mut summary = format!(
        "scene        {}\nvariant      {}\ngrid         {} x {} ({} vertices, {} springs)\nhistory      {} ({} modes, {} bytes/particle)\nintegrator   {}\ndt           {} s\nsimulated    {:.3} s in {} steps\nframes       {} at {} fps (+ frame 0)\nwall time    {:.3} s simulating ({:.2} M particle-steps/s), {:.3} s drawing previews\npoint caches {} (PC2), {} (MDD)\nrest mesh    {}\n",
        spec.kind.name(),
        variant.name(),
        spec.width,
        spec.height,
        n,
        topo.springs.len(),
        if history.is_off() { Scheme::Off.name() } else { spec.scheme.name() },
        history.mode_count(),
        history.bytes_per_particle(),
        spec.integrator.name(),
        spec.dt,
        scene.cloth.time(),
        steps,
        frames,
        args.fps,
        wall,
        (steps as f64 * n as f64) / wall / 1e6,
        render_time,
        pc2_path.display(),
        mdd_path.display(),
        obj_path.display(),
    );
    if preview {
        let _ = writeln!(
            summary,
            "preview      {} (8 frames), {} (15 fps)",
            sheet_path.display(),
            gif_path.display()
        );
    }
    print!("{summary}");
    let txt = path(".txt");
    std::fs::write(&txt, summary).map_err(io(&txt))?;
    Ok(())
}

/// Centre-column out-of-plane displacement from the top edge, per row.
fn centre_profile(scene: &Scene) -> Vec<f64> {
    let (w, h) = (scene.spec.width as usize, scene.spec.height as usize);
    let x = scene.cloth.positions();
    let i = w / 2;
    let top = x[i].z;
    (0..h).map(|j| x[j * w + i].z - top).collect()
}

fn compare(args: &Args) -> Result<(), String> {
    let models: [(&str, Variant, Scheme); 5] = [
        (
            "regular v+n",
            Variant::Regular(RegularDrag::ViscousAndNormal),
            Scheme::Off,
        ),
        (
            "regular visc",
            Variant::Regular(RegularDrag::Viscous),
            Scheme::Off,
        ),
        ("regular norm", Variant::Regular(RegularDrag::Normal), Scheme::Off),
        ("paper u=3", Variant::Fractional, Scheme::PAPER),
        ("fractional", Variant::Fractional, Scheme::DEFAULT),
    ];
    std::fs::create_dir_all(&args.out).map_err(io(&args.out))?;
    let rows_out = 6usize;
    let times: Vec<f64> = (0..rows_out)
        .map(|k| args.seconds * (0.25 + 0.75 * k as f64 / (rows_out - 1) as f64))
        .collect();
    let mut columns: Vec<Vec<Pixmap>> = vec![];
    let mut looks: Vec<(String, Look)> = vec![];
    let bar = progress(
        args.quiet,
        models.len() as u64,
        format!("comparing models on {}", args.scene),
    )?;
    for (name, variant, scheme) in models {
        let spec = spec_from(args, variant, scheme)?;
        let mut scene = spec.build().map_err(|e| e.to_string())?;
        let camera = camera_for(&scene, 280, 210);
        let mut cells = vec![];
        let mut field = vec![];
        let frames = (args.seconds * args.fps).round() as u64;
        let mut next = 0;
        for f in 1..=frames {
            let t = f as f64 / args.fps;
            scene.run_until(t).map_err(|e| format!("{name}, t = {t}: {e}"))?;
            if t >= 0.5 * args.seconds {
                field.push(centre_profile(&scene));
            }
            while next < times.len() && times[next] <= t + 1e-9 {
                cells.push(picture(&scene, &camera)?);
                next += 1;
            }
        }
        let frame_dt = 1.0 / args.fps;
        looks.push((
            name.to_string(),
            describe(&field, spec.spacing(), frame_dt, 0.002),
        ));
        columns.push(cells);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let rows: Vec<Vec<Pixmap>> = (0..rows_out)
        .map(|r| columns.iter().filter_map(|c| c.get(r).cloned()).collect())
        .collect();
    let col_labels: Vec<String> = models.iter().map(|m| m.0.to_string()).collect();
    let row_labels: Vec<String> = times.iter().map(|t| format!("{t:.1}s")).collect();
    let sheet = contact_sheet(&rows, &col_labels, &row_labels).ok_or("empty sheet")?;
    let sheet_path = args.out.join(format!("compare-{}.png", args.scene));
    save_png(&sheet, &sheet_path).map_err(io(&sheet_path))?;
    let mut table = format!(
        "Look of `{}` ({}, {} s, dt {} s, explicit Euler), second half of the bake, centre column:\n\n| model | bumps (mean) | half-amplitude distance (m) | travel speed (m/s) | largest displacement from the top edge (m) |\n|---|---|---|---|---|\n",
        args.scene, args.size, args.seconds, args.dt
    );
    for (name, l) in &looks {
        let opt = |v: Option<f64>, none: &str| v.map_or(none.to_string(), |x| format!("{x:.3}"));
        let _ = writeln!(
            table,
            "| {name} | {:.2} | {} | {} | {:.4} |",
            l.mean_bumps,
            opt(l.half_amplitude_distance, "never halves"),
            opt(l.travel_speed, "no correlation"),
            l.max_displacement
        );
    }
    let table_path = args.out.join(format!("look-{}.md", args.scene));
    std::fs::write(&table_path, &table).map_err(io(&table_path))?;
    print!(
        "{table}\nsheet        {}\ntable        {}\n",
        sheet_path.display(),
        table_path.display()
    );
    Ok(())
}

fn main() {
    let args = Args::parse();
    let result = if args.compare { compare(&args) } else { bake(&args) };
    if let Err(e) = result {
        eprintln!("fraccloth: {e}");
        std::process::exit(1);
    }
}
