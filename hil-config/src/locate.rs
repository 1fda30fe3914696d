//! Locating a config error in its file: the line, column and dotted field
//! path of a TOML parse error or of a component's validation error.
//!
//! The field comes from structure: a deserialisation error's field path
//! from [`field_path`](crate::field_path) (a second pass over the parsed
//! document), a validation error's from its [`HilError::InvalidParameter`]
//! name. The line and column come from the span toml's parser gives the
//! key at that path ([`Spans`]). Message text is read in one case only: a
//! config type that reads its whole table before deserialising its parts
//! (see [`Spans::key_in_read_whole_table`]).

use std::ops::Range;
use std::path::Path;

use serde::de::DeserializeOwned;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use hil_core::{ConfigError, HilError};

use crate::field_path;

/// Parses TOML into `T`, turning errors into located [`ConfigError`]s.
///
/// ```
/// use std::path::Path;
/// #[derive(Debug, serde::Deserialize)]
/// #[serde(deny_unknown_fields)]
/// struct Settings { n_att: u32 }
/// #[derive(Debug, serde::Deserialize)]
/// struct File { session: Settings }
/// let e = hil_config::parse_toml::<File>("[session]\nn_att = \"ten\"\n", Path::new("x.toml"))
///     .unwrap_err();
/// assert_eq!((e.line, e.field.as_deref()), (2, Some("session.n_att")));
/// ```
pub fn parse_toml<T: DeserializeOwned>(
    text: &str,
    path: &Path,
) -> std::result::Result<T, ConfigError> {
    toml::from_str(text).map_err(|e| from_toml::<T>(text, path, &e))
}

/// The located form of toml's error `e` in reading `text` as a `T`.
fn from_toml<T: DeserializeOwned>(text: &str, path: &Path, e: &toml::de::Error) -> ConfigError {
    let message = e.message().trim();
    let toml_at = e.span().map(|s| s.start);
    let spans = Spans::parse(text);
    // A document that parses failed to deserialise: read it again, tracking
    // the path, to name the field.
    let fault = toml::from_str::<toml::Table>(text)
        .ok()
        .and_then(|doc| field_path::fault::<T>(&doc));
    let (keys, at) = match fault {
        Some(fault) => {
            let mut keys = fault.keys;
            if fault.missing.is_none()
                && let Some(s) = &spans
                && let Some(key) = s.key_in_read_whole_table(&keys, message)
            {
                keys.push(key);
            }
            let at = spans.as_ref().and_then(|s| s.key_start(&keys)).or(toml_at);
            keys.extend(fault.missing.map(str::to_string));
            (keys, at)
        }
        // A syntax error: toml's span, and the key it falls in. toml's
        // parser drops an entry it cannot read, so the key of a bad value
        // is read from its line, under the table in force there.
        None => {
            let mut keys = match (&spans, toml_at) {
                (Some(s), Some(at)) => s.keys_at(at),
                _ => Vec::new(),
            };
            if let Some(at) = toml_at
                && keys.is_empty()
            {
                keys = section_at(text, at);
                keys.extend(key_on_line(text, at));
            }
            (keys, toml_at)
        }
    };
    let (line, column) = at.map_or((0, 0), |a| line_col(text, a));
    ConfigError::new(path, line, column, field_name(&keys), message)
}

/// The field a message names: the keys, without the indices of array
/// items (`methods.policy.alpha` for `methods.0.policy.alpha`); the line
/// tells which item.
fn field_name(keys: &[String]) -> Option<String> {
    let named: Vec<&str> = keys
        .iter()
        .map(String::as_str)
        .filter(|k| k.parse::<usize>().is_err())
        .collect();
    (!named.is_empty()).then(|| named.join("."))
}

/// The error `e` raised by validating the table at `section` of a config
/// (`&[]` for the top level): an [`HilError::InvalidParameter`] is located
/// at its parameter's key (a dotted name such as `response_time.sigma` is
/// followed into nested tables), anything else at the section.
///
/// ```
/// use std::path::Path;
/// use hil_core::HilError;
/// let text = "[session]\nn_att = 0\n";
/// let e = HilError::invalid_parameter("n_att", 0, "must be at least 1");
/// let c = hil_config::error_in_section(text, Path::new("x.toml"), &["session"], e);
/// assert_eq!((c.line, c.field.as_deref()), (2, Some("session.n_att")));
/// ```
pub fn error_in_section(text: &str, path: &Path, section: &[&str], e: HilError) -> ConfigError {
    let mut keys: Vec<String> = section.iter().map(|s| s.to_string()).collect();
    let message = match e {
        HilError::InvalidParameter { name, value, why } => {
            keys.extend(name.split('.').map(str::to_string));
            format!("invalid value {value}: {why}")
        }
        other => other.to_string(),
    };
    at_keys(text, path, &keys, &message)
}

