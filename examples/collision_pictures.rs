//! The pictures of docs/collisions.md: the scenes of `tests/collisions.rs`, drawn as wireframes
//! seen from the side (crossing triangles in red, colliders in grey), a row of frames each.
//!
//! `cargo run --release --example collision_pictures` writes `docs/collisions/*.png` (the last, the
//! underwater swing against a 10k-triangle ball, is `collision_cost`'s case 3).

use fraccloth::collide::intersections::{crossing_pairs, self_intersections};
use fraccloth::collide::shapes::{bar, torus};
use fraccloth::forces::{Collider, Plane};
use fraccloth::{Cloth, Integrator, Vec3};
use fraccloth_tools::scenes::{collision_towel, TowelPose};
use plotters::prelude::*;

const FPS: f64 = 30.0;

/// The collision scenes' towel (`scenes::collision_towel`), stepped with symplectic Euler.
fn towel(w: u32, h: u32, spacing: f64, y: f64, pose: TowelPose, thickness: f64) -> Cloth {
    collision_towel(w, h, spacing, y, pose, thickness, Integrator::SymplecticEuler).expect("towel")
}

/// One panel: the cloth's triangle edges projected with `view` (crossing ones red) and the
/// collider's edges in grey.
fn panel(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    title: &str,
    cloth: &Cloth,
    collider: Option<(&[Vec3], &[[u32; 3]])>,
    view: fn(&Vec3) -> (f64, f64),
    range: ((f64, f64), (f64, f64)),
) -> Result<(), Box<dyn std::error::Error>> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(6)
        .build_cartesian_2d(range.0 .0..range.0 .1, range.1 .0..range.1 .1)?;
    if let Some((x, t)) = collider {
        for tri in t {
            let p: Vec<(f64, f64)> = tri
                .iter()
                .chain(std::iter::once(&tri[0]))
                .map(|&i| view(&x[i as usize]))
                .collect();
            chart.draw_series(std::iter::once(PathElement::new(p, RGBColor(170, 170, 170))))?;
        }
    }
    let x = cloth.positions();
    let tris = &cloth.topology().triangles;
    for tri in tris {
        let p: Vec<(f64, f64)> = tri
            .iter()
            .chain(std::iter::once(&tri[0]))
            .map(|&i| view(&x[i as usize]))
            .collect();
        chart.draw_series(std::iter::once(PathElement::new(p, RGBColor(30, 80, 160))))?;
    }
    // Crossing pairs: both triangles in red, each edge its own two-point line (a thick path
    // through three nearly collinear points, a triangle seen edge-on, has a miter join that
    // plotters draws far off the panel).
    for (a, b) in crossing_pairs(x, tris) {
        for t in [tris[a as usize], tris[b as usize]] {
            for k in 0..3 {
                let ends = vec![view(&x[t[k] as usize]), view(&x[t[(k + 1) % 3] as usize])];
                chart.draw_series(std::iter::once(PathElement::new(ends, RED.stroke_width(2))))?;
            }
        }
    }
    Ok(())
}

/// The underwater swing of `width` x `height` at `frequency` Hz and `amplitude` m with
/// `model`, at the automatic step (`collision_cost`'s scenes).
fn swing(
    width: u32,
    height: u32,
    frequency: f64,
    amplitude: f64,
    model: fraccloth::Model,
) -> Result<fraccloth_tools::scenes::Scene, fraccloth::Error> {
    fraccloth_tools::scenes::SceneSpec::underwater_swing(width, height, frequency, amplitude, model).build()
}

fn side(p: &Vec3) -> (f64, f64) {
    (p.z, p.y)
}
fn front(p: &Vec3) -> (f64, f64) {
    (p.x, p.y)
}

