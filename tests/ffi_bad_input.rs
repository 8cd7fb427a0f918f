//! Every bad input through the C ABI returns the right status and a message, writes
//! no output, and leaves the cloth exactly as it was.

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;

struct Handle(*mut FcCloth);
impl Drop for Handle {
    fn drop(&mut self) {
        unsafe { fc_cloth_destroy(self.0) }
    }
}

fn small() -> (FcClothDesc, Handle) {
    let mut desc = fc_cloth_desc_default();
    desc.width = 5;
    desc.height = 4;
    let mut c = null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(&desc, &mut c) }, FC_OK);
    let top: Vec<u32> = (0..5).collect();
    assert_eq!(unsafe { fc_cloth_set_pinned(c, top.as_ptr(), 5) }, FC_OK);
    for _ in 0..10 {
        assert_eq!(unsafe { fc_cloth_step(c, 1e-3) }, FC_OK);
    }
    (desc, Handle(c))
}

fn state(c: *mut FcCloth) -> (Vec<f32>, Vec<f32>, f64) {
    let n = unsafe { fc_cloth_vertex_count(c) };
    let mut x = vec![0f32; 3 * n];
    let mut v = vec![0f32; 3 * n];
    unsafe {
        assert_eq!(fc_cloth_get_positions(c, x.as_mut_ptr(), x.len()), FC_OK);
        assert_eq!(fc_cloth_get_velocities(c, v.as_mut_ptr(), v.len()), FC_OK);
        (x, v, fc_cloth_time(c))
    }
}

