//! The `struct_size` rule: a host built against an older header (here: this header with the
//! fields from `bend_damping_scale` on of `FcClothDesc` removed, all doubles) keeps working with this library, and gets the
//! same cloth as a host built against the current header.

mod common;

use std::path::Path;

fn field_start(header: &str, field: &str) -> usize {
    // The doc comment that opens the field's block, i.e. the "/**" before the declaration.
    let decl = header.find(field).unwrap_or_else(|| panic!("{field} in header"));
    header[..decl].rfind("/**").expect("doc comment before the field")
}

/// The `struct_size` a run of `abi_host` prints.
fn size_of_out(out: &str) -> usize {
    out.lines()
        .find_map(|l| l.strip_prefix("struct_size "))
        .and_then(|s| s.trim().parse().ok())
        .expect("struct_size line")
}

#[test]
fn a_host_built_against_an_older_header_runs_and_agrees() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = std::fs::read_to_string(root.join("include/fraccloth.h")).expect("header");
    // Drop the fields of FcClothDesc from bend_damping_scale on (doubles, every one).
    let start = field_start(&header, "double bend_damping_scale;");
    let end = header.find("} FcClothDesc;").expect("end of FcClothDesc");
    let dropped = header[start..end].matches("\n  double ").count();
    assert!(
        dropped >= 6,
        "bend_damping_scale to bend_reference_spacing: {dropped}"
    );
    let old = format!("{}{}", &header[..start], &header[end..]);
    assert!(!old.contains("added_mass_coefficient;") && old.contains("shear_damping_scale;"));

    let dir = common::scratch_dir("old_host");
    let old_include = dir.join("old-include");
    std::fs::create_dir_all(&old_include).expect("dir");
    std::fs::write(old_include.join("fraccloth.h"), old).expect("write old header");
    let new_dir = dir.join("new");
    let old_dir = dir.join("old");
    std::fs::create_dir_all(&new_dir).expect("dir");
    std::fs::create_dir_all(&old_dir).expect("dir");

    let new_exe = common::compile_c("abi_host.c", &new_dir);
    let inc = format!("-I{}", old_include.display());
    let old_exe = common::compile_c_with("abi_host.c", &[&inc], &old_dir);

    let old_out = common::run(&old_exe, &[]);
    // The new host with the fields the old one lacks at their defaults, as the library gives
    // them to the old host (`abi_host.c`).
    let old_size = size_of_out(&old_out).to_string();
    let new_out = common::run(&new_exe, &[&old_size]);
    let size = size_of_out;
    let checksum = |out: &str| -> String {
        out.lines()
            .find_map(|l| l.strip_prefix("checksum "))
            .expect("checksum line")
            .to_string()
    };
    assert_eq!(size(&new_out), fraccloth::ffi::desc::DESC_SIZE);
    assert_eq!(
        size(&old_out),
        size(&new_out) - 8 * dropped,
        "the old host's struct is {dropped} doubles shorter (bend_damping_scale and after)"
    );
    assert_eq!(
        checksum(&old_out),
        checksum(&new_out),
        "same cloth from the old and the new host"
    );
}
