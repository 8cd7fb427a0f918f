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

fn readelf(args: &[&str], file: &Path) -> String {
    ok(Command::new("readelf").args(args).arg(file), "readelf")
}

/// Global symbols an object or archive defines (readelf: nm's LTO plugin chokes on rustc's bitcode).
fn global_defined(file: &Path) -> Vec<String> {
    readelf(&["-sW"], file)
        .lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f.len() >= 8 && matches!(f[4], "GLOBAL" | "WEAK") && f[6] != "UND").then(|| f[7].to_string())
        })
        .collect()
}

fn install(prefix: &Path, destdir: Option<&Path>) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cmd = Command::new("bash");
    cmd.arg(root.join("scripts/install.sh")).arg(prefix);
    if let Some(d) = destdir {
        cmd.env("DESTDIR", d);
    }
    ok(&mut cmd, "scripts/install.sh")
}

fn libdir(prefix: &Path) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = ok(
        Command::new("bash")
            .arg(root.join("scripts/install.sh"))
            .arg("--print-libdir")
            .arg(prefix),
        "install.sh --print-libdir",
    );
    std::path::PathBuf::from(out.trim())
}

#[test]
fn install_then_build_with_pkg_config_and_cmake() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = scratch_dir("packaging");
    let prefix = dir.join("prefix");
    install(&prefix, None);
    let lib = libdir(&prefix);
    assert!(lib.starts_with(&prefix), "{}", lib.display());
    let (major, version) = (env!("CARGO_PKG_VERSION_MAJOR"), env!("CARGO_PKG_VERSION"));
    let real = lib.join(format!("libfraccloth.so.{version}"));
    for f in [
        real.clone(),
        lib.join(format!("libfraccloth.so.{major}")),
        lib.join("libfraccloth.so"),
        lib.join("libfraccloth.a"),
        prefix.join("include/fraccloth.h"),
        prefix.join("include/fraccloth.hpp"),
        lib.join("pkgconfig/fraccloth.pc"),
        lib.join("cmake/fraccloth/fraccloth-config.cmake"),
        lib.join("cmake/fraccloth/fraccloth-config-version.cmake"),
    ] {
        assert!(f.exists(), "{} not installed", f.display());
    }
    // The shared library: versioned links, SONAME, executable mode, no debug information.
    use std::os::unix::fs::PermissionsExt;
    let mode = std::fs::metadata(&real).expect("metadata").permissions().mode() & 0o777;
    assert_eq!(mode, 0o755, "shared library mode {mode:o}");
    assert_eq!(
        std::fs::read_link(lib.join("libfraccloth.so")).expect("link"),
        Path::new(&format!("libfraccloth.so.{major}"))
    );
    assert!(
        readelf(&["-d"], &real).contains(&format!("[libfraccloth.so.{major}]")),
        "SONAME"
    );
    assert!(
        !readelf(&["-SW"], &real).contains(".debug_info"),
        "installed shared library not stripped"
    );
    // The static library exports the fc_* calls and nothing else.
    let globals = global_defined(&lib.join("libfraccloth.a"));
    let strays: Vec<_> = globals.iter().filter(|s| !s.starts_with("fc_")).collect();
    assert!(
        strays.is_empty(),
        "static library exports non-fc symbols: {strays:?}"
    );
    let exported = global_defined(&real)
        .into_iter()
        .filter(|s| s.starts_with("fc_"))
        .count();
    assert_eq!(
        globals.len(),
        exported,
        "the static library has every fc_ call of the shared one"
    );
    // pkg-config: no rpath in what every consumer gets.
    let pc = std::fs::read_to_string(lib.join("pkgconfig/fraccloth.pc")).expect("pc");
    assert!(!pc.contains("rpath"), "{pc}");

    // Plain cc with pkg-config, shared and static.
    let pc_path = lib.join("pkgconfig");
    let pkg = |args: &[&str]| {
        ok(
            Command::new("pkg-config")
                .args(args)
                .env("PKG_CONFIG_PATH", &pc_path),
            "pkg-config",
        )
    };
    let flags = pkg(&["--cflags", "--libs", "fraccloth"]);
    let exe = dir.join("hello_pkgconfig");
    ok(
        Command::new("cc")
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror"])
            .arg(root.join("examples_c/hello.c"))
            .arg("-o")
            .arg(&exe)
            .args(flags.split_whitespace())
            .arg(format!("-Wl,-rpath,{}", lib.display()))
            .arg("-lm"),
        "cc with pkg-config flags",
    );
    let by_cc = corner(&run(&exe, &[]));
    let private = pkg(&["--libs-only-l", "--static", "fraccloth"]);
    let exe_static = dir.join("hello_static");
    ok(
        Command::new("cc")
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror"])
            .arg(root.join("examples_c/hello.c"))
            .arg("-o")
            .arg(&exe_static)
            .args(pkg(&["--cflags", "fraccloth"]).split_whitespace())
            .arg(lib.join("libfraccloth.a"))
            .args(private.split_whitespace().filter(|f| *f != "-lfraccloth")),
        "cc with the static library",
    );
    assert!(
        !readelf(&["-d"], &exe_static).contains("libfraccloth"),
        "static program needs no libfraccloth"
    );
    assert_eq!(corner(&run(&exe_static, &[])), by_cc);

    // CMake, shared and static targets.
    if Command::new("cmake").arg("--version").output().is_err() {
        assert!(
            std::env::var_os("FC_REQUIRE_CMAKE").is_none(),
            "FC_REQUIRE_CMAKE is set but cmake is not installed"
        );
        eprintln!("cmake not installed: skipping the CMake build (CI requires it)");
    } else {
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
        assert_eq!(corner(&run(&build.join("hello_static"), &[])), by_cc);
        let out = run(&build.join("swing_cpp"), &[dir.join("s.pc2").to_str().unwrap()]);
        assert!(out.contains("moved 2501 0"), "{out}");
    }

    // Uninstall removes everything the install wrote.
    ok(
        Command::new("bash")
            .arg(root.join("scripts/install.sh"))
            .arg("--uninstall")
            .arg(&prefix),
        "uninstall",
    );
    let left: Vec<_> = walk(&prefix);
    assert!(left.is_empty(), "left after uninstall: {left:?}");
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = vec![];
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            out.push(e.path());
            out.extend(walk(&e.path()));
        }
    }
    out
}

