//! A channel wrapper that answers replayed queries from the log.

use std::collections::VecDeque;
use std::path::PathBuf;

use hil_core::channel::QueryChannel;
use hil_core::error::{HilError, Result};
use hil_core::query::{Query, Response};
use hil_core::time::Timestep;

/// A logged answer: episode, timestep, the response and its log line.
pub type LoggedAnswer = (usize, Timestep, Response, usize);

/// Answers the queries a resumed session replays with the person's logged
/// responses (a person must never be asked twice), then passes later
/// queries to the live channel.
pub struct ReplayChannel<'a> {
    /// The live channel, asked once the logged answers run out.
    pub inner: &'a mut dyn QueryChannel,
    /// The logged answers still to give, in order.
    pub logged: VecDeque<LoggedAnswer>,
    /// The episode being replayed (a logged answer must belong to it).
    pub episode: usize,
    /// The log's path, for errors.
    pub path: PathBuf,
}

impl std::fmt::Debug for ReplayChannel<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReplayChannel")
            .field("inner", &self.inner.name())
            .field("logged", &self.logged.len())
            .field("episode", &self.episode)
            .field("path", &self.path)
            .finish()
    }
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
