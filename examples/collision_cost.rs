//! What collisions cost, as ratios within one run (docs/collisions.md, docs/benchmarks.md):
//! the underwater swing (the preset's automatic step, 30 fps frames, 0.5 Hz and 2 Hz) with and
//! without self-collision, at 61 x 41 and 201 x 201, and with a 10k-triangle sphere mesh
//! collider the towel swings against. Each configuration is baked alternately with its
//! baseline, best of `rounds`, so both see the same machine. Prints seconds of bake per
//! simulated second, the ratio, substeps a frame, self-collision looks a frame (and how many of
//! them the proof of `collide/unfolded.rs` settled whole, testing no pair) and the most
//! crossing triangle pairs at any sampled frame, without and with.
//!
//! `cargo run --release --example collision_cost -- [rounds] [case] [seconds]` (default 3
//! rounds, every case; `case` 0-5 runs one; case 5 is case 3 with the ball handed to the cloth
//! again, where it is, before every frame; `seconds` overrides every case's simulated seconds,
//! 4 for the 61 x 41 cases and 1 for 201 x 201 by default: the swing's waves are still growing
//! at 4 s, and a 12 s bake sees more of the bent shapes)

use std::time::Instant;

use fraccloth::collide::intersections::self_intersections;
use fraccloth::collide::shapes::uv_sphere;
use fraccloth::{Model, Vec3};
use fraccloth_tools::scenes::SceneSpec;

const FPS: f64 = 30.0;

#[derive(Clone, Copy)]
struct Case {
    width: u32,
    height: u32,
    frequency: f64,
    amplitude: f64,
    thickness: f64,
    mesh: bool,
    /// The mesh handed to the cloth again before every frame, where it is (as a host that
    /// sends every collider each frame, the Blender add-on among them, does for a still one).
    resent: bool,
    seconds: f64,
}

/// (wall seconds, substeps a frame, looks a frame, most crossing pairs, contacts at the end,
/// looks a frame the proof of `collide/unfolded.rs` settled whole).
fn bake(c: Case) -> (f64, f64, f64, usize, usize, f64) {
    let model = Model {
        self_collision_thickness: c.thickness,
        ..Model::underwater()
    };
    let spec = SceneSpec::underwater_swing(c.width, c.height, c.frequency, c.amplitude, model);
    let mut scene = spec.build().expect("scene");
    // A 10k-triangle ball of 10 cm radius the towel's lower half swings into.
    let (ball, t) = uv_sphere(Vec3::new(0.3, -0.3, 0.1), 0.1, 100, 51);
    let mut ball_id = None;
    if c.mesh {
        assert!(t.len() >= 10_000);
        ball_id = Some(scene.cloth.add_mesh_collider(&ball, &t, None).expect("mesh"));
    }
    let tris = scene.cloth.topology().triangles.clone();
    let frames = (c.seconds * FPS) as usize;
    let (mut wall, mut substeps, mut worst) = (0.0, 0u64, 0);
    let looks0 = scene.cloth.self_collision_looks();
    let proved0 = scene.cloth.self_collision_proved_looks();
    for f in 1..=frames {
        let t0 = Instant::now();
        if let (true, Some(id)) = (c.resent, ball_id) {
            scene
                .cloth
                .set_mesh_collider(id, &ball, None)
                .expect("the same mesh");
        }
        scene.run_until(f as f64 / FPS).expect("frame");
        wall += t0.elapsed().as_secs_f64();
        substeps += u64::from(scene.cloth.step_stats().substeps);
        if f % 10 == 0 {
            worst = worst.max(self_intersections(scene.cloth.positions(), &tris));
        }
    }
    let looks = (scene.cloth.self_collision_looks() - looks0) as f64 / frames as f64;
    let proved = (scene.cloth.self_collision_proved_looks() - proved0) as f64 / frames as f64;
    (
        wall,
        substeps as f64 / frames as f64,
        looks,
        worst,
        scene.cloth.contacts().len(),
        proved,
    )
}

fn main() {
    let rounds: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(3);
    println!(
        "{:<34} {:>9} {:>9} {:>6} {:>13} {:>7} {:>7} {:>12} {:>9}",
        "case",
        "base s/s",
        "with s/s",
        "ratio",
        "substeps b/w",
        "looks",
        "proved",
        "crossing b/w",
        "contacts"
    );
    let towel = |frequency, amplitude| Case {
        width: 61,
        height: 41,
        frequency,
        amplitude,
        thickness: 0.0,
        mesh: false,
        resent: false,
        seconds: 4.0,
    };
    let cases = [
        ("61x41 0.5 Hz 4 cm, self 4 mm", towel(0.5, 0.04), 0.004, false),
        ("61x41 2 Hz 8 cm, self 4 mm", towel(2.0, 0.08), 0.004, false),
        (
            "201x201 0.5 Hz 4 cm, self 1.5 mm",
            Case {
                width: 201,
                height: 201,
                seconds: 1.0,
                ..towel(0.5, 0.04)
            },
            0.0015,
            false,
        ),
        ("61x41 0.5 Hz 4 cm, 10k-tri mesh", towel(0.5, 0.04), 0.0, true),
        ("61x41 2 Hz 4 cm, self 4 mm", towel(2.0, 0.04), 0.004, false),
        (
            "61x41 0.5 Hz 4 cm, mesh sent again",
            Case {
                resent: true,
                ..towel(0.5, 0.04)
            },
            0.0,
            true,
        ),
    ];
    let only: Option<usize> = std::env::args().nth(2).and_then(|s| s.parse().ok());
    let seconds: Option<f64> = std::env::args().nth(3).and_then(|s| s.parse().ok());
    for (k, (name, mut base, thickness, mesh)) in cases.into_iter().enumerate() {
        if only.is_some_and(|o| o != k) {
            continue;
        }
        if let Some(s) = seconds.filter(|s| *s > 0.0) {
            base.seconds = s;
        }
        let with = Case {
            thickness,
            mesh,
            ..base
        };
        let (mut b, mut w) = (f64::INFINITY, f64::INFINITY);
        let mut stats = (0.0, 0.0, 0, 0, 0.0);
        let (mut base_substeps, mut base_crossing) = (0.0, 0);
        for _ in 0..rounds {
            let r = bake(base);
            b = b.min(r.0);
            base_substeps = r.1;
            base_crossing = r.3;
            let r = bake(with);
            w = w.min(r.0);
            stats = (r.1, r.2, r.3, r.4, r.5);
        }
        let s = base.seconds;
        println!(
            "{name:<34} {:>9.3} {:>9.3} {:>6.2} {:>13} {:>7.2} {:>7.2} {:>12} {:>9}",
            b / s,
            w / s,
            w / b,
            format!("{base_substeps:.1}/{:.1}", stats.0),
            stats.1,
            stats.4,
            format!("{base_crossing}/{}", stats.2),
            stats.3
        );
    }
}