/// An error about the key at `key_path` (e.g. `["policy", "alpha"]`; an
/// index such as `"2"` picks an item of an array of tables).
///
/// ```
/// use std::path::Path;
/// let text = "seed = 1\n[policy]\ntype = \"linucb\"\nalpha = 2.0\n";
/// let e = hil_config::error_at_key(text, Path::new("x.toml"), &["policy", "alpha"], "too big".into());
/// assert_eq!((e.line, e.field.as_deref()), (4, Some("policy.alpha")));
/// ```
pub fn error_at_key(text: &str, path: &Path, key_path: &[&str], message: String) -> ConfigError {
    let keys: Vec<String> = key_path.iter().map(|s| s.to_string()).collect();
    at_keys(text, path, &keys, &message)
}

/// `message` located at the deepest key of `keys` the text holds (the
/// table's own line when the key itself is missing), with `keys` as the
/// field.
fn at_keys(text: &str, path: &Path, keys: &[String], message: &str) -> ConfigError {
    let at = Spans::parse(text).and_then(|s| s.key_start(keys));
    let (line, column) = at.map_or((0, 0), |a| line_col(text, a));
    ConfigError::new(path, line, column, field_name(keys), message)
}

/// The spans of every key and value of a TOML document, from toml's parser.
struct Spans<'t> {
    text: &'t str,
    root: Spanned<DeTable<'t>>,
}

impl<'t> Spans<'t> {
    /// The spans of what toml's parser could read: with a syntax error, the
    /// document up to and around it (so the error's key is still found).
    fn parse(text: &'t str) -> Option<Self> {
        let (root, _errors) = DeTable::parse_recoverable(text);
        Some(Self { text, root })
    }

    /// Where the deepest key of `keys` that the document holds starts:
    /// `policy.alpha` at `alpha`, or at `[policy]` if `alpha` is not
    /// written. `None` if not even the first key is written.
    fn key_start(&self, keys: &[String]) -> Option<usize> {
        let mut found = None;
        let mut table = self.root.get_ref();
        let mut rest = keys;
        while let Some((key, tail)) = rest.split_first() {
            let Some((k, v)) = entry(table, key) else {
                break;
            };
            found = Some(k.start);
            rest = tail;
            // Into a table, or into an item of an array (of tables).
            let mut value = v.get_ref();
            if let (DeValue::Array(items), Some((index, tail))) = (value, rest.split_first())
                && let Some(item) = index.parse::<usize>().ok().and_then(|i| items.get(i))
            {
                found = Some(item.span().start.max(k.start));
                value = item.get_ref();
                rest = tail;
            }
            match value {
                DeValue::Table(t) => table = t,
                _ => break,
            }
        }
        found
    }

    /// The key at fault inside the table at `keys`, for an error that
    /// stopped there: a config type that reads its table whole (as
    /// `hil_policies`' linear policies do, to split it between two structs)
    /// raises its errors as messages, so no path reaches inside. Only then
    /// is the message read: the key it names (unknown or missing field), or
    /// the entry whose written value is the one it quotes.
    fn key_in_read_whole_table(&self, keys: &[String], message: &str) -> Option<String> {
        if keys.is_empty() {
            return None;
        }
        let mut table = self.root.get_ref();
        let mut rest = keys;
        while let Some((key, tail)) = rest.split_first() {
            let mut value = entry(table, key)?.1.get_ref();
            rest = tail;
            // Into an item of an array (of tables), as `[[methods]]`.
            if let (DeValue::Array(items), Some((index, tail))) = (value, rest.split_first()) {
                value = items.get(index.parse::<usize>().ok()?)?.get_ref();
                rest = tail;
            }
            match value {
                DeValue::Table(t) => table = t,
                _ => return None,
            }
        }
        let named = quoted_after(message, "unknown field `")
            .or_else(|| quoted_after(message, "missing field `"));
        if let Some(name) = named {
            return Some(name);
        }
        let literal = offending_literal(message)?;
        table.iter().find_map(|(k, v)| {
            let written = self.text[v.span()].trim();
            (written == literal
                || written.replace('\'', "\"") == literal
                || same_number(written, &literal))
            .then(|| k.get_ref().to_string())
        })
    }

    /// The keys of the deepest entry whose key or value holds byte `at`.
    fn keys_at(&self, at: usize) -> Vec<String> {
        let mut keys = Vec::new();
        let mut table = self.root.get_ref();
        'down: loop {
            for (k, v) in table.iter() {
                let (key, value) = (k.span(), v.span());
                if !contains(&key, at) && !contains(&value, at) {
                    continue;
                }
                keys.push(k.get_ref().to_string());
                if let DeValue::Table(t) = v.get_ref() {
                    table = t;
                    continue 'down;
                }
                break 'down;
            }
            break;
        }
        keys
    }
}

