//! A synthetic workload study with the paper's design, calibrated to its
//! published figures (the real study data are not public).
//!
//! Design: every participant does 12 query conditions (difficulty easy/hard
//! × distraction none/easy/hard × interval 1/2 min) of 5.5 min and two
//! baseline conditions (easy or hard distraction, no queries). Queries come
//! at 60, 120, …, 300 s (1-min interval: 5 queries) or 60, 180, 300 s
//! (2-min: 3), so each participant gives 48 pairs (89 × 48 = 4272, D1's
//! count). Response types cycle MCQ → bounding box → open-ended, starting
//! at a different type in each condition. People with limitations have
//! logged survey times (except two, as in the paper); 111 of their surveys
//! are missing, leaving 705 pairs in D2.
//!
//! Workload process (latent, on the [0, 1] scale, before Likert rounding):
//! `participant level + population shift + condition effect + query-kind
//! effects + decaying carry-over of recent queries + noise`; the baseline
//! surveys share the participant level but add a large baseline-only
//! spread and sit lower (the paper's Constant baseline is worse than
//! Average, so WL_0 must be a noisy, biased predictor of later workload). Each TLX
//! subscale adds its own noise and is rounded to the 5-point scale.
//! [`SynthParams`] holds the calibrated values: the level and spread
//! parameters (`mean`, `population_shift`, `participant_sd`,
//! `limited_survey_sd`) are centred so that the D1 and D2 means and sds,
//! averaged over generator seeds 0..100, match the paper's
//! (`hil workload seeds --count 100 --centre`, [`crate::seeds::centre`]);
//! any one generated study (the bundled one included) is one draw around
//! them. See the crate README for the figures.

use hil_config::limits;
use hil_core::{Difficulty, Distraction, ResponseType, Result};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal, Normal};
use serde::{Deserialize, Serialize};

use crate::study::{Population, PosedQuery, Study, StudyRecord};
use crate::tlx::TlxAnswers;

/// Latent-process parameters (workload units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SynthParams {
    /// Mean latent workload during query conditions (no-limitation group).
    pub mean: f64,
    /// Extra latent workload of people with limitations (and OTs).
    pub population_shift: f64,
    /// Participant-level standard deviation.
    pub participant_sd: f64,
    /// Share of the participant level seen in the baseline surveys.
    pub baseline_share: f64,
    /// Baseline-only participant standard deviation.
    pub baseline_sd: f64,
    /// Baseline mean relative to `mean`.
    pub baseline_offset: f64,
    /// Effects of difficulty (easy, hard).
    pub difficulty: [f64; 2],
    /// Effects of response type (mcq, bounding box, open-ended).
    pub response: [f64; 3],
    /// Effects of distraction (none, easy, hard).
    pub distraction: [f64; 3],
    /// Carry-over added per earlier query in the condition, decaying with
    /// time constant `carry_tau_s`.
    pub carry: f64,
    /// Carry-over time constant in seconds.
    pub carry_tau_s: f64,
    /// Per-(participant, condition) standard deviation.
    pub condition_sd: f64,
    /// Per-survey standard deviation.
    pub survey_sd: f64,
    /// Per-subscale standard deviation.
    pub item_sd: f64,
    /// Extra baseline (WL_0) level of people with limitations.
    pub limited_baseline_shift: f64,
    /// Per-survey standard deviation of people with limitations.
    pub limited_survey_sd: f64,
}

impl Default for SynthParams {
    fn default() -> Self {
        Self {
            mean: 0.3221,
            population_shift: 0.0493,
            participant_sd: 0.2846,
            baseline_share: 1.0,
            baseline_sd: 0.37,
            baseline_offset: -0.27,
            difficulty: [-0.06, 0.06],
            response: [-0.12, 0.0, 0.12],
            distraction: [-0.06, 0.0, 0.06],
            carry: 0.02,
            carry_tau_s: 90.0,
            condition_sd: 0.06,
            survey_sd: 0.13,
            item_sd: 0.1,
            limited_baseline_shift: 0.22,
            limited_survey_sd: 0.0801,
        }
    }
}

