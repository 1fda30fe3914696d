//! The limits every count, size and window in a config is checked against
//! when the config is loaded, defined once so that documentation can quote
//! them and every component crate checks the same numbers.
//!
//! A count outside its limit is refused before anything proportional to it
//! is allocated: an `episodes = 9223372036854775807` or a demo plate's
//! `repeat = 4294967296` is a located config error, not an allocation
//! failure. The limits are far above anything the paper's protocols or a
//! real session use, and low enough that a run at the limit fits in memory.
//!
//! | limit | value | applies to |
//! |---|---|---|
//! | [`EPISODES`] | 100 000 | `episodes` of an experiment, `repetitions` and validation `plates` of a user study |
//! | [`ITEMS_PER_EPISODE`] | 100 000 | `items_per_episode`, `session.max_items`, a demo plate's `foods` × `repeat` |
//! | [`ATTEMPTS_PER_ITEM`] | 1 000 | `session.n_att` |
//! | [`WINDOW`] | 1 000 000 | a workload model's `window` (timesteps) |
//! | [`PARTICIPANTS`] | 10 000 | each participant count of a synthetic study |
//! | [`SURVEYS`] | 1 000 000 | a count of surveys of a synthetic study |
//! | [`SECONDS`] | 86 400 | a simulated time in seconds (a day) |
//! | [`SEEDS`] | 10 000 | seeds one run sweeps: a protocol's environment and policy seeds, `--seeds` of `hil kinova calibrate` and `hil demo kinova` |
//! | [`TIMESTEPS`] | 1 000 000 | the last timestep of a workload rollout and of its query schedule |
//! | [`TRIALS`] | 1 000 000 | trials per food and action of a simulated calibration (`--trials`) |
//! | [`CONTEXT_DIM`] | 8 192 | the context dimension of a linear policy's estimator, a Kinova scene, a conformance check and `hil bench policy --dim` |
//! | [`HISTORY`] | 360 | a Granger workload model's history H (lags of Δt = 10 s), `--history`, a selection's `histories` |
//! | [`ARMS`] | 1 024 | the arms of a linear policy's estimator and of `hil bench policy --arms` |
//!
//! Component crates call [`check_count`] (a count that must be at least 1)
//! or [`check_at_most`] (one that may be 0) from their config's
//! `validate`, which the loader runs, so the error names the file, line and
//! field:
//!
//! ```
//! use hil_config::limits::{self, check_count};
//! use hil_core::HilError;
//! assert!(check_count("repeat", 3usize, limits::ITEMS_PER_EPISODE).is_ok());
//! let err = check_count("repeat", 4_294_967_296u64, limits::ITEMS_PER_EPISODE).unwrap_err();
//! assert!(matches!(err, HilError::InvalidParameter { ref name, .. } if name == "repeat"));
//! assert!(check_count("repeat", 0u32, limits::ITEMS_PER_EPISODE).is_err());
//! ```

use hil_core::{HilError, Result};

/// Most episodes one experiment runs.
pub const EPISODES: u64 = 100_000;

/// Most items one episode presents (`items_per_episode`,
/// `session.max_items`, a demo plate's foods × `repeat`).
pub const ITEMS_PER_EPISODE: u64 = 100_000;

/// Most attempts per item (`session.n_att`, the paper's N_att = 10).
pub const ATTEMPTS_PER_ITEM: u64 = 1_000;

/// Longest window, in timesteps, over which a workload model counts queries.
pub const WINDOW: u64 = 1_000_000;

/// Most participants in each group of a synthetic study.
pub const PARTICIPANTS: u64 = 10_000;

/// Most surveys a synthetic study counts (e.g. its missing surveys).
pub const SURVEYS: u64 = 1_000_000;

/// Longest simulated duration in seconds (one day), e.g. a simulated
/// expert's median response time.
pub const SECONDS: f64 = 86_400.0;

/// Most seeds one run sweeps: a protocol's environment or policy seeds, or
/// the consecutive master seeds of a run over seeds ([`consecutive_seeds`]).
pub const SEEDS: u64 = 10_000;

/// Latest timestep a workload rollout reaches, and so its query schedule
/// (Δt = 10 s: about 116 days).
pub const TIMESTEPS: u64 = 1_000_000;

/// Most trials per food and action of a simulated calibration: at the
/// limit, the three calibrated foods take 18 million attempts (days on a
/// workstation), and the job list still fits in memory.
pub const TRIALS: u64 = 1_000_000;

/// Largest context dimension (the paper's image features have 2048). A
/// linear estimator's arm in its dense form holds a packed d × d factor, so
/// at this limit an arm takes 256 MiB; a 20-digit dimension is an error
/// naming the field, not an allocation that aborts the process.
pub const CONTEXT_DIM: u64 = 8192;

/// Longest history H of a Granger workload model, in lags of Δt = 10 s
/// (one hour; the paper tries 1 to 30). A fit's design has 9·H + 2
/// columns, so a 6-digit H asked for terabytes.
pub const HISTORY: u64 = 360;

/// Most arms (actions a linear estimator keeps a model for; the paper's
/// task has six).
pub const ARMS: u64 = 1024;

