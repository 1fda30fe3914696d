//! Signals for the unit tests: repeatable noise and a pure tone.

/// `n` samples of uniform noise in ±`amp` (xorshift from `seed`).
pub fn noise(n: usize, amp: f32, seed: u32) -> Vec<f32> {
    let mut x = seed.max(1);
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            amp * ((x as f32 / u32::MAX as f32) * 2.0 - 1.0)
        })
        .collect()
}

/// `n` samples of a sine of amplitude `amp`, `step` radians per sample.
pub fn tone(n: usize, amp: f32, step: f32) -> Vec<f32> {
    (0..n).map(|i| amp * (i as f32 * step).sin()).collect()
}
