//! `fraccloth look` on caches written to disk: MDD (times inside) and PC2 (with --fps), and
//! clear refusals when the frame rate or the rest mesh does not fit. The meter itself is
//! tested on known fields in the library's `tests/look.rs`.

use std::f64::consts::PI;

use fraccloth::{GridSpec, Vec3};

const FPS: f64 = 30.0;
const SECONDS: f64 = 8.0;
const W: f64 = 2.0 * PI * 0.5;

fn travelling(c: f64, decay: Option<f64>) -> impl Fn(f64, f64) -> f64 {
    move |y: f64, t: f64| {
        let env = decay.map_or(1.0, |l| (-y / l).exp());
        0.04 * env * (W * (t - y / c)).sin()
    }
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: got {got}, want {want}"
    );
}

/// `fraccloth look` on caches written to disk: MDD (times inside) and PC2 (with --fps), and
/// clear refusals when the frame rate or the rest mesh does not fit.
#[test]
fn the_look_command_reads_mdd_and_pc2_caches() {
    use fraccloth::export::{write_obj, CacheFormat, CacheWriter};
    use std::process::Command;
    let dir = std::env::temp_dir().join(format!("fc-look-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let grid = GridSpec {
        width: 11,
        height: 41,
        spacing: 0.01,
        total_mass: 0.1,
    }
    .build()
    .unwrap();
    let rest = dir.join("rest.obj");
    write_obj(
        std::fs::File::create(&rest).unwrap(),
        &grid.rest_positions,
        &grid.triangles,
    )
    .unwrap();
    let wave = travelling(0.133, Some(0.2));
    let frames = (SECONDS * FPS) as u32 + 1;
    for (format, name) in [(CacheFormat::Mdd, "c.mdd"), (CacheFormat::Pc2, "c.pc2")] {
        let mut w = CacheWriter::create(
            &dir.join(name),
            format,
            grid.vertex_count(),
            &grid.triangles,
            1.0,
            FPS,
            frames,
        )
        .unwrap();
        for k in 0..frames {
            let t = f64::from(k) / FPS;
            let x: Vec<Vec3> = grid
                .rest_positions
                .iter()
                .map(|p| p + Vec3::new(0.0, 0.0, wave(-p.y, t)))
                .collect();
            w.write_frame(&x).unwrap();
        }
        w.finish().unwrap();
    }
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_fraccloth"))
            .arg("look")
            .args(args)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr),
        )
    };
    let rest_s = rest.to_str().unwrap();
    for (cache, extra) in [("c.mdd", vec![]), ("c.pc2", vec!["--fps", "30"])] {
        let path = dir.join(cache);
        let mut args = vec![path.to_str().unwrap(), "--rest", rest_s, "--json"];
        args.extend(extra);
        let (ok, text) = run(&args);
        assert!(ok, "{text}");
        let speed: f64 = text
            .split("\"travel_speed\": ")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .and_then(|s| s.trim().parse().ok())
            .unwrap_or_else(|| panic!("no travel speed in {text}"));
        close(speed, 0.133, 0.05, cache);
    }
    let pc2 = dir.join("c.pc2");
    let (ok, text) = run(&[pc2.to_str().unwrap(), "--rest", rest_s]);
    assert!(!ok && text.contains("give --fps"), "{text}");
    let other = dir.join("other.obj");
    write_obj(
        std::fs::File::create(&other).unwrap(),
        &grid.rest_positions[..10],
        &[[0, 1, 2]],
    )
    .unwrap();
    let mdd = dir.join("c.mdd");
    let (ok, text) = run(&[mdd.to_str().unwrap(), "--rest", other.to_str().unwrap()]);
    assert!(!ok && text.contains("451 vertices"), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}
