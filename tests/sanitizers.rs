//! Memory checking of the C ABI from C: every C example and a stress program
//! (`examples_c/stress.c`: every call, good and bad arguments, caches, snapshots, thousands of
//! checks) built with AddressSanitizer + UndefinedBehaviorSanitizer (leak checking on) must run
//! clean; the stress program and every C example must also run clean under valgrind memcheck
//! (zero errors, zero definite/indirect/possible leaks). The library itself is the normal
//! build: ASan checks what it does to the heap through malloc, valgrind checks every access.
//!
//! valgrind is optional on a developer machine (skipped with a note) but required in CI
//! (`FC_REQUIRE_VALGRIND=1`).

mod common;

use std::process::Command;

use common::{compile_c_with, scratch_dir};

const SANITIZE: &[&str] = &[
    "-g",
    "-fsanitize=address,undefined",
    "-fno-sanitize-recover=all",
    "-fno-omit-frame-pointer",
];

fn run_checked(cmd: &mut Command, what: &str) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    assert!(!stderr.contains("ERROR: AddressSanitizer"), "{what}:\n{stderr}");
    assert!(!stderr.contains("runtime error"), "{what} (UBSan):\n{stderr}");
    stdout
}

#[test]
#[ignore = "long: run by `cargo test --release -- --ignored` (CI's long step)"]
fn c_programs_under_address_and_undefined_behavior_sanitizers() {
    let dir = scratch_dir("asan");
    for (source, args) in [
        ("stress.c", vec![dir.to_str().unwrap().to_string()]),
        ("hello.c", vec![]),
        ("bad_input.c", vec![]),
        (
            "swing.c",
            vec![dir.join("s.pc2").to_str().unwrap().to_string(), "0.5".into()],
        ),
    ] {
        let exe = compile_c_with(source, SANITIZE, &dir);
        let out = run_checked(
            Command::new(&exe)
                .args(&args)
                .env("ASAN_OPTIONS", "detect_leaks=1:halt_on_error=1:abort_on_error=0")
                .env("UBSAN_OPTIONS", "halt_on_error=1:print_stacktrace=1"),
            source,
        );
        if source == "stress.c" {
            let checks: u32 = out
                .trim()
                .strip_prefix("stress ok ")
                .unwrap_or_else(|| panic!("{out}"))
                .parse()
                .unwrap();
            assert!(checks > 5000, "{checks}");
        }
    }
}

#[test]
#[ignore = "long: run by `cargo test --release -- --ignored` (CI's long step)"]
fn c_programs_under_valgrind_memcheck() {
    if Command::new("valgrind").arg("--version").output().is_err() {
        assert!(
            std::env::var_os("FC_REQUIRE_VALGRIND").is_none(),
            "FC_REQUIRE_VALGRIND is set but valgrind is not installed"
        );
        eprintln!("valgrind not installed: skipped (CI requires it)");
        return;
    }
    let dir = scratch_dir("valgrind");
    for (source, args) in [
        ("stress.c", vec![dir.to_str().unwrap().to_string(), "1".into()]),
        ("bad_input.c", vec![]),
        ("hello.c", vec![]),
        (
            "swing.c",
            vec![dir.join("s.pc2").to_str().unwrap().to_string(), "0.2".into()],
        ),
    ] {
        let exe = compile_c_with(source, &["-g"], &dir);
        let out = Command::new("valgrind")
            .args([
                "--error-exitcode=3",
                "--leak-check=full",
                "--errors-for-leak-kinds=definite,indirect,possible",
                "--show-leak-kinds=definite,indirect,possible",
            ])
            .arg(&exe)
            .args(&args)
            .output()
            .expect("valgrind runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "{source} under valgrind ({}):\n{stderr}",
            out.status
        );
        assert!(stderr.contains("ERROR SUMMARY: 0 errors"), "{source}:\n{stderr}");
        assert!(
            stderr.contains("no leaks are possible") || stderr.contains("definitely lost: 0 bytes"),
            "{source}:\n{stderr}"
        );
    }
}
