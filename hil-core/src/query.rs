//! Queries to the human and their responses.
//!
//! A query carries the paper's three query variables (response type,
//! difficulty, distraction) so that the workload model sees exactly what was
//! asked.

use serde::{Deserialize, Serialize};

use crate::action::{ActionSpace, ArmId};
use crate::context::{Context, Item};
use crate::time::Timestep;

/// How the person answers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ResponseType {
    /// Multiple choice (a semantic label or an action).
    #[default]
    Mcq,
    /// Draw a bounding box around an item.
    BoundingBox,
    /// Free text, e.g. why an attempt failed.
    OpenEnded,
}

/// How hard the question is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Difficulty {
    /// Easy question.
    #[default]
    Easy,
    /// Hard question.
    Hard,
}

/// What else the person is doing when asked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Distraction {
    /// No concurrent task.
    #[default]
    None,
    /// An easy concurrent task (e.g. simple additions).
    Easy,
    /// A hard concurrent task (e.g. transcribing a video).
    Hard,
}

impl ResponseType {
    /// All variants in one-hot order.
    pub const ALL: [Self; 3] = [Self::Mcq, Self::BoundingBox, Self::OpenEnded];
}
impl Difficulty {
    /// All variants in one-hot order.
    pub const ALL: [Self; 2] = [Self::Easy, Self::Hard];
}
impl Distraction {
    /// All variants in one-hot order.
    pub const ALL: [Self; 3] = [Self::None, Self::Easy, Self::Hard];
}

/// The kind of a query: the variables that drive querying workload.
///
/// The default is the paper's simulation default: an easy multiple-choice
/// question with no distraction.
///
/// It is written as a table of its fields, and read from one or from its
/// text form (`"open_ended/hard"`, see [`FromStr`](std::str::FromStr)), so
/// a config may say `query_kind = "bounding_box/hard/easy"`.
///
/// ```
/// use hil_core::{QueryKind, ResponseType, Difficulty, Distraction};
/// let k = QueryKind::default();
/// assert_eq!((k.response, k.difficulty, k.distraction),
///            (ResponseType::Mcq, Difficulty::Easy, Distraction::None));
/// let text: QueryKind = serde_json::from_str(r#""open_ended/hard""#).unwrap();
/// let table: QueryKind =
///     serde_json::from_str(r#"{"response": "open_ended", "difficulty": "hard"}"#).unwrap();
/// assert_eq!(text, table);
/// assert!(serde_json::from_str::<QueryKind>(r#""mcq/medium""#).is_err());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
pub struct QueryKind {
    /// How the person answers.
    pub response: ResponseType,
    /// How hard the question is.
    pub difficulty: Difficulty,
    /// What else the person is doing.
    pub distraction: Distraction,
}

/// The table form of [`QueryKind`], read with serde's own checks (unknown
/// fields refused, missing ones defaulted).
#[derive(Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct QueryKindTable {
    response: ResponseType,
    difficulty: Difficulty,
    distraction: Distraction,
}

impl<'de> Deserialize<'de> for QueryKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Either;
        impl<'de> serde::de::Visitor<'de> for Either {
            type Value = QueryKind;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(
                    "a query kind: text `response/difficulty/distraction` \
                     (e.g. \"mcq/easy/none\") or a table of those fields",
                )
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> std::result::Result<QueryKind, E> {
                s.parse().map_err(E::custom)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> std::result::Result<QueryKind, A::Error> {
                let t =
                    QueryKindTable::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                Ok(QueryKind {
                    response: t.response,
                    difficulty: t.difficulty,
                    distraction: t.distraction,
                })
            }
        }
        d.deserialize_any(Either)
    }
}

/// One spelling per variant, shared by `Display` and `FromStr` (and so by
/// every CSV column, CLI flag and label that names a query variable).
macro_rules! spelled {
    ($t:ty, $what:literal, $($v:ident => $s:literal),+ $(,)?) => {
        impl $t {
            /// The variable's spelling, as configs and data files write it.
            pub const fn as_str(self) -> &'static str {
                match self { $(Self::$v => $s),+ }
            }
        }
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.as_str())
            }
        }
        impl std::str::FromStr for $t {
            type Err = crate::error::HilError;
            fn from_str(s: &str) -> crate::error::Result<Self> {
                match s.trim() {
                    $($s => Ok(Self::$v),)+
                    other => Err(crate::error::HilError::invalid_parameter(
                        $what,
                        format!("`{other}`"),
                        format!("expected one of: {}", [$($s),+].join(", ")),
                    )),
                }
            }
        }
    };
}
spelled!(ResponseType, "response type", Mcq => "mcq", BoundingBox => "bounding_box", OpenEnded => "open_ended");
spelled!(Difficulty, "difficulty", Easy => "easy", Hard => "hard");
spelled!(Distraction, "distraction", None => "none", Easy => "easy", Hard => "hard");

/// `response/difficulty/distraction`, e.g. `mcq/easy/none`.
///
/// ```
/// use hil_core::QueryKind;
/// let k: QueryKind = "bounding_box/hard/easy".parse().unwrap();
/// assert_eq!(k.to_string(), "bounding_box/hard/easy");
/// // Trailing parts may be left out; they keep their defaults.
/// assert_eq!("open_ended".parse::<QueryKind>().unwrap().to_string(), "open_ended/easy/none");
/// assert!("mcq/medium".parse::<QueryKind>().is_err());
/// assert!("".parse::<QueryKind>().is_err());
/// ```
impl std::fmt::Display for QueryKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}/{}/{}",
            self.response, self.difficulty, self.distraction
        )
    }
}

