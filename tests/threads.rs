//! Results do not depend on the number of threads: the same cloth stepped inside rayon pools
//! of 1, 2 and 8 threads ends in bitwise-identical positions and velocities, for every force
//! model, history scheme and integrator, with a collider. The cloth is large enough
//! (> `parallel::MIN_PARALLEL` particles) for the passes to be split among threads.

use fraccloth::history::{HalfDerivative, Scheme};
use fraccloth::topology::grid_index;
use fraccloth::{forces::Sphere, Cloth, ClothConfig, GridSpec, Integrator, RegularDrag, Vec3};
use fraccloth_tools::scenes::Variant;

const W: u32 = 131;
const H: u32 = 129;

fn cloth(variant: Variant, scheme: Scheme, integrator: Integrator) -> Cloth {
    cloth_sized(W, H, variant, scheme, integrator)
}

fn cloth_sized(w: u32, h: u32, variant: Variant, scheme: Scheme, integrator: Integrator) -> Cloth {
    let spacing = 0.01;
    let topology = GridSpec {
        width: w,
        height: h,
        spacing,
        total_mass: 0.24 / 2501.0 * f64::from(w * h),
    }
    .build()
    .unwrap();
    let mut model = variant.model(spacing);
    model.current = Vec3::new(0.05, 0.0, 0.2);
    let config = ClothConfig {
        model,
        scheme,
        integrator,
        ..ClothConfig::default()
    };
    let mut c = Cloth::new(topology, config).unwrap();
    let top: Vec<u32> = (0..w).map(|i| grid_index(w, i, 0)).collect();
    c.set_pinned(&top).unwrap();
    c.add_sphere(Sphere {
        center: Vec3::new(0.0, -0.6, 0.08),
        radius: 0.1,
        velocity: Vec3::new(0.0, 0.0, -0.1),
    })
    .unwrap();
    c
}

fn run(threads: usize, variant: Variant, scheme: Scheme, integrator: Integrator) -> Vec<u64> {
    run_cloth(threads, cloth(variant, scheme, integrator), variant, integrator)
}

fn run_cloth(threads: usize, mut c: Cloth, variant: Variant, integrator: Integrator) -> Vec<u64> {
    let dt = if integrator == Integrator::ImplicitEuler {
        1.0 / 60.0
    } else if variant == Variant::Underwater {
        // The sphere's contact on the preset's light cloth needs a finer step.
        1e-4
    } else {
        5e-4
    };
    let steps = if integrator == Integrator::ImplicitEuler {
        4
    } else {
        40
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        for _ in 0..steps {
            c.step(dt).unwrap();
        }
    });
    c.positions()
        .iter()
        .chain(c.velocities())
        .flat_map(|p| p.iter().map(|x| x.to_bits()))
        .collect()
}

/// Steps the fractional cloth `make` gives on 1, 2 and 8 threads, asserts the same bits, and
/// returns them.
fn same_bits_on_1_2_and_8_threads(make: impl Fn() -> Cloth) -> Vec<u64> {
    let one = run_cloth(1, make(), Variant::Fractional, Integrator::SymplecticEuler);
    for threads in [2, 8] {
        let many = run_cloth(threads, make(), Variant::Fractional, Integrator::SymplecticEuler);
        let differing = one.iter().zip(&many).filter(|(a, b)| a != b).count();
        assert_eq!(
            differing, 0,
            "{differing} numbers differ between 1 and {threads} threads"
        );
    }
    one
}

#[test]
fn bitwise_identical_for_1_2_and_8_threads() {
    const { assert!((W * H) as usize >= fraccloth::MIN_PARALLEL) };
    let cases = [
        (Variant::Fractional, Scheme::DEFAULT, Integrator::SymplecticEuler),
        (Variant::Fractional, Scheme::PAPER, Integrator::ExplicitEuler),
        (
            Variant::Regular(RegularDrag::ViscousAndNormal),
            Scheme::Off,
            Integrator::SymplecticEuler,
        ),
        (Variant::Fractional, Scheme::DEFAULT, Integrator::ImplicitEuler),
        // The carried water's turning forces and the wide form drag: passes of their own,
        // split over the pool in chunks (`forces/inertia.rs`, `forces/wide_drag.rs`).
        (Variant::Underwater, Scheme::DEFAULT, Integrator::SymplecticEuler),
        (Variant::Underwater, Scheme::DEFAULT, Integrator::ImplicitEuler),
    ];
    for (variant, scheme, integrator) in cases {
        let one = run(1, variant, scheme, integrator);
        for threads in [2, 8] {
            let many = run(threads, variant, scheme, integrator);
            let differing = one.iter().zip(&many).filter(|(a, b)| a != b).count();
            assert_eq!(
                differing,
                0,
                "{} {} {}: {differing} of {} numbers differ between 1 and {threads} threads",
                variant.name(),
                scheme.name(),
                integrator.name(),
                one.len()
            );
        }
        // The run did move the cloth (a frozen cloth would compare equal trivially).
        let rest = cloth(variant, scheme, integrator);
        let moved = rest
            .positions()
            .iter()
            .flat_map(|p| p.iter().map(|x| x.to_bits()))
            .zip(&one)
            .filter(|(a, b)| a != *b)
            .count();
        assert!(moved > (W * H) as usize, "{moved}");
    }
}

