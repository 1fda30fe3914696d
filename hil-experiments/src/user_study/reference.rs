//! What the published success rates allow: the exact expected plate of a
//! robot that always asks and whose every attempt, with the action the
//! expert names, succeeds at that action's published rate.
//!
//! The paper's real study reports AlwaysQuery at r_task_avg 0.87; a
//! simulated study can only be as good as the rates its foods are
//! calibrated to. This bound is computed, not simulated: under the study's
//! protocol (up to N_att attempts per item, the next item after a success)
//! and its metric (r_task_avg = successes / attempts on a plate, the 0/1
//! outcome being the task reward of an attempt whose probability is not
//! known), every item's attempts are a truncated geometric draw, and the
//! plate's joint distribution of successes and attempts is exact.

use hil_config::{EnvironmentConfig, ExpertRate};
use hil_core::{HilError, Result};
use serde::Serialize;

/// Expected figures of one plate ([`expected_plate`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PlateExpectation {
    /// E[successes / attempts] over the plate: the expected r_task_avg.
    pub r_task_avg: f64,
    /// E[items fed].
    pub n_success: f64,
    /// E[attempts].
    pub attempts: f64,
}

/// The exact expected plate when item `i`'s every attempt succeeds with
/// probability `rates[i]`, independently, and an item gets at most `n_att`
/// attempts (none after its first success).
///
/// ```
/// use hil_experiments::user_study::expected_plate;
/// // One item that succeeds half the time, two attempts: fed at the first
/// // (r = 1) with 1/2, at the second (r = 1/2) with 1/4, never (r = 0)
/// // with 1/4.
/// let e = expected_plate(&[0.5], 2)?;
/// assert!((e.r_task_avg - 0.625).abs() < 1e-12);
/// assert!((e.n_success - 0.75).abs() < 1e-12);
/// assert!((e.attempts - 1.5).abs() < 1e-12);
/// # Ok::<(), hil_core::HilError>(())
/// ```
pub fn expected_plate(rates: &[f64], n_att: u32) -> Result<PlateExpectation> {
    if n_att == 0 {
        return Err(HilError::invalid_parameter(
            "n_att",
            "0",
            "must be at least 1",
        ));
    }
    if let Some((i, p)) = rates
        .iter()
        .enumerate()
        .find(|(_, p)| !(0.0..=1.0).contains(*p))
    {
        return Err(HilError::invalid_parameter(
            format!("rates[{i}]"),
            p.to_string(),
            "a success rate must be in [0, 1]",
        ));
    }
    let n_att = n_att as usize;
    let items = rates.len();
    // joint[s][a]: probability of s successes in a attempts so far.
    let max_a = items * n_att;
    let mut joint = vec![vec![0.0; max_a + 1]; items + 1];
    joint[0][0] = 1.0;
    for &p in rates {
        let mut next = vec![vec![0.0; max_a + 1]; items + 1];
        for s in 0..=items {
            for a in 0..=max_a {
                let q = joint[s][a];
                if q == 0.0 {
                    continue;
                }
                // Fed at attempt k, after k - 1 failures.
                for k in 1..=n_att {
                    let pk = (1.0 - p).powi(k as i32 - 1) * p;
                    if s < items && a + k <= max_a {
                        next[s + 1][a + k] += q * pk;
                    }
                }
                // Never fed: all n_att attempts failed.
                if a + n_att <= max_a {
                    next[s][a + n_att] += q * (1.0 - p).powi(n_att as i32);
                }
            }
        }
        joint = next;
    }
    let mut e = PlateExpectation {
        r_task_avg: 0.0,
        n_success: 0.0,
        attempts: 0.0,
    };
    for (s, row) in joint.iter().enumerate() {
        for (a, &q) in row.iter().enumerate() {
            if a > 0 {
                e.r_task_avg += q * s as f64 / a as f64;
            }
            e.n_success += q * s as f64;
            e.attempts += q * a as f64;
        }
    }
    Ok(e)
}

/// An always-asking robot at the published rates of the actions the
/// expert names: the most a simulated AlwaysQuery can be expected to
/// score on foods calibrated to those rates.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PublishedReference {
    /// Every item of a plate with the expert's action and its published rate.
    pub items: Vec<ExpertRate>,
    /// Attempts per item.
    pub n_att: u32,
    /// The expected plate ([`expected_plate`]).
    pub expected: PlateExpectation,
}

