//! Running out of memory is an error, never an abort: under an address-space limit (as
//! `ulimit -v` or a container sets), requests too large for it return
//! `FC_ERROR_OUT_OF_MEMORY` and the process goes on.
//!
//! One test in its own binary: the limit applies to the whole process.

use std::ptr::null_mut;

use fraccloth::ffi::FcStatus::*;
use fraccloth::ffi::*;

fn vm_size() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmSize:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn set_address_space_limit(bytes: u64) -> libc::rlimit {
    let mut old = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    unsafe {
        assert_eq!(libc::getrlimit(libc::RLIMIT_AS, &mut old), 0);
        let new = libc::rlimit {
            rlim_cur: bytes as libc::rlim_t,
            rlim_max: old.rlim_max,
        };
        assert_eq!(libc::setrlimit(libc::RLIMIT_AS, &new), 0);
    }
    old
}

fn create(width: u32, height: u32, scheme: u32, u: u32) -> (FcStatus, *mut FcCloth) {
    let mut desc = fc_cloth_desc_default();
    desc.width = width;
    desc.height = height;
    desc.history_scheme = scheme;
    desc.history_u = u;
    desc.integrator = 1; // symplectic: stable at 1 ms
    let mut c = null_mut();
    (unsafe { fc_cloth_create_grid(&desc, &mut c) }, c)
}

#[test]
fn requests_too_large_for_memory_are_refused_not_aborted() {
    let Some(vm) = vm_size() else {
        eprintln!("no /proc/self/status: skipped");
        return;
    };
    // Before the limit: a cloth with a long full history (about 120 MB) and a host buffer
    // for its snapshot.
    let (s, full) = create(101, 84, 2 /* FC_HISTORY_FULL */, 3);
    assert_eq!(s, FC_OK);
    let top: Vec<u32> = (0..101).collect();
    unsafe {
        assert_eq!(fc_cloth_set_pinned(full, top.as_ptr(), top.len()), FC_OK);
        for _ in 0..500 {
            assert_eq!(fc_cloth_step(full, 1e-3), FC_OK);
        }
    }
    let size = unsafe { fc_cloth_snapshot_size(full) };
    assert!(size > 100_000_000, "{size}");
    let mut buffer = vec![0u8; size];
    let mesh_xyz: Vec<f32> = (0..6_000_000).map(|k| (k % 1000) as f32 * 1e-3).collect();

    let old = set_address_space_limit(vm + 32 * 1024 * 1024 + size as u64);

    // Sizing the snapshot allocates nothing; assembling it needs its size again: refused.
    assert_eq!(unsafe { fc_cloth_snapshot_size(full) }, size);
    let mut written = 0;
    let s = unsafe { fc_cloth_save_snapshot(full, buffer.as_mut_ptr().cast(), size, &mut written) };
    assert!(s == FC_ERROR_OUT_OF_MEMORY || s == FC_OK, "{s:?}");
    // A call of several substeps keeps a copy of the state to stay atomic: with a history
    // this long the copy does not fit, and the call is refused, not aborted.
    assert_eq!(
        unsafe { fc_cloth_step_substeps(full, 0.01, 10) },
        FC_ERROR_OUT_OF_MEMORY
    );
    // Single steps grow the full history until it no longer fits: refused, not aborted.
    let mut refused = FC_OK;
    for _ in 0..400 {
        refused = unsafe { fc_cloth_step(full, 1e-3) };
        if refused != FC_OK {
            break;
        }
    }
    assert_eq!(refused, FC_ERROR_OUT_OF_MEMORY);
    unsafe { fc_cloth_destroy(full) };

    // Grids far beyond the limit: the documented largest, and 1024 x 1024.
    for (w, h) in [(4096, 4096), (1024, 1024)] {
        let (s, c) = create(w, h, 0, 3);
        assert_eq!(s, FC_ERROR_OUT_OF_MEMORY, "{w} x {h}");
        assert!(c.is_null());
    }
    // A truncated history with a very large u.
    let (s, c) = create(100, 100, 1 /* FC_HISTORY_TRUNCATED */, 20_000);
    assert_eq!(s, FC_ERROR_OUT_OF_MEMORY);
    assert!(c.is_null());
    // A mesh of two million vertices (the host's arrays exist; the cloth would not fit).
    let desc = fc_cloth_desc_default();
    let indices = [0u32, 1, 2];
    let mut m = null_mut();
    let s = unsafe {
        fc_cloth_create_mesh(
            &desc,
            mesh_xyz.as_ptr(),
            mesh_xyz.len() / 3,
            indices.as_ptr(),
            3,
            3,
            &mut m,
        )
    };
    assert_eq!(s, FC_ERROR_OUT_OF_MEMORY);
    assert!(m.is_null());
    // What fits still works under the limit.
    let (s, c) = create(61, 41, 0, 3);
    assert_eq!(s, FC_OK);
    unsafe {
        assert_eq!(fc_cloth_step(c, 1e-3), FC_OK);
        fc_cloth_destroy(c);
    }
    unsafe { libc::setrlimit(libc::RLIMIT_AS, &old) };

    self_collision_that_does_not_fit_is_refused();
    a_cloth_whose_self_collision_does_not_fit_is_refused();
}

