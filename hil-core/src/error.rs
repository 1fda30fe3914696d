//! The one error type every trait method returns.
//!
//! Variants are structured (like faer's errors) so that callers can react to
//! the kind of failure, and every message names what was wrong and where.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// Result alias used across hil.
pub type Result<T, E = HilError> = std::result::Result<T, E>;

/// An underlying error kept as an [`HilError`]'s source, so a caller can
/// walk the chain or downcast it (e.g. to the simulator's own error type).
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Errors raised by hil components.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HilError {
    /// A value handed to a component is outside what it accepts.
    #[error("invalid {what}: {why}")]
    InvalidInput {
        /// The value at fault, e.g. `context[3]` or `arm`.
        what: String,
        /// Why it was rejected, including the offending value.
        why: String,
    },
    /// A context has the wrong dimension.
    #[error("context dimension mismatch: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Dimension the component was built for.
        expected: usize,
        /// Dimension it received.
        got: usize,
    },
    /// An arm index is not in the action space.
    #[error("arm {arm} is out of range: the action space has {n_arms} arms")]
    ArmOutOfRange {
        /// The offending arm index.
        arm: usize,
        /// Number of arms available.
        n_arms: usize,
    },
    /// A hyperparameter or configuration value failed validation.
    #[error("invalid parameter `{name}` = {value}: {why}")]
    InvalidParameter {
        /// Parameter name as it appears in configs.
        name: String,
        /// The rejected value, rendered.
        value: String,
        /// The rule it broke.
        why: String,
    },
    /// A configuration file could not be parsed or validated.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Reading or writing a file failed.
    #[error("{op} {}: {source}", path.display())]
    Io {
        /// What was being done (`reading`, `writing`, ...).
        op: &'static str,
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A data file is malformed.
    #[error("{}:{record}: field `{field}`: {why}", path.display())]
    Data {
        /// The file at fault.
        path: PathBuf,
        /// Line or record number (1-based) at fault.
        record: usize,
        /// Column or field at fault.
        field: String,
        /// What is wrong with it.
        why: String,
    },
    /// (De)serialising state or parameters failed: almost always reading
    /// one that is malformed (a missing field, a wrong type), so the
    /// message says what was invalid, not which direction failed.
    #[error("invalid {what}: {source}")]
    Serde {
        /// What was being (de)serialised.
        what: String,
        /// The serialiser's error (e.g. a `serde_json::Error`).
        #[source]
        source: BoxError,
    },
    /// A numerical routine failed (e.g. a factorisation met a matrix that is
    /// not positive definite).
    #[error("{what}: {source}")]
    Numerical {
        /// What was being computed.
        what: String,
        /// The linear-algebra library's error.
        #[source]
        source: BoxError,
    },
    /// A component is in a state where the call makes no sense
    /// (e.g. `execute` before `next_item`).
    #[error("{component}: {why}")]
    State {
        /// The component that refused.
        component: String,
        /// What is wrong.
        why: String,
    },
    /// The implementation does not offer this operation at all (e.g. a
    /// policy that cannot checkpoint, or a build of `hil` without the
    /// MuJoCo physics), as opposed to refusing it in its current state
    /// ([`HilError::State`]). Callers may skip what is unsupported.
    #[error("{component} does not support {operation}: {why}")]
    Unsupported {
        /// The component (or program) asked.
        component: String,
        /// What it was asked to do.
        operation: String,
        /// Why not, and what to use or do instead.
        why: String,
    },
    /// A human (or channel) failed in a way the session cannot recover from.
    #[error("query channel `{channel}` failed: {why}")]
    Channel {
        /// Channel name.
        channel: String,
        /// What happened.
        why: String,
        /// The underlying error (e.g. the terminal's I/O error), if any.
        #[source]
        source: Option<BoxError>,
    },
    /// A simulator or external backend failed (diverged, crashed, missing library).
    #[error("backend `{backend}` failed: {why}")]
    Backend {
        /// Backend name.
        backend: String,
        /// What happened.
        why: String,
        /// The backend's own error (e.g. `hil_kinova_mujoco::KinovaError`), if any.
        #[source]
        source: Option<BoxError>,
    },
    /// A plugin failed to load, handshake or run.
    #[error("plugin {}: {why}", path.display())]
    Plugin {
        /// The shared library concerned.
        path: PathBuf,
        /// What happened.
        why: String,
    },
}

impl HilError {
    /// Shorthand for [`HilError::InvalidInput`].
    pub fn invalid_input(what: impl Into<String>, why: impl Into<String>) -> Self {
        Self::InvalidInput {
            what: what.into(),
            why: why.into(),
        }
    }

    /// Shorthand for [`HilError::InvalidParameter`]; the value is shortened
    /// by [`echo`].
    pub fn invalid_parameter(
        name: impl Into<String>,
        value: impl std::fmt::Display,
        why: impl Into<String>,
    ) -> Self {
        Self::InvalidParameter {
            name: name.into(),
            value: echo(&value.to_string()).into_owned(),
            why: why.into(),
        }
    }

    /// The same error, with an [`HilError::InvalidParameter`]'s name put
    /// under `table` (`crossover` becomes `estimator.crossover`) for a
    /// parameter checked by the code of a nested table; other errors as
    /// they are.
    ///
    /// ```
    /// use hil_core::HilError;
    /// let e = HilError::invalid_parameter("crossover", f64::NAN, "must be > 0").within("estimator");
    /// assert!(matches!(e, HilError::InvalidParameter { ref name, .. } if name == "estimator.crossover"));
    /// ```
    pub fn within(self, table: &str) -> Self {
        match self {
            Self::InvalidParameter { name, value, why } => Self::InvalidParameter {
                name: format!("{table}.{name}"),
                value,
                why,
            },
            other => other,
        }
    }

