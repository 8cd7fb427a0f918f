//! The C++ wrapper (`bindings/cpp/fraccloth.hpp`): `examples_cpp/swing.cpp` is compiled with
//! `c++ -std=c++17 -Wall -Wextra -Werror`, run, and its numbers checked against the same
//! calls made from Rust through the C ABI; its PC2 is read back.

mod common;

use common::{compile_cpp, run, scratch_dir};
use fraccloth::ffi::FcStatus::FC_OK;
use fraccloth::ffi::*;

fn line<'a>(out: &'a str, key: &str) -> Vec<&'a str> {
    out.lines()
        .find_map(|l| l.strip_prefix(key).map(|r| r.split_whitespace().collect()))
        .unwrap_or_else(|| panic!("no line {key:?} in:\n{out}"))
}

/// The C++ example's calls, made from Rust.
fn same_calls_from_rust() -> (usize, Vec<f32>) {
    let desc = fc_cloth_desc_default();
    let mut c = std::ptr::null_mut();
    unsafe {
        assert_eq!(fc_cloth_create_grid(&desc, &mut c), FC_OK);
        let top: Vec<u32> = (0..desc.width).collect();
        assert_eq!(fc_cloth_set_pinned(c, top.as_ptr(), top.len()), FC_OK);
        let n = fc_cloth_vertex_count(c);
        let mut rest = vec![0f32; 3 * n];
        assert_eq!(fc_cloth_get_positions(c, rest.as_mut_ptr(), rest.len()), FC_OK);
        let mut id = 0;
        let (p, nrm) = ([0.0f32, -0.6, 0.0], [0.0f32, 1.0, 0.0]);
        let zero = [0.0f32; 3];
        assert_eq!(
            fc_cloth_add_plane(c, p.as_ptr(), nrm.as_ptr(), zero.as_ptr(), &mut id),
            FC_OK
        );
        let centre = [0.0f32, -0.3, 0.2];
        assert_eq!(
            fc_cloth_add_sphere(c, centre.as_ptr(), 0.05, zero.as_ptr(), &mut id),
            FC_OK
        );
        assert_eq!(fc_cloth_set_collider_friction(c, id, 0.3), FC_OK);
        let mut targets = vec![0f32; 3 * top.len()];
        let dt = 5e-4;
        for k in 1..=4000 {
            let t = f64::from(k) * dt;
            for (i, &v) in top.iter().enumerate() {
                let v = v as usize;
                targets[3 * i] = rest[3 * v];
                targets[3 * i + 1] = rest[3 * v + 1];
                targets[3 * i + 2] =
                    rest[3 * v + 2] + (0.1 * (2.0 * std::f64::consts::PI * 0.5 * t).sin()) as f32;
            }
            assert_eq!(
                fc_cloth_set_pin_targets(c, top.as_ptr(), targets.as_ptr(), top.len()),
                FC_OK
            );
            assert_eq!(fc_cloth_step(c, dt), FC_OK);
        }
        let mut x = vec![0f32; 3 * n];
        assert_eq!(fc_cloth_get_positions(c, x.as_mut_ptr(), x.len()), FC_OK);
        fc_cloth_destroy(c);
        (n - desc.width as usize, x)
    }
}

#[test]
fn cpp_wrapper_runs_the_swing_like_the_c_abi() {
    let dir = scratch_dir("cpp-swing");
    let exe = compile_cpp("swing.cpp", &dir);
    let pc2 = dir.join("swing.pc2");
    let out = run(&exe, &[pc2.to_str().unwrap()]);
    let (corner, x) = same_calls_from_rust();
    let printed = line(&out, "corner ");
    assert_eq!(printed[0].parse::<usize>().unwrap(), corner);
    for c in 0..3 {
        let v: f32 = printed[1 + c].parse().unwrap();
        assert_eq!(v, x[3 * corner + c], "component {c}");
    }
    // Errors become exceptions with the status and the library's message.
    let err = line(&out, "error ");
    assert_eq!(err[0], "2");
    assert!(out.contains("dt must be finite"), "{out}");
    assert_eq!(line(&out, "capsule "), vec!["0.02", "0.1"]);
    assert_eq!(line(&out, "desc "), vec!["61", "1"]);
    // Index buffer (2 * 60 * 40 triangles) and one normal per vertex.
    assert_eq!(line(&out, "mesh "), vec!["14400", "7503"]);
    // The double-precision state round-trips exactly.
    assert_eq!(line(&out, "exact "), vec!["1"]);
    // A moved-from handle is empty.
    assert_eq!(line(&out, "moved "), vec!["2501", "0"]);
    // The PC2 has 40 frames, the last equal to the final positions.
    let b = std::fs::read(&pc2).unwrap();
    let frames = i32::from_le_bytes(b[28..32].try_into().unwrap()) as usize;
    assert_eq!(frames, 40);
    let n = x.len() / 3;
    let last: Vec<f32> = b[32 + (frames - 1) * n * 12..]
        .chunks(4)
        .map(|q| f32::from_le_bytes(q.try_into().unwrap()))
        .collect();
    assert_eq!(last, x);
}