/// A 201 x 201 cloth with self-collision, stepped flat (its buffers sized), then folded in two
/// with its layers half a thickness apart: its next look finds some 10^5 pairs, and their lists
/// and contacts (tens of MB) do not fit under a limit of 8 MB more than it uses. The step is
/// refused with `FC_ERROR_OUT_OF_MEMORY` and the cloth left as it was; with the limit lifted,
/// the same step succeeds.
/// A `width` x `height` grid's description, symplectic Euler, self-collision at `relative`
/// spacings (0: off).
fn grid_desc(width: u32, height: u32, relative: f64) -> FcClothDesc {
    let mut desc = fc_cloth_desc_default();
    desc.width = width;
    desc.height = height;
    desc.integrator = 1;
    desc.self_collision_relative = relative;
    desc
}

/// The calling thread's last error message.
fn last_error() -> String {
    unsafe { std::ffi::CStr::from_ptr(fc_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn self_collision_that_does_not_fit_is_refused() {
    let (w, h) = (201u32, 201u32);
    let desc = grid_desc(w, h, 0.4);
    let mut c = null_mut();
    assert_eq!(unsafe { fc_cloth_create_grid(&desc, &mut c) }, FC_OK);
    let n = w as usize * h as usize;
    let mut x = vec![0.0f64; 3 * n];
    unsafe {
        assert_eq!(fc_cloth_step(c, 1e-4), FC_OK);
        assert_eq!(fc_cloth_get_positions_f64(c, x.as_mut_ptr(), x.len()), FC_OK);
    }
    // The grid's axes from its corner: along a row, across rows, and the normal.
    let at = |x: &[f64], i: usize, j: usize| {
        let k = 3 * (j * w as usize + i);
        [x[k], x[k + 1], x[k + 2]]
    };
    let (o, r, u) = (at(&x, 0, 0), at(&x, 1, 0), at(&x, 0, 1));
    let a: [f64; 3] = std::array::from_fn(|k| r[k] - o[k]);
    let b: [f64; 3] = std::array::from_fn(|k| u[k] - o[k]);
    let normal = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let len = normal.iter().map(|v| v * v).sum::<f64>().sqrt();
    let spacing = a.iter().map(|v| v * v).sum::<f64>().sqrt();
    let gap = 0.5 * 0.4 * spacing;
    // Rows past the middle laid back over the first half, `gap` above it.
    let mid = h as usize / 2;
    let flat = x.clone();
    for j in mid + 1..h as usize {
        for i in 0..w as usize {
            let under = at(&flat, i, 2 * mid - j);
            let k = 3 * (j * w as usize + i);
            for d in 0..3 {
                x[k + d] = under[d] + gap * normal[d] / len;
            }
        }
    }
    unsafe {
        assert_eq!(fc_cloth_set_positions_f64(c, x.as_ptr(), x.len()), FC_OK);
    }
    let Some(vm) = vm_size() else { return };
    let old = set_address_space_limit(vm + 8 * 1024 * 1024);
    let refused = unsafe { fc_cloth_step(c, 1e-4) };
    let message = last_error();
    let mut after = vec![0.0f64; 3 * n];
    let read = unsafe { fc_cloth_get_positions_f64(c, after.as_mut_ptr(), after.len()) };
    unsafe { libc::setrlimit(libc::RLIMIT_AS, &old) };
    assert_eq!(refused, FC_ERROR_OUT_OF_MEMORY);
    assert_eq!(read, FC_OK);
    assert!(after == x, "a refused step changes nothing");
    assert!(message.contains("self-collision"), "{message}");
    // The limit lifted, the same step goes: the layers are pushed apart.
    unsafe {
        assert_eq!(fc_cloth_step(c, 1e-4), FC_OK);
        assert_eq!(
            fc_cloth_get_positions_f64(c, after.as_mut_ptr(), after.len()),
            FC_OK
        );
        fc_cloth_destroy(c);
    }
    assert!(after.iter().all(|v| v.is_finite()) && after != x);
}

/// A 301 x 301 cloth under the least address-space limit (in 50 MB steps) at which it creates
/// without self-collision: with self-collision (about 1.1 kB a particle more, checked up
/// front) it is refused with `FC_ERROR_OUT_OF_MEMORY` and a message naming self-collision. And
/// a description that turns self-collision on for a cloth stepping under a limit 20 MB above
/// its use is refused, the cloth kept.
fn a_cloth_whose_self_collision_does_not_fit_is_refused() {
    let (desc, with) = (grid_desc(301, 301, 0.0), grid_desc(301, 301, 0.4));
    let Some(vm) = vm_size() else { return };
    let mut plain = null_mut();
    for step in 1..=40u64 {
        let old = set_address_space_limit(vm + step * 50 * 1024 * 1024);
        let s = unsafe { fc_cloth_create_grid(&desc, &mut plain) };
        if s != FC_OK {
            unsafe { libc::setrlimit(libc::RLIMIT_AS, &old) };
            assert_eq!(s, FC_ERROR_OUT_OF_MEMORY);
            continue;
        }
        let mut d = null_mut();
        let created = unsafe { fc_cloth_create_grid(&with, &mut d) };
        let created_message = last_error();
        unsafe { libc::setrlimit(libc::RLIMIT_AS, &old) };
        assert_eq!(created, FC_ERROR_OUT_OF_MEMORY, "{created_message}");
        assert!(d.is_null());
        assert!(created_message.contains("self-collision"), "{created_message}");
        break;
    }
    assert!(!plain.is_null(), "the plain cloth never fitted");
    unsafe { assert_eq!(fc_cloth_step(plain, 1e-4), FC_OK) };
    let Some(now) = vm_size() else { return };
    let old = set_address_space_limit(now + 20 * 1024 * 1024);
    let turned_on = unsafe { fc_cloth_set_desc(plain, &with) };
    let turned_on_message = last_error();
    let stepped = unsafe { fc_cloth_step(plain, 1e-4) };
    unsafe { libc::setrlimit(libc::RLIMIT_AS, &old) };
    assert_eq!(turned_on, FC_ERROR_OUT_OF_MEMORY, "{turned_on_message}");
    assert!(
        turned_on_message.contains("self-collision"),
        "{turned_on_message}"
    );
    assert_eq!(stepped, FC_OK, "the cloth is kept");
    // With room, it turns on.
    unsafe {
        assert_eq!(fc_cloth_set_desc(plain, &with), FC_OK);
        assert_eq!(fc_cloth_step(plain, 1e-4), FC_OK);
        fc_cloth_destroy(plain);
    }
}
