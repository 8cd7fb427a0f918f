//! `fc_cloth_get_desc` and `fc_cloth_set_desc`: reading a cloth's description back and changing
//! its coefficients between steps.

use std::ffi::CStr;

use fraccloth::ffi::FcStatus::{FC_ERROR_INVALID_ARGUMENT, FC_OK};
use fraccloth::ffi::*;

fn message() -> String {
    unsafe { CStr::from_ptr(fc_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn create(d: &FcClothDesc) -> *mut FcCloth {
    let mut c = std::ptr::null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(d, &mut c) }, FC_OK, "{}", message());
    let top: Vec<u32> = (0..d.width).collect();
    assert_eq!(unsafe { fc_cloth_set_pinned(c, top.as_ptr(), top.len()) }, FC_OK);
    c
}

fn positions(c: *mut FcCloth) -> Vec<f64> {
    let n = unsafe { fc_cloth_vertex_count(c) };
    let mut x = vec![0.0; 3 * n];
    assert_eq!(
        unsafe { fc_cloth_get_positions_f64(c, x.as_mut_ptr(), x.len()) },
        FC_OK
    );
    x
}

fn get(c: *mut FcCloth) -> FcClothDesc {
    let mut d = fc_cloth_desc_default();
    assert_eq!(unsafe { fc_cloth_get_desc(c, &mut d) }, FC_OK);
    d
}

#[test]
fn the_description_reads_back_and_a_round_trip_changes_nothing() {
    let mut d = fc_cloth_desc_default();
    assert_eq!(unsafe { fc_cloth_desc_preset(4, &mut d) }, FC_OK);
    d.width = 31;
    d.height = 21;
    d.spacing = 0.02;
    d.added_mass_coefficient = 0.5;
    let (a, b) = (create(&d), create(&d));
    let got = get(a);
    assert_eq!((got.width, got.height), (31, 21));
    assert!((got.spacing - 0.02).abs() < 1e-7);
    assert!((got.total_mass - 0.24).abs() < 1e-6, "{}", got.total_mass); // spacing is a float
    assert!((got.areal_density - 1.0).abs() < 1e-6);
    // The added mass as C_a rho_w W, W = 0.4 m: 200 kg/m^2 on top of the preset's, the
    // coefficient folded in.
    assert!(
        (got.added_mass - (d.added_mass + 200.0)).abs() < 1e-4 && got.added_mass_coefficient == 0.0,
        "{}",
        got.added_mass
    );
    assert_eq!(got.entrained_mass, d.entrained_mass);
    assert_eq!(got.integrator, d.integrator);
    assert_eq!(unsafe { fc_cloth_set_desc(a, &got) }, FC_OK, "{}", message());
    for _ in 0..200 {
        unsafe {
            fc_cloth_step(a, 1e-3);
            fc_cloth_step(b, 1e-3);
        }
    }
    assert_eq!(positions(a), positions(b));
    unsafe {
        fc_cloth_destroy(a);
        fc_cloth_destroy(b);
    }
}

#[test]
fn coefficients_change_between_steps_and_bad_changes_change_nothing() {
    let mut d = fc_cloth_desc_default();
    d.width = 21;
    d.height = 15;
    let (a, b) = (create(&d), create(&d));
    for _ in 0..100 {
        unsafe {
            fc_cloth_step(a, 5e-4);
            fc_cloth_step(b, 5e-4);
        }
    }
    let mut stiff = get(a);
    stiff.stretch_stiffness *= 10.0;
    stiff.integrator = FcIntegrator::FC_INTEGRATOR_SYMPLECTIC_EULER as u32;
    assert_eq!(unsafe { fc_cloth_set_desc(a, &stiff) }, FC_OK, "{}", message());
    assert_eq!(get(a).stretch_stiffness, 10.0 * d.stretch_stiffness);
    for _ in 0..100 {
        unsafe {
            assert_eq!(fc_cloth_step(a, 2e-4), FC_OK);
            fc_cloth_step(b, 2e-4);
        }
    }
    assert_ne!(positions(a), positions(b));
    // Refused, naming the reason, and nothing changes.
    let before = get(a);
    let x = positions(a);
    type Change = Box<dyn Fn(&mut FcClothDesc)>;
    let cases: Vec<(&str, Change)> = vec![
        (
            "history",
            Box::new(|d| d.history_scheme = FcHistoryScheme::FC_HISTORY_FULL as u32),
        ),
        ("history", Box::new(|d| d.history_tolerance = 1e-6)),
        (
            "fractional",
            Box::new(|d| {
                d.history_drag = 0.0;
                d.spring_damping = 0.0;
            }),
        ),
        ("viscous_drag", Box::new(|d| d.viscous_drag = f64::NAN)),
        ("integrator", Box::new(|d| d.integrator = 77)),
    ];
    for (word, change) in cases {
        let mut bad = before;
        change(&mut bad);
        assert_eq!(
            unsafe { fc_cloth_set_desc(a, &bad) },
            FC_ERROR_INVALID_ARGUMENT,
            "{word}"
        );
        assert!(message().contains(word), "{word}: {}", message());
        let now = get(a);
        assert_eq!(
            (
                now.stretch_stiffness,
                now.viscous_drag,
                now.history_scheme,
                now.integrator
            ),
            (
                before.stretch_stiffness,
                before.viscous_drag,
                before.history_scheme,
                before.integrator
            )
        );
        assert_eq!(positions(a), x);
    }
    unsafe {
        fc_cloth_destroy(a);
        fc_cloth_destroy(b);
    }
}

/// `fc_cloth_set_current_f64` sets the current exactly as the description holds it; the float
/// call rounds it to float.
#[test]
fn the_current_in_double_precision_reads_back_exactly() {
    let c = create(&fc_cloth_desc_default());
    let exact = [0.1f64, -0.2, 0.3];
    assert_eq!(unsafe { fc_cloth_set_current_f64(c, exact.as_ptr()) }, FC_OK);
    assert_eq!(get(c).current, exact);
    let float = [0.1f32, -0.2, 0.3];
    assert_eq!(unsafe { fc_cloth_set_current(c, float.as_ptr()) }, FC_OK);
    assert_eq!(get(c).current, float.map(f64::from));
    let bad = [f64::NAN, 0.0, 0.0];
    assert_eq!(
        unsafe { fc_cloth_set_current_f64(c, bad.as_ptr()) },
        FC_ERROR_INVALID_ARGUMENT
    );
    assert_eq!(
        get(c).current,
        float.map(f64::from),
        "a refused current changes nothing"
    );
    unsafe { fc_cloth_destroy(c) };
}
