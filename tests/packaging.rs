//! Packaging for C hosts: `scripts/install.sh PREFIX` installs the library, headers, a
//! pkg-config file and a CMake package; `examples_c/` then builds with plain `cc` through
//! pkg-config and with CMake's `find_package(fraccloth)`, and the programs run.
//!
//! CMake is optional on a developer machine (the CMake half is skipped with a note when
//! `cmake` is missing) but required in CI, which sets `FC_REQUIRE_CMAKE=1`.

mod common;

use std::path::Path;
use std::process::Command;

use common::{run, scratch_dir};

fn ok(cmd: &mut Command, what: &str) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn corner(out: &str) -> String {
    out.lines()
        .find(|l| l.starts_with("corner"))
        .unwrap_or_else(|| panic!("no corner line in {out}"))
        .to_string()
}

#[test]
fn install_then_build_with_pkg_config_and_cmake() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = scratch_dir("packaging");
    let prefix = dir.join("prefix");
    ok(
        Command::new("bash")
            .arg(root.join("scripts/install.sh"))
            .arg(&prefix),
        "scripts/install.sh",
    );
    for f in [
        "lib/libfraccloth.so",
        "lib/libfraccloth.a",
        "include/fraccloth.h",
        "include/fraccloth.hpp",
        "lib/pkgconfig/fraccloth.pc",
        "lib/cmake/fraccloth/fraccloth-config.cmake",
        "lib/cmake/fraccloth/fraccloth-config-version.cmake",
    ] {
        assert!(prefix.join(f).exists(), "{f} not installed");
    }
    // Plain cc with pkg-config.
    let pc_path = prefix.join("lib/pkgconfig");
    let flags = ok(
        Command::new("pkg-config")
            .args(["--cflags", "--libs", "fraccloth"])
            .env("PKG_CONFIG_PATH", &pc_path),
        "pkg-config",
    );
    let exe = dir.join("hello_pkgconfig");
    ok(
        Command::new("cc")
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror"])
            .arg(root.join("examples_c/hello.c"))
            .arg("-o")
            .arg(&exe)
            .args(flags.split_whitespace())
            .arg("-lm"),
        "cc with pkg-config flags",
    );
    let by_cc = corner(&run(&exe, &[]));
    // CMake.
    if Command::new("cmake").arg("--version").output().is_err() {
        assert!(
            std::env::var_os("FC_REQUIRE_CMAKE").is_none(),
            "FC_REQUIRE_CMAKE is set but cmake is not installed"
        );
        eprintln!("cmake not installed: skipping the CMake build (CI requires it)");
        return;
    }
    let build = dir.join("cmake-build");
    ok(
        Command::new("cmake")
            .arg("-S")
            .arg(root.join("examples_c"))
            .arg("-B")
            .arg(&build)
            .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display())),
        "cmake configure",
    );
    ok(Command::new("cmake").arg("--build").arg(&build), "cmake build");
    assert_eq!(corner(&run(&build.join("hello"), &[])), by_cc);
    let out = run(&build.join("swing_cpp"), &[dir.join("s.pc2").to_str().unwrap()]);
    assert!(out.contains("moved 2501 0"), "{out}");
}