impl std::str::FromStr for QueryKind {
    type Err = crate::error::HilError;
    fn from_str(s: &str) -> crate::error::Result<Self> {
        let mut k = QueryKind::default();
        let parts: Vec<&str> = s.split('/').map(str::trim).collect();
        if parts.iter().all(|p| p.is_empty()) {
            // "" or "//" names nothing: the default must be asked for.
            return Err(crate::error::HilError::invalid_parameter(
                "query kind",
                format!("`{s}`"),
                "names no response type (e.g. `mcq`, `mcq/easy/none`)",
            ));
        }
        if parts.len() > 3 {
            return Err(crate::error::HilError::invalid_parameter(
                "query kind",
                format!("`{s}`"),
                "expected at most response/difficulty/distraction",
            ));
        }
        for (i, part) in parts.iter().enumerate().filter(|(_, p)| !p.is_empty()) {
            match i {
                0 => k.response = part.parse()?,
                1 => k.difficulty = part.parse()?,
                _ => k.distraction = part.parse()?,
            }
        }
        Ok(k)
    }
}

/// Everything a channel needs to pose one query.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Query {
    /// Session timestep of the query.
    pub t: Timestep,
    /// The item the robot is working on.
    pub item: Item,
    /// The kind of question asked.
    pub kind: QueryKind,
    /// The robot actions the person may choose from.
    pub actions: ActionSpace,
    /// The context the policy saw (channels may show a rendering of it).
    pub context: Context,
    /// The best action, when the environment is simulated and knows it.
    /// Only simulated experts may read this; a human channel must not show it.
    pub oracle_best: Option<ArmId>,
}

impl Query {
    /// A query of `kind` at timestep `t` about `item`, seen as `context`,
    /// answered from `actions`.
    ///
    /// ```
    /// use hil_core::{ActionSpace, ArmId, Context, Item, Query, QueryKind};
    /// let q = Query::new(1, Item::new(0, "banana"), QueryKind::default(),
    ///     ActionSpace::new(["a", "b"]).unwrap(), Context::new(vec![0.0; 4]).unwrap())
    ///     .with_oracle_best(ArmId(1));
    /// assert_eq!(q.oracle_best, Some(ArmId(1)));
    /// ```
    pub fn new(
        t: Timestep,
        item: Item,
        kind: QueryKind,
        actions: ActionSpace,
        context: Context,
    ) -> Self {
        Self {
            t,
            item,
            kind,
            actions,
            context,
            oracle_best: None,
        }
    }

    /// With the best action, known to a simulated environment (`None`: not
    /// known).
    pub fn with_oracle_best(mut self, arm: impl Into<Option<ArmId>>) -> Self {
        self.oracle_best = arm.into();
        self
    }
}

/// An axis-aligned box in normalised image coordinates (0..1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct BoundingBox {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
}

impl BoundingBox {
    /// The box from (`x0`, `y0`) to (`x1`, `y1`), in normalised image coordinates.
    pub fn new(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Self { x0, y0, x1, y1 }
    }
}

/// What the person answered.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Answer {
    /// A robot action to use.
    Action {
        /// The chosen arm.
        arm: ArmId,
    },
    /// A semantic label (e.g. the food's name).
    Label {
        /// The label.
        label: String,
    },
    /// A bounding box around the item.
    BoundingBox {
        /// The box.
        bbox: BoundingBox,
    },
    /// Free text.
    Text {
        /// The text.
        text: String,
    },
    /// The person said they do not know.
    Declined,
    /// No answer arrived in time.
    TimedOut,
}

/// A channel's response to a [`Query`].
///
/// ```
/// use hil_core::{ArmId, Response};
/// let r = Response::action(ArmId(2)).with_response_time(1.5);
/// assert_eq!((r.expert_arm, r.response_time_s), (Some(ArmId(2)), Some(1.5)));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Response {
    /// What the person answered.
    pub answer: Answer,
    /// The robot action the answer implies, if any. For [`Answer::Action`]
    /// this is that arm; channels may map other answers to an action too.
    pub expert_arm: Option<ArmId>,
    /// Seconds the person took to answer, when measured or simulated.
    pub response_time_s: Option<f64>,
}

impl Response {
    /// `answer`, implying the robot action `expert_arm` (if any), given in
    /// `response_time_s` seconds (when measured).
    pub fn new(answer: Answer, expert_arm: Option<ArmId>, response_time_s: Option<f64>) -> Self {
        Self {
            answer,
            expert_arm,
            response_time_s,
        }
    }

    /// A response choosing `arm`.
    pub fn action(arm: ArmId) -> Self {
        Self::new(Answer::Action { arm }, Some(arm), None)
    }

    /// A response with no usable action.
    pub fn without_action(answer: Answer) -> Self {
        Self::new(answer, None, None)
    }

    /// With the seconds the person took to answer (`None`: not measured).
    pub fn with_response_time(mut self, seconds: impl Into<Option<f64>>) -> Self {
        self.response_time_s = seconds.into();
        self
    }
}
