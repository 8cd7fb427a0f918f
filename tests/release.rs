//! Release hygiene: one version everywhere, the license texts present, and every code name the
//! README's equation-to-code table cites present in the file it names.

use std::path::Path;

fn read(p: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(p))
        .unwrap_or_else(|e| panic!("{p}: {e}"))
}

#[test]
fn the_version_is_defined_once_and_every_package_carries_it() {
    let v = env!("CARGO_PKG_VERSION");
    for package in ["cli/Cargo.toml", "tools/Cargo.toml"] {
        assert!(
            read(package).contains(&format!("version = \"{v}\"")),
            "{package} is not at {v}"
        );
    }
    let py = read("bindings/python/pyproject.toml");
    assert!(
        py.contains(&format!("version = \"{v}\"")),
        "bindings/python/pyproject.toml is not at {v}"
    );
    let parts: Vec<&str> = v.split('.').collect();
    let tuple = format!("\"version\": ({}, {}, {}),", parts[0], parts[1], parts[2]);
    assert!(
        read("bindings/blender/fraccloth_blender/__init__.py").contains(&tuple),
        "the add-on's bl_info is not at {v}"
    );
    // The CMake example asks for this major.minor (the package accepts the same major.minor).
    let cmake = read("examples_c/CMakeLists.txt");
    let wanted = format!("find_package(fraccloth {}.{} REQUIRED)", parts[0], parts[1]);
    assert!(
        cmake.contains(&wanted),
        "examples_c/CMakeLists.txt does not ask for {}.{}",
        parts[0],
        parts[1]
    );
    // The header's FC_VERSION and fc_version() come from the crate version (tests/header.rs).
    let number: u32 = parts[0].parse::<u32>().unwrap() * 1_000_000
        + parts[1].parse::<u32>().unwrap() * 1_000
        + parts[2].parse::<u32>().unwrap();
    assert_eq!(fraccloth::ffi::fc_version(), number);
    let header = read("include/fraccloth.h");
    for (name, value) in ["MAJOR", "MINOR", "PATCH"].iter().zip(&parts) {
        assert!(
            header.contains(&format!("#define FC_VERSION_{name} {value}")),
            "header FC_VERSION_{name}"
        );
    }
    // The changelog's latest entry is this version.
    let changelog = read("CHANGELOG.md");
    let first = changelog.lines().find(|l| l.starts_with("## [")).unwrap_or("");
    assert!(
        first.starts_with(&format!("## [{v}]")),
        "CHANGELOG.md's latest entry is {first:?}, not {v}"
    );
}

#[test]
fn the_license_texts_are_there_and_named_the_same_everywhere() {
    assert!(read("LICENSE-MIT").contains("Permission is hereby granted, free of charge"));
    assert!(
        read("LICENSE-APACHE").contains("Apache License")
            && read("LICENSE-APACHE").contains("Version 2.0, January 2004")
    );
    let spdx = "MIT OR Apache-2.0";
    for p in [
        "Cargo.toml",
        "cli/Cargo.toml",
        "tools/Cargo.toml",
        "bindings/python/pyproject.toml",
        "bindings/blender/fraccloth_blender/__init__.py",
    ] {
        assert!(read(p).contains(spdx), "{p} does not name {spdx}");
    }
}

#[test]
fn every_name_in_the_readme_equation_table_exists() {
    let readme = read("README.md");
    let start = readme
        .find("## The paper's equations in the code")
        .expect("the table's section");
    let section = &readme[start..];
    let end = section[3..].find("\n## ").map_or(section.len(), |e| e + 3);
    let mut checked = 0;
    for row in section[..end].lines().filter(|l| l.starts_with('|')) {
        // Each cell: `path` (`name`), ...
        let code = row.rsplit('|').nth(1).unwrap_or("");
        let mut file: Option<String> = None;
        for piece in code
            .split('`')
            .enumerate()
            .filter(|(k, _)| k % 2 == 1)
            .map(|(_, p)| p)
        {
            if piece.contains('/') && piece.ends_with(".rs") {
                assert!(
                    Path::new(env!("CARGO_MANIFEST_DIR")).join(piece).exists(),
                    "README cites {piece}, which does not exist"
                );
                file = Some(piece.to_string());
                checked += 1;
            } else if piece.ends_with(".rs") {
                // A file beside the last one named: `full.rs`.
                let dir = file
                    .as_deref()
                    .and_then(|f| f.rsplit_once('/'))
                    .map(|(d, _)| d.to_string())
                    .unwrap_or_default();
                let path = format!("{dir}/{piece}");
                assert!(
                    Path::new(env!("CARGO_MANIFEST_DIR")).join(&path).exists(),
                    "README cites {path}, which does not exist"
                );
                checked += 1;
            } else if let Some(f) = &file {
                let text = read(f);
                assert!(
                    text.contains(&format!("fn {piece}("))
                        || text.contains(&format!("fn {piece}<"))
                        || text.contains(&format!("fn {piece} ")),
                    "README cites `{piece}` in {f}, which has no such function"
                );
                checked += 1;
            }
        }
    }
    assert!(
        checked >= 10,
        "only {checked} names checked: the table's format changed?"
    );
}
