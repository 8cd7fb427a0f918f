//! `FRACCLOTH_SIMD` caps the vector width for measurement; every width bakes the same bits.

#[test]
fn every_vector_width_bakes_the_same_bits() {
    let bake = |width: Option<&str>| {
        let out = std::env::temp_dir().join(format!(
            "fc-simd-{}-{}",
            width.unwrap_or("widest"),
            std::process::id()
        ));
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_fraccloth"));
        cmd.args([
            "--no-preview",
            "--quiet",
            "--size",
            "21x15",
            "--seconds",
            "1",
            "--out",
        ])
        .arg(&out);
        match width {
            Some(w) => cmd.env("FRACCLOTH_SIMD", w),
            None => cmd.env_remove("FRACCLOTH_SIMD"),
        };
        let run = cmd.output().expect("the baker runs");
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let bytes = std::fs::read(out.join("swing-underwater.pc2")).unwrap();
        std::fs::remove_dir_all(&out).unwrap();
        bytes
    };
    let widest = bake(None);
    for w in ["avx2", "baseline"] {
        assert!(
            bake(Some(w)) == widest,
            "{w} bakes other bits than the widest width"
        );
    }
}
