//! A bar swept through a hanging towel at 1 to 5 m/s (docs/collisions.md): does each frame
//! step, how many substeps and retries, and where the row at the bar's height ends up.
//!
//! `cargo run --release --example fast_bar -- [SPEED ...] [key=value ...]` (keys: added,
//! entrained, thin=0|1)

use fraccloth::collide::shapes::bar;
use fraccloth::{Integrator, Model, Vec3};
use fraccloth_tools::scenes::{collision_towel_with, TowelPose};

const FPS: f64 = 30.0;

fn main() {
    let mut speeds = Vec::new();
    let mut model = Model::underwater();
    let mut half_width = 0.002;
    let mut ends = 1.0;
    let mut integrator = Integrator::SymplecticEuler;
    let mut pinrow = false;
    let mut max_substep = fraccloth::cloth::AUTO;
    for a in std::env::args().skip(1) {
        match a.split_once('=') {
            Some(("added", v)) => model.water.added_mass = v.parse().expect("added"),
            Some(("entrained", v)) => model.water.entrained_mass = v.parse().expect("entrained"),
            Some(("half", v)) => half_width = v.parse().expect("half"),
            Some(("ends", v)) => ends = v.parse().expect("ends"),
            Some(("implicit", _)) => integrator = Integrator::ImplicitEuler,
            Some(("pinrow", _)) => pinrow = true,
            Some(("dt", v)) => max_substep = v.parse().expect("dt"),
            _ => speeds.push(a.parse::<f64>().expect("speed")),
        }
    }
    if speeds.is_empty() {
        speeds = vec![1.0, 2.0, 3.0, 5.0];
    }
    let y = -0.3;
    for speed in speeds {
        let mut cloth =
            collision_towel_with(21, 21, 0.02, 0.0, TowelPose::Hanging, model, integrator).expect("towel");
        let mut top: Vec<u32> = (0..21).collect();
        if pinrow {
            top.extend(15 * 21..16 * 21);
        }
        cloth.set_pinned(&top).expect("pins");
        let rest: Vec<Vec3> = cloth.positions().to_vec();
        let mut config = cloth.config().clone();
        config.max_substep = max_substep;
        cloth.reconfigure(config).expect("max_substep");
        let (bx, bt) = bar(
            Vec3::new(-0.4 * ends, y, 0.0),
            Vec3::new(0.4 * ends, y, 0.0),
            half_width,
            1,
        );
        let away = if pinrow { 10.0 } else { 0.0 };
        let at = |z: f64| -> Vec<Vec3> { bx.iter().map(|p| p + Vec3::new(away, 0.0, z)).collect() };
        let id = cloth.add_mesh_collider(&at(0.1), &bt, None).expect("bar");
        let mut z = 0.1;
        let sweep = (0.2 / speed * FPS).round() as usize;
        let (mut substeps, mut retries, mut failed) = (0u64, 0u64, None);
        for frame in 0..sweep + 30 {
            if frame < sweep {
                z -= speed / FPS;
            }
            cloth.set_mesh_collider(id, &at(z), None).expect("move");
            let trace = std::env::var("TRACE").is_ok();
            let calls = if trace { 10 } else { 1 };
            let mut res = Ok(());
            let z0 = if frame < sweep { z + speed / FPS } else { z };
            for k in 0..calls {
                if trace {
                    let zk = z0 + (z - z0) * f64::from(k + 1) / f64::from(calls);
                    cloth.set_mesh_collider(id, &at(zk), None).expect("move");
                    if pinrow {
                        let t: Vec<Vec3> = (15 * 21..16 * 21)
                            .map(|i| rest[i] + Vec3::new(0.0, 0.0, zk.min(0.0)))
                            .collect();
                        let idx: Vec<u32> = (15 * 21..16 * 21).collect();
                        cloth.set_pin_targets(&idx, &t).expect("targets");
                    }
                }
                res = cloth.step(1.0 / FPS / f64::from(calls));
                if trace {
                    let (i, v) = cloth
                        .velocities()
                        .iter()
                        .enumerate()
                        .map(|(i, v)| (i, v.norm()))
                        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
                    let x = cloth.positions()[i];
                    println!("  t {:.4} max speed {v:.3} at vertex {i} (row {}, col {}) at {:.4} {:.4} {:.4}; bar z {z:.4}", (frame as f64 + (k + 1) as f64 / f64::from(calls)) / FPS, i / 21, i % 21, x.x, x.y, x.z);
                }
                if res.is_err() {
                    break;
                }
            }
            match res {
                Ok(()) => {
                    substeps += u64::from(cloth.step_stats().substeps);
                    retries += u64::from(cloth.step_stats().retries);
                }
                Err(e) => {
                    failed = Some((frame, e.message));
                    break;
                }
            }
        }
        let row = &cloth.positions()[15 * 21..16 * 21];
        let row_z = row.iter().map(|p| p.z).sum::<f64>() / 21.0;
        match failed {
            None => println!("{speed} m/s: baked, {substeps} substeps, {retries} retries, row 15 mean z {row_z:.3} (bar at {z:.3})"),
            Some((f, m)) => println!("{speed} m/s: refused at frame {f} (sweep {sweep} frames): {m}"),
        }
    }
}
