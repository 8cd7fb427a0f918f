//! Helpers for the unit tests.

/// Deterministic pseudo-random numbers in [-0.5, 0.5) (a 64-bit linear congruential generator),
/// the same sequence on every machine for a given seed.
pub(crate) fn numbers(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// A `width x height` grid of 0.1 m spacing (0.2 kg) with every vertex moved up to 1.5 cm
/// (seeded by `seed`) and random velocities: a crumpled, moving patch.
pub(crate) fn crumpled_grid(
    width: u32,
    height: u32,
    seed: u64,
) -> (crate::Topology, Vec<crate::Vec3>, Vec<crate::Vec3>) {
    use crate::Vec3;
    let t = crate::GridSpec {
        width,
        height,
        spacing: 0.1,
        total_mass: 0.2,
    }
    .build()
    .expect("a valid grid");
    let mut r = numbers(seed);
    let x = t
        .rest_positions
        .iter()
        .map(|p| p + 0.03 * Vec3::new(r(), r(), r()))
        .collect();
    let v = (0..t.vertex_count()).map(|_| Vec3::new(r(), r(), r())).collect();
    (t, x, v)
}
