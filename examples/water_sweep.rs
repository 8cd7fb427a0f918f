//! The underwater preset across the scenes an artist would try (issue: water that holds in
//! every scene): the swing at several drive frequencies, sizes and integrators, measured with
//! the look meter, one line per bake.
//!
//! `cargo run --release --example water_sweep -- [KEY=VALUE ...]`
//!
//! Keys (defaults in brackets): `scene=swing|curtain` [swing; the curtain is 1 x 1.5 m],
//! `freq=0.25,0.5,1,2` (Hz), `amp=0.04` (m), `size=61x41` [51x76 for the curtain],
//! `current=X,Y,Z` (m/s; with `amp=0`, how far the tip leans and flutters), `integrator=symplectic|implicit|explicit|symplectic2|implicit2` [symplectic], `dt` [2 ms
//! explicit, 1/30 s implicit], `auto=1` (each `dt` split by the automatic step, as a host with
//! `max_substep` automatic; with `dt=0.0333`, frames), `seconds=12`, `ramp=0` (s), and the preset's coefficients to try
//! others: `added=` (normal added mass, kg/m^2), `entrained=` (kg/m^2), `cd=` (form drag), `scale=` (its smoothing length, m),
//! `skin=` (N s/m^3), `unsteady=` (N s/m^3) and `memory=` (s) (the unsteady skin drag and its running mean's time constant), `coarse=` (coarse added mass, kg/m^2) and `coarse_len=` [0.2] (its patch spacing, m), `damping=` (spring damping), `dscale=S,H,B` (its multiple per family: stretch, shear, bend), `bend=` (the bend springs' stiffness, times the
//! preset's), `stretch=` (the stretch and shear springs' stiffness, times the preset's), `mode=velocity|fractional|strain|none` (what the
//! springs damp), `history=` (history drag per area, N s^1/2/m^3; the SOE history is kept),
//! `self=` (self-collision thickness in spacings, friction 0.3; 0.4 is the tests' 4 mm at 1 cm).
//! The last columns: the substeps a step call took on average (self-collision splits a
//! substep its step limit refuses), the free vertices its limit slowed (summed over steps: the
//! motion held back) and the bake's wall-clock seconds.

use fraccloth::{Integrator, Model, Vec3};
use fraccloth_tools::look::measure;
use fraccloth_tools::scenes::{Drive, SceneKind, SceneSpec, Variant};

