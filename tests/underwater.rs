//! The water's terms against closed forms: a flat plate settling face-first (form drag and
//! added mass) and edgewise (skin drag), the same at two resolutions (per-area coefficients),
//! and a free cloth with strongly anisotropic added mass that must not gain energy.

use fraccloth::history::Scheme;
use fraccloth::model::{SpringDamping, Water};
use fraccloth::topology::{MeshMass, MeshSpec};
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model, Vec3};

const MU: f64 = 0.5; // areal density, kg/m^2
const SIDE: f64 = 0.1; // plate side, m
const RHO_W: f64 = 1000.0;
const RHO_C: f64 = 1100.0;

/// Net weight in water per unit area over areal density: g (1 - rho_w / rho_c).
fn g_eff() -> f64 {
    9.81 * (1.0 - RHO_W / RHO_C)
}

/// A square plate of `cells` x `cells` quads as a mesh, masses lumped from areas (so every
/// particle carries mu A_i and the plate stays flat as it falls), in the x-y plane.
fn plate(cells: u32, gravity: Vec3, water: Water, integrator: Integrator) -> Cloth {
    let spacing = SIDE / f64::from(cells);
    let grid = GridSpec {
        width: cells + 1,
        height: cells + 1,
        spacing,
        total_mass: MU * SIDE * SIDE,
    }
    .build()
    .unwrap();
    let w = cells + 1;
    let quads: Vec<u32> = (0..cells)
        .flat_map(|j| {
            (0..cells).flat_map(move |i| [j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i])
        })
        .collect();
    let t = MeshSpec {
        positions: &grid.rest_positions,
        indices: &quads,
        face_size: 4,
        mass: MeshMass::ArealDensity(MU),
    }
    .build()
    .unwrap();
    let model = Model {
        cloth_density: RHO_C,
        water_density: RHO_W,
        gravity,
        stretch_stiffness: 5.0,
        shear_stiffness: 1.0,
        bend_stiffness: 0.1,
        spring_damping: 0.0,
        spring_damping_mode: SpringDamping::None,
        viscous_drag: 0.0,
        history_drag: 0.0,
        normal_drag: 0.0,
        water,
        ..Model::fractional()
    };
    Cloth::new(
        t,
        ClothConfig {
            model,
            scheme: Scheme::Off,
            integrator,
            ..ClothConfig::default()
        },
    )
    .unwrap()
}

fn mean_velocity(c: &Cloth) -> Vec3 {
    c.velocities().iter().sum::<Vec3>() / c.vertex_count() as f64
}

fn run(c: &mut Cloth, seconds: f64, dt: f64) {
    let steps = (seconds / dt).round() as usize;
    for _ in 0..steps {
        c.step(dt).unwrap();
    }
}

#[test]
fn a_plate_falling_face_first_reaches_the_terminal_speed_of_form_drag() {
    // Falling along its normal (the grid lies in x-y; gravity along -z): the net weight
    // mu g' A balances 1/2 rho C_d A v^2, so v_t = sqrt(2 mu g' / (rho C_d)) whatever A.
    let water = Water {
        form_drag: 2.0,
        added_mass: 20.0,
        ..Water::default()
    };
    let expected = (2.0 * MU * g_eff() / (RHO_W * 2.0)).sqrt();
    for integrator in [Integrator::SymplecticEuler, Integrator::ImplicitEuler] {
        for cells in [10, 20] {
            let mut c = plate(cells, Vec3::new(0.0, 0.0, -9.81), water, integrator);
            let dt = if integrator == Integrator::ImplicitEuler {
                1e-2
            } else {
                2e-4
            };
            run(&mut c, 6.0, dt);
            let v = mean_velocity(&c);
            assert!(
                (v.z + expected).abs() < 0.01 * expected,
                "{integrator:?} {cells}: {v} vs -{expected}"
            );
            assert!(v.x.abs() + v.y.abs() < 1e-6 * expected, "it falls straight: {v}");
        }
    }
}

#[test]
fn added_mass_slows_the_start_of_a_face_first_fall_and_not_an_edgewise_one() {
    // From rest, particle i's first acceleration is its net weight over (m_i + m_a A_i)
    // face-first, g' mu / (mu + m_a) with masses lumped from areas, and g' edgewise.
    let water = Water {
        added_mass: 20.0,
        ..Water::default()
    };
    for integrator in [Integrator::SymplecticEuler, Integrator::ImplicitEuler] {
        first_steps_accelerate(water, integrator, |t, i| {
            assert!((t.masses[i] - MU * t.areas[i]).abs() < 1e-15);
            g_eff() * t.masses[i] / (t.masses[i] + 20.0 * t.areas[i])
        });
    }
}

