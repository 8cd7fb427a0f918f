//! The committed header must be exactly what cbindgen generates from the sources now.
//! Regenerate deliberately with `FC_BLESS_HEADER=1 cargo test --test header`.

use std::path::Path;

fn generate() -> String {
    let root = env!("CARGO_MANIFEST_DIR");
    let mut config =
        cbindgen::Config::from_file(Path::new(root).join("cbindgen.toml")).expect("cbindgen.toml parses");
    let (major, minor, patch) = (
        env!("CARGO_PKG_VERSION_MAJOR"),
        env!("CARGO_PKG_VERSION_MINOR"),
        env!("CARGO_PKG_VERSION_PATCH"),
    );
    config.after_includes = Some(format!(
        "\n#define FC_VERSION_MAJOR {major}\n#define FC_VERSION_MINOR {minor}\n#define FC_VERSION_PATCH {patch}\n\
         /* Equals fc_version() of the library this header belongs to. */\n\
         #define FC_VERSION (FC_VERSION_MAJOR * 1000000 + FC_VERSION_MINOR * 1000 + FC_VERSION_PATCH)\n"
    ));
    // cbindgen writes its trailer after the include guard; the inline functions belong inside.
    let trailer = config.trailer.take().unwrap_or_default();
    let bindings = cbindgen::Builder::new()
        .with_crate(root)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut out = Vec::new();
    bindings.write(&mut out);
    let header = String::from_utf8(out).expect("header is UTF-8");
    let guard_end = "#endif  /* FRACCLOTH_H */";
    assert!(header.contains(guard_end), "cbindgen's include guard changed");
    header.replacen(guard_end, &format!("{}\n{guard_end}", trailer.trim_end()), 1)
}

#[test]
fn committed_header_matches_cbindgen() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/fraccloth.h");
    let fresh = generate();
    if std::env::var_os("FC_BLESS_HEADER").is_some() {
        std::fs::write(&path, &fresh).expect("write header");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/fraccloth.h differs from what cbindgen generates now; \
         regenerate with FC_BLESS_HEADER=1 cargo test --test header and commit it"
    );
}

/// The header's words on `FC_PRESET_UNDERWATER` name the preset's coefficients as the model
/// has them (they once still said 10 kg/m^2 after the preset changed to 8).
#[test]
fn the_header_names_the_underwater_presets_coefficients() {
    let header = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("include/fraccloth.h"))
        .expect("read header");
    let end = header.find("FC_PRESET_UNDERWATER =").expect("the preset");
    let start = header[..end].rfind("/**").expect("its comment");
    let text = header[start..end].replace("\n   *", "");
    let w = fraccloth::Model::underwater().water;
    for said in [
        format!("normal added mass ({} kg/m^2", w.added_mass),
        format!("form drag (C_d = {})", w.form_drag),
        format!("smoothed over {} m", w.form_drag_scale),
        format!("skin drag ({} N s/m^3", w.skin_drag),
        format!(
            "plus {} on the unsteady part over a {} s mean",
            w.skin_drag_unsteady, w.skin_drag_memory
        ),
    ] {
        assert!(text.contains(&said), "the header should say {said:?}: {text}");
    }
}
