//! Snapshots through the C ABI: continuing from a restored snapshot is bitwise identical to
//! never having stopped; truncated, corrupted and foreign snapshots are rejected and leave the
//! cloth as it was.

use std::ffi::{c_void, CStr};
use std::ptr::{null, null_mut};

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;

struct Handle(*mut FcCloth);
impl Drop for Handle {
    fn drop(&mut self) {
        unsafe { fc_cloth_destroy(self.0) }
    }
}

fn message() -> String {
    unsafe { CStr::from_ptr(fc_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// A small swinging cloth with a sphere and a plane, a soft pin, a current.
fn make(width: u32, scheme: u32) -> Handle {
    // The paper's fractional model: its history drag and spring damping read the history
    // (the default preset, the underwater one, keeps none).
    let mut desc = fc_cloth_desc_default();
    assert_eq!(
        unsafe { fc_cloth_desc_preset(FcPreset::FC_PRESET_FRACTIONAL_PAPER as u32, &mut desc) },
        FC_OK
    );
    desc.width = width;
    desc.height = 8;
    // The same mass per particle at every width (the 10-wide cloth's own).
    desc.total_mass *= f64::from(width) / 10.0;
    desc.history_scheme = scheme;
    desc.integrator = 1; // symplectic
    let mut c = null_mut();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&desc, &mut c), FC_OK);
        let top: Vec<u32> = (0..width).collect();
        assert_eq!(fc_cloth_set_pinned(c, top.as_ptr(), top.len()), FC_OK);
        let soft = [width * 7];
        assert_eq!(fc_cloth_pin_group(c, soft.as_ptr(), 1, 0.3), FC_OK);
        let mut id = 0;
        let centre = [0.0f32, -0.05, 0.03];
        assert_eq!(
            fc_cloth_add_sphere(c, centre.as_ptr(), 0.02, null(), &mut id),
            FC_OK
        );
        assert_eq!(fc_cloth_set_collider_friction(c, id, 0.5), FC_OK);
        let (p, n) = ([0.0f32, -0.2, 0.0], [0.0f32, 1.0, 0.0]);
        assert_eq!(
            fc_cloth_add_plane(c, p.as_ptr(), n.as_ptr(), null(), &mut id),
            FC_OK
        );
        let current = [0.0f32, 0.0, 0.1];
        assert_eq!(fc_cloth_set_current(c, current.as_ptr()), FC_OK);
    }
    Handle(c)
}

fn step(c: &Handle, k0: usize, steps: usize) {
    step_wide(c, 10, k0, steps);
}

/// Steps a cloth `width` wide, its first ten top vertices swung.
fn step_wide(c: &Handle, width: u32, k0: usize, steps: usize) {
    let top: Vec<u32> = (0..10).collect();
    let x0 = -0.005 * (width - 1) as f32;
    for k in k0..k0 + steps {
        let z = 0.02 * (k as f32 * 0.01).sin();
        let t: Vec<f32> = top.iter().flat_map(|&i| [x0 + 0.01 * i as f32, 0.0, z]).collect();
        unsafe {
            assert_eq!(
                fc_cloth_set_pin_targets(c.0, top.as_ptr(), t.as_ptr(), top.len()),
                FC_OK
            );
            assert_eq!(fc_cloth_step(c.0, 5e-4), FC_OK, "{}", message());
        }
    }
}

fn state(c: &Handle) -> (Vec<f32>, Vec<f32>, f64) {
    let n = unsafe { fc_cloth_vertex_count(c.0) };
    let (mut x, mut v) = (vec![0f32; 3 * n], vec![0f32; 3 * n]);
    unsafe {
        assert_eq!(fc_cloth_get_positions(c.0, x.as_mut_ptr(), x.len()), FC_OK);
        assert_eq!(fc_cloth_get_velocities(c.0, v.as_mut_ptr(), v.len()), FC_OK);
        (x, v, fc_cloth_time(c.0))
    }
}