/// The `n` consecutive master seeds `first`, `first + 1`, ... of a run over
/// seeds (wrapping past `u64::MAX` to 0), after checking that `n`, the
/// field or flag `name`, is in `1..=`[`SEEDS`]: a typo of 20 digits is an
/// error naming the flag, not an allocation failure.
///
/// ```
/// use hil_config::limits::consecutive_seeds;
/// assert_eq!(consecutive_seeds("--seeds", 9001, 3)?, [9001, 9002, 9003]);
/// assert_eq!(consecutive_seeds("--seeds", u64::MAX, 2)?, [u64::MAX, 0]);
/// assert!(consecutive_seeds("--seeds", 1, 0).is_err());
/// assert!(consecutive_seeds("--seeds", 1, u64::MAX).is_err());
/// # Ok::<(), hil_core::HilError>(())
/// ```
pub fn consecutive_seeds<T>(name: &str, first: u64, n: T) -> Result<Vec<u64>>
where
    T: TryInto<u64> + std::fmt::Display + Copy,
{
    check_count(name, n, SEEDS)?;
    // Checked above: n fits in u64 and is at most SEEDS.
    let n: u64 = n.try_into().unwrap_or(0);
    Ok((0..n).map(|i| first.wrapping_add(i)).collect())
}

/// Checks that the count `value` of the field `name` is in `1..=max`.
///
/// The error is [`HilError::InvalidParameter`] naming `name`; a config
/// loader turns it into a [`super::ConfigError`] naming the file, line and
/// field.
pub fn check_count<T>(name: &str, value: T, max: u64) -> Result<()>
where
    T: TryInto<u64> + std::fmt::Display + Copy,
{
    in_range(name, value, 1, max)
}

/// Checks that the size `value` of the field `name` is in `0..=max`.
pub fn check_at_most<T>(name: &str, value: T, max: u64) -> Result<()>
where
    T: TryInto<u64> + std::fmt::Display + Copy,
{
    in_range(name, value, 0, max)
}

fn in_range<T>(name: &str, value: T, min: u64, max: u64) -> Result<()>
where
    T: TryInto<u64> + std::fmt::Display + Copy,
{
    // A value that does not fit in u64 (a negative number) is out of range.
    match value.try_into() {
        Ok(v) if (min..=max).contains(&v) => Ok(()),
        _ => Err(HilError::invalid_parameter(
            name,
            value,
            format!("must be between {min} and {max}"),
        )),
    }
}

/// Checks that the real `value` of the field `name` is finite and in
/// `[min, max]`.
///
/// ```
/// use hil_config::limits::check_real_in;
/// assert!(check_real_in("sd", 0.5, 0.0, 1.0).is_ok());
/// assert!(check_real_in("sd", f64::NAN, 0.0, 1.0).is_err());
/// assert!(check_real_in("sd", 1.5, 0.0, 1.0).is_err());
/// ```
pub fn check_real_in(name: &str, value: f64, min: f64, max: f64) -> Result<()> {
    check_real(name, value, (min..=max).contains(&value), || {
        format!("must be a number in [{min}, {max}]")
    })
}

/// Checks that the real `value` of the field `name` is finite, over 0 and
/// at most `max` (a size, a force, a density).
///
/// ```
/// use hil_config::limits::check_real_positive;
/// assert!(check_real_positive("density", 950.0, 5000.0).is_ok());
/// assert!(check_real_positive("density", 0.0, 5000.0).is_err());
/// ```
pub fn check_real_positive(name: &str, value: f64, max: f64) -> Result<()> {
    check_real(name, value, value > 0.0 && value <= max, || {
        format!("must be over 0 and at most {max}")
    })
}

/// Checks that the duration `value` (seconds) of the field `name` is finite,
/// positive and at most [`SECONDS`].
pub fn check_seconds(name: &str, value: f64) -> Result<()> {
    check_real(name, value, value > 0.0 && value <= SECONDS, || {
        format!("must be a number of seconds in (0, {SECONDS}]")
    })
}

/// The one shape of the real-valued checks: `value` must be finite and
/// `in_range`, else the error says `why`.
fn check_real(name: &str, value: f64, in_range: bool, why: impl FnOnce() -> String) -> Result<()> {
    if value.is_finite() && in_range {
        Ok(())
    } else {
        Err(HilError::invalid_parameter(name, value, why()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_inclusive() {
        assert!(check_count("n", 1u32, 5).is_ok());
        assert!(check_count("n", 5usize, 5).is_ok());
        assert!(check_count("n", 6usize, 5).is_err());
        assert!(check_count("n", 0usize, 5).is_err());
        assert!(check_at_most("n", 0usize, 5).is_ok());
        assert!(check_at_most("n", -1i64, 5).is_err());
        assert!(check_at_most("n", usize::MAX, 5).is_err());
        assert!(check_seconds("t", SECONDS).is_ok());
        for bad in [0.0, -1.0, f64::INFINITY, f64::NAN, SECONDS * 2.0] {
            assert!(check_seconds("t", bad).is_err(), "{bad}");
        }
    }
}
