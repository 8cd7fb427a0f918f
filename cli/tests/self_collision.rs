//! `--self-collision SPACINGS` reaches the cloth: the brisk swing's crumple (31 x 21 at 2 cm,
//! 2 Hz, 8 cm, 4 s) crosses itself without it and, at 0.3 spacings (6 mm, the thickness
//! `tests/collisions.rs` bakes it with), at no frame of the cache with it; a negative value
//! is refused with the reason.

use fraccloth::collide::intersections::self_intersections;
use fraccloth_tools::read::{read_cache, read_obj};

/// Bakes the crumple with `extra` arguments; the most crossing triangle pairs at any cached
/// frame, or the baker's error.
fn worst_crossings(name: &str, extra: &[&str]) -> Result<usize, String> {
    let out = std::env::temp_dir().join(format!("fc-self-collision-{name}-{}", std::process::id()));
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fraccloth"))
        .args(["--no-preview", "--quiet", "--size", "31x21", "--frequency", "2"])
        .args(["--amplitude", "0.08", "--seconds", "4", "--out"])
        .arg(&out)
        .args(extra)
        .output()
        .expect("the baker runs");
    if !run.status.success() {
        return Err(String::from_utf8_lossy(&run.stderr).into_owned());
    }
    let rest = read_obj(&out.join("swing-underwater.obj")).expect("rest mesh");
    let cache = read_cache(&out.join("swing-underwater.pc2")).expect("cache");
    assert_eq!(cache.frames.len(), 121);
    let worst = cache
        .frames
        .iter()
        .map(|x| self_intersections(x, &rest.triangles))
        .max()
        .unwrap_or(0);
    std::fs::remove_dir_all(&out).unwrap();
    Ok(worst)
}

#[test]
fn the_bakers_self_collision_keeps_the_crumple_from_crossing_itself() {
    let without = worst_crossings("off", &[]).unwrap();
    let with = worst_crossings("on", &["--self-collision", "0.3"]).unwrap();
    println!("crossing pairs at worst: {without} without, {with} with --self-collision 0.3");
    assert!(without > 0, "the crumple crosses itself without self-collision");
    assert_eq!(with, 0, "no triangle pair crosses at any cached frame");
    let e = worst_crossings("bad", &["--self-collision=-1"]).unwrap_err();
    assert!(e.contains("--self-collision"), "{e}");
}