/// The study design and latent parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SynthConfig {
    /// Participants without limitations (paper: 89).
    pub n_no_limitation: usize,
    /// Participants with mobility limitations (paper: 14).
    pub n_mobility_limitation: usize,
    /// Occupational therapists simulating limitations (paper: 3).
    pub n_occupational_therapist: usize,
    /// Participants with limitations whose survey time was not logged (paper: 2).
    pub n_unlogged: usize,
    /// Query surveys of D2 missing at random (111 gives the paper's 705 pairs).
    pub d2_missing_surveys: usize,
    /// Median logged survey time in seconds (D2).
    pub survey_time_median_s: f64,
    /// Latent parameters.
    pub params: SynthParams,
}

impl Default for SynthConfig {
    fn default() -> Self {
        Self {
            n_no_limitation: 89,
            n_mobility_limitation: 14,
            n_occupational_therapist: 3,
            n_unlogged: 2,
            d2_missing_surveys: 111,
            survey_time_median_s: 25.0,
            params: SynthParams::default(),
        }
    }
}

/// Seconds at which queries come in a 5.5-min condition.
pub fn query_times(interval_min: u8) -> Vec<f64> {
    match interval_min {
        1 => vec![60.0, 120.0, 180.0, 240.0, 300.0],
        _ => vec![60.0, 180.0, 300.0],
    }
}

/// Condition length in seconds.
pub const CONDITION_SECONDS: f64 = 330.0;

impl SynthConfig {
    /// A small study for tests: `n1` participants without limitations and
    /// `n2` with, no missing surveys.
    pub fn small(n1: usize, n2: usize) -> Self {
        Self {
            n_no_limitation: n1,
            n_mobility_limitation: n2,
            n_occupational_therapist: 0,
            n_unlogged: 0,
            d2_missing_surveys: 0,
            ..Self::default()
        }
    }

    /// Checks the counts against [`limits::PARTICIPANTS`] and
    /// [`limits::SURVEYS`] and the survey time against [`limits::SECONDS`];
    /// [`SynthConfig::generate`] calls it first.
    pub fn validate(&self) -> Result<()> {
        for (name, n) in [
            ("n_no_limitation", self.n_no_limitation),
            ("n_mobility_limitation", self.n_mobility_limitation),
            ("n_occupational_therapist", self.n_occupational_therapist),
            ("n_unlogged", self.n_unlogged),
        ] {
            limits::check_at_most(name, n, limits::PARTICIPANTS)?;
        }
        limits::check_at_most(
            "d2_missing_surveys",
            self.d2_missing_surveys,
            limits::SURVEYS,
        )?;
        limits::check_seconds("survey_time_median_s", self.survey_time_median_s)
    }

