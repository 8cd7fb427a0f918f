//! `fraccloth`: bakes a built-in underwater cloth scene to a PC2 point cache plus an OBJ rest
//! mesh that Blender, Maya or 3ds Max can load (Mesh Cache modifier), with preview pictures: a
//! contact sheet (PNG) and an animated GIF. `--compare` bakes one scene with the paper's three
//! regular models, its fractional preset, the fractional model with the accurate history and
//! the underwater preset side by side, and measures the look of each (`fraccloth_tools::look`).
//!
//! With no arguments it bakes the underwater `swing` scene (61 x 41, 12 s) into `out/`.
//! `fraccloth look CACHE --rest REST.obj` measures the look of any point cache.

// Picture loops walk several arrays with one index; that reads better than zips.
#![allow(clippy::needless_range_loop)]

use std::fmt::Write as _;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Parser, Subcommand};

mod render;
use fraccloth::export::{write_obj, CacheFormat, CacheWriter};
use fraccloth::history::Scheme;
use fraccloth::{HalfDerivative, Integrator, RegularDrag, Vec3};
use fraccloth_tools::look::{measure, measure_stream, Look};
use fraccloth_tools::read::{read_cache, read_obj};
use fraccloth_tools::scenes::{stable_dt, Drive, Scene, SceneKind, SceneSpec, Variant, DEFAULT_DT};
use indicatif::{ProgressBar, ProgressStyle};
use render::{contact_sheet, render_frame, save_png, side_view, space_time, Camera, GifWriter, Scene3d};
use tiny_skia::Pixmap;

#[derive(Parser, Debug)]
#[command(
    version,
    about = "Bake an underwater cloth scene to PC2 and MDD point caches, an OBJ rest mesh and preview pictures",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    bake: Args,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Measure the look of a point cache of a hanging cloth driven at its top edge:
    /// half-waves, travel speed, depth of the motion, zigzag, bulges (docs/look.md).
    Look(LookArgs),
}

#[derive(clap::Args, Debug)]
struct LookArgs {
    /// The cache: an MDD (frame times inside) or a PC2 (give --fps).
    cache: PathBuf,
    /// The rest mesh (OBJ) with the cache's vertex order.
    #[arg(long)]
    rest: PathBuf,
    /// Frames per second (required for PC2; overrides an MDD's own times).
    #[arg(long)]
    fps: Option<f64>,
    /// The up axis of the cache: x, y, z, -x, -y or -z (Blender's own caches are z-up).
    #[arg(long, default_value = "y")]
    up: String,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Also write the side view and the space-time plot as PNGs with this path prefix.
    #[arg(long)]
    pictures: Option<PathBuf>,
}

