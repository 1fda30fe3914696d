//! A workload model rolled out over a query schedule: WL_t at every
//! timestep from WL_0, with the queries asked at given timesteps (what `hil
//! workload rollout` prints and plots).

use hil_core::{HilError, QueryHistory, QueryKind, Result, Timestep, WorkloadModel};

/// One timestep of a rollout.
#[derive(Clone, Debug, PartialEq)]
pub struct RolloutStep {
    /// The timestep (Δt = 10 s each).
    pub t: Timestep,
    /// The model's workload at `t`, after the queries asked at `t`.
    pub wl: f64,
    /// The queries asked at `t`.
    pub asked: Vec<QueryKind>,
}

/// `model`'s workload at every timestep `0..=end` from `wl0`, the queries
/// of `schedule` entering the history at their timesteps; WL_t is
/// [`hil_core::workload::workload_at`], the session's own (so WL_0 at
/// t = 0, and a non-finite prediction is an error naming the model).
///
/// `end` is at most [`hil_config::limits::TIMESTEPS`] (see
/// [`default_end`]); the schedule's timesteps must not decrease and must
/// not pass `end`, else the error names the entry (`schedule[i]`): a query
/// is never silently dropped.
///
/// ```
/// use hil_core::QueryKind;
/// use hil_workload::rollout::rollout;
/// let model = hil_workload::bundled::load("f12_sim").unwrap();
/// let steps = rollout(model.as_ref(), 0.5, &[(2, QueryKind::default())], 4).unwrap();
/// assert_eq!(steps.len(), 5);
/// assert_eq!(steps[2].asked, [QueryKind::default()]);
/// assert!(steps[2].wl > steps[1].wl); // a query raises the workload
/// assert!(rollout(model.as_ref(), 0.5, &[(5, QueryKind::default())], 4).is_err());
/// ```
pub fn rollout(
    model: &dyn WorkloadModel,
    wl0: f64,
    schedule: &[(Timestep, QueryKind)],
    end: Timestep,
) -> Result<Vec<RolloutStep>> {
    hil_core::workload::check_wl0(wl0)?;
    hil_config::limits::check_at_most("steps", end, hil_config::limits::TIMESTEPS)?;
    let mut prev = 0;
    for (i, &(t, _)) in schedule.iter().enumerate() {
        let why = if t < prev {
            format!("times must not decrease (previous query at {prev})")
        } else if t > end {
            format!("timestep {t} is after the rollout's last step, {end}")
        } else {
            prev = t;
            continue;
        };
        return Err(HilError::invalid_parameter(
            format!("schedule[{i}]"),
            t,
            why,
        ));
    }
    let mut history = QueryHistory::new();
    let mut steps = Vec::with_capacity(end as usize + 1);
    let mut next = 0;
    for t in 0..=end {
        let mut asked = Vec::new();
        while next < schedule.len() && schedule[next].0 == t {
            history.push(t, schedule[next].1)?;
            asked.push(schedule[next].1);
            next += 1;
        }
        let wl = hil_core::workload::workload_at(model, wl0, &history, t)?;
        steps.push(RolloutStep { t, wl, asked });
    }
    Ok(steps)
}

/// The last step of a rollout over `schedule` when none is given: ten
/// steps (100 s) past the last query, or 10 without queries.
///
/// ```
/// use hil_core::QueryKind;
/// use hil_workload::rollout::default_end;
/// assert_eq!(default_end(&[(3, QueryKind::default())]), 13);
/// assert_eq!(default_end(&[]), 10);
/// ```
pub fn default_end(schedule: &[(Timestep, QueryKind)]) -> Timestep {
    // Saturating: a timestep near u64::MAX must not wrap to a short rollout
    // (rollout then refuses the end by its limit).
    schedule
        .iter()
        .map(|q| q.0)
        .max()
        .unwrap_or(0)
        .saturating_add(10)
}

/// Parses a query schedule `t:response/difficulty/distraction,...` (a
/// query without a kind is the default kind); timesteps must not decrease.
/// Errors name the entry (`schedule[i]`).
///
/// ```
/// let q = hil_workload::rollout::parse_schedule("3:mcq/easy/none, 9").unwrap();
/// assert_eq!((q[0].0, q[1].0), (3, 9));
/// ```
pub fn parse_schedule(s: &str) -> Result<Vec<(Timestep, QueryKind)>> {
    let mut out: Vec<(Timestep, QueryKind)> = Vec::new();
    for (i, item) in s
        .split(',')
        .map(str::trim)
        .filter(|x| !x.is_empty())
        .enumerate()
    {
        let bad = |why: String| HilError::invalid_parameter(format!("schedule[{i}]"), item, why);
        let (t, kind) = item.split_once(':').unwrap_or((item, ""));
        let t: Timestep = t
            .trim()
            .parse()
            .map_err(|_| bad(format!("`{t}` is not a timestep (non-negative integer)")))?;
        if t > hil_config::limits::TIMESTEPS {
            return Err(bad(format!(
                "timestep {t} is past the last one a rollout reaches ({})",
                hil_config::limits::TIMESTEPS
            )));
        }
        let k: QueryKind = if kind.trim().is_empty() {
            QueryKind::default()
        } else {
            kind.parse().map_err(|e: HilError| bad(e.to_string()))?
        };
        if let Some(prev) = out.last()
            && t < prev.0
        {
            return Err(bad(format!(
                "times must not decrease (previous query at {})",
                prev.0
            )));
        }
        out.push((t, k));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::ResponseType;

    #[test]
    fn schedule_parsing() {
        let q = parse_schedule("3:mcq/easy/none, 9:open_ended/hard/easy,9").unwrap();
        assert_eq!(q.len(), 3);
        assert_eq!(q[1].1.response, ResponseType::OpenEnded);
        assert_eq!(q[2].1, QueryKind::default());
        assert!(
            parse_schedule("3:telepathy")
                .unwrap_err()
                .to_string()
                .contains("telepathy")
        );
        assert!(parse_schedule("5,3").is_err());
        // A timestep past the limit is refused by name (its `+ 10` for the
        // default end wrapped around before).
        let err = parse_schedule("1,18446744073709551615").unwrap_err();
        assert!(
            matches!(err, HilError::InvalidParameter { ref name, .. } if name == "schedule[1]"),
            "{err}"
        );
    }

    #[test]
    fn a_rollout_past_the_limit_is_refused() {
        let model = crate::bundled::load("f12_sim").unwrap();
        let err = rollout(model.as_ref(), 0.5, &[], u64::MAX).unwrap_err();
        assert!(matches!(err, HilError::InvalidParameter { ref name, .. } if name == "steps"));
        let last = hil_config::limits::TIMESTEPS;
        assert!(rollout(model.as_ref(), 0.5, &[], last + 1).is_err());
    }

    #[test]
    fn two_queries_at_one_timestep_are_both_asked() {
        let model = crate::bundled::load("f12_sim").unwrap();
        let kinds = parse_schedule("1,1:mcq/easy/none").unwrap();
        let steps = rollout(model.as_ref(), 0.5, &kinds, 2).unwrap();
        assert_eq!(steps[1].asked.len(), 2);
        assert!(steps[0].asked.is_empty() && steps[2].asked.is_empty());
        assert!(rollout(model.as_ref(), 1.5, &kinds, 2).is_err());
    }
}
