//! Reliability findings, each with a test that failed before its fix: snapshots whose
//! checksum is right but whose contents are impossible, snapshot bytes after a refused step,
//! an implicit solve stopped at its cap, positions beyond the float range, cache parameters
//! that cannot be written, a full disk, and a length checked before it is read.

use std::ffi::CString;
use std::ptr::null_mut;

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;
use fraccloth::history::Scheme;
use fraccloth::{Cloth, ClothConfig, ErrorKind, GridSpec, Integrator, Vec3};

const W: usize = 6;
const H: usize = 5;
const N: usize = W * H;

fn cloth(scheme: Scheme, integrator: Integrator) -> Cloth {
    let t = GridSpec {
        width: W as u32,
        height: H as u32,
        spacing: 0.02,
        total_mass: 0.03,
    }
    .build()
    .unwrap();
    let mut c = Cloth::new(
        t,
        ClothConfig {
            scheme,
            integrator,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    let top: Vec<u32> = (0..W as u32).collect();
    c.set_pinned(&top).unwrap();
    for k in 0..40 {
        let off = Vec3::new(0.0, 0.0, 0.01 * (0.3 * k as f64).sin());
        let targets: Vec<Vec3> = top
            .iter()
            .map(|&i| c.topology().rest_positions[i as usize] + off)
            .collect();
        c.set_pin_targets(&top, &targets).unwrap();
        c.step(1e-3).unwrap();
    }
    c
}

/// Byte offsets in a snapshot of a cloth of `N` vertices with `pins` pins and no colliders
/// (the layout in `src/cloth/snapshot.rs`).
struct Layout {
    velocity0: usize,
    history: usize,
}

fn layout(pins: usize) -> Layout {
    let header = 24;
    let after_solver = header + 8 * 3 + 8 + 1 + 8 + 8 + 8 + 24 + 8 + 4;
    let positions = after_solver + 8;
    let velocity0 = positions + 24 * N + 8;
    let weights = velocity0 + 24 * N;
    let pin_list = weights + 8 + 8 * N;
    let targets = pin_list + 8 + 4 * pins;
    let slots = targets + 8 + 24 * N;
    Layout {
        velocity0,
        history: slots + 8,
    }
}

/// Writes `v` at `at`, recomputes the checksum, and expects the load to be refused with a
/// message containing `says`, leaving the cloth able to step.
fn refused(c: &mut Cloth, bytes: &[u8], at: usize, v: f64, says: &str) {
    let mut b = bytes.to_vec();
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
    let end = b.len() - 4;
    let crc = crc32fast::hash(&b[..end]);
    b[end..].copy_from_slice(&crc.to_le_bytes());
    let before = c.save_snapshot().unwrap();
    let e = c.load_snapshot(&b).expect_err(says);
    assert!(e.message.contains(says), "{says}: {}", e.message);
    assert_eq!(
        c.save_snapshot().unwrap(),
        before,
        "a refused load changed the cloth"
    );
    c.step(1e-3).expect("the cloth still steps");
}

#[test]
fn snapshots_with_a_valid_checksum_but_impossible_contents_are_refused() {
    for scheme in [Scheme::DEFAULT, Scheme::PAPER, Scheme::Full] {
        let mut c = cloth(scheme, Integrator::SymplecticEuler);
        let bytes = c.save_snapshot().unwrap();
        let l = layout(W);
        refused(&mut c, &bytes, l.velocity0, f64::NAN, "velocity");
        refused(&mut c, &bytes, l.velocity0, 1e6, "max_speed");
        refused(&mut c, &bytes, l.velocity0 - 24 * N - 8 + 8, 1e300, "float range");
        // The motion averages (two f64 before the skin drag's empty mean and the checksum;
        // `src/cloth/motion.rs`).
        let motion = bytes.len() - 4 - 8 - 16;
        refused(&mut c, &bytes, motion, f64::NAN, "motion averages");
        refused(&mut c, &bytes, motion + 8, -1.0, "motion averages");
        refused(&mut c, &bytes, motion, f64::INFINITY, "motion averages");
        // The end of the history state: before the collision state (three empty counts), the
        // motion averages and the checksum.
        let tail = motion - 24;
        match scheme {
            Scheme::SumOfExponentials { .. } => {
                // The first mode of the first particle, then the step sizes at the end.
                refused(&mut c, &bytes, l.history + 8, f64::INFINITY, "SOE history mode");
                refused(&mut c, &bytes, tail - 16, -1e-3, "step size");
                refused(&mut c, &bytes, tail - 16, f64::NAN, "step size");
            }
            Scheme::Truncated { .. } => {
                refused(
                    &mut c,
                    &bytes,
                    l.history + 8,
                    f64::NAN,
                    "truncated history sample",
                );
                refused(&mut c, &bytes, tail - 8, 0.0, "step size");
            }
            Scheme::Full => {
                // times: u64 count, then the times; the last one in the future.
                let count = u64::from_le_bytes(bytes[l.history..l.history + 8].try_into().unwrap()) as usize;
                let last = l.history + 8 + 8 * (count - 1);
                refused(&mut c, &bytes, last, 1e3, "full history time");
                refused(&mut c, &bytes, last, f64::NAN, "full history time");
                refused(&mut c, &bytes, tail - 8, f64::NAN, "time now");
                refused(&mut c, &bytes, l.history + 8 + 8 * count + 8, f64::NAN, "sample");
            }
            Scheme::Off => {}
        }
    }
}

#[test]
fn a_refused_step_leaves_the_snapshot_bytes_as_they_were() {
    for scheme in [Scheme::DEFAULT, Scheme::PAPER, Scheme::Full] {
        for integrator in [Integrator::ExplicitEuler, Integrator::SymplecticEuler] {
            let mut c = cloth(scheme, integrator);
            let before = c.save_snapshot().unwrap();
            assert_eq!(before.len(), c.snapshot_size());
            let e = c.step(1e3).expect_err("a 1000 s explicit step explodes");
            assert_eq!(e.kind, ErrorKind::Unstable);
            assert_eq!(c.save_snapshot().unwrap(), before, "{scheme:?} {integrator:?}");
        }
    }
}

#[test]
fn an_implicit_solve_stopped_at_its_cap_is_refused_unless_accepted() {
    let mut c = cloth(Scheme::DEFAULT, Integrator::ImplicitEuler);
    c.set_solver(fraccloth::integrate::SolverSettings {
        tolerance: 1e-14,
        max_iterations: 2,
    })
    .unwrap();
    let before = c.save_snapshot().unwrap();
    let e = c.step(1.0 / 24.0).expect_err("2 iterations cannot reach 1e-14");
    assert_eq!(e.kind, ErrorKind::NotConverged, "{}", e.message);
    assert!(e.message.contains("2 iterations"), "{}", e.message);
    assert_eq!(c.save_snapshot().unwrap(), before);
    c.set_accept_unconverged(true);
    c.step(1.0 / 24.0).unwrap();
    assert_eq!(c.solver_stats().iterations, 2);
}

#[test]
fn positions_beyond_the_float_range_make_the_step_unstable() {
    // Unpinned, the cloth sinks at its terminal speed; an absurd implicit step carries it
    // past the largest float (the state is finite in f64, the host would read infinities).
    let mut c = cloth(Scheme::DEFAULT, Integrator::ImplicitEuler);
    c.set_pinned(&[]).unwrap();
    c.set_accept_unconverged(true);
    let before = c.save_snapshot().unwrap();
    let e = c.step(1e40).expect_err("a 1e40 s step leaves the float range");
    assert_eq!(e.kind, ErrorKind::Unstable, "{}", e.message);
    assert_eq!(c.save_snapshot().unwrap(), before);
    // A max_speed that lets velocities leave the float range is refused up front.
    let t = GridSpec {
        width: 3,
        height: 3,
        spacing: 0.1,
        total_mass: 0.1,
    }
    .build()
    .unwrap();
    let e = Cloth::new(
        t,
        ClothConfig {
            max_speed: 1e39,
            ..ClothConfig::default()
        },
    )
    .unwrap_err();
    assert!(e.message.contains("max_speed"), "{}", e.message);
}

fn ffi_cloth() -> *mut FcCloth {
    let mut desc = fc_cloth_desc_default();
    desc.width = 4;
    desc.height = 3;
    let mut c = null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(&desc, &mut c) }, FC_OK);
    c
}

