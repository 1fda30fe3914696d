//! One participant's progress through the study: rebuilt from their event
//! log, moved on by the task clock and their answers, every change logged
//! before it is acknowledged.
//!
//! The task clock runs while the participant works on the distraction task
//! or a robot query, and stops during surveys and between conditions. It
//! only advances while the participant's page is connected (it asks for
//! the state several times a second): after more than `away_after_s`
//! without a request, the gap is not counted. After a server restart the
//! clock continues from the last logged event of the condition.

use std::time::{Duration, Instant};

use hil_core::{Answer, HilError, Result};
use hil_workload::study::Population;
use hil_workload::tlx::TlxAnswers;
use serde_json::{Value, json};

use crate::design::Design;
use crate::log::{Event, EventLog, Line};
use crate::materials::{self, Expected, StudyQuery};

/// Where the participant is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Before a condition: its instructions and a start button.
    Intro,
    /// Working on the distraction task; `query` is open if set.
    Task {
        /// The open query's number.
        query: Option<usize>,
    },
    /// A TLX survey after query `query`, or at the condition end (`None`).
    Survey {
        /// The query the survey follows.
        query: Option<usize>,
    },
    /// Every condition done.
    Done,
}

/// The outcome of a submission.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Submitted {
    /// Logged now.
    Saved,
    /// Already logged earlier with the same contents (a repeated request,
    /// e.g. after a lost response): nothing is written again.
    AlreadySaved,
}

/// Why a submission was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum Refused {
    /// It does not match what the participant is being asked now.
    NotOpen(String),
    /// The answer itself is malformed.
    Invalid(String),
    /// Writing the log failed: nothing was saved.
    Storage(String),
}

/// Progress within the current condition, as the log says.
#[derive(Clone, Debug, Default)]
struct Progress {
    /// Index into the order of the current condition.
    pos: usize,
    started: bool,
    shown: usize,
    answered: usize,
    surveyed: usize,
    task_s: f64,
    distraction_answers: usize,
    surveys_total: usize,
    /// Of `surveys_total`, those at the end of a query condition.
    end_of_condition_surveys: usize,
}

impl Progress {
    /// Applies a logged event for a participant taking conditions in
    /// `order`; the error says why the event does not fit.
    fn apply(
        &mut self,
        order: &[usize],
        design: &Design,
        event: &Event,
    ) -> std::result::Result<(), String> {
        let current = order
            .get(self.pos)
            .map(|&i| design.conditions()[i].id.as_str());
        let check = |c: &str| match current {
            Some(at) if at == c => Ok(()),
            Some(at) => Err(format!(
                "is about condition `{c}`, but the participant is at condition `{at}`"
            )),
            None => Err(format!(
                "is about condition `{c}`, but the participant has done every condition"
            )),
        };
        let p = self;
        match event {
            Event::Enrolled { .. } => return Err("a second `enrolled` line".into()),
            Event::ConditionStarted { condition } => {
                check(condition)?;
                p.started = true;
                p.task_s = 0.0;
            }
            Event::QueryShown {
                condition,
                query,
                task_s,
                ..
            } => {
                check(condition)?;
                if *query != p.shown {
                    return Err(format!("shows query {query}, expected {}", p.shown));
                }
                p.shown += 1;
                p.task_s = *task_s;
            }
            Event::QueryAnswered {
                condition,
                query,
                task_s,
                ..
            } => {
                check(condition)?;
                if *query != p.answered || p.answered >= p.shown {
                    return Err(format!("answers query {query}, which is not open"));
                }
                p.answered += 1;
                p.task_s = *task_s;
            }
            Event::SurveySubmitted {
                condition,
                query,
                task_s,
                ..
            } => {
                check(condition)?;
                p.surveys_total += 1;
                match query {
                    Some(k) => {
                        if *k != p.surveyed || p.surveyed >= p.answered {
                            return Err(format!("a survey after query {k}, which is not due"));
                        }
                        p.surveyed += 1;
                        p.task_s = *task_s;
                    }
                    None => {
                        let query_condition = order
                            .get(p.pos)
                            .is_some_and(|&i| design.conditions()[i].queries.is_some());
                        *p = Progress {
                            pos: p.pos + 1,
                            surveys_total: p.surveys_total,
                            end_of_condition_surveys: p.end_of_condition_surveys
                                + usize::from(query_condition),
                            ..Progress::default()
                        };
                    }
                }
            }
            Event::DistractionAnswered {
                condition,
                task_s,
                index,
                ..
            } => {
                check(condition)?;
                if *index != p.distraction_answers {
                    return Err(format!(
                        "distraction answer {index}, expected {}",
                        p.distraction_answers
                    ));
                }
                p.distraction_answers += 1;
                p.task_s = p.task_s.max(*task_s);
            }
            Event::Resumed { task_s, .. } => {
                if p.started {
                    p.task_s = *task_s;
                }
            }
        }
        Ok(())
    }
}