fn message() -> String {
    unsafe { CStr::from_ptr(fc_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// Runs `call` on a fresh cloth; asserts the status, a message, and an untouched state.
fn rejects(what: &str, want: FcStatus, call: impl FnOnce(*mut FcCloth) -> FcStatus) {
    let (_, h) = small();
    let before = state(h.0);
    let got = call(h.0);
    assert_eq!(got, want, "{what}: {}", message());
    assert!(!message().is_empty(), "{what}: no message");
    assert_eq!(state(h.0), before, "{what}: state changed");
    // The cloth still works afterwards, and success clears the message.
    assert_eq!(unsafe { fc_cloth_step(h.0, 1e-3) }, FC_OK);
    assert_eq!(message(), "");
}

#[test]
fn step_rejects_bad_dt_and_null() {
    for dt in [0.0, -1e-3, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        rejects(&format!("dt = {dt}"), FC_ERROR_INVALID_ARGUMENT, |c| unsafe {
            fc_cloth_step(c, dt)
        });
    }
    assert_eq!(unsafe { fc_cloth_step(null_mut(), 1e-3) }, FC_ERROR_NULL_ARGUMENT);
    assert!(message().contains("cloth"));
}

#[test]
fn buffers_of_the_wrong_length_or_null_are_rejected() {
    let (_, h) = small();
    let n = unsafe { fc_cloth_vertex_count(h.0) };
    let good = state(h.0).0;
    for len in [0, 3 * n - 1, 3 * n + 1, 3 * n + 3, usize::MAX] {
        rejects(
            &format!("set_positions len {len}"),
            FC_ERROR_INVALID_ARGUMENT,
            |c| unsafe { fc_cloth_set_positions(c, good.as_ptr(), len) },
        );
        let mut out = vec![7f32; 3 * n + 3];
        rejects(
            &format!("get_positions len {len}"),
            FC_ERROR_INVALID_ARGUMENT,
            |c| unsafe { fc_cloth_get_positions(c, out.as_mut_ptr(), len) },
        );
        assert!(out.iter().all(|&v| v == 7.0), "output written on error");
    }
    rejects("set_positions NULL", FC_ERROR_NULL_ARGUMENT, |c| unsafe {
        fc_cloth_set_positions(c, null(), 3 * n)
    });
    rejects("get_positions NULL", FC_ERROR_NULL_ARGUMENT, |c| unsafe {
        fc_cloth_get_positions(c, null_mut(), 3 * n)
    });
    assert_eq!(
        unsafe { fc_cloth_get_positions(null(), null_mut(), 0) },
        FC_ERROR_NULL_ARGUMENT
    );
}

#[test]
fn non_finite_values_are_rejected() {
    let (_, h) = small();
    let n = unsafe { fc_cloth_vertex_count(h.0) };
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut x = state(h.0).0;
        x[3 * n - 2] = bad;
        rejects(
            "set_positions non-finite",
            FC_ERROR_INVALID_ARGUMENT,
            |c| unsafe { fc_cloth_set_positions(c, x.as_ptr(), 3 * n) },
        );
        let idx = [1u32];
        let t = [0.0, bad, 0.0];
        rejects("pin target non-finite", FC_ERROR_INVALID_ARGUMENT, |c| unsafe {
            fc_cloth_set_pin_targets(c, idx.as_ptr(), t.as_ptr(), 1)
        });
        rejects("current non-finite", FC_ERROR_INVALID_ARGUMENT, |c| unsafe {
            fc_cloth_set_current(c, t.as_ptr())
        });
        let center = [0.0, -0.1, bad];
        let mut id = 99u32;
        rejects("sphere non-finite", FC_ERROR_INVALID_ARGUMENT, |c| unsafe {
            fc_cloth_add_sphere(c, center.as_ptr(), 0.05, null(), &mut id)
        });
        rejects(
            "sphere radius non-finite",
            FC_ERROR_INVALID_ARGUMENT,
            |c| unsafe { fc_cloth_add_sphere(c, [0.0f32; 3].as_ptr(), bad, null(), &mut id) },
        );
        assert_eq!(id, 99, "id written on error");
    }
}

#[test]
fn out_of_range_indices_and_ids_are_rejected() {
    let idx = [0u32, 1, 20];
    rejects("pin out of range", FC_ERROR_OUT_OF_RANGE, |c| unsafe {
        fc_cloth_set_pinned(c, idx.as_ptr(), 3)
    });
    let t = [0f32; 9];
    rejects("target out of range", FC_ERROR_OUT_OF_RANGE, |c| unsafe {
        fc_cloth_set_pin_targets(c, idx.as_ptr(), t.as_ptr(), 3)
    });
    let unpinned = [7u32];
    rejects(
        "target of an unpinned vertex",
        FC_ERROR_INVALID_ARGUMENT,
        |c| unsafe { fc_cloth_set_pin_targets(c, unpinned.as_ptr(), t.as_ptr(), 1) },
    );
    rejects("remove missing collider", FC_ERROR_OUT_OF_RANGE, |c| unsafe {
        fc_cloth_remove_collider(c, 0)
    });
    rejects("move missing sphere", FC_ERROR_OUT_OF_RANGE, |c| unsafe {
        fc_cloth_set_sphere(c, 4, t.as_ptr(), 0.1, null())
    });
    rejects("pins NULL", FC_ERROR_NULL_ARGUMENT, |c| unsafe {
        fc_cloth_set_pinned(c, null(), 2)
    });
}

#[test]
fn bad_descriptions_are_rejected_without_output() {
    let base = fc_cloth_desc_default();
    type Change = Box<dyn Fn(&mut FcClothDesc)>;
    let cases: Vec<(&str, Change)> = vec![
        ("width 1", Box::new(|d| d.width = 1)),
        ("height 0", Box::new(|d| d.height = 0)),
        ("spacing 0", Box::new(|d| d.spacing = 0.0)),
        ("spacing NaN", Box::new(|d| d.spacing = f32::NAN)),
        ("mass NaN", Box::new(|d| d.total_mass = f64::NAN)),
        ("areal density negative", Box::new(|d| d.areal_density = -1.0)),
        ("cloth density 0", Box::new(|d| d.cloth_density = 0.0)),
        ("stiffness negative", Box::new(|d| d.stretch_stiffness = -1.0)),
        ("drag infinite", Box::new(|d| d.viscous_drag = f64::INFINITY)),
        ("gravity NaN", Box::new(|d| d.gravity[1] = f64::NAN)),
        ("scheme unknown", Box::new(|d| d.history_scheme = 42)),
        (
            "u zero",
            Box::new(|d| {
                d.history_scheme = FcHistoryScheme::FC_HISTORY_TRUNCATED as u32;
                d.history_u = 0
            }),
        ),
        (
            "u huge",
            Box::new(|d| {
                d.history_scheme = FcHistoryScheme::FC_HISTORY_TRUNCATED as u32;
                d.history_u = u32::MAX
            }),
        ),
        (
            "grid of 2^25 vertices",
            Box::new(|d| {
                d.width = 1 << 13;
                d.height = 1 << 12
            }),
        ),
        ("soe tolerance 0", Box::new(|d| d.history_tolerance = 0.0)),
        ("soe tolerance NaN", Box::new(|d| d.history_tolerance = f64::NAN)),
        ("soe tolerance 0.5", Box::new(|d| d.history_tolerance = 0.5)),
        ("soe horizon below min_dt", Box::new(|d| d.history_horizon = 1e-5)),
        ("soe min_dt negative", Box::new(|d| d.history_min_dt = -1.0)),
        ("integrator unknown", Box::new(|d| d.integrator = 9)),
        ("damping mode unknown", Box::new(|d| d.spring_damping_mode = 4)),
        ("max speed 0", Box::new(|d| d.max_speed = 0.0)),
        (
            "huge grid",
            Box::new(|d| {
                d.width = u32::MAX;
                d.height = u32::MAX
            }),
        ),
    ];
    for (what, change) in cases {
        let mut d = base;
        change(&mut d);
        let sentinel = 0x1 as *mut FcCloth;
        let mut out = sentinel;
        let st = unsafe { fc_cloth_create_grid(&d, &mut out) };
        assert_eq!(st, FC_ERROR_INVALID_ARGUMENT, "{what}: {}", message());
        assert!(!message().is_empty());
        assert_eq!(out, sentinel, "{what}: output written on error");
    }
    // No mass at all: the message says which two fields to set.
    let mut d = base;
    d.total_mass = 0.0;
    d.areal_density = 0.0;
    let mut out = null_mut();
    assert_eq!(
        unsafe { fc_cloth_create_grid(&d, &mut out) },
        FC_ERROR_INVALID_ARGUMENT
    );
    assert!(
        message().contains("no mass") && message().contains("areal_density"),
        "{}",
        message()
    );
    let mut out = null_mut();
    assert_eq!(
        unsafe { fc_cloth_create_grid(null(), &mut out) },
        FC_ERROR_NULL_ARGUMENT
    );
    assert_eq!(
        unsafe { fc_cloth_create_grid(&base, null_mut()) },
        FC_ERROR_NULL_ARGUMENT
    );
    assert_eq!(
        unsafe { fc_cloth_desc_preset(17, &mut fc_cloth_desc_default()) },
        FC_ERROR_INVALID_ARGUMENT
    );
    assert_eq!(
        unsafe { fc_cloth_desc_preset(0, null_mut()) },
        FC_ERROR_NULL_ARGUMENT
    );
}

#[test]
fn unstable_step_reports_and_leaves_state_unchanged() {
    // A pin jumping 1 m in 1 ms asks for 1000 m/s: refused as unstable.
    let (_, h) = small();
    let idx = [2u32];
    let far = [10.0f32, 0.0, 0.0];
    assert_eq!(
        unsafe { fc_cloth_set_pin_targets(h.0, idx.as_ptr(), far.as_ptr(), 1) },
        FC_OK
    );
    let before = state(h.0);
    assert_eq!(unsafe { fc_cloth_step(h.0, 1e-3) }, FC_ERROR_UNSTABLE);
    let m = message();
    assert!(m.contains("explicit Euler") && m.contains("0.001"), "{m}");
    assert_eq!(state(h.0), before);
}

#[test]
fn null_handles_are_harmless() {
    unsafe {
        fc_cloth_destroy(null_mut());
        assert_eq!(fc_cloth_vertex_count(null()), 0);
        assert_eq!(fc_cloth_time(null()), 0.0);
        assert_eq!(fc_cloth_set_pinned(null_mut(), null(), 0), FC_ERROR_NULL_ARGUMENT);
        assert_eq!(fc_cloth_remove_collider(null_mut(), 0), FC_ERROR_NULL_ARGUMENT);
        let s = CStr::from_ptr(fc_status_string(4)).to_str().unwrap();
        assert_eq!(s, "unstable");
        assert_eq!(
            CStr::from_ptr(fc_status_string(-3)).to_str().unwrap(),
            "unknown status"
        );
    }
    let v: Vec<u32> = env!("CARGO_PKG_VERSION")
        .split('.')
        .map(|p| p.parse().unwrap())
        .collect();
    assert_eq!(fc_version(), v[0] * 1_000_000 + v[1] * 1_000 + v[2]);
}