/// Steps a plate in `water` once from rest, face first and edgewise, and checks each particle's
/// face-first acceleration against `want(topology, i)` and the edgewise one against g' (1e-6).
fn first_steps_accelerate(
    water: Water,
    integrator: Integrator,
    want: impl Fn(&fraccloth::Topology, usize) -> f64,
) {
    let h = 1e-4;
    let mut face = plate(10, Vec3::new(0.0, 0.0, -9.81), water, integrator);
    face.step(h).unwrap();
    for (i, v) in face.velocities().iter().enumerate() {
        let (a, want) = (-v.z / h, want(face.topology(), i));
        assert!(
            (a - want).abs() < 1e-6 * want,
            "{integrator:?} face-first {i}: {a} vs {want}"
        );
    }
    let mut edge = plate(10, Vec3::new(0.0, -9.81, 0.0), water, integrator);
    edge.step(h).unwrap();
    let a = -mean_velocity(&edge).y / h;
    assert!(
        (a - g_eff()).abs() < 1e-6 * g_eff(),
        "{integrator:?} edgewise {a} vs {}",
        g_eff()
    );
}

#[test]
fn a_plate_falling_edgewise_reaches_the_terminal_speed_of_skin_drag() {
    // Along its plane only the skin drag acts: mu g' A = k_s A v, v_t = mu g' / k_s. The
    // form drag, switched on too, sees no normal velocity.
    let water = Water {
        skin_drag: 5.0,
        form_drag: 2.0,
        added_mass: 20.0,
        ..Water::default()
    };
    let expected = MU * g_eff() / 5.0;
    for cells in [10, 20] {
        let mut c = plate(
            cells,
            Vec3::new(0.0, -9.81, 0.0),
            water,
            Integrator::SymplecticEuler,
        );
        run(&mut c, 2.0, 2e-4);
        let v = mean_velocity(&c);
        assert!(
            (v.y + expected).abs() < 1e-3 * expected,
            "{cells}: {v} vs -{expected}"
        );
    }
}

/// The edgewise fall of [`a_plate_falling_edgewise_meets_a_young_boundary_layer_first`] as
/// its two equations say, by RK4 at a fine step: `mu v' = mu g' - k_s v - k_u (v - M)`,
/// `M' = (v - M) / T`, from rest; the speed at each of `times`.
fn edgewise_fall(ks: f64, ku: f64, memory: f64, times: &[f64]) -> Vec<f64> {
    let f = |v: f64, m: f64| ((MU * g_eff() - ks * v - ku * (v - m)) / MU, (v - m) / memory);
    let (mut v, mut m, mut t, h) = (0.0, 0.0, 0.0, 1e-5);
    times
        .iter()
        .map(|&end| {
            while t < end - 0.5 * h {
                let (a1, b1) = f(v, m);
                let (a2, b2) = f(v + 0.5 * h * a1, m + 0.5 * h * b1);
                let (a3, b3) = f(v + 0.5 * h * a2, m + 0.5 * h * b2);
                let (a4, b4) = f(v + h * a3, m + h * b3);
                v += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
                m += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
                t += h;
            }
            v
        })
        .collect()
}

#[test]
fn a_plate_falling_edgewise_meets_a_young_boundary_layer_first() {
    // The unsteady skin drag: along its plane the plate meets k_s + k_u while its boundary
    // layer is young (the running mean M of its velocity has not caught up) and k_s alone once
    // the flow is steady. Its mean speed through the whole step against the two equations
    // (`edgewise_fall`), and the terminal speed the steady drag alone sets.
    let (ks, ku, memory) = (1.0, 2.0, 0.5);
    let water = Water {
        skin_drag: ks,
        skin_drag_unsteady: ku,
        skin_drag_memory: memory,
        form_drag: 2.0,
        added_mass: 20.0,
        ..Water::default()
    };
    let times = [0.25, 0.5, 1.0, 2.0, 6.0];
    let want = edgewise_fall(ks, ku, memory, &times);
    let steady_only = edgewise_fall(ks, 0.0, memory, &times);
    let dt = 5e-5;
    let mut c = plate(10, Vec3::new(0.0, -9.81, 0.0), water, Integrator::SymplecticEuler);
    let mut t = 0.0;
    for (k, &end) in times.iter().enumerate() {
        run(&mut c, end - t, dt);
        t = end;
        let v = -mean_velocity(&c).y;
        println!(
            "t {end} s: {v:.5} m/s, equations {:.5} (steady drag alone {:.5})",
            want[k], steady_only[k]
        );
        assert!(
            (v - want[k]).abs() < 1e-3 * want[k],
            "t {end}: {v} against {}",
            want[k]
        );
    }
    // The young layer slows the start by a third and more; the steady drag alone sets the end
    // (the equations after a minute: the mean's slow mode takes tens of seconds).
    assert!(want[1] < 0.7 * steady_only[1], "{want:?} against {steady_only:?}");
    let terminal = MU * g_eff() / ks;
    let end = edgewise_fall(ks, ku, memory, &[60.0])[0];
    assert!(
        (end - terminal).abs() < 1e-3 * terminal,
        "{end} against {terminal}"
    );
}