/// The entry of `table` whose key is `key`: its key's span and its value.
fn entry<'a, 't>(
    table: &'a DeTable<'t>,
    key: &str,
) -> Option<(Range<usize>, &'a Spanned<DeValue<'t>>)> {
    table
        .iter()
        .find(|(k, _)| k.get_ref().as_ref() == key)
        .map(|(k, v)| (k.span(), v))
}

fn contains(span: &Range<usize>, at: usize) -> bool {
    span.start <= at && at < span.end.max(span.start + 1)
}

/// 1-based line and column of byte `offset`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(offset, |p| offset - p - 1) + 1;
    (line, column)
}

/// The text between `prefix` and the next backquote of `message`.
fn quoted_after(message: &str, prefix: &str) -> Option<String> {
    let rest = &message[message.find(prefix)? + prefix.len()..];
    Some(rest[..rest.find('`')?].to_string())
}

/// The value a serde "invalid type/value" message quotes, as TOML writes
/// it: `string "two"` gives `"two"`, `` integer `5` `` gives `5`.
fn offending_literal(message: &str) -> Option<String> {
    let rest = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "))?;
    if let Some(r) = rest.strip_prefix("string \"") {
        return Some(format!("\"{}\"", &r[..r.find('"')?]));
    }
    let start = rest.find('`')? + 1;
    let end = start + rest[start..].find('`')?;
    Some(rest[start..end].to_string())
}

/// Whether two number literals have the same value (`1e12` written,
/// `1000000000000.0` quoted by serde).
fn same_number(written: &str, quoted: &str) -> bool {
    let number = |s: &str| s.replace('_', "").parse::<f64>().ok();
    matches!((number(written), number(quoted)), (Some(a), Some(b)) if a == b)
}

/// The `[a.b]` table in force at byte `offset` (for a syntax error, which
/// has no parse tree).
fn section_at(text: &str, offset: usize) -> Vec<String> {
    let mut section = Vec::new();
    let mut pos = 0;
    for raw in text.split_inclusive('\n') {
        if pos > offset {
            break;
        }
        let l = raw.trim();
        let inner = l
            .strip_prefix("[[")
            .and_then(|r| r.split("]]").next())
            .or_else(|| l.strip_prefix('[').and_then(|r| r.split(']').next()));
        if let Some(inner) = inner {
            section = inner
                .split('.')
                .map(|s| s.trim().trim_matches('"').to_string())
                .collect();
        }
        pos += raw.len();
    }
    section
}

/// The key written on the line of byte `offset` (`key = ...`).
fn key_on_line(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let start = text[..offset].rfind('\n').map_or(0, |p| p + 1);
    let end = text[offset..].find('\n').map_or(text.len(), |p| offset + p);
    let line = text[start..end].trim_start();
    if line.starts_with('#') || line.starts_with('[') {
        return None;
    }
    let key = line[..line.find('=')?].trim().trim_matches('"');
    (!key.is_empty()).then(|| key.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::{Deserialize, Deserializer};

    /// A component that reads its table whole and checks it itself, so its
    /// errors reach the locator as bare messages.
    #[derive(Debug)]
    struct ReadWhole;

    impl<'de> Deserialize<'de> for ReadWhole {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            use serde::de::Error as _;
            let table = toml::Table::deserialize(d)?;
            match table.get("alpha") {
                Some(toml::Value::Float(_)) | None => Ok(Self),
                Some(_) => Err(D::Error::custom(
                    "invalid type: string \"high\", expected f64",
                )),
            }
        }
    }

    #[derive(Debug, Deserialize)]
    #[allow(dead_code)]
    struct Method {
        label: String,
        policy: ReadWhole,
    }

    #[derive(Debug, Deserialize)]
    #[allow(dead_code)]
    struct Study {
        methods: Vec<Method>,
    }

    #[test]
    fn a_bare_message_inside_an_array_of_tables_names_the_key_it_quotes() {
        let text = "[[methods]]\nlabel = \"a\"\npolicy = { alpha = 0.5 }\n\
                    [[methods]]\nlabel = \"b\"\n[methods.policy]\ntype = \"x\"\nalpha = \"high\"\n";
        let e = parse_toml::<Study>(text, Path::new("s.toml")).unwrap_err();
        assert_eq!(e.line, 8, "{e}");
        assert_eq!(e.field.as_deref(), Some("methods.policy.alpha"), "{e}");
    }
}