#[derive(clap::Args, Debug)]
struct Args {
    /// Scene: swing, sway, sphere, current (the towel still in a current along its plane),
    /// kelp (a buoyant 10 x 100 cm strip pinned at its foot) or curtain (1 x 1.5 m, swung).
    #[arg(long, default_value = "swing")]
    scene: String,
    /// Model: underwater (the water's physics per unit area; the default), fractional (the
    /// paper's), regular (normal drag), regular-viscous, regular-viscous-normal.
    #[arg(long, default_value = "underwater")]
    variant: String,
    /// Grid size as COLUMNSxROWS (the paper uses 61x41 and 31x21; default 61x41, 11x101 for
    /// kelp: 1 cm spacing; 51x76 for the curtain: 2 cm).
    #[arg(long)]
    size: Option<String>,
    /// Drive frequency of the pinned edge, Hz (default: the scene's own, 0.5 Hz for swing).
    #[arg(long)]
    frequency: Option<f64>,
    /// Drive amplitude of the pinned edge, m (default: the scene's own, 4 cm for the
    /// underwater swing; 0 holds the edge still).
    #[arg(long)]
    amplitude: Option<f64>,
    /// Water current as X,Y,Z in m/s (default: the scene's own; none but for `current`).
    #[arg(long, value_parser = parse_vec3)]
    current: Option<Vec3>,
    /// Seconds over which the drive fades in (default 0: a sudden start, as the paper's).
    #[arg(long)]
    ramp: Option<f64>,
    /// Build the cloth as an irregular triangle mesh (the grid's vertices moved at random by up
    /// to 15 % of the spacing, random diagonals) instead of the grid.
    #[arg(long)]
    jittered: bool,
    /// Bake your own mesh (an OBJ: triangles or quads, y up, metres; vertex order kept in the
    /// caches) instead of the built-in towel, with the scene's drive on its pins and every
    /// water option. 1 kg/m^2. Pins: --pin-group, --pin-file or --pin-top (default: the top
    /// row).
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// With --mesh: pin the vertices of the OBJ group (`g` or `o` name) NAME.
    #[arg(long)]
    pin_group: Option<String>,
    /// With --mesh: pin the vertices listed in FILE (0-based indices, separated by spaces,
    /// commas or new lines).
    #[arg(long)]
    pin_file: Option<PathBuf>,
    /// With --mesh: pin the ROWS highest rows of vertices (those within ROWS - 1/2 mean edge
    /// lengths of the highest vertex). Default 1 when no other pin option is given.
    #[arg(long)]
    pin_top: Option<f64>,
    /// Self-collision: the distance the cloth keeps from itself, in its spacings (0.4: 4 mm on
    /// the 1 cm towel; default 0, off). For scenes that fold (brisk swings, drops); it costs a
    /// search for nearby triangles every few substeps (docs/collisions.md).
    #[arg(long, default_value_t = 0.0)]
    self_collision: f64,
    /// Simulated seconds.
    #[arg(long, default_value_t = 12.0)]
    seconds: f64,
    /// Frames per second written to the cache.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Time step, seconds. Default: the automatic step for the underwater preset (each frame
    /// split into as few substeps as the cloth needs); for the paper's models a stable fixed
    /// step for the size and integrator (0.5 ms at 1 cm spacing, shrinking with the spacing for
    /// the explicit integrators; 1/30 s implicit).
    #[arg(long)]
    dt: Option<f64>,
    /// Integrator: explicit (the paper's Eq. 7), symplectic, implicit (stable at frame rate; first
    /// order, it damps fast motion: at the automatic step its substeps are kept short enough for
    /// the motion that the shot holds, at a fixed --dt of a frame a 1-2 Hz swing's free edge moves
    /// 15-70 % less than with symplectic); second order: symplectic2, implicit2 (each step extrapolated from a whole
    /// and two half steps); xpbd (stretch and shear springs as compliant constraints: about 3
    /// substeps a 60 Hz frame instead of 14, softer in the cloth's plane and fewer ripples at
    /// 2 Hz, docs/realtime.md). Default: symplectic for the underwater preset, explicit for the
    /// paper's models.
    #[arg(long)]
    integrator: Option<String>,
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
    /// Bake the scene with six models side by side (three regular, the paper's fractional
    /// preset, the fractional model with the accurate history, the underwater preset) into one
    /// comparison sheet, and measure their look.
    #[arg(long)]
    compare: bool,
    /// Also write every frame as an OBJ (NAME_0001.obj, ...).
    #[arg(long)]
    obj_frames: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, z] = parts[..] else {
        return Err(format!("{s:?} is not X,Y,Z"));
    };
    let p = |v: &str| v.trim().parse::<f64>().map_err(|e| format!("{s:?}: {e}"));
    let v = Vec3::new(p(x)?, p(y)?, p(z)?);
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(format!("{s:?} is not finite"))
    }
}

/// The scene named by `--scene`.
fn scene_kind(args: &Args) -> Result<SceneKind, String> {
    SceneKind::from_name(&args.scene).ok_or_else(|| {
        format!(
            "unknown scene {:?} (swing, sway, sphere, current, kelp, curtain)",
            args.scene
        )
    })
}

