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
