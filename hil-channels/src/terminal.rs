//! A query channel for a person at a terminal.

use std::io::{BufRead, BufReader, Stderr, Stdin, Write};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use hil_config::QueryChannelConfig;
use hil_core::{
    Answer, BoundingBox, HilError, Query, QueryChannel, Response, ResponseType, Result,
};

use crate::present::{
    check_bbox, check_text, describe_item, describe_kind, question, validate_answer,
};
use hil_config::TaskContext;

/// Config of the terminal channel, `type = "terminal"` (no parameters): the
/// prompt is written to standard error and answers are read from standard
/// input, so `--json` output on standard output stays clean.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerminalChannelConfig {}

#[typetag::serde(name = "terminal")]
impl QueryChannelConfig for TerminalChannelConfig {
    fn build(&self, _ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        Ok(Box::new(TerminalChannel::stdio()))
    }
}

/// Asks queries at a terminal: the item, the kind of question (response
/// type, difficulty, distraction), then
///
/// - multiple choice: numbered actions, answered by number or name;
/// - bounding box: four numbers `x0 y0 x1 y1` in [0, 1] (left, top, right,
///   bottom of the box in the camera picture);
/// - open-ended: a line of text (naming one action, e.g. "TA0", makes the
///   robot use it).
///
/// `?` answers "I don't know" ([`Answer::Declined`]: the policy acts on its
/// own). An invalid answer is explained and asked again.
///
/// End of input (Ctrl-D) or `q` stops the session with an error saying so.
/// Ctrl-C is not seen by the channel: it interrupts the process (`hil run`
/// then prints where the log is and how to resume, and exits with status
/// 130). Either way every step answered before is already in the
/// interaction log, and `hil run --resume LOG` asks the unanswered query
/// again.
///
/// Generic over its reader and writer so that it can be driven by tests:
///
/// ```
/// use hil_channels::TerminalChannel;
/// use hil_core::{ArmId, Context, Item, Query, QueryChannel, QueryKind};
/// let input: &[u8] = b"7\n2\n";  // 7 is out of range: asked again
/// let mut out = Vec::new();
/// let mut ch = TerminalChannel::new(input, &mut out);
/// let actions = hil_envs::feeding::action_space();
/// let context = Context::new(vec![0.0]).unwrap();
/// let q = Query::new(1, Item::new(0, "banana"), QueryKind::default(), actions, context);
/// assert_eq!(ch.ask(&q).unwrap().expert_arm, Some(ArmId(1)));
/// drop(ch);
/// assert!(String::from_utf8(out).unwrap().contains("2) VS90"));
/// ```
#[derive(Debug)]
pub struct TerminalChannel<R, W> {
    input: R,
    output: W,
}

impl TerminalChannel<BufReader<Stdin>, Stderr> {
    /// A channel on standard input and standard error.
    pub fn stdio() -> Self {
        Self::new(BufReader::new(std::io::stdin()), std::io::stderr())
    }
}

/// What one line of input meant.
enum Parsed {
    Answer(Answer),
    Retry(String),
    Quit,
}

impl<R: BufRead, W: Write> TerminalChannel<R, W> {
    /// A channel reading answers from `input` and writing prompts to `output`.
    pub fn new(input: R, output: W) -> Self {
        Self { input, output }
    }

    fn io_err(&self, e: std::io::Error) -> HilError {
        HilError::channel("terminal", format!("terminal I/O failed: {e}")).with_source(e)
    }

