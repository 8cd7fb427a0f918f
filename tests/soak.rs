//! Long run: 1e6 steps of a fractional cloth with the SOE history (500 s of simulated time at
//! 0.5 ms) with a swinging edge and a collider. The state stays finite and bounded, the
//! history's size per particle never changes, and the heap does not grow: live bytes
//! (counted by a global allocator) after the millionth step equal those after the tenth.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicIsize, Ordering};

use fraccloth::forces::Sphere;
use fraccloth::{Cloth, ClothConfig, GridSpec, HalfDerivative, Integrator, Vec3};

struct Live;
static LIVE: AtomicIsize = AtomicIsize::new(0);

unsafe impl GlobalAlloc for Live {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size() as isize, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as isize, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE.fetch_add(new_size as isize - layout.size() as isize, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Live = Live;

#[test]
fn a_million_steps_with_soe_history() {
    let w = 5u32;
    let t = GridSpec {
        width: w,
        height: 4,
        spacing: 0.01,
        total_mass: 0.002,
    }
    .build()
    .unwrap();
    let mut c = Cloth::new(
        t,
        ClothConfig {
            integrator: Integrator::SymplecticEuler,
            ..ClothConfig::default()
        },
    )
    .unwrap();
    let top: Vec<u32> = (0..w).collect();
    c.set_pinned(&top).unwrap();
    let rest: Vec<Vec3> = top.iter().map(|&i| c.positions()[i as usize]).collect();
    c.add_sphere(Sphere {
        center: Vec3::new(0.0, -0.02, 0.02),
        radius: 0.01,
        velocity: Vec3::zeros(),
    })
    .unwrap();
    let mut targets = rest.clone();
    let bytes = c.history().bytes_per_particle();
    let mut live_after_warmup = 0;
    let dt = 5e-4;
    for k in 1..=1_000_000u64 {
        let z = 0.01 * (k as f64 * dt * 2.0).sin();
        for (t, r) in targets.iter_mut().zip(&rest) {
            *t = r + Vec3::new(0.0, 0.0, z);
        }
        c.set_pin_targets(&top, &targets).unwrap();
        c.step(dt).unwrap();
        if k == 10 {
            live_after_warmup = LIVE.load(Ordering::Relaxed);
        }
        if k % 100_000 == 0 {
            assert!(c
                .positions()
                .iter()
                .all(|p| p.iter().all(|x| x.is_finite()) && p.norm() < 1.0));
            assert_eq!(c.history().bytes_per_particle(), bytes);
            assert_eq!(
                LIVE.load(Ordering::Relaxed),
                live_after_warmup,
                "heap grew by step {k}"
            );
        }
    }
    assert_eq!(c.step_count(), 1_000_000);
    assert!((c.time() - 500.0).abs() < 1e-6, "{}", c.time());
    assert_eq!(c.history().mode_count(), 16);
}
