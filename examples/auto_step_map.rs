//! The automatic step's safety factor, measured: for every preset, integrator, mesh kind and
//! size, the largest fixed step that completes the swing (bisection) against the estimate of
//! `Cloth::auto_substep` (without its safety factor). The smallest ratio over each integrator's
//! cases bounds its safety factor (`fraccloth::cloth::safety`; docs/stability.md).
//!
//! `cargo run --release --example auto_step_map [SECONDS, default 4]`

use fraccloth::history::Scheme;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model, RegularDrag, Topology, Vec3};
use fraccloth_tools::scenes::{Drive, SceneKind, Variant};

/// A grid's topology, or the same vertices jittered and triangulated with random diagonals.
fn topology(w: u32, h: u32, jittered: bool) -> Topology {
    let spacing = 0.6 / f64::from(w - 1);
    let grid = GridSpec {
        width: w,
        height: h,
        spacing,
        total_mass: f64::from((w - 1) * (h - 1)) * spacing * spacing,
    }
    .build()
    .expect("a grid");
    if jittered {
        fraccloth_tools::scenes::jittered_mesh(&grid, w, 1.0, 12345).expect("a mesh")
    } else {
        grid
    }
}

/// Whether `seconds` of the swing at fixed step `dt` complete.
fn completes(
    t: &Topology,
    w: u32,
    model: Model,
    scheme: Scheme,
    integrator: Integrator,
    dt: f64,
    seconds: f64,
) -> bool {
    let config = ClothConfig {
        model,
        scheme,
        integrator,
        ..ClothConfig::default()
    };
    let mut cloth = Cloth::new(t.clone(), config).expect("a cloth");
    let top: Vec<u32> = (0..w).collect();
    cloth.set_pinned(&top).expect("pins");
    let rest: Vec<Vec3> = top.iter().map(|&i| cloth.positions()[i as usize]).collect();
    let drive = Drive::of(SceneKind::Swing, Variant::Underwater);
    let steps = (seconds / dt).ceil() as usize;
    for k in 1..=steps {
        let off = drive.offset(SceneKind::Swing, k as f64 * dt);
        let targets: Vec<Vec3> = rest.iter().map(|p| p + off).collect();
        cloth.set_pin_targets(&top, &targets).expect("targets");
        if cloth.step(dt).is_err() {
            return false;
        }
    }
    // Past the bound a mode grows before the speed limit refuses it: a moving cloth faster than
    // 2 m/s here has left the swing's motion.
    cloth.velocities().iter().all(|v| v.norm() < 2.0)
}

fn main() {
    let seconds: f64 = std::env::args()
        .nth(1)
        .map_or(4.0, |s| s.parse().expect("seconds"));
    let models: [(&str, Model, Scheme, Integrator); 7] = [
        (
            "underwater, symplectic",
            Model::underwater(),
            Scheme::Off,
            Integrator::SymplecticEuler,
        ),
        (
            "underwater, explicit",
            Model::underwater(),
            Scheme::Off,
            Integrator::ExplicitEuler,
        ),
        (
            "underwater, symplectic2",
            Model::underwater(),
            Scheme::Off,
            Integrator::ExtrapolatedSymplectic,
        ),
        (
            "paper (u = 3), explicit",
            Model::fractional(),
            Scheme::PAPER,
            Integrator::ExplicitEuler,
        ),
        (
            "fractional SOE, symplectic",
            Model::fractional(),
            Scheme::DEFAULT,
            Integrator::SymplecticEuler,
        ),
        (
            "regular, symplectic",
            Model::regular(RegularDrag::Normal),
            Scheme::Off,
            Integrator::SymplecticEuler,
        ),
        (
            "regular, explicit",
            Model::regular(RegularDrag::Normal),
            Scheme::Off,
            Integrator::ExplicitEuler,
        ),
    ];
    println!("| case | mesh | estimate (ms) | largest stable step (ms) | ratio |");
    println!("|---|---|---|---|---|");
    let mut worst = f64::INFINITY;
    for (w, h, jittered) in [(31, 21, false), (61, 41, false), (61, 41, true), (121, 81, false)] {
        let t = topology(w, h, jittered);
        let mesh = format!(
            "{w} x {h} {}",
            if jittered { "jittered triangles" } else { "grid" }
        );
        for (name, model, scheme, integrator) in &models {
            // The paper's per-particle drags are stated at 1 cm.
            let spacing = 0.6 / f64::from(w - 1);
            let model = if matches!(
                name.split(',').next(),
                Some("paper (u = 3)" | "fractional SOE" | "regular")
            ) {
                fraccloth_tools::scenes::scale_drags(*model, spacing)
            } else {
                *model
            };
            let config = ClothConfig {
                model,
                scheme: *scheme,
                integrator: *integrator,
                ..ClothConfig::default()
            };
            let mut probe = Cloth::new(t.clone(), config).expect("a cloth");
            probe.set_pinned(&(0..w).collect::<Vec<u32>>()).expect("pins");
            let estimate = probe.auto_substep(1.0) / fraccloth::cloth::safety(*integrator);
            // Bracket from the estimate (halving down or doubling up), then bisect in log space:
            // lo completes, hi does not.
            let ok = |dt: f64| completes(&t, w, model, *scheme, *integrator, dt, seconds);
            let (mut lo, mut hi) = (estimate, 2.0 * estimate);
            if ok(lo) {
                while ok(hi) && hi < 64.0 * estimate {
                    (lo, hi) = (hi, 2.0 * hi);
                }
            } else {
                hi = lo;
                lo /= 2.0;
                while !ok(lo) && lo > estimate / 64.0 {
                    (lo, hi) = (lo / 2.0, lo);
                }
            }
            for _ in 0..5 {
                let mid = (lo * hi).sqrt();
                if ok(mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let ratio = lo / estimate;
            worst = worst.min(ratio);
            println!(
                "| {name} | {mesh} | {:.3} | {:.3} | {ratio:.2} |",
                estimate * 1e3,
                lo * 1e3
            );
        }
    }
    println!(
        "\nsmallest ratio {worst:.2}; the automatic step takes {} of the estimate ({} with symplectic Euler)",
        fraccloth::cloth::SAFETY,
        fraccloth::cloth::SAFETY_SYMPLECTIC
    );
}
