//! History schemes through the C ABI: the default, the counts reported, and "model no
//! more than a scene needs".

use fraccloth::ffi::FcStatus::FC_OK;
use fraccloth::ffi::*;

fn create(d: &FcClothDesc) -> *mut FcCloth {
    let mut c = std::ptr::null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(d, &mut c) }, FC_OK);
    c
}

#[test]
fn default_is_the_accurate_scheme_and_reports_its_modes() {
    let d = fc_cloth_desc_default();
    assert_eq!(d.history_scheme, FcHistoryScheme::FC_HISTORY_SOE as u32);
    let c = create(&d);
    let modes = unsafe { fc_cloth_history_mode_count(c) };
    // 1e-3 on [1e-4 s, 3600 s]: the raw trapezoid rule needs 34 modes; compression keeps fewer.
    assert!((5..34).contains(&modes), "{modes} modes");
    assert_eq!(
        unsafe { fc_cloth_history_bytes_per_particle(c) },
        (modes as usize + 2) * 24
    );
    unsafe { fc_cloth_destroy(c) };
}

#[test]
fn tighter_tolerance_needs_more_modes() {
    let mut d = fc_cloth_desc_default();
    d.width = 3;
    d.height = 3;
    let mut last = 0;
    for tol in [1e-2, 1e-4, 1e-6, 1e-8] {
        d.history_tolerance = tol;
        let c = create(&d);
        let m = unsafe { fc_cloth_history_mode_count(c) };
        assert!(m > last, "tol {tol}: {m} modes after {last}");
        last = m;
        unsafe { fc_cloth_destroy(c) };
    }
}

#[test]
fn cloths_without_fractional_terms_keep_no_history() {
    for preset in [1u32, 2, 3] {
        let mut d = fc_cloth_desc_default();
        assert_eq!(unsafe { fc_cloth_desc_preset(preset, &mut d) }, FC_OK);
        let c = create(&d);
        assert_eq!(
            unsafe { fc_cloth_history_bytes_per_particle(c) },
            0,
            "preset {preset}"
        );
        assert_eq!(unsafe { fc_cloth_history_mode_count(c) }, 0);
        unsafe { fc_cloth_destroy(c) };
    }
    // A fractional cloth with the history switched off also keeps none.
    let mut d = fc_cloth_desc_default();
    d.history_scheme = FcHistoryScheme::FC_HISTORY_OFF as u32;
    let c = create(&d);
    assert_eq!(unsafe { fc_cloth_history_bytes_per_particle(c) }, 0);
    unsafe { fc_cloth_destroy(c) };
}

#[test]
fn paper_preset_is_eq6_with_u_3() {
    let mut d = fc_cloth_desc_default();
    assert_eq!(unsafe { fc_cloth_desc_preset(0, &mut d) }, FC_OK);
    assert_eq!(d.history_scheme, FcHistoryScheme::FC_HISTORY_TRUNCATED as u32);
    assert_eq!(d.history_u, 3);
    let c = create(&d);
    assert_eq!(unsafe { fc_cloth_history_bytes_per_particle(c) }, 3 * 24);
    unsafe { fc_cloth_destroy(c) };
}