/// A participant's progress in numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tally {
    /// Surveys submitted, all kinds.
    pub surveys: usize,
    /// Of those, the surveys at the end of a query condition: exported to
    /// the second CSV ([`crate::export::Export`]); the others are the study
    /// CSV's rows.
    pub end_of_condition_surveys: usize,
    /// Conditions completed.
    pub conditions_done: usize,
    /// Conditions in the participant's order.
    pub conditions: usize,
}

impl Tally {
    fn of(p: &Progress, conditions: usize) -> Self {
        Self {
            surveys: p.surveys_total,
            end_of_condition_surveys: p.end_of_condition_surveys,
            conditions_done: p.pos.min(conditions),
            conditions,
        }
    }
}

/// Surveys submitted and conditions completed, of the participant log
/// `lines` (read-only: for `hil study status` while a server may write).
pub fn tally(design: &Design, path: &std::path::Path, lines: &[Line]) -> Result<Tally> {
    let Some(Event::Enrolled { order, .. }) = lines.first().map(|l| &l.event) else {
        return Err(hil_textdata::data_error(
            path,
            1,
            "event",
            "the first line must be `enrolled`",
        ));
    };
    let order = order
        .iter()
        .map(|id| {
            design.condition(id).map(|(i, _)| i).ok_or_else(|| {
                hil_textdata::data_error(
                    path,
                    1,
                    "order",
                    format!("condition `{id}` is not in the design"),
                )
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut p = Progress::default();
    for l in &lines[1..] {
        p.apply(&order, design, &l.event)
            .map_err(|why| hil_textdata::data_error(path, l.seq + 1, "event", why))?;
    }
    Ok(Tally::of(&p, order.len()))
}

/// A participant being served.
#[derive(Debug)]
pub struct Participant {
    /// Pseudonymous id.
    pub id: String,
    /// Population.
    pub population: Population,
    /// Enrolment number.
    pub number: usize,
    /// The link's secret token.
    pub token: String,
    /// Condition indices into the design, in this participant's order.
    pub order: Vec<usize>,
    log: EventLog,
    progress: Progress,
    last_tick: Option<Instant>,
    query_shown_at: Option<Instant>,
    survey_shown_at: Option<Instant>,
    last_seen: Option<Instant>,
    resumed_pending: bool,
    /// Every event after enrolment, as logged: what a repeated submission
    /// is compared with.
    saved: Vec<Event>,
}

fn line_error(log: &EventLog, seq: usize, why: String) -> HilError {
    hil_textdata::data_error(log.path(), seq + 1, "event", why)
}

impl Participant {
    /// Enrols a new participant, writing the first line of their log.
    pub fn enrol(
        design: &Design,
        path: &std::path::Path,
        id: String,
        population: Population,
        number: usize,
        token: String,
    ) -> Result<Self> {
        let order = design.order(number);
        let ids = order
            .iter()
            .map(|&i| design.conditions()[i].id.clone())
            .collect();
        let log = EventLog::create(
            path,
            Event::Enrolled {
                participant: id.clone(),
                population,
                number,
                token: token.clone(),
                order: ids,
            },
        )?;
        Ok(Self::new(id, population, number, token, order, log, false))
    }

    fn new(
        id: String,
        population: Population,
        number: usize,
        token: String,
        order: Vec<usize>,
        log: EventLog,
        resumed_pending: bool,
    ) -> Self {
        Self {
            id,
            population,
            number,
            token,
            order,
            log,
            progress: Progress::default(),
            last_tick: None,
            query_shown_at: None,
            survey_shown_at: None,
            last_seen: None,
            resumed_pending,
            saved: Vec::new(),
        }
    }

    /// Reopens a participant's log and replays it, checking every line
    /// against the design.
    pub fn open(design: &Design, path: &std::path::Path) -> Result<Self> {
        let (log, lines, replayed) = EventLog::open(path)?;
        let Some(Line {
            event:
                Event::Enrolled {
                    participant,
                    population,
                    number,
                    token,
                    order,
                },
            ..
        }) = lines.first().cloned()
        else {
            return Err(line_error(
                &log,
                0,
                "the first line must be `enrolled`".into(),
            ));
        };
        let order = order
            .iter()
            .map(|id| {
                design.condition(id).map(|(i, _)| i).ok_or_else(|| {
                    line_error(
                        &log,
                        0,
                        format!("condition `{id}` is not in this study's design"),
                    )
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut p = Self::new(participant, population, number, token, order, log, true);
        for line in &lines[1..] {
            p.apply(design, &line.event)
                .map_err(|why| line_error(&p.log, line.seq, why))?;
        }
        // A restart leaves its mark: when, and what was read back.
        let resumed = Event::Resumed {
            condition: p.current().map(|c| design.conditions()[c].id.clone()),
            task_s: p.progress.task_s,
            replayed: Some(replayed),
        };
        p.apply(design, &resumed)
            .map_err(|why| line_error(&p.log, replayed.lines, why))?;
        p.log.append(resumed)?;
        Ok(p)
    }

    /// The design index of the condition in progress (`None` when done).
    pub fn current(&self) -> Option<usize> {
        self.order.get(self.progress.pos).copied()
    }

    /// Updates the progress with a logged event; the error says why the
    /// event does not fit.
    fn apply(&mut self, design: &Design, event: &Event) -> std::result::Result<(), String> {
        self.progress.apply(&self.order, design, event)?;
        self.saved.push(event.clone());
        Ok(())
    }

    /// Logs `event` and applies it.
    fn record(&mut self, design: &Design, event: Event) -> std::result::Result<(), Refused> {
        // Check before writing: a line that does not fit is never logged,
        // and a line that could not be written is not counted.
        let before = self.progress.clone();
        if let Err(why) = self.apply(design, &event) {
            self.progress = before;
            return Err(Refused::NotOpen(why));
        }
        if let Err(e) = self.log.append(event) {
            self.progress = before;
            self.saved.pop();
            return Err(Refused::Storage(e.to_string()));
        }
        Ok(())
    }

    /// Where the participant is now.
    pub fn phase(&self, design: &Design) -> Phase {
        let p = &self.progress;
        let Some(c) = self.current() else {
            return Phase::Done;
        };
        if !p.started {
            return Phase::Intro;
        }
        if p.answered > p.surveyed {
            return Phase::Survey {
                query: Some(p.surveyed),
            };
        }
        if p.shown > p.answered {
            return Phase::Task {
                query: Some(p.answered),
            };
        }
        if p.surveyed == design.query_times_s(c).len() && p.task_s >= design.duration_s() {
            return Phase::Survey { query: None };
        }
        Phase::Task { query: None }
    }

    /// Surveys submitted so far, and conditions done of all.
    pub fn counts(&self) -> Tally {
        Tally::of(&self.progress, self.order.len())
    }

    /// Real time since the page last asked for the state.
    pub fn last_seen(&self) -> Option<Duration> {
        self.last_seen.map(|t| t.elapsed())
    }

    /// Moves the task clock to `now` and opens a query that is due. Called
    /// on every request from the participant's page.
    pub fn tick(&mut self, design: &Design, now: Instant, away: Duration) -> Result<()> {
        self.last_seen = Some(now);
        let Some(c) = self.current() else {
            return Ok(());
        };
        let scale = design.config().time_scale;
        match self.phase(design) {
            Phase::Task { query } => {
                let times = design.query_times_s(c);
                match self.last_tick {
                    Some(t) if now.duration_since(t) <= away => {
                        let mut task =
                            self.progress.task_s + now.duration_since(t).as_secs_f64() * scale;
                        if self.progress.surveyed == times.len() && query.is_none() {
                            // No query left: the condition ends on time.
                            task = task.min(design.duration_s().max(self.progress.task_s));
                        }
                        self.progress.task_s = task;
                    }
                    _ => {
                        if self.resumed_pending || self.last_tick.is_some() {
                            // Back after a restart or an absence: say so in the log.
                            self.log.append(Event::Resumed {
                                condition: Some(design.conditions()[c].id.clone()),
                                task_s: self.progress.task_s,
                                replayed: None,
                            })?;
                        }
                    }
                }
                self.resumed_pending = false;
                self.last_tick = Some(now);
                let p = &self.progress;
                if query.is_none()
                    && p.shown == p.surveyed
                    && p.shown < times.len()
                    && p.task_s >= times[p.shown]
                {
                    let k = p.shown;
                    let factors = design.conditions()[c].queries.expect("query condition");
                    let event = Event::QueryShown {
                        condition: design.conditions()[c].id.clone(),
                        query: k,
                        task_s: round3(p.task_s),
                        difficulty: factors.difficulty,
                        response: design.response_type(self.number, c, k),
                    };
                    self.record(design, event).map_err(refused_to_error)?;
                    self.query_shown_at = Some(now);
                }
                if matches!(self.phase(design), Phase::Task { query: Some(_) })
                    && self.query_shown_at.is_none()
                {
                    self.query_shown_at = Some(now);
                }
            }
            Phase::Survey { .. } => {
                self.last_tick = None;
                self.survey_shown_at.get_or_insert(now);
            }
            Phase::Intro | Phase::Done => self.last_tick = None,
        }
        if matches!(self.phase(design), Phase::Survey { .. }) {
            self.survey_shown_at.get_or_insert(now);
        }
        Ok(())
    }

    /// The query open now, with its materials.
    pub fn open_query(&self, design: &Design) -> Option<(usize, StudyQuery)> {
        let Phase::Task { query: Some(k) } = self.phase(design) else {
            return None;
        };
        Some((k, self.query_at(design, self.current()?, k)))
    }

    /// The query `k` of condition `c` for this participant.
    pub fn query_at(&self, design: &Design, c: usize, k: usize) -> StudyQuery {
        let factors = design.conditions()[c].queries.expect("query condition");
        materials::study_query(
            design.config().seed,
            [self.number as u64, c as u64, k as u64],
            factors.difficulty,
            design.response_type(self.number, c, k),
        )
    }

    /// Where a submission about `condition` / `item` stands relative to
    /// the participant's progress: `Some(true)` if it is in the past.
    fn is_past(&self, design: &Design, condition: &str, item_done: bool) -> Option<bool> {
        let (idx, _) = design.condition(condition)?;
        let pos = self.order.iter().position(|&c| c == idx)?;
        Some(pos < self.progress.pos || (pos == self.progress.pos && item_done))
    }

    /// A submission for a place the participant has passed: saved already
    /// if `saved_at` finds the same contents (`sent`) logged there,
    /// otherwise refused, saying what was saved at `place` or that nothing
    /// was asked there.
    fn resubmitted(
        &self,
        place: String,
        saved_at: impl Fn(&Event) -> Option<Value>,
        sent: Value,
    ) -> std::result::Result<Submitted, Refused> {
        match self.saved.iter().find_map(saved_at) {
            Some(saved) if saved == sent => Ok(Submitted::AlreadySaved),
            Some(saved) => Err(Refused::NotOpen(format!(
                "{place} was saved already as {saved}; it stays (sent: {sent})"
            ))),
            None => Err(Refused::NotOpen(format!(
                "nothing was asked at {place}, and it is past"
            ))),
        }
    }

    /// Starts the condition `condition` (the current one).
    pub fn start(
        &mut self,
        design: &Design,
        condition: &str,
        now: Instant,
    ) -> std::result::Result<Submitted, Refused> {
        if self.is_past(design, condition, self.progress.started) == Some(true) {
            return Ok(Submitted::AlreadySaved);
        }
        self.record(
            design,
            Event::ConditionStarted {
                condition: condition.to_string(),
            },
        )?;
        self.last_tick = Some(now);
        self.resumed_pending = false;
        Ok(Submitted::Saved)
    }

    /// Records the answer to query `k` of `condition`.
    pub fn answer(
        &mut self,
        design: &Design,
        condition: &str,
        k: usize,
        answer: Answer,
        now: Instant,
    ) -> std::result::Result<Submitted, Refused> {
        if self.is_past(design, condition, k < self.progress.answered) == Some(true) {
            return self.resubmitted(
                format!("the answer to query {k} of condition `{condition}`"),
                |e| match e {
                    Event::QueryAnswered {
                        condition: c,
                        query,
                        answer,
                        ..
                    } if c == condition && *query == k => Some(json!(answer)),
                    _ => None,
                },
                json!(answer),
            );
        }
        let Some((open, q)) = self.open_query(design) else {
            return Err(Refused::NotOpen("no query is open".into()));
        };
        if open != k {
            return Err(Refused::NotOpen(format!("query {k} is not open")));
        }
        let (correct, iou) = check_answer(&q.expected, &answer)?;
        let response_time_s = self
            .query_shown_at
            .map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        self.record(
            design,
            Event::QueryAnswered {
                condition: condition.to_string(),
                query: k,
                task_s: round3(self.progress.task_s),
                answer,
                response_time_s: round3(response_time_s),
                correct,
                iou: iou.map(round3),
            },
        )?;
        self.query_shown_at = None;
        self.survey_shown_at = Some(now);
        self.last_tick = None;
        Ok(Submitted::Saved)
    }

    /// Records a survey after query `query` (or at the end, `None`).
    pub fn survey(
        &mut self,
        design: &Design,
        condition: &str,
        query: Option<usize>,
        tlx: TlxAnswers,
        now: Instant,
    ) -> std::result::Result<Submitted, Refused> {
        let done = match query {
            Some(k) => k < self.progress.surveyed,
            None => false,
        };
        if self.is_past(design, condition, done) == Some(true) {
            let place = match query {
                Some(k) => format!("the survey after query {k} of condition `{condition}`"),
                None => format!("the end-of-condition survey of `{condition}`"),
            };
            return self.resubmitted(
                place,
                |e| match e {
                    Event::SurveySubmitted {
                        condition: c,
                        query: q,
                        tlx,
                        ..
                    } if c == condition && *q == query => Some(json!(tlx)),
                    _ => None,
                },
                json!(tlx),
            );
        }
        if self.phase(design) != (Phase::Survey { query }) {
            return Err(Refused::NotOpen("this survey is not open".into()));
        }
        let tlx = TlxAnswers::new(
            tlx.mental,
            tlx.temporal,
            tlx.performance,
            tlx.effort,
            tlx.frustration,
        )
        .map_err(|e| Refused::Invalid(e.to_string()))?;
        let survey_time_s = self
            .survey_shown_at
            .map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        self.record(
            design,
            Event::SurveySubmitted {
                condition: condition.to_string(),
                query,
                task_s: round3(self.progress.task_s),
                tlx,
                survey_time_s: (survey_time_s * 10.0).round() / 10.0,
            },
        )?;
        self.survey_shown_at = None;
        // The task clock restarts now.
        self.last_tick = Some(now);
        Ok(Submitted::Saved)
    }

    /// Records distraction answer `index` of `condition`.
    pub fn distraction(
        &mut self,
        design: &Design,
        condition: &str,
        index: usize,
        answer: String,
        materials: &crate::materials::Materials,
    ) -> std::result::Result<Submitted, Refused> {
        if self.is_past(design, condition, index < self.progress.distraction_answers) == Some(true)
        {
            return self.resubmitted(
                format!("task answer {index} of condition `{condition}`"),
                |e| match e {
                    Event::DistractionAnswered {
                        condition: c,
                        index: i,
                        answer,
                        ..
                    } if c == condition && *i == index => Some(json!(answer)),
                    _ => None,
                },
                json!(answer),
            );
        }
        if !matches!(self.phase(design), Phase::Task { .. }) {
            return Err(Refused::NotOpen(
                "the distraction task is not running".into(),
            ));
        }
        if answer.chars().count() > 2000 {
            return Err(Refused::Invalid("at most 2000 characters".into()));
        }
        let c = self.current().expect("in a condition");
        let correct = match design.conditions()[c].distraction {
            hil_core::Distraction::Easy => {
                let (a, b) = materials.addition(design, self.number, c, index);
                Some(answer.trim().parse::<u64>().ok() == Some(u64::from(a) + u64::from(b)))
            }
            hil_core::Distraction::Hard => None,
            hil_core::Distraction::None => {
                return Err(Refused::NotOpen(
                    "this condition has no distraction task".into(),
                ));
            }
        };
        self.record(
            design,
            Event::DistractionAnswered {
                condition: condition.to_string(),
                task_s: round3(self.progress.task_s),
                index,
                answer,
                correct,
            },
        )?;
        Ok(Submitted::Saved)
    }

    /// What the participant's page shows now.
    pub fn view(&self, design: &Design, materials: &crate::materials::Materials) -> Value {
        let phase = self.phase(design);
        let Some(c) = self.current() else {
            return json!({"phase": "done", "participant": self.id});
        };
        let cond = &design.conditions()[c];
        let p = &self.progress;
        let distraction = match cond.distraction {
            hil_core::Distraction::None => json!({"type": "none"}),
            hil_core::Distraction::Easy => {
                let (a, b) = materials.addition(design, self.number, c, p.distraction_answers);
                json!({"type": "addition", "index": p.distraction_answers, "a": a, "b": b})
            }
            hil_core::Distraction::Hard => {
                let n = materials::revealed_words(p.task_s, materials.words_per_min);
                let words = &materials.passage;
                let from = n.saturating_sub(12);
                let shown: Vec<&str> = (from..n).map(|i| words[i % words.len()].as_str()).collect();
                json!({"type": "transcription", "index": p.distraction_answers, "words": shown})
            }
        };
        let mut v = json!({
            "phase": match phase {
                Phase::Intro => "intro",
                Phase::Task { .. } => "task",
                Phase::Survey { .. } => "survey",
                Phase::Done => "done",
            },
            "participant": self.id,
            "condition": {
                "id": cond.id,
                "number": p.pos + 1,
                "of": self.order.len(),
                "distraction": cond.distraction.as_str(),
                "queries": cond.queries.is_some(),
            },
            "distraction": distraction,
            "task_s": p.task_s,
            "duration_s": design.duration_s(),
        });
        if let Some((k, q)) = self.open_query(design) {
            let (options, kind) = match &q.expected {
                Expected::Choice { options, .. } => (options.clone(), "mcq"),
                Expected::Box { .. } => (Vec::new(), "bounding_box"),
                Expected::Text => (Vec::new(), "open_ended"),
            };
            v["query"] = json!({
                "number": k,
                "question": q.question,
                "kind": kind,
                "options": options,
                "pictures": (0..q.pictures.len())
                    .map(|i| format!("image/{}/{k}/{i}", cond.id))
                    .collect::<Vec<_>>(),
                "alt": q.pictures.iter().map(materials::describe).collect::<Vec<_>>(),
            });
        }
        if let Phase::Survey { query } = phase {
            v["survey"] = json!({
                "query": query,
                "questions": crate::tlx::questions(self.population),
            });
        }
        v
    }
}

/// Checks an answer against what the query expects.
fn check_answer(
    expected: &Expected,
    answer: &Answer,
) -> std::result::Result<(Option<bool>, Option<f64>), Refused> {
    match (expected, answer) {
        (_, Answer::Declined) => Ok((None, None)),
        (Expected::Choice { options, correct }, Answer::Label { label }) => {
            if options.contains(label) {
                Ok((Some(label == correct), None))
            } else {
                Err(Refused::Invalid(format!(
                    "`{label}` is not one of the choices"
                )))
            }
        }
        (Expected::Box { truth }, Answer::BoundingBox { bbox }) => {
            let ok = [bbox.x0, bbox.y0, bbox.x1, bbox.y1]
                .iter()
                .all(|v| v.is_finite() && (0.0..=1.0).contains(v))
                && bbox.x0 < bbox.x1
                && bbox.y0 < bbox.y1;
            if ok {
                Ok((None, Some(materials::iou(truth, bbox))))
            } else {
                Err(Refused::Invalid(
                    "a box needs 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1".into(),
                ))
            }
        }
        (Expected::Text, Answer::Text { text }) => {
            if text.trim().is_empty() || text.chars().count() > 2000 {
                Err(Refused::Invalid(
                    "the answer must be 1 to 2000 characters".into(),
                ))
            } else {
                Ok((None, None))
            }
        }
        _ => Err(Refused::Invalid(
            "this kind of answer does not fit the question".into(),
        )),
    }
}

fn refused_to_error(r: Refused) -> HilError {
    match r {
        Refused::NotOpen(w) | Refused::Invalid(w) | Refused::Storage(w) => {
            HilError::state("study session", w)
        }
    }
}

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}
