//! A bake the baker stops on a refused step says so, exits non-zero, and leaves caches whose
//! headers count exactly the frames they hold.

use fraccloth_tools::read::read_cache;

#[test]
fn a_refused_bake_leaves_honest_caches() {
    let out = std::env::temp_dir().join(format!("fc-refused-bake-{}", std::process::id()));
    // Symplectic Euler at 30 ms on the underwater towel: far past its bound, refused within
    // the first frames of a 12 s bake that announced 361.
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fraccloth"))
        .args(["--no-preview", "--quiet", "--dt", "0.03", "--out"])
        .arg(&out)
        .output()
        .expect("the baker runs");
    assert!(!run.status.success(), "the bake was not refused");
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("unstable"), "{err}");
    for name in ["swing-underwater.pc2", "swing-underwater.mdd"] {
        let path = out.join(name);
        let bytes = std::fs::metadata(&path).expect("the cache is there").len();
        let back = read_cache(&path).expect("the cache reads back");
        let frames = back.frames.len() as u64;
        assert!(frames < 361, "{name}: {frames} frames");
        let header = if name.ends_with("pc2") { 32 } else { 8 + 4 * frames };
        assert_eq!(
            bytes,
            header + frames * 2501 * 12,
            "{name}: the header counts {frames} frames"
        );
    }
    std::fs::remove_dir_all(&out).unwrap();
}