impl PublishedReference {
    /// The reference of `environment` under a protocol of `n_att`
    /// attempts per item, or `None` when the environment has no published
    /// table ([`EnvironmentConfig::published_expert_rates`]).
    pub fn of(environment: &dyn EnvironmentConfig, n_att: u32) -> Result<Option<Self>> {
        let Some(items) = environment.published_expert_rates()? else {
            return Ok(None);
        };
        let rates: Vec<f64> = items.iter().map(|r| r.rate).collect();
        let expected = expected_plate(&rates, n_att)?;
        Ok(Some(Self {
            items,
            n_att,
            expected,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every outcome of every item enumerated: the definition, slowly.
    fn brute_force(rates: &[f64], n_att: usize) -> PlateExpectation {
        let outcomes: Vec<Vec<(usize, usize, f64)>> = rates
            .iter()
            .map(|&p| {
                let mut o: Vec<(usize, usize, f64)> = (1..=n_att)
                    .map(|k| (1, k, (1.0 - p).powi(k as i32 - 1) * p))
                    .collect();
                o.push((0, n_att, (1.0 - p).powi(n_att as i32)));
                o
            })
            .collect();
        let mut e = PlateExpectation {
            r_task_avg: 0.0,
            n_success: 0.0,
            attempts: 0.0,
        };
        let mut pick = vec![0usize; rates.len()];
        loop {
            let (mut s, mut a, mut q) = (0, 0, 1.0);
            for (i, &j) in pick.iter().enumerate() {
                let (si, ai, qi) = outcomes[i][j];
                s += si;
                a += ai;
                q *= qi;
            }
            e.r_task_avg += q * s as f64 / a as f64;
            e.n_success += q * s as f64;
            e.attempts += q * a as f64;
            // Next combination (odometer).
            let mut i = 0;
            loop {
                if i == pick.len() {
                    return e;
                }
                pick[i] += 1;
                if pick[i] < outcomes[i].len() {
                    break;
                }
                pick[i] = 0;
                i += 1;
            }
        }
    }

    #[test]
    fn the_expectation_is_the_enumerated_one() {
        for (rates, n_att) in [
            (vec![0.2, 1.0, 1.0], 3),
            (vec![0.57, 0.53, 0.93], 3),
            (vec![0.1, 0.5, 0.9, 0.3], 2),
            (vec![0.0, 0.7], 4),
        ] {
            let fast = expected_plate(&rates, n_att).unwrap();
            let slow = brute_force(&rates, n_att as usize);
            for (a, b) in [
                (fast.r_task_avg, slow.r_task_avg),
                (fast.n_success, slow.n_success),
                (fast.attempts, slow.attempts),
            ] {
                assert!((a - b).abs() < 1e-12, "{rates:?}: {fast:?} vs {slow:?}");
            }
        }
    }

    #[test]
    fn sure_and_hopeless_items_give_the_obvious_plate() {
        let sure = expected_plate(&[1.0; 3], 3).unwrap();
        assert_eq!(
            (sure.r_task_avg, sure.n_success, sure.attempts),
            (1.0, 3.0, 3.0)
        );
        let hopeless = expected_plate(&[0.0; 3], 3).unwrap();
        assert_eq!(
            (hopeless.r_task_avg, hopeless.n_success, hopeless.attempts),
            (0.0, 0.0, 9.0)
        );
        let empty = expected_plate(&[], 3).unwrap();
        assert_eq!((empty.r_task_avg, empty.n_success), (0.0, 0.0));
    }

    #[test]
    fn a_rate_outside_0_1_or_no_attempt_is_refused() {
        for (rates, n_att) in [(vec![0.5, 1.2], 3), (vec![f64::NAN], 3), (vec![0.5], 0)] {
            let err = expected_plate(&rates, n_att).unwrap_err();
            assert!(matches!(err, HilError::InvalidParameter { .. }), "{err:?}");
        }
    }

    #[cfg(feature = "physics")]
    #[test]
    fn the_papers_study_is_read_against_the_isolated_rates_of_the_expert_actions() {
        let cfg = crate::user_study::UserStudyConfig::paper();
        let r = PublishedReference::of(cfg.environment.as_ref(), cfg.session.n_att)
            .unwrap()
            .expect("kinova_feeding has a published table");
        // The environment's rates (hil-kinova-mujoco tests them: banana TA0
        // 0.2, carrot and cantaloupe VS90 1.0 when alone on the plate).
        let rates: Vec<f64> = r.items.iter().map(|i| i.rate).collect();
        assert_eq!(rates, [0.2, 1.0, 1.0], "{r:?}");
        // Carrot and melon fed at once; banana at attempt 1, 2, 3 or
        // never: 0.2·1 + 0.16·3/4 + 0.128·3/5 + 0.512·2/5.
        assert!((r.expected.r_task_avg - 0.6016).abs() < 1e-12, "{r:?}");
        assert!((r.expected.n_success - 2.488).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn an_environment_without_a_published_table_has_no_reference() {
        let env = hil_envs::FoodReplayConfig {
            dataset: None,
            foods: vec!["banana".into()],
            pretrain_foods: vec!["apple".into()],
            items_per_episode: 2,
            outcomes: Default::default(),
            pretrain_reward: Default::default(),
        };
        assert_eq!(PublishedReference::of(&env, 3).unwrap(), None);
    }
}