/// Columns and rows: `--size`, or the scene's own.
fn size_of(args: &Args) -> Result<(u32, u32), String> {
    match &args.size {
        Some(s) => parse_size(s),
        None => Ok(scene_kind(args)?.default_size()),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size {s:?} is not COLUMNSxROWS"))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("size {s:?}: {e}"));
    Ok((p(w)?, p(h)?))
}

/// The integrator and step a bake uses: as given, or the variant's own and a stable step.
fn integrator_and_dt(args: &Args, variant: Variant) -> Result<(Integrator, f64), String> {
    let key = match (&args.integrator, variant) {
        (Some(k), _) => k.as_str(),
        (None, Variant::Underwater) => "symplectic",
        (None, _) => "explicit",
    };
    let integrator = Integrator::ALL
        .into_iter()
        .find(|i| i.key() == key)
        .ok_or_else(|| {
            let keys: Vec<&str> = Integrator::ALL.iter().map(Integrator::key).collect();
            format!("unknown integrator {key:?} ({})", keys.join(", "))
        })?;
    let (width, _) = size_of(args)?;
    let spacing = scene_kind(args)?.extent().0 / f64::from(width.max(2) - 1);
    let dt = args.dt.unwrap_or_else(|| stable_dt(spacing, integrator));
    if !(dt.is_finite() && dt > 0.0) {
        return Err(format!("--dt must be positive, got {dt}"));
    }
    Ok((integrator, dt))
}

fn scheme_from(args: &Args) -> Result<Scheme, String> {
    let dt = args.dt.unwrap_or(DEFAULT_DT);
    Ok(match args.history.as_str() {
        "soe" => Scheme::SumOfExponentials {
            tolerance: args.tolerance,
            horizon: fraccloth::history::DEFAULT_SOE_HORIZON.max(2.0 * args.seconds),
            min_dt: fraccloth::history::DEFAULT_SOE_MIN_DT.min(dt),
        },
        "paper" => Scheme::Truncated { u: args.u },
        "full" => Scheme::Full,
        "off" => Scheme::Off,
        other => return Err(format!("unknown history {other:?} (soe, paper, full, off)")),
    })
}

fn spec_from(args: &Args, variant: Variant, scheme: Scheme) -> Result<SceneSpec, String> {
    let kind = scene_kind(args)?;
    let (width, height) = size_of(args)?;
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.fps.is_finite() && args.fps > 0.0) {
        return Err("--seconds and --fps must be positive".into());
    }
    let (integrator, dt) = integrator_and_dt(args, variant)?;
    let own = Drive::of(kind, variant);
    let drive = Drive {
        amplitude: args.amplitude.unwrap_or(own.amplitude),
        frequency: args.frequency.unwrap_or(own.frequency),
        ramp: args.ramp.unwrap_or(own.ramp),
        current: args.current.unwrap_or(own.current),
    };
    let finite = drive.amplitude.is_finite() && drive.frequency.is_finite() && drive.ramp.is_finite();
    if !(finite && drive.frequency > 0.0 && drive.ramp >= 0.0) {
        return Err("--amplitude must be finite, --frequency positive, --ramp >= 0".into());
    }
    if !(args.self_collision.is_finite() && args.self_collision >= 0.0) {
        return Err(format!(
            "--self-collision must be >= 0 spacings, got {}",
            args.self_collision
        ));
    }
    // The underwater preset steps once per frame with the automatic step unless --dt is given.
    let auto = args.dt.is_none() && variant == Variant::Underwater;
    Ok(SceneSpec {
        width,
        height,
        dt: if auto { 1.0 / args.fps } else { dt },
        max_substep: if auto { fraccloth::cloth::AUTO } else { 0.0 },
        jittered: args.jittered,
        self_collision: args.self_collision,
        scheme,
        integrator,
        drive,
        ..SceneSpec::paper(kind, variant)
    })
}