fn save(c: &Handle) -> Vec<u8> {
    let size = unsafe { fc_cloth_snapshot_size(c.0) };
    let mut buf = vec![0u8; size];
    let mut written = 0;
    let s =
        unsafe { fc_cloth_save_snapshot(c.0, buf.as_mut_ptr().cast::<c_void>(), buf.len(), &mut written) };
    assert_eq!(s, FC_OK, "{}", message());
    assert_eq!(written, size);
    buf
}

fn load(c: &Handle, bytes: &[u8]) -> FcStatus {
    unsafe { fc_cloth_load_snapshot(c.0, bytes.as_ptr().cast::<c_void>(), bytes.len()) }
}

#[test]
fn restore_continues_bitwise_for_every_history_scheme() {
    for scheme in [0u32, 1, 2, 3] {
        let a = make(10, scheme);
        step(&a, 0, 300);
        let snap = save(&a);
        step(&a, 300, 300);
        let end = state(&a);
        // A fresh cloth restored from the snapshot, and the original rewound to it.
        let b = make(10, scheme);
        assert_eq!(load(&b, &snap), FC_OK, "{}", message());
        step(&b, 300, 300);
        assert_eq!(state(&b), end, "scheme {scheme}: fresh cloth");
        assert_eq!(load(&a, &snap), FC_OK);
        step(&a, 300, 300);
        assert_eq!(state(&a), end, "scheme {scheme}: rewound cloth");
    }
}

/// A cloth whose SOE modes pass `DEFER_FROM_BYTES` folds every other step
/// (`SumOfExponentials::with_deferred_fold`): saved after an even and an odd number of steps
/// (the next pass taking its sum ahead, or a sample pending), it continues bitwise.
#[test]
fn a_large_cloth_that_defers_its_folds_restores_bitwise() {
    let width = 5600; // x 8 rows: 44 800 particles, 17 MB of modes
    let bytes = unsafe { fc_cloth_history_bytes_per_particle(make(10, 3).0) };
    let a = make(width, 3);
    // Two more samples a particle when deferring: the pending one and the sum ahead.
    assert_eq!(unsafe { fc_cloth_history_bytes_per_particle(a.0) }, bytes + 48);
    step_wide(&a, width, 0, 20);
    for at in [20, 21] {
        step_wide(&a, width, 20, at - 20);
        let snap = save(&a);
        step_wide(&a, width, at, 20);
        let end = state(&a);
        let b = make(width, 3);
        assert_eq!(load(&b, &snap), FC_OK, "{}", message());
        step_wide(&b, width, at, 20);
        assert_eq!(state(&b), end, "saved after {at} steps");
        assert_eq!(load(&a, &snap), FC_OK);
        step_wide(&a, width, at, 20);
        assert_eq!(state(&a), end, "rewound to step {at}");
        assert_eq!(load(&a, &snap), FC_OK);
    }
}