/// Every call of the C header is reachable from the C++ wrapper, and a program using every
/// member of the wrapper builds with -Wall -Wextra -Wshadow -Wconversion -Werror and runs.
#[test]
fn the_wrapper_covers_the_whole_abi_and_builds_with_strict_warnings() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = std::fs::read_to_string(root.join("include/fraccloth.h")).expect("header");
    let hpp = std::fs::read_to_string(root.join("bindings/cpp/fraccloth.hpp")).expect("hpp");
    // Called by the header's own inline fc_cloth_desc_default / _preset / fc_cloth_get_desc,
    // which the wrapper uses.
    let through_inline = [
        "fc_cloth_desc_init",
        "fc_cloth_desc_preset_sized",
        "fc_cloth_get_desc_sized",
    ];
    let mut calls: Vec<&str> = header
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|w| w.starts_with("fc_") && header.contains(&format!("{w}(")))
        .collect();
    calls.sort_unstable();
    calls.dedup();
    assert!(calls.len() > 50, "{calls:?}");
    let missing: Vec<_> = calls
        .iter()
        .filter(|c| !through_inline.contains(c) && !hpp.contains(&format!("{c}(")))
        .collect();
    assert!(
        missing.is_empty(),
        "C calls the C++ wrapper does not cover: {missing:?}"
    );

    let dir = scratch_dir("cpp_tour");
    let exe = common::compile_cpp_with("abi_tour.cpp", &["-Wshadow", "-Wconversion", "-Wpedantic"], &dir);
    let out = run(&exe, &[dir.to_str().expect("utf-8 path")]);
    assert!(out.contains("tour ok"), "{out}");
    assert_eq!(line(&out, "default width"), ["61"]);
}

/// The engine example: the cloth on a simulation thread, a render thread reading a double
/// buffer, one tick refused on purpose. The renderer never sees a torn or older frame, the
/// refused tick changes nothing (the run equals one without it but for that tick's pins), and
/// the result does not depend on the render thread's timing (two runs agree bit for bit).
#[test]
fn engine_example_survives_a_refused_tick_and_never_shows_a_torn_frame() {
    let dir = scratch_dir("cpp-engine");
    let exe = common::compile_cpp_with("engine.cpp", &["-pthread", "-Wshadow", "-Wconversion"], &dir);
    let first = run(&exe, &["120"]);
    let second = run(&exe, &["120"]);
    assert_eq!(
        line(&first, "ticks "),
        ["120", "refused", "1", "published", "119"],
        "{first}"
    );
    assert!(first.contains("tick 60 refused: status 4"), "{first}");
    let seen = line(&first, "render reads ");
    assert!(
        seen[0].parse::<u64>().unwrap() > 0,
        "the renderer read frames: {first}"
    );
    assert_eq!(&seen[1..], ["torn", "0", "backwards", "0"]);
    assert_eq!(line(&first, "last tick "), ["120"]);
    assert_eq!(line(&first, "corner "), line(&second, "corner "));
    // With XPBD: the same refusal and recovery, and the tick's cost reported (not asserted).
    let xpbd = run(&exe, &["120", "--xpbd"]);
    assert_eq!(
        line(&xpbd, "ticks "),
        ["120", "refused", "1", "published", "119"],
        "{xpbd}"
    );
    assert_eq!(
        &line(&xpbd, "render reads ")[1..],
        ["torn", "0", "backwards", "0"]
    );
    let cost = line(&xpbd, "step_ms ");
    assert!(
        cost[1].parse::<f64>().unwrap() > 0.0 && cost[3].parse::<f64>().unwrap() > 0.0,
        "{xpbd}"
    );
    assert_ne!(
        line(&xpbd, "corner "),
        line(&first, "corner "),
        "XPBD steps its own way"
    );
}
