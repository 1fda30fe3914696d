//! Running an [`Experiment`] with its interaction record: [`run_recorded`]
//! logs every step through a [`Recorder`], and continues a killed session
//! from its log (see [`hil_core::record`] for the format and the
//! guarantees).

use std::collections::VecDeque;

use hil_core::metrics::EpisodeMetrics;
use hil_core::record::{LoggedRecord, LoggedSession, Record, RecordLog, Recorder, ReplayChannel};
use hil_core::{HilError, Result, Session, SessionObserver};

use crate::experiment::{Experiment, ExperimentSummary};

/// Where a resumed session starts, derived from its log.
struct ResumePlan {
    start_episode: usize,
    /// The checkpoint to restore: its episode, state and log line.
    restore: Option<(usize, serde_json::Value, usize)>,
    metrics_before: Vec<EpisodeMetrics>,
    expected: Vec<LoggedRecord>,
    answers: VecDeque<hil_core::record::LoggedAnswer>,
}

fn plan(session: &LoggedSession, log: &RecordLog) -> Result<ResumePlan> {
    let data_err = |line: usize, field: &str, why: String| HilError::Data {
        path: log.path().to_path_buf(),
        record: line,
        field: field.to_string(),
        why,
    };
    // The last checkpoint whose episode ends are all present.
    let mut ends: Vec<EpisodeMetrics> = Vec::new();
    let mut cut = None;
    for (i, r) in session.records.iter().enumerate() {
        match &r.record {
            Record::EpisodeEnd { episode, metrics } => {
                if *episode != ends.len() {
                    return Err(data_err(
                        r.line,
                        "episode",
                        format!(
                            "episode {episode} ends where episode {} was expected",
                            ends.len()
                        ),
                    ));
                }
                ends.push(metrics.clone());
            }
            Record::Checkpoint { episode, policy } if *episode + 1 == ends.len() => {
                cut = Some((i, *episode, policy.clone(), r.line));
            }
            _ => {}
        }
    }
    let (first, start_episode, restore, metrics_before) = match cut {
        Some((i, k, state, line)) => (i + 1, k + 1, Some((k, state, line)), ends[..=k].to_vec()),
        None => (0, 0, None, Vec::new()),
    };
    let expected: Vec<LoggedRecord> = session.records[first..]
        .iter()
        .filter(|r| !matches!(r.record, Record::Resumed { .. }))
        .cloned()
        .collect();
    let answers = expected
        .iter()
        .filter_map(|r| match &r.record {
            Record::Step { episode, step } => step
                .response
                .clone()
                .map(|resp| (*episode, step.t, resp, r.line)),
            _ => None,
        })
        .collect();
    Ok(ResumePlan {
        start_episode,
        restore,
        metrics_before,
        expected,
        answers,
    })
}

/// Runs `exp`, recording every step into `log`; with `resume` (the log's
/// contents, from [`RecordLog::open`]), continues the logged session
/// instead. `on_episode` is called with each episode's number and metrics,
/// including episodes restored from the log.
///
/// See [`hil_core::record`] for the guarantees.
pub fn run_recorded(
    exp: &mut Experiment,
    log: RecordLog,
    resume: Option<&LoggedSession>,
    observers: &mut [&mut dyn SessionObserver],
    mut on_episode: impl FnMut(usize, &EpisodeMetrics),
) -> Result<ExperimentSummary> {
    let path = log.path().to_path_buf();
    let (mut recorder, plan) = match resume {
        None => (
            Recorder::new(log),
            ResumePlan {
                start_episode: 0,
                restore: None,
                metrics_before: Vec::new(),
                expected: Vec::new(),
                answers: VecDeque::new(),
            },
        ),
        Some(session) => {
            if session.header.episodes != exp.episodes || session.header.seed != exp.seed {
                return Err(HilError::Data {
                    path,
                    record: 1,
                    field: "header".into(),
                    why: format!(
                        "the log is for seed {} and {} episode(s), the experiment has seed {} and {}",
                        session.header.seed, session.header.episodes, exp.seed, exp.episodes
                    ),
                });
            }
            let mut plan = plan(session, &log)?;
            let marker = Record::Resumed {
                lines: log.lines(),
                truncated_bytes: session.truncated_bytes,
                from_checkpoint: plan.restore.as_ref().map(|(k, _, _)| *k),
            };
            let expected = std::mem::take(&mut plan.expected);
            (Recorder::resuming(log, expected, marker), plan)
        }
    };
    if let Some((k, state, line)) = plan.restore {
        exp.policy.restore(state).map_err(|e| HilError::Data {
            path: path.clone(),
            record: line,
            field: format!("checkpoint of episode {k}"),
            why: format!("the policy could not restore it: {e}"),
        })?;
    }
    let mut metrics = plan.metrics_before;
    for (k, m) in metrics.iter().enumerate() {
        on_episode(k, m);
    }
    let seeds: Vec<u64> = (0..exp.episodes).map(|k| exp.episode_seed(k)).collect();
    let mut channel = ReplayChannel {
        inner: exp.channel.as_mut(),
        logged: plan.answers,
        episode: 0,
        path: path.clone(),
    };
    for (k, &seed) in seeds.iter().enumerate().skip(plan.start_episode) {
        recorder.set_episode(k);
        channel.episode = k;
        let mut session = Session::new(
            exp.settings.clone(),
            exp.environment.as_mut(),
            exp.policy.as_mut(),
            &mut channel,
            exp.workload.clone(),
        )
        .with_forecast(exp.forecast.clone());
        let mut all: Vec<&mut dyn SessionObserver> = Vec::with_capacity(observers.len() + 1);
        all.push(&mut recorder);
        for o in observers.iter_mut() {
            all.push(&mut **o);
        }
        let report = session.run_episode(seed, &mut all)?;
        // Checkpoint the policy at the episode boundary, where nothing else
        // carries over (environment, channel and workload are reseeded).
        if let Ok(state) = exp.policy.save() {
            recorder.emit(&Record::Checkpoint {
                episode: k,
                policy: state,
            })?;
        }
        on_episode(k, &report.metrics);
        metrics.push(report.metrics);
    }
    if let Some(extra) = recorder.next_expected() {
        return Err(HilError::Data {
            path,
            record: extra.line,
            field: extra.record.kind().to_string(),
            why: "the log continues past the end of the session the config describes".into(),
        });
    }
    Ok(ExperimentSummary::new(metrics))
}
