//! The automatic step (`max_substep = FC_MAX_SUBSTEP_AUTO`): one `fc_cloth_step` per frame runs
//! the underwater preset (it used to fail after three frames with `max_substep = 0`), a jittered
//! triangle mesh and a brisk drive bake without a refused frame, the stats say what each call did,
//! and a fixed `max_substep` keeps its own substeps.

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;
use fraccloth::Integrator;
use fraccloth_tools::scenes::{Drive, SceneKind, SceneSpec, Variant};

#[test]
fn the_underwater_preset_steps_once_per_frame() {
    let mut desc = fc_cloth_desc_default();
    assert_eq!(
        unsafe { fc_cloth_desc_preset(FcPreset::FC_PRESET_UNDERWATER as u32, &mut desc) },
        FC_OK
    );
    assert!(desc.max_substep < 0.0, "the preset asks for the automatic step");
    let mut c = std::ptr::null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(&desc, &mut c) }, FC_OK);
    let top: Vec<u32> = (0..desc.width).collect();
    assert_eq!(unsafe { fc_cloth_set_pinned(c, top.as_ptr(), top.len()) }, FC_OK);
    let n = unsafe { fc_cloth_vertex_count(c) };
    let mut xyz = vec![0f32; 3 * n];
    unsafe { fc_cloth_get_positions(c, xyz.as_mut_ptr(), xyz.len()) };
    let rest: Vec<f32> = xyz[..3 * top.len()].to_vec();
    let (mut most, mut estimate) = (0u32, 0f64);
    for f in 1..=90 {
        let z = (0.04 * (std::f64::consts::TAU * 0.5 * f64::from(f) / 30.0).sin()) as f32;
        let targets: Vec<f32> = rest.chunks(3).flat_map(|p| [p[0], p[1], z]).collect();
        unsafe { fc_cloth_set_pin_targets(c, top.as_ptr(), targets.as_ptr(), top.len()) };
        let status = unsafe { fc_cloth_step(c, 1.0 / 30.0) };
        assert_eq!(status, FC_OK, "frame {f}");
        let (mut substeps, mut retries) = (0u32, 0u32);
        assert_eq!(
            unsafe { fc_cloth_get_step_stats(c, &mut substeps, &mut retries, &mut estimate) },
            FC_OK
        );
        most = most.max(substeps);
        assert_eq!(retries, 0, "frame {f}");
        assert!(substeps >= 2 && estimate > 0.0 && estimate * f64::from(substeps) >= 1.0 / 30.0 - 1e-12);
    }
    println!(
        "underwater preset, 61 x 41, 30 fps: at most {most} substeps a frame, estimate {estimate:.3e} s"
    );
    // NULL outputs are allowed; a NULL cloth is an error.
    assert_eq!(
        unsafe {
            fc_cloth_get_step_stats(
                c,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
            )
        },
        FC_OK
    );
    assert_ne!(
        unsafe {
            fc_cloth_get_step_stats(
                std::ptr::null(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
            )
        },
        FC_OK
    );
    unsafe { fc_cloth_destroy(c) };
}

fn bake_auto(spec: SceneSpec, seconds: f64) -> (u64, u32, u32) {
    let mut scene = SceneSpec {
        dt: 1.0 / 30.0,
        max_substep: fraccloth::cloth::AUTO,
        ..spec
    }
    .build()
    .unwrap();
    let (mut substeps, mut most, mut retries) = (0u64, 0u32, 0u32);
    for f in 1..=(seconds * 30.0) as usize {
        scene
            .run_until(f as f64 / 30.0)
            .unwrap_or_else(|e| panic!("frame {f} refused: {}", e.message));
        let s = scene.cloth.step_stats();
        (substeps, most, retries) = (
            substeps + u64::from(s.substeps),
            most.max(s.substeps),
            retries + s.retries,
        );
    }
    (substeps, most, retries)
}

#[test]
fn a_jittered_mesh_and_a_brisk_drive_bake_without_a_refused_frame() {
    let towel = SceneSpec {
        integrator: Integrator::SymplecticEuler,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
    };
    let (sum, most, retries) = bake_auto(
        SceneSpec {
            jittered: true,
            ..towel
        },
        20.0,
    );
    println!(
        "jittered triangles, 20 s: {:.1} substeps a frame on average, most {most}, {retries} retries",
        sum as f64 / 600.0
    );
    let brisk = Drive {
        frequency: 2.0,
        amplitude: 0.08,
        ..towel.drive
    };
    let (sum, most, retries) = bake_auto(
        SceneSpec {
            drive: brisk,
            ..towel
        },
        20.0,
    );
    println!(
        "2 Hz, 8 cm, 20 s: {:.1} substeps a frame on average, most {most}, {retries} retries",
        sum as f64 / 600.0
    );
}

#[test]
fn a_fixed_max_substep_keeps_its_substeps() {
    let spec = SceneSpec {
        integrator: Integrator::SymplecticEuler,
        dt: 1.0 / 30.0,
        max_substep: 1e-3,
        width: 21,
        height: 15,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Underwater)
    };
    let mut scene = spec.build().unwrap();
    scene.run_until(1.0 / 30.0).unwrap();
    let s = scene.cloth.step_stats();
    assert_eq!((s.substeps, s.retries, s.estimate), (34, 0, 0.0));
}
