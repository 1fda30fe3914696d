//! Facts of the food-acquisition data set the paper simulates with
//! (Feng et al. 2019), from `shared/reference/kinova-gen3-and-fork-facts.md`.

/// Seconds the food must stay on the fork after leaving the plate for an
/// attempt to count as a success.
pub const HOLD_SECONDS: f64 = 5.0;
/// Trials per (food, action, setting) behind each published rate: 30 per
/// (food, action) over three placements.
pub const TRIALS_PER_SETTING: usize = 10;