#[test]
fn per_area_drags_give_the_same_motion_at_any_resolution() {
    // A hanging cloth released from rest at two resolutions, with only per-area drags: the
    // bottom edge's sinking after 1 s agrees to 1 %.
    let water = Water {
        viscous_drag: 2.0,
        normal_drag: 5.0,
        form_drag: 1.0,
        added_mass: 10.0,
        ..Water::default()
    };
    let depth = |cells: u32| {
        let mut c = plate(
            cells,
            Vec3::new(0.0, -9.81, 0.0),
            water,
            Integrator::SymplecticEuler,
        );
        // Pin the top edge, tilt the gravity a little out of plane so the cloth swings.
        let top: Vec<u32> = (0..=cells).collect();
        c.set_pinned(&top).unwrap();
        run(&mut c, 1.0, 2e-4);
        let bottom = (cells * (cells + 1)..(cells + 1) * (cells + 1)).map(|i| c.positions()[i as usize].y);
        assert!(c.topology().grid.is_none());
        bottom.sum::<f64>() / f64::from(cells + 1)
    };
    let (a, b) = (depth(10), depth(20));
    assert!((a - b).abs() < 0.01 * a.abs(), "{a} vs {b}");
}

/// A free plate (no gravity, no drag) with 100 times its mass as normal added mass, crumpled,
/// and its crumpled positions.
fn crumpled_plate(integrator: Integrator) -> (Cloth, Vec<Vec3>) {
    let water = Water {
        added_mass: 100.0 * MU,
        ..Water::default()
    };
    crumpled_plate_in(integrator, water)
}

/// [`crumpled_plate`] in water `water`.
fn crumpled_plate_in(integrator: Integrator, water: Water) -> (Cloth, Vec<Vec3>) {
    let mut c = plate(10, Vec3::zeros(), water, integrator);
    let x: Vec<Vec3> = c
        .positions()
        .iter()
        .map(|p| p + Vec3::new(0.0, 0.0, 0.01 * (40.0 * p.x).sin() * (30.0 * p.y).cos()))
        .collect();
    c.set_positions(&x).unwrap();
    (c, x)
}

/// Energy over 10 s of a crumpled free plate in `water`: at the start, least, most, at the
/// end (J), and how far it moved (m).
struct FreeEnergy {
    start: f64,
    least: f64,
    worst: f64,
    end: f64,
    moved: f64,
}

fn free_energy(integrator: Integrator, dt: f64, water: Water) -> FreeEnergy {
    let (mut c, x) = crumpled_plate_in(integrator, water);
    let start = c.energy();
    let (mut least, mut worst) = (start, start);
    for _ in 0..(10.0 / dt) as usize {
        c.step(dt).unwrap();
        let e = c.energy();
        worst = worst.max(e);
        least = least.min(e);
    }
    let moved = c
        .positions()
        .iter()
        .zip(&x)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    FreeEnergy {
        start,
        least,
        worst,
        end: c.energy(),
        moved,
    }
}