/// A cloth whose SOE modes pass `DEFER_FROM_BYTES` folds every other step
/// (`SumOfExponentials::with_deferred_fold`): its passes that take the sum ahead and those that
/// fold two samples split over the pool as the others do, with the same bits.
#[test]
fn a_cloth_that_defers_its_folds_gives_the_same_bits_for_1_2_and_8_threads() {
    let (w, h) = (211, 211); // 44 521 particles, 17 MB of modes
    let make = || {
        cloth_sized(
            w,
            h,
            Variant::Fractional,
            Scheme::DEFAULT,
            Integrator::SymplecticEuler,
        )
    };
    let small = cloth(Variant::Fractional, Scheme::DEFAULT, Integrator::SymplecticEuler);
    // Two more samples a particle when deferring: the pending one and the sum ahead.
    assert_eq!(
        make().history().bytes_per_particle(),
        small.history().bytes_per_particle() + 48
    );
    let one = same_bits_on_1_2_and_8_threads(make);
    let rest: Vec<u64> = make()
        .positions()
        .iter()
        .flat_map(|p| p.iter().map(|x| x.to_bits()))
        .collect();
    assert!(rest.iter().zip(&one).filter(|(a, b)| a != b).count() > (w * h) as usize);
}

/// An irregular triangle mesh (random diagonals, jittered) large enough for the pool and for
/// several groups of the tile walk: its bend springs are summed from choice runs
/// (`topology::Choice`), and the bits do not depend on the thread count.
#[test]
fn an_irregular_mesh_gives_the_same_bits_for_1_2_and_8_threads() {
    let make = || {
        let grid = GridSpec {
            width: W,
            height: H,
            spacing: 0.01,
            total_mass: 1.0,
        }
        .build()
        .unwrap();
        let topology = fraccloth_tools::scenes::jittered_mesh(&grid, W, 0.5, 7).unwrap();
        assert_eq!(topology.tile_runs.choices.iter().flatten().count(), 2);
        let config = ClothConfig {
            model: Variant::Fractional.model(0.01),
            ..ClothConfig::default()
        };
        let mut c = Cloth::new(topology, config).unwrap();
        let top: Vec<u32> = (0..W).map(|i| grid_index(W, i, 0)).collect();
        c.set_pinned(&top).unwrap();
        c
    };
    same_bits_on_1_2_and_8_threads(make);
}

/// A cloth's own thread setting (`Cloth::set_threads`, `fc_cloth_set_threads`): the calling
/// thread only, its own pool of 3, and the shared pool give the same bits.
#[test]
fn per_cloth_threads_give_the_same_bits() {
    let steps = |threads: u32| -> Vec<u64> {
        let mut c = cloth(Variant::Fractional, Scheme::DEFAULT, Integrator::SymplecticEuler);
        c.set_threads(threads).unwrap();
        assert_eq!(c.threads(), threads);
        for _ in 0..20 {
            c.step(5e-4).unwrap();
        }
        c.positions()
            .iter()
            .chain(c.velocities())
            .flat_map(|p| p.iter().map(|x| x.to_bits()))
            .collect()
    };
    // Inside a pool of 4 so that the shared setting really spreads the work.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(4).build().unwrap();
    let shared = pool.install(|| steps(0));
    assert_eq!(pool.install(|| steps(1)), shared, "calling thread only");
    assert_eq!(steps(3), shared, "the cloth's own pool of 3");
    let mut c = cloth(Variant::Fractional, Scheme::DEFAULT, Integrator::SymplecticEuler);
    assert!(c.set_threads(100_000).is_err());
    assert_eq!(c.threads(), 0, "a refused setting changes nothing");
}
