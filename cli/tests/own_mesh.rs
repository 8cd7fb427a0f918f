//! `fraccloth --mesh model.obj`: a studio's own mesh baked with the underwater preset, pinned
//! by an OBJ group, a list of vertices or the top rows; the caches keep the OBJ's vertex order.

use fraccloth::Vec3;
use fraccloth_tools::read::read_cache;

/// A 13 x 9 quad mesh of 3 cm spacing hanging in the x-y plane, its top row of faces in the
/// group `hem`, written with its rows bottom-up (so the order is not the built-in grid's).
fn write_obj(dir: &std::path::Path) -> (std::path::PathBuf, Vec<Vec3>) {
    let (w, h) = (13usize, 9usize);
    let mut x = Vec::new();
    for j in (0..h).rev() {
        for i in 0..w {
            x.push(Vec3::new(0.03 * i as f64, -0.03 * j as f64, 0.0));
        }
    }
    let id = |i: usize, j: usize| (h - 1 - j) * w + i + 1; // 1-based, row j from the top
    let mut text = String::from("o towel\n");
    for p in &x {
        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for j in 0..h - 1 {
        text += if j == 0 { "g hem\n" } else { "g body\n" };
        for i in 0..w - 1 {
            text += &format!(
                "f {} {} {} {}\n",
                id(i, j),
                id(i, j + 1),
                id(i + 1, j + 1),
                id(i + 1, j)
            );
        }
    }
    let path = dir.join("towel.obj");
    std::fs::write(&path, text).unwrap();
    (path, x)
}

fn bake(dir: &std::path::Path, extra: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_fraccloth"))
        .args(["--no-preview", "--quiet", "--seconds", "4", "--out"])
        .arg(dir)
        .args(extra)
        .output()
        .expect("the baker runs")
}

#[test]
fn a_mesh_of_your_own_bakes_pinned_by_its_group_in_its_own_vertex_order() {
    let dir = std::env::temp_dir().join(format!("fc-own-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (obj, rest) = write_obj(&dir);
    let run = bake(
        &dir,
        &[
            "--mesh",
            obj.to_str().unwrap(),
            "--pin-group",
            "hem",
            "--amplitude",
            "0.05",
        ],
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let summary = String::from_utf8_lossy(&run.stdout);
    assert!(summary.contains("towel.obj (26 pinned)"), "{summary}");
    let cache = read_cache(&dir.join("towel-underwater.pc2")).unwrap();
    assert_eq!(cache.frames.len(), 121);
    // Frame 0 is the OBJ as written, in its order.
    for (a, b) in cache.frames[0].iter().zip(&rest) {
        assert!((a - b).norm() < 1e-6);
    }
    // The hem (the two top rows: the faces of `hem`) follows the drive along z; the bottom
    // row hangs below its rest height and lags behind.
    let last = cache.frames.last().unwrap();
    let top = (8 * 13..9 * 13).map(|k| last[k]);
    let z0 = last[8 * 13].z;
    assert!(top
        .clone()
        .all(|p| (p.z - z0).abs() < 1e-6 && (p.y - 0.0).abs() < 1e-6));
    let bottom = &last[..13];
    assert!(
        bottom.iter().all(|p| p.y < -0.2),
        "the bottom hangs: {:?}",
        bottom[6]
    );
    let moved = cache.frames.iter().map(|f| f[6].z.abs()).fold(0.0f64, f64::max);
    println!("bottom middle swings up to {moved:.4} m");
    assert!(moved > 0.005, "the bottom moves with the swing: {moved}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pins_from_a_file_or_the_top_and_bad_pins_refused_with_the_reason() {
    let dir = std::env::temp_dir().join(format!("fc-own-mesh-pins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (obj, _) = write_obj(&dir);
    let obj = obj.to_str().unwrap();
    // The top row by default: 13 pinned.
    let run = bake(&dir, &["--mesh", obj]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stdout).contains("(13 pinned)"));
    // A list: two corners.
    let list = dir.join("pins.txt");
    std::fs::write(&list, "104, 116\n").unwrap();
    let run = bake(&dir, &["--mesh", obj, "--pin-file", list.to_str().unwrap()]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stdout).contains("(2 pinned)"));
    // A group that is not there, a vertex that is not there, pins without a mesh.
    let err = |extra: &[&str]| String::from_utf8_lossy(&bake(&dir, extra).stderr).to_string();
    let e = err(&["--mesh", obj, "--pin-group", "hemm"]);
    assert!(
        e.contains("no group named \"hemm\"") && e.contains("hem, body"),
        "{e}"
    );
    std::fs::write(&list, "117").unwrap();
    let e = err(&["--mesh", obj, "--pin-file", list.to_str().unwrap()]);
    assert!(e.contains("vertex 117 does not exist"), "{e}");
    let e = err(&["--pin-top", "2"]);
    assert!(e.contains("go with --mesh"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