#[test]
fn a_free_cloth_with_coarse_added_mass_does_not_gain_energy() {
    // The scale-aware inertia (`forces/coarse_water.rs`): on top of the local 100 times the
    // cloth's mass, the plate's motion smoother than 5 cm carries another 100 times. Its
    // turning forces are Lagrange's (unit test), so the energy, the coarse water's included,
    // is conserved by the equations and only the step changes it.
    let water = Water {
        added_mass: 100.0 * MU,
        coarse_added_mass: 100.0 * MU,
        coarse_length: 0.05,
        ..Water::default()
    };
    for (integrator, dt) in [
        (Integrator::SymplecticEuler, 1e-4),
        (Integrator::ImplicitEuler, 1e-3),
    ] {
        let FreeEnergy {
            start: e0,
            worst,
            end,
            moved,
            ..
        } = free_energy(integrator, dt, water);
        println!("{integrator:?} dt {dt}, coarse water: energy {e0:.4e} J at the start, at most {worst:.4e}, {end:.4e} at the end; moved {moved:.4} m");
        assert!(
            worst <= e0 * 1.02,
            "{integrator:?}: energy grew from {e0} to {worst}"
        );
        assert!(moved > 2e-3, "{integrator:?}: the cloth moved only {moved} m");
    }
    // Without the turning forces' coarse part the symplectic bake blows up within the 10 s (a
    // step refused as unstable): checked by hand, dropping `add_turning`'s two terms.
}

#[test]
fn a_coarse_length_too_short_for_the_cloth_is_refused_with_one_that_works() {
    // The coarse level's matrix is dense and factored every step: at most 256 patches. On the
    // 0.1 m plate, 1 mm makes 100 x 100 cells; the message names a length that fits, which is
    // accepted, and a refused reconfigure leaves the cloth as it was.
    let water = |length: f64| Water {
        added_mass: 5.0,
        coarse_added_mass: 10.0,
        coarse_length: length,
        ..Water::default()
    };
    let make = |w: Water| {
        let mut model = Model::underwater();
        model.water = w;
        let grid = GridSpec {
            width: 11,
            height: 11,
            spacing: SIDE / 10.0,
            total_mass: MU * SIDE * SIDE,
        }
        .build()
        .unwrap();
        Cloth::new(
            grid,
            ClothConfig {
                model,
                ..ClothConfig::default()
            },
        )
    };
    let Err(err) = make(water(1e-3)) else {
        panic!("a 1 mm coarse length on a 0.1 m plate was accepted")
    };
    let msg = err.to_string();
    println!("{msg}");
    assert!(msg.contains("at most 256 patches"), "{msg}");
    let suggested: f64 = msg
        .rsplit("at least ")
        .next()
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .expect("a suggested length");
    let mut c = make(water(suggested)).expect("the suggested length is accepted");
    c.step(1e-4).unwrap();
    // A zero length with coarse water on is refused too; a refused reconfigure changes nothing.
    assert!(make(water(0.0)).is_err());
    let before = c.config().clone();
    let mut bad = before.clone();
    bad.model.water.coarse_length = 1e-4;
    assert!(c.reconfigure(bad).is_err());
    assert_eq!(c.config().model, before.model);
}

#[test]
fn coarse_added_mass_slows_a_whole_plate_face_first_and_not_edgewise() {
    // A flat plate pushed by a uniform force per area moves rigidly: its coarse water adds
    // exactly `coarse_added_mass` per area (the patches are a partition of unity), so every
    // particle's first acceleration face-first is g' mu / (mu + m_a + m_c); edgewise g'.
    let (ma, mc) = (20.0, 30.0);
    let water = Water {
        added_mass: ma,
        coarse_added_mass: mc,
        coarse_length: 0.04,
        ..Water::default()
    };
    for integrator in [Integrator::SymplecticEuler, Integrator::ImplicitEuler] {
        first_steps_accelerate(water, integrator, |_, _| g_eff() * MU / (MU + ma + mc));
    }
}

#[test]
fn a_free_cloth_with_strongly_anisotropic_added_mass_does_not_gain_energy() {
    // No gravity, no drag: only springs and 100 times the cloth's mass for normal motion, none
    // along the cloth. Crumpled and released, the energy (with the water's kinetic part) must
    // not grow over 10 s beyond the integrator's own error: the carried water's turning forces
    // (`forces/inertia.rs`) make the equations Lagrange's, so the energy is conserved by the
    // equations and only the step changes it.
    for (integrator, dt) in [
        (Integrator::SymplecticEuler, 1e-4),
        (Integrator::ImplicitEuler, 1e-3),
    ] {
        let water = Water {
            added_mass: 100.0 * MU,
            ..Water::default()
        };
        let FreeEnergy {
            start: e0,
            least,
            worst,
            end,
            moved,
        } = free_energy(integrator, dt, water);
        println!(
            "{integrator:?} dt {dt}: energy {e0:.4e} J at the start, {least:.4e} to {worst:.4e} over 10 s, {end:.4e} at the end"
        );
        assert!(
            worst <= e0 * 1.02,
            "{integrator:?}: energy grew from {e0} to {worst}"
        );
        // And it moved: the test is not of a cloth at rest.
        assert!(moved > 2e-3, "{integrator:?}: the cloth moved only {moved} m");
    }
}

