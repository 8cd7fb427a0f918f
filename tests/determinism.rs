//! Determinism, as Box2D's determinism test does it: every built-in scene is run and the bits
//! of its final positions and velocities are hashed; the hashes are committed in
//! `tests/determinism_hashes.txt` and must not change unless on purpose
//! (`FC_BLESS_HASHES=1 cargo test --test determinism` rewrites the file). Each scene runs in
//! rayon pools of 1, 2 and 8 threads, and every run must give the committed hash. A large cloth
//! (above `parallel::MIN_PARALLEL`, so its passes really are split among threads) is included.
//! Also: 8 handles stepped at once on 8 threads, each equal to the same cloth stepped alone.

use std::collections::BTreeMap;
use std::path::Path;

use fraccloth::history::Scheme;
use fraccloth::topology::grid_index;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model, RegularDrag, Vec3};
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};

fn fnv(cloth: &Cloth) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in cloth.positions().iter().chain(cloth.velocities()) {
        for c in p.iter() {
            for b in c.to_bits().to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    h
}

/// (name, runner) for every case.
fn cases() -> Vec<(String, Box<dyn Fn() -> Cloth + Sync>)> {
    let mut v: Vec<(String, Box<dyn Fn() -> Cloth + Sync>)> = vec![];
    for kind in SceneKind::ALL {
        for variant in [Variant::Fractional, Variant::Regular(RegularDrag::Normal)] {
            for (label, scheme, integrator) in [
                ("default", Scheme::DEFAULT, Integrator::ExplicitEuler),
                ("paper", Scheme::PAPER, Integrator::ExplicitEuler),
                ("implicit", Scheme::DEFAULT, Integrator::ImplicitEuler),
            ] {
                if label != "default" && variant != Variant::Fractional {
                    continue;
                }
                let spec = SceneSpec {
                    scheme,
                    integrator,
                    dt: if integrator == Integrator::ImplicitEuler {
                        1.0 / 60.0
                    } else {
                        5e-4
                    },
                    ..SceneSpec::paper(kind, variant)
                };
                let name = format!("{}-{}-{label}", kind.name(), variant.name());
                v.push((
                    name,
                    Box::new(move || {
                        let mut s = spec.build().unwrap();
                        s.run_until(0.5).unwrap();
                        s.cloth
                    }),
                ));
            }
        }
    }
    v.push(("large-131x129-soe-symplectic".into(), Box::new(large)));
    // The underwater preset (normal added mass: the turning forces' grid path on one thread,
    // the pool's chunks on two and eight), at the towel's size and past the pool's threshold.
    v.push((
        "swing-underwater-61x41-auto".into(),
        Box::new(|| {
            let spec = SceneSpec::underwater_swing(61, 41, 1.0, 0.04, Model::underwater());
            let mut s = spec.build().unwrap();
            s.run_until(0.5).unwrap();
            s.cloth
        }),
    ));
    v.push((
        "large-131x129-underwater-symplectic".into(),
        Box::new(large_underwater),
    ));
    // XPBD (its constraints projected on one thread in a fixed order; the force pass split).
    v.push((
        "swing-underwater-61x41-xpbd-auto".into(),
        Box::new(|| {
            let spec = SceneSpec {
                integrator: Integrator::Xpbd,
                ..SceneSpec::underwater_swing(61, 41, 1.0, 0.04, Model::underwater())
            };
            let mut s = spec.build().unwrap();
            s.run_until(0.5).unwrap();
            s.cloth
        }),
    ));
    v.push((
        "large-131x129-underwater-xpbd".into(),
        Box::new(|| large_stepped(Model::underwater(), Integrator::Xpbd)),
    ));
    v
}

fn large() -> Cloth {
    large_stepped(Variant::Fractional.model(0.01), Integrator::SymplecticEuler)
}

fn large_underwater() -> Cloth {
    large_stepped(Model::underwater(), Integrator::SymplecticEuler)
}

/// A 131 x 129 cloth of `model` hanging from its top row in a current, 30 steps of
/// `integrator`.
fn large_stepped(mut model: Model, integrator: Integrator) -> Cloth {
    let (w, h) = (131u32, 129u32);
    let t = GridSpec {
        width: w,
        height: h,
        spacing: 0.01,
        total_mass: 0.24 / 2501.0 * f64::from(w * h),
    }
    .build()
    .unwrap();
    model.current = Vec3::new(0.05, 0.0, 0.2);
    let mut c = Cloth::new(
        t,
        ClothConfig {
            model,
            integrator,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    let top: Vec<u32> = (0..w).map(|i| grid_index(w, i, 0)).collect();
    c.set_pinned(&top).unwrap();
    for _ in 0..30 {
        c.step(5e-4).unwrap();
    }
    c
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn committed_hashes_for_every_scene_and_thread_count() {
    const { assert!(131 * 129 >= fraccloth::MIN_PARALLEL) };
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/determinism_hashes.txt");
    let mut got = BTreeMap::new();
    for (name, run) in cases() {
        let hashes: Vec<u64> = [1, 2, 8].iter().map(|&t| in_pool(t, || fnv(&run()))).collect();
        assert!(
            hashes.iter().all(|&h| h == hashes[0]),
            "{name}: hashes differ across 1, 2, 8 threads: {hashes:x?}"
        );
        got.insert(name, hashes[0]);
    }
    let text: String = got.iter().map(|(k, h)| format!("{k} {h:016x}\n")).collect();
    if std::env::var_os("FC_BLESS_HASHES").is_some() {
        std::fs::write(&file, &text).unwrap();
        return;
    }
    let want =
        std::fs::read_to_string(&file).expect("tests/determinism_hashes.txt (bless with FC_BLESS_HASHES=1)");
    let want: BTreeMap<String, String> = want
        .lines()
        .filter_map(|l| l.split_once(' '))
        .map(|(k, h)| (k.to_string(), h.to_string()))
        .collect();
    for (name, h) in &got {
        assert_eq!(
            want.get(name).map(String::as_str),
            Some(format!("{h:016x}").as_str()),
            "{name}: the result changed (if on purpose: FC_BLESS_HASHES=1 cargo test --test determinism)"
        );
    }
    assert_eq!(want.len(), got.len(), "cases added or removed");
}

#[test]
fn eight_handles_on_eight_threads_match_single_threaded_runs() {
    let all = cases();
    let chosen: Vec<_> = all
        .iter()
        .filter(|(n, _)| !n.starts_with("large"))
        .take(8)
        .collect();
    assert_eq!(chosen.len(), 8);
    let alone: Vec<u64> = chosen.iter().map(|(_, run)| fnv(&run())).collect();
    let together: Vec<u64> = std::thread::scope(|s| {
        let handles: Vec<_> = chosen.iter().map(|(_, run)| s.spawn(|| fnv(&run()))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(alone, together);
    // Different scenes really differ (so equality above is not trivial).
    let mut distinct = alone.clone();
    distinct.sort();
    distinct.dedup();
    assert_eq!(distinct.len(), 8);
}