    /// Shorthand for [`HilError::State`].
    pub fn state(component: impl Into<String>, why: impl Into<String>) -> Self {
        Self::State {
            component: component.into(),
            why: why.into(),
        }
    }

    /// Shorthand for [`HilError::Unsupported`].
    ///
    /// ```
    /// use hil_core::HilError;
    /// let e = HilError::unsupported("my_policy", "checkpoints", "it keeps no state worth saving");
    /// assert!(matches!(e, HilError::Unsupported { .. }));
    /// ```
    pub fn unsupported(
        component: impl Into<String>,
        operation: impl Into<String>,
        why: impl Into<String>,
    ) -> Self {
        Self::Unsupported {
            component: component.into(),
            operation: operation.into(),
            why: why.into(),
        }
    }

    /// Shorthand for [`HilError::Serde`]: `source` is the serialiser's error
    /// (kept as the source) or a message.
    pub fn serde(what: impl Into<String>, source: impl Into<BoxError>) -> Self {
        Self::Serde {
            what: what.into(),
            source: source.into(),
        }
    }

    /// Shorthand for [`HilError::Numerical`].
    pub fn numerical(what: impl Into<String>, source: impl Into<BoxError>) -> Self {
        Self::Numerical {
            what: what.into(),
            source: source.into(),
        }
    }

    /// A [`HilError::Channel`] saying why `channel` failed.
    pub fn channel(channel: impl Into<String>, why: impl Into<String>) -> Self {
        Self::Channel {
            channel: channel.into(),
            why: why.into(),
            source: None,
        }
    }

    /// A [`HilError::Backend`] saying why `backend` failed.
    pub fn backend(backend: impl Into<String>, why: impl Into<String>) -> Self {
        Self::Backend {
            backend: backend.into(),
            why: why.into(),
            source: None,
        }
    }

    /// The same [`HilError::Channel`] or [`HilError::Backend`] error with
    /// `source` kept as its cause; other errors as they are.
    ///
    /// ```
    /// use std::error::Error;
    /// use hil_core::HilError;
    /// let io = std::io::Error::other("pipe closed");
    /// let e = HilError::channel("terminal", "terminal I/O failed").with_source(io);
    /// assert_eq!(e.source().unwrap().to_string(), "pipe closed");
    /// ```
    pub fn with_source(self, cause: impl Into<BoxError>) -> Self {
        match self {
            Self::Channel { channel, why, .. } => Self::Channel {
                channel,
                why,
                source: Some(cause.into()),
            },
            Self::Backend { backend, why, .. } => Self::Backend {
                backend,
                why,
                source: Some(cause.into()),
            },
            other => other,
        }
    }

    /// Shorthand for [`HilError::Io`].
    pub fn io(op: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            op,
            path: path.into(),
            source,
        }
    }
}

/// Most characters of an offending value that an error message repeats.
pub const ECHO_CHARS: usize = 64;

/// `value` as an error message repeats it: whole if it has at most
/// [`ECHO_CHARS`] characters, else its first [`ECHO_CHARS`] characters and
/// its length, so a 100 KB value in a config never becomes a 100 KB
/// message. Every error that quotes a value it was given goes through this.
///
/// ```
/// use hil_core::error::echo;
/// assert_eq!(echo("0.5"), "0.5");
/// let long = "x".repeat(100_000);
/// let shown = echo(&long);
/// assert!(shown.starts_with("xxxx") && shown.ends_with("(100000 bytes)"));
/// assert!(shown.len() < 100);
/// ```
pub fn echo(value: &str) -> Cow<'_, str> {
    match value.char_indices().nth(ECHO_CHARS) {
        None => Cow::Borrowed(value),
        Some((cut, _)) => Cow::Owned(format!("{}… ({} bytes)", &value[..cut], value.len())),
    }
}

/// A configuration error, located in its file. `hil_config` finds the
/// location (from the TOML parser and the field path).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}:{column}: {}{message}", path.display(), field.as_ref().map(|f| format!("field `{f}`: ")).unwrap_or_default())]
pub struct ConfigError {
    /// The file at fault.
    pub path: PathBuf,
    /// 1-based line (0 if unknown).
    pub line: usize,
    /// 1-based column (0 if unknown).
    pub column: usize,
    /// Dotted path of the field at fault, e.g. `policy.alpha`.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl ConfigError {
    /// The error `message` about `field` at `line`:`column` of `path`
    /// (0 where unknown). The field and any value the message quotes are
    /// shortened by [`echo`], so a 100 KB key or value never becomes a
    /// 100 KB message.
    pub fn new(
        path: &Path,
        line: usize,
        column: usize,
        field: Option<String>,
        message: &str,
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            column,
            field: field.map(|f| echo(&f).into_owned()),
            message: echo_quoted(message),
        }
    }
}

/// `message` with every `` `quoted` `` or `"quoted"` part shortened by
/// [`echo`]; a message still longer than a few values (unbalanced quotes) is
/// shortened as a whole.
fn echo_quoted(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(1024));
    let mut rest = message;
    while let Some(open) = rest.find(['`', '"']) {
        let quote = &rest[open..open + 1];
        let Some(len) = rest[open + 1..].find(quote) else {
            break;
        };
        let inner = &rest[open + 1..open + 1 + len];
        out.push_str(&rest[..=open]);
        out.push_str(&echo(inner));
        out.push_str(quote);
        rest = &rest[open + 2 + len..];
    }
    out.push_str(rest);
    if out.chars().count() > 8 * ECHO_CHARS {
        let cut = out
            .char_indices()
            .nth(8 * ECHO_CHARS)
            .map_or(out.len(), |(i, _)| i);
        out = format!("{}… ({} bytes)", &out[..cut], message.len());
    }
    out
}
