//! Running an [`Experiment`] with its interaction record: [`run_recorded`]
//! logs every step through a [`Recorder`], and continues a killed session
//! from its log (see [`hil_record`] for the format and the
//! guarantees).

use std::collections::VecDeque;

use hil_core::metrics::EpisodeMetrics;
use hil_core::{HilError, Result, Session, SessionObserver};
use hil_record::{LoggedRecord, LoggedSession, Record, RecordLog, Recorder, ReplayChannel};

use crate::experiment::{Experiment, ExperimentSummary};

/// What a resumed session replays, derived from its log.
///
/// A resume replays the whole logged session from the header's config and
/// seed, checking every record it produces against the log (decisions,
/// outcomes, episode summaries, checkpoints), and only then appends. It
/// does not restore the last checkpoint and trust what came before: an
/// episode summary edited to disagree with its steps, or a header whose
/// config was changed, would then pass unseen (and an unkeyed chain can be
/// recomputed by whoever edits the log). The logged answers
/// are given back in order, so no person is asked twice.
struct ResumePlan {
    expected: Vec<LoggedRecord>,
    answers: VecDeque<hil_record::LoggedAnswer>,
}

fn plan(session: &LoggedSession, log: &RecordLog) -> Result<ResumePlan> {
    let mut ended = 0;
    for r in &session.records {
        if let Record::EpisodeEnd { episode, .. } = &r.record {
            if *episode != ended {
                return Err(HilError::Data {
                    path: log.path().to_path_buf(),
                    record: r.line,
                    field: "episode".into(),
                    why: format!("episode {episode} ends where episode {ended} was expected"),
                });
            }
            ended += 1;
        }
    }
    let expected: Vec<LoggedRecord> = session
        .records
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
    Ok(ResumePlan { expected, answers })
}

/// Runs `exp`, recording every step into `log`; with `resume` (the log's
/// contents, from [`RecordLog::open`]), continues the logged session
/// instead. `on_episode` is called with each episode's number and metrics,
/// including episodes restored from the log.
///
/// See [`hil_record`] for the guarantees.
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
                // Every resume replays from the start (see `ResumePlan`).
                from_checkpoint: None,
            };
            let expected = std::mem::take(&mut plan.expected);
            (Recorder::resuming(log, expected, marker), plan)
        }
    };
    let mut metrics = Vec::with_capacity(exp.episodes);
    let seeds: Vec<u64> = (0..exp.episodes).map(|k| exp.episode_seed(k)).collect();
    let mut channel = ReplayChannel {
        inner: exp.channel.as_mut(),
        logged: plan.answers,
        episode: 0,
        path: path.clone(),
    };
    for (k, &seed) in seeds.iter().enumerate() {
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
