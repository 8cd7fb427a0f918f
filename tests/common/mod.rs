//! Shared helpers for tests that build C programs against the library.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

pub mod reference;

/// The directory holding `libfraccloth.so` built for this test run.
pub fn lib_dir() -> PathBuf {
    build_lib();
    let exe = std::env::current_exe().expect("current exe");
    // target/<profile>/deps/<test-binary>
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target dir")
        .to_path_buf();
    assert!(
        dir.join("libfraccloth.so").exists() || dir.join("libfraccloth.dylib").exists(),
        "no shared library in {}; cargo builds it with the tests",
        dir.display()
    );
    dir
}

/// A fresh scratch directory under the target dir.
pub fn scratch_dir(name: &str) -> PathBuf {
    let d = lib_dir().join("c-tests").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

/// Compiles one C file from `examples_c/` with `cc -std=c99 -Wall -Wextra -Werror`.
pub fn compile_c(source: &str, out_dir: &Path) -> PathBuf {
    compile("cc", &["-std=c99"], "examples_c", source, out_dir)
}

/// As [`compile_c`], with extra flags (e.g. sanitizers); the executable is `out_dir/stem`.
pub fn compile_c_with(source: &str, flags: &[&str], out_dir: &Path) -> PathBuf {
    let mut all = vec!["-std=c99"];
    all.extend_from_slice(flags);
    compile("cc", &all, "examples_c", source, out_dir)
}

/// Compiles one C++ file from `examples_cpp/` against `bindings/cpp/fraccloth.hpp` with
/// `c++ -std=c++17 -Wall -Wextra -Werror`.
pub fn compile_cpp(source: &str, out_dir: &Path) -> PathBuf {
    compile_cpp_with(source, &[], out_dir)
}

/// As [`compile_cpp`], with extra flags (e.g. more warnings).
pub fn compile_cpp_with(source: &str, flags: &[&str], out_dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let include = format!("-I{}", root.join("bindings").join("cpp").display());
    let mut all = vec!["-std=c++17", include.as_str()];
    all.extend_from_slice(flags);
    compile("c++", &all, "examples_cpp", source, out_dir)
}

fn compile(compiler: &str, flags: &[&str], dir: &str, source: &str, out_dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = lib_dir();
    let stem = Path::new(source)
        .file_stem()
        .expect("stem")
        .to_string_lossy()
        .to_string();
    let exe = out_dir.join(stem);
    let status = Command::new(compiler)
        .args(flags)
        .args(["-Wall", "-Wextra", "-Werror", "-O1"])
        .arg("-I")
        .arg(root.join("include"))
        .arg(root.join(dir).join(source))
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lfraccloth", "-lm"])
        .status()
        .unwrap_or_else(|e| panic!("{compiler} runs: {e}"));
    assert!(status.success(), "{compiler} failed on {source}");
    exe
}

/// Runs a compiled program; returns stdout, asserting a zero exit.
pub fn run(exe: &Path, args: &[&str]) -> String {
    let out = Command::new(exe).args(args).output().expect("program runs");
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{} failed: {}\n{}",
        exe.display(),
        stdout,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Builds the shared library for this test run (cargo test does not build the cdylib).
pub fn build_lib() {
    static BUILT: std::sync::Once = std::sync::Once::new();
    BUILT.call_once(build_lib_now);
}

fn build_lib_now() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // The profile of this test binary (target/<profile>/deps/<binary>): `cargo test --release`
    // must link the C programs against the release library, not a stale one.
    let exe = std::env::current_exe().expect("current exe");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .and_then(Path::file_name)
        .and_then(|d| d.to_str())
        .unwrap_or("debug")
        .to_string();
    let profile = if profile_dir == "debug" {
        "dev".to_string()
    } else {
        profile_dir
    };
    let status = Command::new(cargo)
        .args(["build", "--lib", "--quiet", "--profile", &profile])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .expect("cargo runs");
    assert!(status.success());
    // The library's SONAME is libfraccloth.so.MAJOR (build.rs): a program linked with
    // -lfraccloth asks the loader for that name, which cargo does not create. The install
    // makes the same link (scripts/install.sh).
    let dir = exe.parent().and_then(Path::parent).expect("target dir");
    let link = dir.join(format!("libfraccloth.so.{}", env!("CARGO_PKG_VERSION_MAJOR")));
    if dir.join("libfraccloth.so").exists() && std::fs::symlink_metadata(&link).is_err() {
        std::os::unix::fs::symlink("libfraccloth.so", &link).expect("SONAME link");
    }
}