    fn show(&mut self, query: &Query) -> std::io::Result<()> {
        let o = &mut self.output;
        writeln!(o)?;
        writeln!(
            o,
            "── The robot asks (step {}, item {}) ──",
            query.t,
            query.item.index + 1
        )?;
        writeln!(o, "Item: {}", describe_item(query))?;
        writeln!(o, "Kind: {}", describe_kind(&query.kind))?;
        writeln!(o, "{}", question(query))?;
        match query.kind.response {
            ResponseType::Mcq => {
                for (i, name) in query.actions.names().iter().enumerate() {
                    write!(o, "  {}) {name}", i + 1)?;
                }
                writeln!(o)?;
                writeln!(
                    o,
                    "Type the number or name of the action, ? if you don't know, q to stop."
                )?;
            }
            ResponseType::BoundingBox => {
                writeln!(
                    o,
                    "Type x0 y0 x1 y1 between 0 and 1 (left top right bottom of the box in the \
                     picture, e.g. 0.3 0.3 0.7 0.7), ? if you don't know, q to stop."
                )?;
            }
            ResponseType::OpenEnded => {
                writeln!(
                    o,
                    "Type your answer on one line, ? if you don't know, q to stop."
                )?;
            }
        }
        Ok(())
    }

    fn parse(query: &Query, line: &str) -> Parsed {
        let line = line.trim();
        match line {
            "?" => return Parsed::Answer(Answer::Declined),
            "q" | "Q" => return Parsed::Quit,
            "" => return Parsed::Retry("please type an answer".into()),
            _ => {}
        }
        match query.kind.response {
            ResponseType::Mcq => {
                let arm = match line.parse::<usize>() {
                    Ok(n) if (1..=query.actions.len()).contains(&n) => Some(n - 1),
                    Ok(_) => None,
                    Err(_) => query
                        .actions
                        .names()
                        .iter()
                        .position(|a| a.eq_ignore_ascii_case(line)),
                };
                match arm {
                    Some(a) => Parsed::Answer(Answer::Action {
                        arm: hil_core::ArmId(a),
                    }),
                    None => Parsed::Retry(format!(
                        "`{line}` is not one of the choices: type a number from 1 to {}",
                        query.actions.len()
                    )),
                }
            }
            ResponseType::BoundingBox => {
                let nums: std::result::Result<Vec<f64>, _> = line
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|s| !s.is_empty())
                    .map(str::parse::<f64>)
                    .collect();
                match nums.as_deref() {
                    Ok([x0, y0, x1, y1]) => {
                        let bbox = BoundingBox::new(*x0, *y0, *x1, *y1);
                        match check_bbox(&bbox) {
                            Ok(()) => Parsed::Answer(Answer::BoundingBox { bbox }),
                            Err(why) => Parsed::Retry(why),
                        }
                    }
                    _ => Parsed::Retry("type four numbers: x0 y0 x1 y1".into()),
                }
            }
            ResponseType::OpenEnded => match check_text(line) {
                Ok(()) => Parsed::Answer(Answer::Text {
                    text: line.to_string(),
                }),
                Err(why) => Parsed::Retry(why),
            },
        }
    }
}

impl<R: BufRead + Send, W: Write + Send> QueryChannel for TerminalChannel<R, W> {
    fn name(&self) -> &str {
        "terminal"
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        let start = Instant::now();
        self.show(query).map_err(|e| self.io_err(e))?;
        loop {
            write!(self.output, "answer> ")
                .and_then(|()| self.output.flush())
                .map_err(|e| self.io_err(e))?;
            let mut line = String::new();
            let n = self
                .input
                .read_line(&mut line)
                .map_err(|e| self.io_err(e))?;
            if n == 0 {
                let _ = writeln!(self.output);
                return Err(HilError::channel(
                    "terminal",
                    format!(
                        "input ended before the query at step {} was answered; the session \
                         stops here (resume it with `hil run --resume LOG`)",
                        query.t
                    ),
                ));
            }
            match Self::parse(query, &line) {
                Parsed::Answer(answer) => {
                    let expert_arm = validate_answer(query, &answer)?;
                    let seconds = start.elapsed().as_secs_f64();
                    return Ok(Response::new(answer, expert_arm, Some(seconds)));
                }
                Parsed::Retry(why) => {
                    writeln!(self.output, "  {why}").map_err(|e| self.io_err(e))?;
                }
                Parsed::Quit => {
                    return Err(HilError::channel(
                        "terminal",
                        format!(
                            "the session was stopped at the terminal at step {} (resume it with \
                             `hil run --resume LOG`)",
                            query.t
                        ),
                    ));
                }
            }
        }
    }
}