#[test]
fn set_pin_weights_checks_the_count_before_reading() {
    let c = ffi_cloth();
    // A buffer of 3 floats announced as far more: refused before anything is read (this
    // read past the buffer, or crashed, before).
    let w = [0.5f32; 3];
    for count in [13, usize::MAX / 4] {
        assert_eq!(
            unsafe { fc_cloth_set_pin_weights(c, w.as_ptr(), count) },
            FC_ERROR_INVALID_ARGUMENT
        );
    }
    unsafe { fc_cloth_destroy(c) };
}

#[test]
fn cache_parameters_that_cannot_be_written_are_refused() {
    let c = ffi_cloth();
    let dir = std::env::temp_dir().join(format!("fc-rel-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = CString::new(dir.join("a.pc2").to_str().unwrap()).unwrap();
    let open = |format: u32, start: f64, fps: f64, expected: u32| {
        let mut cache = null_mut();
        let s = unsafe { fc_cache_open(path.as_ptr(), format, c, start, fps, expected, &mut cache) };
        unsafe { fc_cache_close(cache) };
        s
    };
    assert_eq!(
        open(0, 1e300, 24.0, 1),
        FC_ERROR_INVALID_ARGUMENT,
        "PC2 start 1e300 would be inf"
    );
    assert_eq!(
        open(1, 1.0, 1e-300, 10),
        FC_ERROR_INVALID_ARGUMENT,
        "MDD times would be inf"
    );
    assert_eq!(
        open(2, 9.2e18, 24.0, 1),
        FC_ERROR_INVALID_ARGUMENT,
        "OBJ frame numbers would wrap"
    );
    assert_eq!(
        open(1, 1.0, 24.0, 10_000_000),
        FC_ERROR_INVALID_ARGUMENT,
        "40 MB of MDD times"
    );
    assert_eq!(open(1, 1.0, 24.0, 100), FC_OK);
    std::fs::remove_dir_all(&dir).ok();
    unsafe { fc_cloth_destroy(c) };
}

#[test]
fn a_full_disk_is_an_error_not_a_success() {
    if !std::path::Path::new("/dev/full").exists() {
        eprintln!("no /dev/full here: skipped");
        return;
    }
    let c = ffi_cloth();
    let full = CString::new("/dev/full").unwrap();
    assert_eq!(unsafe { fc_cloth_write_obj(c, full.as_ptr()) }, FC_ERROR_IO);
    unsafe { fc_cloth_destroy(c) };
}
