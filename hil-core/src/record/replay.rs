//! A channel wrapper that answers replayed queries from the log.

use std::collections::VecDeque;
use std::path::PathBuf;

use crate::channel::QueryChannel;
use crate::error::{HilError, Result};
use crate::query::{Query, Response};
use crate::time::Timestep;

/// A logged answer: episode, timestep, the response and its log line.
pub(crate) type LoggedAnswer = (usize, Timestep, Response, usize);

/// Answers the queries a resumed session replays with the person's logged
/// responses (a person must never be asked twice), then passes later
/// queries to the live channel.
pub(crate) struct ReplayChannel<'a> {
    pub(crate) inner: &'a mut dyn QueryChannel,
    pub(crate) logged: VecDeque<LoggedAnswer>,
    pub(crate) episode: usize,
    pub(crate) path: PathBuf,
}

impl QueryChannel for ReplayChannel<'_> {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn seed(&mut self, seed: u64) {
        self.inner.seed(seed);
    }

    fn endpoint(&self) -> Option<String> {
        self.inner.endpoint()
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        let Some((episode, t, _, line)) = self.logged.front() else {
            return self.inner.ask(query);
        };
        if (*episode, *t) != (self.episode, query.t) {
            return Err(HilError::Data {
                path: self.path.clone(),
                record: *line,
                field: "step.response".into(),
                why: format!(
                    "the resumed session diverged from the log: it asks at episode {} t = {}, \
                     but the next logged answer is for episode {episode} t = {t}",
                    self.episode, query.t
                ),
            });
        }
        let (_, _, response, _) = self.logged.pop_front().expect("front exists");
        Ok(response)
    }
}