/// A packager's staged install for PREFIX=/usr: files under DESTDIR, in the GNUInstallDirs
/// library directory, with /usr (not the staging directory) inside the pkg-config file.
#[test]
fn staged_install_for_usr() {
    let dir = scratch_dir("packaging-destdir");
    install(Path::new("/usr"), Some(&dir));
    let lib = libdir(Path::new("/usr"));
    let staged = dir.join(lib.strip_prefix("/").expect("absolute"));
    assert!(staged.join("libfraccloth.a").exists(), "{}", staged.display());
    if Path::new("/etc/debian_version").exists() {
        assert!(
            lib.starts_with("/usr/lib/") && lib != Path::new("/usr/lib"),
            "Debian multiarch libdir expected, got {}",
            lib.display()
        );
    }
    let pc = std::fs::read_to_string(staged.join("pkgconfig/fraccloth.pc")).expect("pc");
    assert!(pc.starts_with("prefix=/usr\n"), "{pc}");
    assert!(
        !pc.contains(dir.to_str().unwrap()),
        "the staging directory leaked into the .pc"
    );
}

/// The README's "Building a C program" lines, run as written from the repository's root.
#[test]
fn readme_c_build_lines_run() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README");
    let block = readme
        .split("<!-- c-build: begin -->")
        .nth(1)
        .and_then(|s| s.split("<!-- c-build: end -->").next())
        .expect("c-build markers in the README");
    let script = block
        .trim()
        .strip_prefix("```sh")
        .and_then(|s| s.strip_suffix("```"))
        .expect("a sh code block between the markers");
    let out = ok(
        Command::new("bash")
            .args(["-euo", "pipefail", "-c", script])
            .current_dir(root)
            .env_remove("PKG_CONFIG_PATH"),
        "the README's build lines",
    );
    let corners: Vec<_> = out.lines().filter(|l| l.starts_with("corner")).collect();
    assert_eq!(corners.len(), 2, "{out}");
    assert_eq!(corners[0], corners[1], "shared and static programs agree");
}