#[test]
fn bad_snapshots_are_rejected_and_change_nothing() {
    let a = make(10, 3);
    step(&a, 0, 100);
    let snap = save(&a);
    let b = make(10, 3);
    step(&b, 0, 37);
    let before = (state(&b), save(&b));
    let unchanged = |what: &str| {
        assert_eq!((state(&b), save(&b)), before, "{what}: cloth changed");
    };
    // Every truncation.
    for len in (0..snap.len()).step_by(97).chain([snap.len() - 1]) {
        assert_eq!(load(&b, &snap[..len]), FC_ERROR_INVALID_ARGUMENT, "length {len}");
    }
    unchanged("truncated");
    // One flipped bit anywhere.
    let mut flips = 0;
    for pos in (0..snap.len()).step_by(13) {
        let mut bad = snap.clone();
        bad[pos] ^= 1 << (pos % 8);
        assert_eq!(
            load(&b, &bad),
            FC_ERROR_INVALID_ARGUMENT,
            "bit flip at byte {pos}"
        );
        flips += 1;
    }
    assert!(flips > 100);
    assert!(
        message().contains("checksum") || message().contains("snapshot"),
        "{}",
        message()
    );
    unchanged("corrupted");
    // Extra bytes, another format version, another cloth, another history scheme.
    let mut long = snap.clone();
    long.push(0);
    assert_eq!(load(&b, &long), FC_ERROR_INVALID_ARGUMENT);
    let mut other = snap.clone();
    other[8] = other[8].wrapping_add(1);
    assert_eq!(load(&b, &other), FC_ERROR_INVALID_ARGUMENT);
    assert!(message().contains("version"), "{}", message());
    let wider = make(11, 3);
    assert_eq!(load(&wider, &snap), FC_ERROR_INVALID_ARGUMENT);
    assert!(message().contains("another cloth"), "{}", message());
    let paper = make(10, 1);
    assert_eq!(load(&paper, &snap), FC_ERROR_INVALID_ARGUMENT);
    assert!(message().contains("history"), "{}", message());
    unchanged("foreign");
    // Buffer too small, NULLs.
    let mut small = vec![0u8; snap.len() - 1];
    let s = unsafe { fc_cloth_save_snapshot(b.0, small.as_mut_ptr().cast(), small.len(), null_mut()) };
    assert_eq!(s, FC_ERROR_INVALID_ARGUMENT);
    assert!(
        small.iter().all(|&x| x == 0),
        "a failed save wrote into the buffer"
    );
    unsafe {
        assert_eq!(fc_cloth_load_snapshot(b.0, null(), 10), FC_ERROR_NULL_ARGUMENT);
        assert_eq!(
            fc_cloth_save_snapshot(b.0, null_mut(), 10, null_mut()),
            FC_ERROR_NULL_ARGUMENT
        );
        assert_eq!(fc_cloth_snapshot_size(null()), 0);
    }
    unchanged("null");
    // And the good one still loads.
    assert_eq!(load(&b, &snap), FC_OK);
    assert_eq!(state(&b), state(&a));
}

/// A snapshot loaded back into the cloth that saved it, after more frames, continues with the
/// bits of the frames it rewinds to, for every integrator (the implicit solves, the
/// extrapolated steps) and the underwater preset and the fractional model at the automatic
/// step: the load's trial step runs on the cloth itself (0.9.20) and must leave nothing of
/// itself behind, in the state or in what the next calls read from their scratch.
#[test]
fn a_rewound_cloth_continues_bitwise_with_every_integrator() {
    use fraccloth::{Integrator, Model};
    use fraccloth_tools::scenes::SceneSpec;
    let frames = |scene: &mut fraccloth_tools::scenes::Scene, k: usize| -> Vec<u64> {
        let mut bits = vec![];
        for _ in 0..k {
            scene.step().unwrap();
            bits.extend(
                scene
                    .cloth
                    .positions()
                    .iter()
                    .flat_map(|p| p.iter().map(|c| c.to_bits())),
            );
            bits.push(scene.cloth.step_stats().substeps.into());
        }
        bits
    };
    for integrator in [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::ImplicitEuler,
        Integrator::ExtrapolatedSymplectic,
        Integrator::ExtrapolatedImplicit,
    ] {
        for model in [Model::underwater(), Model::fractional()] {
            let mut spec = SceneSpec::underwater_swing(9, 7, 1.0, 0.04, model);
            spec.integrator = integrator;
            let mut scene = spec.build().unwrap();
            frames(&mut scene, 6);
            let saved = scene.cloth.save_snapshot().unwrap();
            let want = frames(&mut scene, 5);
            let (stats, solver) = (scene.cloth.step_stats(), scene.cloth.solver_stats());
            scene.cloth.load_snapshot(&saved).unwrap();
            // The last call's statistics, not the trial step's.
            assert_eq!(scene.cloth.step_stats(), stats, "{integrator:?}");
            assert_eq!(
                format!("{:?}", scene.cloth.solver_stats()),
                format!("{solver:?}"),
                "{integrator:?}"
            );
            assert_eq!(frames(&mut scene, 5), want, "{integrator:?}, rewound");
        }
    }
}