fn main() {
    let args = fraccloth_tools::args::Args::from_env();
    let get = |k: &str| args.get(k);
    let num = |k: &str, d: f64| args.num(k, d);
    let freqs: Vec<f64> = get("freq")
        .unwrap_or("0.25,0.5,1,2".into())
        .split(',')
        .map(|f| f.parse().expect("a frequency"))
        .collect();
    let kind = match get("scene").as_deref() {
        None | Some("swing") => SceneKind::Swing,
        Some("curtain") => SceneKind::Curtain,
        Some(other) => panic!("unknown scene {other} (swing or curtain)"),
    };
    let (w, h) = get("size").map_or(
        if kind == SceneKind::Curtain {
            (51, 76)
        } else {
            (61, 41)
        },
        |s| {
            let (a, b) = s.split_once('x').expect("COLSxROWS");
            (a.parse().expect("cols"), b.parse().expect("rows"))
        },
    );
    let integrator = Integrator::ALL
        .into_iter()
        .find(|i| i.key() == get("integrator").as_deref().unwrap_or("symplectic"))
        .expect("an integrator");
    let mut model = Model::underwater();
    let w_ = &mut model.water;
    w_.added_mass = num("added", w_.added_mass);
    w_.entrained_mass = num("entrained", w_.entrained_mass);
    w_.form_drag = num("cd", w_.form_drag);
    w_.form_drag_scale = num("scale", w_.form_drag_scale);
    w_.skin_drag = num("skin", w_.skin_drag);
    w_.skin_drag_unsteady = num("unsteady", w_.skin_drag_unsteady);
    w_.skin_drag_memory = num("memory", w_.skin_drag_memory);
    w_.coarse_added_mass = num("coarse", w_.coarse_added_mass);
    w_.coarse_length = num("coarse_len", 0.2);
    model.spring_damping = num("damping", model.spring_damping);
    if let Some(d) = get("dscale") {
        let v: Vec<f64> = d
            .split(',')
            .map(|x| x.parse().expect("STRETCH,SHEAR,BEND"))
            .collect();
        model.spring_damping_scale = v.try_into().expect("dscale=STRETCH,SHEAR,BEND: three numbers");
    }
    // Bending stiffness as a multiple of the preset's (its bend springs' k).
    model.bend_stiffness *= num("bend", 1.0);
    model.stretch_stiffness *= num("stretch", 1.0);
    model.shear_stiffness *= num("stretch", 1.0);
    model.water.history_drag = num("history", model.water.history_drag);
    if let Some(t) = get("self") {
        model.self_collision_relative = t.parse().expect("self=THICKNESS in spacings");
        model.self_collision_friction = 0.3;
    }
    if let Some(mode) = get("mode") {
        model.spring_damping_mode = match mode.as_str() {
            "velocity" => fraccloth::model::SpringDamping::Velocity,
            "fractional" => fraccloth::model::SpringDamping::Fractional,
            "strain" => fraccloth::model::SpringDamping::FractionalStrain,
            "none" => fraccloth::model::SpringDamping::None,
            other => panic!("unknown mode {other}"),
        };
    }
    let seconds = num("seconds", 12.0);
    let fps = 30.0;
    println!(
        "# {w}x{h} {} added {} (coarse {} over {} m) entrained {} C_d {} over {} m, skin {} (+{} unsteady over {} s) damping {}",
        integrator.key(),
        model.water.added_mass,
        model.water.coarse_added_mass,
        model.water.coarse_length,
        model.water.entrained_mass,
        model.water.form_drag,
        model.water.form_drag_scale,
        model.water.skin_drag,
        model.water.skin_drag_unsteady,
        model.water.skin_drag_memory,
        model.spring_damping
    );
    println!("freq Hz | half-waves | travel m/s | mid | bottom | zigzag | hang m | max speed m/s | substeps a call | slowed | s | status");
    for f in freqs {
        let spec = SceneSpec {
            width: w,
            height: h,
            integrator,
            dt: num(
                "dt",
                if integrator.is_implicit() {
                    1.0 / 30.0
                } else {
                    2e-3
                },
            ),
            drive: Drive {
                amplitude: num("amp", 0.04),
                frequency: f,
                ramp: num("ramp", 0.0),
                current: get("current").map_or(Vec3::zeros(), |c| {
                    let v: Vec<f64> = c.split(',').map(|x| x.parse().expect("X,Y,Z")).collect();
                    Vec3::new(v[0], v[1], v[2])
                }),
            },
            scheme: fraccloth::history::Scheme::DEFAULT,
            max_substep: if get("auto").is_some() {
                fraccloth::cloth::AUTO
            } else {
                0.0
            },
            ..SceneSpec::paper(kind, Variant::Underwater)
        };
        let spec = SceneSpec {
            model: Some(Model {
                current: spec.drive.current,
                ..model
            }),
            ..spec
        };
        let mut scene = spec.build().expect("a scene");
        let topo = scene.cloth.topology().clone();
        let (mut frames, mut times) = (vec![scene.cloth.positions().to_vec()], vec![0.0]);
        let mut status = "ok".to_string();
        let mut vmax: f64 = 0.0;
        let (mut calls, mut substeps) = (0u64, 0u64);
        let clock = std::time::Instant::now();
        for k in 1..=(seconds * fps) as usize {
            // One step call at a time (`Scene::run_until`'s loop), so that each call's
            // substeps are counted.
            while scene.cloth.time() + 0.5 * spec.dt < k as f64 / fps {
                if let Err(e) = scene.step() {
                    status = e.to_string();
                    break;
                }
                calls += 1;
                substeps += u64::from(scene.cloth.step_stats().substeps);
            }
            if status != "ok" {
                break;
            }
            frames.push(scene.cloth.positions().to_vec());
            times.push(k as f64 / fps);
            vmax = scene
                .cloth
                .velocities()
                .iter()
                .map(|v| v.norm())
                .fold(vmax, f64::max);
        }
        let wall = clock.elapsed().as_secs_f64();
        let per_call = substeps as f64 / calls.max(1) as f64;
        if spec.drive.amplitude == 0.0 {
            let root = scene.top_row()[w as usize / 2] as usize;
            let tip = (h as usize - 1) * w as usize + w as usize / 2;
            let s = fraccloth_tools::look::measure_stream(&topo.rest_positions, &frames, &times, root, tip);
            let d = scene.cloth.positions()[tip] - topo.rest_positions[tip];
            println!(
                "still | {s:?} | tip moved ({:.4}, {:.4}, {:.4}) m | {status}",
                d.x, d.y, d.z
            );
            continue;
        }
        match measure(&topo.rest_positions, &topo.triangles, &frames, &times, Vec3::y()) {
            Ok(look) => {
                let d = &look.descriptors;
                println!(
                    "{f} | {:.2} | {} | {:.3} | {:.3} | {} | {:.3} | {vmax:.3} | {per_call:.2} | {} | {wall:.1} | {status}",
                    d.half_waves,
                    d.travel_speed.map_or("-".into(), |c| format!("{c:.3}")),
                    d.mid_ratio,
                    d.bottom_ratio,
                    d.zigzag.map_or("-".into(), |z| format!("{z:.2}")),
                    d.hang_depth,
                    scene.cloth.step_limit_stats().slowed
                );
            }
            Err(e) => println!("{f} | not measured: {e} | {status}"),
        }
    }
}