/// The user's mesh (`--mesh`): its topology (quads kept when every face is one), the pinned
/// vertices and the mean edge length.
fn user_mesh(args: &Args, path: &Path) -> Result<(fraccloth::Topology, Vec<u32>, f64), String> {
    use fraccloth::topology::{MeshMass, MeshSpec};
    let obj = read_obj(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if obj.faces.is_empty() {
        return Err(format!("{}: no faces", path.display()));
    }
    let quads = obj.faces.iter().all(|f| f.len() == 4);
    let indices: Vec<u32> = if quads {
        obj.faces.iter().flatten().copied().collect()
    } else {
        obj.triangles.iter().flatten().copied().collect()
    };
    let topology = MeshSpec {
        positions: &obj.positions,
        indices: &indices,
        face_size: if quads { 4 } else { 3 },
        mass: MeshMass::ArealDensity(1.0),
    }
    .build()
    .map_err(|e| format!("{}: {e}", path.display()))?;
    let edges: Vec<f64> = obj
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .map(|(a, b)| (obj.positions[a as usize] - obj.positions[b as usize]).norm())
        .collect();
    let spacing = edges.iter().sum::<f64>() / edges.len() as f64;
    let n = obj.positions.len();
    let mut pins: Vec<u32> = Vec::new();
    if let Some(name) = &args.pin_group {
        let names: Vec<&str> = obj.groups.iter().map(|(g, _)| g.as_str()).collect();
        pins.extend(obj.group_vertices(name).ok_or_else(|| {
            format!(
                "{}: no group named {name:?} (its groups: {})",
                path.display(),
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        })?);
    }
    if let Some(file) = &args.pin_file {
        let text = std::fs::read_to_string(file).map_err(io(file))?;
        for tok in text
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
        {
            let i: u32 = tok
                .parse()
                .map_err(|e| format!("{}: {tok:?} is not a vertex index: {e}", file.display()))?;
            if i as usize >= n {
                return Err(format!(
                    "{}: vertex {i} does not exist (the mesh has {n})",
                    file.display()
                ));
            }
            pins.push(i);
        }
    }
    let rows = match args.pin_top {
        Some(r) if !(r.is_finite() && r > 0.0) => return Err(format!("--pin-top must be positive, got {r}")),
        Some(r) => Some(r),
        None if pins.is_empty() => Some(1.0),
        None => None,
    };
    if let Some(rows) = rows {
        let top = obj
            .positions
            .iter()
            .map(|p| p.y)
            .fold(f64::NEG_INFINITY, f64::max);
        let below = (rows - 0.5) * spacing;
        pins.extend((0..n as u32).filter(|&i| obj.positions[i as usize].y >= top - below));
    }
    pins.sort_unstable();
    pins.dedup();
    Ok((topology, pins, spacing))
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

fn parse_up(s: &str) -> Result<Vec3, String> {
    let (sign, axis) = s.strip_prefix('-').map_or((1.0, s), |a| (-1.0, a));
    let v = match axis.trim_start_matches('+') {
        "x" => Vec3::x(),
        "y" => Vec3::y(),
        "z" => Vec3::z(),
        _ => return Err(format!("--up {s:?}: give x, y, z, -x, -y or -z")),
    };
    Ok(sign * v)
}

/// Side view and space-time plot of a measured look, at `prefix-side.png` and
/// `prefix-spacetime.png`; returns the two paths.
fn write_look_pictures(look: &Look, title: &str, prefix: &Path) -> Result<[PathBuf; 2], String> {
    let stem = prefix.file_name().and_then(|s| s.to_str()).unwrap_or("look");
    let side = prefix.with_file_name(format!("{stem}-side.png"));
    let st = prefix.with_file_name(format!("{stem}-spacetime.png"));
    let pix = side_view(look, title, 360, 480).ok_or("cannot draw the side view")?;
    save_png(&pix, &side).map_err(io(&side))?;
    let pix = space_time(look, title, 640, 360).ok_or("cannot draw the space-time plot")?;
    save_png(&pix, &st).map_err(io(&st))?;
    Ok([side, st])
}

/// `fraccloth look`: measure a cache read from disk.
fn look_command(a: &LookArgs) -> Result<(), String> {
    let up = parse_up(&a.up)?;
    let mesh = read_obj(&a.rest).map_err(io(&a.rest))?;
    let cache = read_cache(&a.cache).map_err(io(&a.cache))?;
    if cache.vertex_count != mesh.positions.len() {
        return Err(format!(
            "{} has {} vertices, the rest mesh {} has {}",
            a.cache.display(),
            cache.vertex_count,
            a.rest.display(),
            mesh.positions.len()
        ));
    }
    let frames = cache.frames.len();
    let times = match (a.fps, cache.times) {
        (Some(fps), _) if fps.is_finite() && fps > 0.0 => (0..frames).map(|k| k as f64 / fps).collect(),
        (Some(fps), _) => return Err(format!("--fps must be positive, got {fps}")),
        (None, Some(t)) => t,
        (None, None) => return Err("a PC2 cache does not store its frame rate: give --fps".into()),
    };
    let look = measure(&mesh.positions, &mesh.triangles, &cache.frames, &times, up)
        .map_err(|e| format!("{}: {e}", a.cache.display()))?;
    if a.json {
        println!("{}", look.to_json());
    } else {
        print!("{}", look.summary());
    }
    if let Some(prefix) = &a.pictures {
        let title = a.cache.file_name().and_then(|s| s.to_str()).unwrap_or("cache");
        let [side, st] = write_look_pictures(&look, title, prefix)?;
        if !a.json {
            println!("pictures           {}, {}", side.display(), st.display());
        }
    }
    Ok(())
}

fn bake(args: &Args) -> Result<(), String> {
    let variant = Variant::from_name(&args.variant).ok_or_else(|| {
        format!(
            "unknown variant {:?} (underwater, fractional, regular, regular-viscous, regular-viscous-normal)",
            args.variant
        )
    })?;
    let spec = spec_from(args, variant, scheme_from(args)?)?;
    if args.mesh.is_none() && (args.pin_group.is_some() || args.pin_file.is_some() || args.pin_top.is_some())
    {
        return Err("--pin-group, --pin-file and --pin-top go with --mesh".into());
    }
    let (mut scene, stem) = match &args.mesh {
        None => (
            spec.build().map_err(|e| e.to_string())?,
            format!("{}-{}", spec.kind.name(), variant.name()),
        ),
        Some(path) => {
            let (topology, pins, spacing) = user_mesh(args, path)?;
            let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh");
            let scene = spec
                .build_on(topology, &pins, spacing)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            (scene, format!("{name}-{}", variant.name()))
        }
    };
    std::fs::create_dir_all(&args.out).map_err(io(&args.out))?;
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
    // The frames, for the look meter.
    let mut recorded: Vec<Vec<Vec3>> = Vec::with_capacity(frames as usize + 1);
    let bar = progress(args.quiet, frames, format!("baking {stem}"))?;
    let started = Instant::now();
    // The automatic step's substeps per frame: sum, most, retries.
    let (mut substeps, mut most, mut retries) = (0u64, 0u32, 0u32);
    for f in 0..=frames {
        if f > 0 {
            scene
                .run_until(f as f64 / args.fps)
                .map_err(|e| format!("frame {f}: {e}"))?;
            let s = scene.cloth.step_stats();
            (substeps, most, retries) = (
                substeps + u64::from(s.substeps),
                most.max(s.substeps),
                retries + s.retries,
            );
            bar.inc(1);
        }
        for (cache, p) in caches.iter_mut() {
            cache.write_frame(scene.cloth.positions()).map_err(io(p))?;
        }
        recorded.push(scene.cloth.positions().to_vec());
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
            render::draw_label(cell, label, 6, 6, 2);
        }
        let rows: Vec<Vec<Pixmap>> = sheet_cells.chunks(4).map(|c| c.to_vec()).collect();
        let sheet = contact_sheet(&rows, &[], &[]).ok_or("empty sheet")?;
        save_png(&sheet, &sheet_path).map_err(io(&sheet_path))?;
    }
    let steps = scene.cloth.step_count();
    let n = topo.vertex_count();
    let history = &scene.cloth.history();
    let mut summary = format!(
        "scene        {}\nvariant      {}\ncloth        {} ({} vertices, {} springs)\nhistory      {} ({} modes, {} bytes/particle)\nintegrator   {}\ndt           {}\nsimulated    {:.3} s in {} steps\nframes       {} at {} fps (+ frame 0)\nwall time    {:.3} s simulating ({:.2} M particle-steps/s), {:.3} s drawing previews\npoint caches {} (PC2), {} (MDD)\nrest mesh    {}\n",
        spec.kind.name(),
        variant.name(),
        match &args.mesh {
            Some(p) => format!("{} ({} pinned)", p.display(), scene.top_row().len()),
            None => format!("grid {} x {}", spec.width, spec.height),
        },
        n,
        topo.springs.len(),
        if history.is_off() { Scheme::Off.name() } else { spec.scheme.name() },
        history.mode_count(),
        history.bytes_per_particle(),
        spec.integrator.name(),
        if spec.max_substep < 0.0 {
            format!(
                "automatic: {:.2} substeps per frame on average ({:.3} ms), most {most}, {retries} frames retried",
                substeps as f64 / frames.max(1) as f64,
                1e3 / args.fps / (substeps as f64 / frames.max(1) as f64)
            )
        } else {
            format!("{} s", spec.dt)
        },
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
    let times: Vec<f64> = (0..recorded.len()).map(|k| k as f64 / args.fps).collect();
    let driven = spec.drive.amplitude != 0.0;
    let look = if driven {
        measure(
            &topo.rest_positions,
            &topo.triangles,
            &recorded,
            &times,
            Vec3::y(),
        )
    } else {
        Err(fraccloth::Error::invalid(
            "the pinned edge is held still (no drive): see the stream below",
        ))
    };
    match look {
        Ok(look) => {
            let json = path("-look.json");
            std::fs::write(&json, look.to_json() + "\n").map_err(io(&json))?;
            let _ = write!(
                summary,
                "look (centre column, `fraccloth look`), {}:\n{}",
                json.display(),
                look.summary()
            );
            if preview {
                let [side, st] = write_look_pictures(&look, &stem, &args.out.join(&stem))?;
                let _ = writeln!(summary, "look pictures {}, {}", side.display(), st.display());
            }
        }
        Err(e) => {
            let _ = writeln!(summary, "look         not measured: {e}");
        }
    }
    // A still cloth in a current: how far it leans and how its free edge flutters.
    if !driven && args.mesh.is_some() {
        let _ = writeln!(
            summary,
            "stream       not measured on a mesh of your own (the lean is measured on the built-in scenes)"
        );
    } else if !driven {
        let (w, h) = (spec.width as usize, spec.height as usize);
        let root = scene.top_row()[w / 2] as usize;
        let tip = if spec.kind == SceneKind::Kelp {
            w / 2
        } else {
            (h - 1) * w + w / 2
        };
        match measure_stream(&topo.rest_positions, &recorded, &times, root, tip) {
            Ok(stream) => {
                let json = path("-stream.json");
                std::fs::write(&json, stream.to_json() + "\n").map_err(io(&json))?;
                let _ = write!(summary, "stream ({}):\n{}", json.display(), stream.summary());
            }
            Err(e) => {
                let _ = writeln!(summary, "stream       not measured: {e}");
            }
        }
    }
    print!("{summary}");
    let txt = path(".txt");
    std::fs::write(&txt, summary).map_err(io(&txt))?;
    Ok(())
}

/// Stacks pictures top to bottom on the sheet's dark background.
fn stack(pictures: &[Pixmap]) -> Result<Pixmap, String> {
    let w = pictures.iter().map(Pixmap::width).max().unwrap_or(1);
    let h = pictures.iter().map(Pixmap::height).sum::<u32>().max(1);
    let mut out = Pixmap::new(w, h).ok_or("bad sheet size")?;
    out.fill(tiny_skia::Color::from_rgba8(12, 16, 24, 255));
    let mut y = 0;
    for p in pictures {
        out.draw_pixmap(
            0,
            y as i32,
            p.as_ref(),
            &tiny_skia::PixmapPaint::default(),
            tiny_skia::Transform::identity(),
            None,
        );
        y += p.height();
    }
    Ok(out)
}

/// The look table's header and one row.
const LOOK_HEADER: &str = "| model | half-waves | travel speed (m/s) | half-amplitude depth (m) | mid / bottom ratio | zigzag | bulges | hang depth (m) |\n|---|---|---|---|---|---|---|---|\n";

fn look_row(name: &str, look: &Look) -> String {
    let d = &look.descriptors;
    let opt = |v: Option<f64>, none: &str| v.map_or(none.to_string(), |x| format!("{x:.3}"));
    format!(
        "| {name} | {:.2} | {} | {} | {:.2} / {:.2} | {} | {:.2} | {:.3} |\n",
        d.half_waves,
        opt(d.travel_speed, "none"),
        opt(d.half_amplitude_depth, "never"),
        d.mid_ratio,
        d.bottom_ratio,
        opt(d.zigzag, "n/a"),
        d.bulges,
        d.hang_depth
    )
}

fn compare(args: &Args) -> Result<(), String> {
    let models: [(&str, Variant, Scheme); 6] = [
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
        ("underwater", Variant::Underwater, Scheme::DEFAULT),
    ];
    std::fs::create_dir_all(&args.out).map_err(io(&args.out))?;
    let rows_out = 6usize;
    let times: Vec<f64> = (0..rows_out)
        .map(|k| args.seconds * (0.25 + 0.75 * k as f64 / (rows_out - 1) as f64))
        .collect();
    let mut columns: Vec<Vec<Pixmap>> = vec![];
    let (mut sides, mut spacetimes) = (vec![], vec![]);
    let mut table = String::new();
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
        let frames = (args.seconds * args.fps).round() as u64;
        let mut recorded = vec![scene.cloth.positions().to_vec()];
        let mut next = 0;
        for f in 1..=frames {
            let t = f as f64 / args.fps;
            scene.run_until(t).map_err(|e| format!("{name}, t = {t}: {e}"))?;
            recorded.push(scene.cloth.positions().to_vec());
            while next < times.len() && times[next] <= t + 1e-9 {
                cells.push(picture(&scene, &camera)?);
                next += 1;
            }
        }
        let topo = scene.cloth.topology();
        let frame_times: Vec<f64> = (0..recorded.len()).map(|k| k as f64 / args.fps).collect();
        match measure(
            &topo.rest_positions,
            &topo.triangles,
            &recorded,
            &frame_times,
            Vec3::y(),
        ) {
            Ok(look) => {
                table += &look_row(name, &look);
                sides.push(side_view(&look, name, 280, 380).ok_or("cannot draw a side view")?);
                spacetimes.push(space_time(&look, name, 280, 220).ok_or("cannot draw a space-time plot")?);
            }
            Err(e) => {
                table += &format!("| {name} | not measured: {e} |||||||\n");
            }
        }
        columns.push(cells);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let rows: Vec<Vec<Pixmap>> = (0..rows_out)
        .map(|r| columns.iter().filter_map(|c| c.get(r).cloned()).collect())
        .collect();
    let col_labels: Vec<String> = models.iter().map(|m| m.0.to_string()).collect();
    let row_labels: Vec<String> = times.iter().map(|t| format!("{t:.1}s")).collect();
    let mut parts = vec![contact_sheet(&rows, &col_labels, &row_labels).ok_or("empty sheet")?];
    // The side views and space-time plots under the 3D frames, column for column.
    let left = 8 * 2 * row_labels.iter().map(String::len).max().unwrap_or(0) as u32 + 8;
    for plots in [&sides, &spacetimes] {
        if plots.len() == columns.len() {
            let sheet = contact_sheet(&[plots.to_vec()], &[], &[]).ok_or("empty sheet")?;
            let mut shifted = Pixmap::new(left + sheet.width(), sheet.height()).ok_or("bad sheet size")?;
            shifted.fill(tiny_skia::Color::from_rgba8(12, 16, 24, 255));
            shifted.draw_pixmap(
                left as i32,
                0,
                sheet.as_ref(),
                &tiny_skia::PixmapPaint::default(),
                tiny_skia::Transform::identity(),
                None,
            );
            parts.push(shifted);
        }
    }
    let sheet = stack(&parts)?;
    let sheet_path = args.out.join(format!("compare-{}.png", args.scene));
    save_png(&sheet, &sheet_path).map_err(io(&sheet_path))?;
    let table = format!(
        "Look of `{}` ({}, {} s; each model with its own integrator and a stable step unless given: explicit Euler for the paper's models, symplectic Euler for the underwater preset), measured by `fraccloth look` on the centre column over whole drive periods of the second half:\n\n{LOOK_HEADER}{table}",
        args.scene,
        size_of(args).map(|(w, h)| format!("{w}x{h}"))?,
        args.seconds
    );
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
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Look(a)) => look_command(a),
        None if cli.bake.compare => compare(&cli.bake),
        None => bake(&cli.bake),
    };
    if let Err(e) = result {
        eprintln!("fraccloth: {e}");
        std::process::exit(1);
    }
}
