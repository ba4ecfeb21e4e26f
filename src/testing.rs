//! Helpers shared by the unit tests.

/// A deterministic stream of numbers in `[0, 1)` from `seed` (a 64-bit linear congruential
/// generator, its top 53 bits), for scattering test boxes and points reproducibly.
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed;
    move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
}