    /// Generates the study deterministically from `seed`.
    pub fn generate(&self, seed: u64) -> Result<Study> {
        self.validate()?;
        let p = &self.params;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let std_normal = Normal::new(0.0, 1.0).expect("valid");
        let survey_time =
            LogNormal::new(self.survey_time_median_s.max(1e-3).ln(), 0.4).expect("valid");
        let mut records = Vec::new();
        let pops = std::iter::repeat_n(Population::NoLimitation, self.n_no_limitation)
            .chain(std::iter::repeat_n(
                Population::MobilityLimitation,
                self.n_mobility_limitation,
            ))
            .chain(std::iter::repeat_n(
                Population::OccupationalTherapist,
                self.n_occupational_therapist,
            ));
        let mut limited_seen = 0;
        let mut d2_query_rows: Vec<usize> = Vec::new();
        for (pi, pop) in pops.enumerate() {
            let id = format!("p{:03}", pi + 1);
            let logged = pop.is_limited() && {
                limited_seen += 1;
                limited_seen > self.n_unlogged
            };
            let mut z = || std_normal.sample(&mut rng);
            let level = p.participant_sd * z();
            let shift = if pop.is_limited() {
                p.population_shift
            } else {
                0.0
            };
            // people with limitations: a higher resting level and noisier answers
            let (base_shift, survey_sd) = if pop.is_limited() {
                (p.limited_baseline_shift, p.limited_survey_sd)
            } else {
                (0.0, p.survey_sd)
            };
            let base_level = p.mean
                + shift
                + base_shift
                + p.baseline_offset
                + p.baseline_share * level
                + p.baseline_sd * z();
            let survey = |rng: &mut ChaCha8Rng, latent: f64| -> (TlxAnswers, Option<f64>) {
                let mut item = |off: f64| -> u8 {
                    let v = (latent + off + p.item_sd * std_normal.sample(rng)).clamp(0.0, 1.0);
                    (1.0 + 4.0 * v).round() as u8
                };
                let (m, t, e) = (item(0.0), item(-0.03), item(0.02));
                let perf = item(-0.2).max(1);
                let frus = item(-0.15);
                let tlx = TlxAnswers::new(m, t, 6 - perf, e, frus)
                    .expect("answers in 1..=5 by construction");
                let st = logged.then(|| (survey_time.sample(rng) * 10.0).round() / 10.0);
                (tlx, st)
            };
            for (bi, dist) in [Distraction::Easy, Distraction::Hard]
                .into_iter()
                .enumerate()
            {
                let latent = base_level
                    + p.distraction[dist as usize]
                    + survey_sd * std_normal.sample(&mut rng);
                let (tlx, st) = survey(&mut rng, latent);
                records.push(StudyRecord {
                    participant: id.clone(),
                    population: pop,
                    condition: format!("baseline_{}", ["easy", "hard"][bi]),
                    query_time_s: CONDITION_SECONDS,
                    query: None,
                    distraction: dist,
                    tlx,
                    survey_time_s: st,
                    line: 0,
                });
            }
            let mut ci = 0;
            for difficulty in Difficulty::ALL {
                for distraction in Distraction::ALL {
                    for interval_min in [1u8, 2] {
                        ci += 1;
                        let cond_effect = p.condition_sd * std_normal.sample(&mut rng);
                        let times = query_times(interval_min);
                        let start = rng.random_range(0..3usize);
                        for (k, &tau) in times.iter().enumerate() {
                            let response = ResponseType::ALL[(start + k) % 3];
                            let carry: f64 = times[..k]
                                .iter()
                                .map(|&s| p.carry * (-(tau - s) / p.carry_tau_s).exp())
                                .sum();
                            let latent = p.mean
                                + shift
                                + level
                                + cond_effect
                                + p.difficulty[difficulty as usize]
                                + p.response[response as usize]
                                + p.distraction[distraction as usize]
                                + carry
                                + survey_sd * std_normal.sample(&mut rng);
                            let (tlx, st) = survey(&mut rng, latent);
                            if pop.is_limited() {
                                d2_query_rows.push(records.len());
                            }
                            records.push(StudyRecord {
                                participant: id.clone(),
                                population: pop,
                                condition: format!("c{ci:02}"),
                                query_time_s: tau,
                                query: Some(PosedQuery {
                                    difficulty,
                                    response,
                                    interval_min,
                                }),
                                distraction,
                                tlx,
                                survey_time_s: st,
                                line: 0,
                            });
                        }
                    }
                }
            }
        }
        d2_query_rows.shuffle(&mut rng);
        let mut drop = vec![false; records.len()];
        for &i in d2_query_rows.iter().take(self.d2_missing_surveys) {
            drop[i] = true;
        }
        let records: Vec<StudyRecord> = records
            .into_iter()
            .zip(drop)
            .filter(|(_, d)| !d)
            .map(|(r, _)| r)
            .collect();
        Study::from_records(format!("synthetic study (seed {seed})"), records)
    }
}