/// A side view of `cloth` titled with `label`, the time `when` and how many of its triangle
/// pairs cross.
fn crossings_panel(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    label: &str,
    when: &str,
    cloth: &Cloth,
    range: ((f64, f64), (f64, f64)),
) -> Result<(), Box<dyn std::error::Error>> {
    let n = self_intersections(cloth.positions(), &cloth.topology().triangles);
    panel(
        area,
        &format!("{label}, {when}: {n} crossing pairs"),
        cloth,
        None,
        side,
        range,
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all("docs/collisions")?;
    let floor = Collider::Plane(Plane {
        point: Vec3::zeros(),
        normal: Vec3::y(),
        velocity: Vec3::zeros(),
    });

    // 1. The drop, with and without self-collision: side view at 1, 2.5 and 5 s.
    let root = BitMapBackend::new("docs/collisions/drop.png", (1500, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let rows = root.split_evenly((2, 3));
    for (r, thickness) in [0.005, 0.0].into_iter().enumerate() {
        let mut cloth = towel(21, 31, 0.02, 0.62, TowelPose::Wavy, thickness);
        cloth.add_collider(floor)?;
        let mut f = 0;
        for (k, until) in [30, 75, 150].into_iter().enumerate() {
            while f < until {
                cloth.step(1.0 / FPS)?;
                f += 1;
            }
            let label = if thickness > 0.0 {
                "self-collision 5 mm"
            } else {
                "no self-collision"
            };
            let when = format!("{:.1} s", f as f64 / FPS);
            crossings_panel(
                &rows[3 * r + k],
                label,
                &when,
                &cloth,
                ((-0.35, 0.35), (-0.02, 0.65)),
            )?;
        }
    }
    root.present()?;

    // 2. A towel over a turning torus: front view at 0.5, 1.5 and 3 s.
    let (tx, tt) = torus(Vec3::zeros(), 0.12, 0.05, 48, 16);
    let root = BitMapBackend::new("docs/collisions/torus.png", (1500, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    let cells = root.split_evenly((1, 3));
    let mut cloth = towel(25, 25, 0.016, 0.08, TowelPose::Flat, 0.0);
    let id = cloth.add_mesh_collider(&tx, &tt, None)?;
    cloth.set_collider_friction(id, 0.5)?;
    let mut f = 0;
    for (k, until) in [15, 45, 90].into_iter().enumerate() {
        let mut posed = tx.clone();
        while f < until {
            f += 1;
            let a = 0.5 * f as f64 / FPS;
            let rot = nalgebra::Rotation3::from_axis_angle(&Vec3::y_axis(), a)
                * nalgebra::Rotation3::from_axis_angle(&Vec3::x_axis(), 0.2 * a.sin());
            posed = tx.iter().map(|p| rot * p).collect();
            cloth.set_mesh_collider(id, &posed, None)?;
            cloth.step(1.0 / FPS)?;
        }
        let inside = fraccloth::collide::intersections::vertices_inside(cloth.positions(), &posed, &tt);
        panel(
            &cells[k],
            &format!("torus mesh, {:.1} s: {inside} vertices inside", f as f64 / FPS),
            &cloth,
            Some((&posed, &tt)),
            front,
            ((-0.5, 0.3), (-0.15, 0.15)),
        )?;
    }
    root.present()?;

    // 3. A 4 mm bar through a hanging towel of 2 cm spacing: side view at 0.5, 1 and 2 s.
    let root = BitMapBackend::new("docs/collisions/bar.png", (1500, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    let cells = root.split_evenly((1, 3));
    let mut cloth = towel(21, 21, 0.02, 0.0, TowelPose::Hanging, 0.0);
    let top: Vec<u32> = (0..21).collect();
    cloth.set_pinned(&top)?;
    let (bx, bt) = bar(Vec3::new(-0.4, -0.3, 0.0), Vec3::new(0.4, -0.3, 0.0), 0.002, 1);
    let at = |z: f64| -> Vec<Vec3> { bx.iter().map(|p| p + Vec3::new(0.0, 0.0, z)).collect() };
    let id = cloth.add_mesh_collider(&at(0.1), &bt, None)?;
    let (mut z, mut f) = (0.1, 0);
    for (k, until) in [15, 30, 60].into_iter().enumerate() {
        while f < until {
            f += 1;
            z -= 0.1 / FPS;
            cloth.set_mesh_collider(id, &at(z), None)?;
            cloth.step(1.0 / FPS)?;
        }
        let posed = at(z);
        panel(
            &cells[k],
            &format!("4 mm bar, {:.1} s (bar at z = {z:.2} m)", f as f64 / FPS),
            &cloth,
            Some((&posed, &bt)),
            side,
            ((-0.2, 0.15), (-0.45, 0.02)),
        )?;
    }
    root.present()?;

    // 4. The underwater swing (61 x 41, 0.5 Hz, 4 cm) against a 10k-triangle ball it starts
    // touching (`collision_cost` case 3): side view at 0.1, 1 and 2 s, with the substeps and
    // refused attempts of the frame drawn.
    use fraccloth::collide::shapes::uv_sphere;
    let mut scene = swing(61, 41, 0.5, 0.04, fraccloth::Model::underwater())?;
    let (bx, bt) = uv_sphere(Vec3::new(0.3, -0.3, 0.1), 0.1, 100, 51);
    scene.cloth.add_mesh_collider(&bx, &bt, None)?;
    let root = BitMapBackend::new("docs/collisions/ball.png", (1500, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    let cells = root.split_evenly((1, 3));
    let mut f = 0;
    for (k, until) in [3, 30, 60].into_iter().enumerate() {
        while f < until {
            f += 1;
            scene.run_until(f as f64 / FPS)?;
        }
        let stats = scene.cloth.step_stats();
        let inside = fraccloth::collide::intersections::vertices_inside(scene.cloth.positions(), &bx, &bt);
        panel(
            &cells[k],
            &format!(
                "10k-triangle ball, {:.1} s: {} substeps, {} retries, {inside} inside",
                f as f64 / FPS,
                stats.substeps,
                stats.retries
            ),
            &scene.cloth,
            Some((&bx, &bt)),
            side,
            ((-0.25, 0.25), (-0.45, 0.02)),
        )?;
    }
    root.present()?;
    // 5. The brisk swing (31 x 21, 2 Hz, 8 cm: it crumples under its pins) with and without
    // self-collision 6 mm (`tests/collisions.rs`): side view at 1, 2 and 4 s.
    let root = BitMapBackend::new("docs/collisions/brisk.png", (1500, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let rows = root.split_evenly((2, 3));
    for (r, thickness) in [0.006, 0.0].into_iter().enumerate() {
        let model = fraccloth::Model {
            self_collision_thickness: thickness,
            ..fraccloth::Model::underwater()
        };
        let mut scene = swing(31, 21, 2.0, 0.08, model)?;
        let mut f = 0;
        for (k, until) in [30, 60, 120].into_iter().enumerate() {
            while f < until {
                f += 1;
                scene.run_until(f as f64 / FPS)?;
            }
            let label = if thickness > 0.0 {
                "2 Hz 8 cm, self-collision 6 mm"
            } else {
                "2 Hz 8 cm, no self-collision"
            };
            let when = format!("{:.0} s", f as f64 / FPS);
            crossings_panel(
                &rows[3 * r + k],
                label,
                &when,
                &scene.cloth,
                ((-0.25, 0.25), (-0.45, 0.05)),
            )?;
        }
    }
    root.present()?;
    println!("wrote docs/collisions/drop.png, torus.png, bar.png, ball.png, brisk.png");
    Ok(())
}