#[test]
fn explicit_euler_gains_energy_with_anisotropic_added_mass_only_as_its_step_makes_it() {
    // Explicit Euler gains energy on any undamped oscillator, in proportion to its step: on
    // the crumpled free cloth of the test above, the growth of log(energy) over 0.25 s must halve
    // with the step (the integrator's error), not stay (which would be the equations').
    let growth = |dt: f64| {
        let (mut c, _) = crumpled_plate(Integrator::ExplicitEuler);
        let e0 = c.energy();
        let mut worst = e0;
        for _ in 0..(0.25 / dt) as usize {
            c.step(dt).unwrap();
            worst = worst.max(c.energy());
        }
        (worst / e0).ln()
    };
    let (coarse, fine) = (growth(1e-5), growth(5e-6));
    println!("explicit Euler: log energy growth over 0.25 s {coarse:.4e} at dt 1e-5, {fine:.4e} at 5e-6");
    assert!(
        fine > 0.0 && (1.6..2.4).contains(&(coarse / fine)),
        "{coarse} {fine}"
    );
}

#[test]
fn an_added_mass_coefficient_is_water_density_times_the_cloths_width() {
    // The plate is 0.1 m square, so W = 0.1 m: C_a = pi/4 means rho_w pi W / 4 kg/m^2.
    let c_a = std::f64::consts::FRAC_PI_4;
    let by_coefficient = plate(
        10,
        Vec3::new(0.0, 0.0, -9.81),
        Water {
            added_mass: 5.0,
            added_mass_coefficient: c_a,
            ..Water::default()
        },
        Integrator::SymplecticEuler,
    );
    let per_area = 5.0 + c_a * RHO_W * SIDE;
    assert!((by_coefficient.topology().width() - SIDE).abs() < 1e-12);
    assert!((by_coefficient.model().water.added_mass - per_area).abs() < 1e-9);
    assert_eq!(by_coefficient.model().water.added_mass_coefficient, 0.0);
    // The same motion as the added mass given directly (the first step's accelerations).
    let mut a = by_coefficient;
    let mut b = plate(
        10,
        Vec3::new(0.0, 0.0, -9.81),
        Water {
            added_mass: per_area,
            ..Water::default()
        },
        Integrator::SymplecticEuler,
    );
    for _ in 0..50 {
        a.step(1e-3).unwrap();
        b.step(1e-3).unwrap();
    }
    for (p, q) in a.positions().iter().zip(b.positions()) {
        assert!((p - q).norm() < 1e-12, "{p} vs {q}");
    }
}

#[test]
fn a_cloths_width_is_the_smaller_extent_in_its_own_plane_in_any_orientation() {
    let grid = GridSpec {
        width: 61,
        height: 41,
        spacing: 0.01,
        total_mass: 0.24,
    }
    .build()
    .unwrap();
    assert!((grid.width() - 0.4).abs() < 1e-9, "{}", grid.width());
    // The same sheet turned about an oblique axis, as a mesh.
    let turn =
        nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(Vec3::new(1.0, 2.0, 3.0)), 0.7);
    let positions: Vec<Vec3> = grid.rest_positions.iter().map(|p| turn * p).collect();
    let indices: Vec<u32> = grid.triangles.iter().flatten().copied().collect();
    let turned = MeshSpec {
        positions: &positions,
        indices: &indices,
        face_size: 3,
        mass: MeshMass::ArealDensity(MU),
    }
    .build()
    .unwrap();
    assert!((turned.width() - 0.4).abs() < 1e-9, "{}", turned.width());
}

#[test]
fn bad_water_coefficients_name_the_field() {
    for (field, water) in [
        (
            "added_mass_coefficient",
            Water {
                added_mass_coefficient: -0.5,
                ..Water::default()
            },
        ),
        (
            "added_mass",
            Water {
                added_mass: -1.0,
                ..Water::default()
            },
        ),
        (
            "form_drag",
            Water {
                form_drag: f64::NAN,
                ..Water::default()
            },
        ),
        (
            "skin_drag",
            Water {
                skin_drag: -0.1,
                ..Water::default()
            },
        ),
        (
            "normal_drag_per_area",
            Water {
                normal_drag: f64::INFINITY,
                ..Water::default()
            },
        ),
    ] {
        let model = Model {
            water,
            ..Model::fractional()
        };
        let e = model.validate().unwrap_err();
        assert!(e.message.contains(field), "{field}: {}", e.message);
    }
}
