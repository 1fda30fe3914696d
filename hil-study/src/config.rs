//! The study's TOML config: the design, the server and the materials, every
//! field validated, errors located at the file, line and key.

use std::net::{IpAddr, Ipv4Addr};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use hil_config::{limits::check_seconds, parse_toml};
use hil_core::{Difficulty, Distraction, HilError, ResponseType, Result};

/// How conditions are ordered across participants.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// A balanced Latin square (Williams design): each condition appears
    /// once in every position and follows every other condition equally
    /// often, over a full set of participants (n rows for an even number
    /// of conditions, 2n for an odd one).
    BalancedLatinSquare,
    /// The same order for everyone (the design's listing order).
    Fixed,
}

/// Where the baseline conditions (distraction only) come. The paper lists
/// its two baselines but does not say where in the session they came or
/// in which order; `first` is hil's choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BaselinePosition {
    /// Before the first robot query, in the listed order: a workload
    /// measured before any query (the default).
    First,
    /// After the last query condition, in the listed order.
    Last,
    /// Counterbalanced: every other participant takes them first, the
    /// others last, and their order among themselves rotates every two
    /// participants (so with two baselines, each of first/last × both
    /// orders once in every four participants).
    Counterbalanced,
}

/// The study design; the defaults are the paper's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DesignConfig {
    /// Minutes each condition lasts on the task clock (survey time excluded).
    pub condition_min: f64,
    /// Robot-query difficulties, one factor of the design.
    pub difficulties: Vec<Difficulty>,
    /// Distraction tasks, one factor of the design.
    pub distractions: Vec<Distraction>,
    /// Minutes between queries, one factor of the design (1 or 2: the
    /// values the study CSV format holds).
    pub intervals_min: Vec<u8>,
    /// The response types queries cycle through within a condition.
    pub response_types: Vec<ResponseType>,
    /// The distraction of each baseline condition (no robot queries).
    pub baselines: Vec<Distraction>,
    /// Where the baselines come.
    pub baseline_position: BaselinePosition,
    /// Minutes from the condition start to the first query.
    pub first_query_min: f64,
    /// No query is scheduled within this many minutes of the condition end.
    pub last_query_margin_min: f64,
    /// How conditions are ordered across participants.
    pub order: Order,
    /// Study minutes per real minute: 1 for a real study; 60 turns every
    /// minute of the design into a second (for rehearsals and tests). The
    /// exported times stay in study seconds; survey times are real seconds.
    pub time_scale: f64,
    /// Seed of the materials (which pictures, sums, items each query shows).
    pub seed: u64,
}

impl Default for DesignConfig {
    fn default() -> Self {
        Self {
            condition_min: 5.5,
            difficulties: Difficulty::ALL.to_vec(),
            distractions: Distraction::ALL.to_vec(),
            intervals_min: vec![1, 2],
            response_types: ResponseType::ALL.to_vec(),
            baselines: vec![Distraction::Easy, Distraction::Hard],
            baseline_position: BaselinePosition::First,
            first_query_min: 1.0,
            last_query_margin_min: 0.5,
            order: Order::BalancedLatinSquare,
            time_scale: 1.0,
            seed: 0,
        }
    }
}

fn default_bind() -> IpAddr {
    IpAddr::V4(Ipv4Addr::LOCALHOST)
}

/// Where the study is served.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ServerConfig {
    /// Address to listen on: loopback by default, `0.0.0.0` for a tablet on
    /// the LAN (the machine's addresses are then printed).
    pub bind: IpAddr,
    /// Port; 0 picks a free one.
    pub port: u16,
    /// Host names the pages may be reached by besides IP addresses and
    /// `localhost`.
    pub allowed_hosts: Vec<String>,
    /// Real seconds without a request from the participant's page after
    /// which they count as away: the task clock does not run while away.
    pub away_after_s: f64,
    /// Serve HTTPS on loopback too. Beyond loopback (`--lan`) the pages
    /// are always served over HTTPS: plain HTTP would carry the
    /// participants' tokens across the lab's network in clear.
    pub https: bool,
    /// The lab's certificate chain (PEM), with [`tls_key`](Self::tls_key);
    /// relative to the config. Without them, HTTPS uses a self-signed
    /// certificate made in the data folder at the first start.
    pub tls_cert: Option<PathBuf>,
    /// The private key of [`tls_cert`](Self::tls_cert) (PEM).
    pub tls_key: Option<PathBuf>,
}

impl ServerConfig {
    /// Whether the pages are served over HTTPS: beyond loopback always,
    /// on loopback when asked (`https`, or a certificate given).
    ///
    /// ```
    /// let mut s = hil_study::ServerConfig::default();
    /// assert!(!s.uses_https());                  // loopback: plain HTTP
    /// s.bind = "0.0.0.0".parse().unwrap();
    /// assert!(s.uses_https());                   // a tablet on the LAN: HTTPS
    /// ```
    pub fn uses_https(&self) -> bool {
        !self.bind.is_loopback() || self.https || self.tls_cert.is_some()
    }
}

impl Default for ServerConfig {
    fn default() -> Self {
        Self {
            bind: default_bind(),
            port: 0,
            allowed_hosts: Vec::new(),
            away_after_s: 3.0,
            https: false,
            tls_cert: None,
            tls_key: None,
        }
    }
}

/// The distraction tasks' and queries' materials.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MaterialsConfig {
    /// A folder of the lab's own materials (relative to the config):
    /// `passage.txt` replaces the transcription passage, and
    /// `images/<food>.png|jpg|jpeg|webp` replace the drawn picture of a
    /// food in single-item questions.
    pub dir: Option<PathBuf>,
    /// Words of the transcription passage revealed per study minute.
    pub transcription_words_per_min: f64,
    /// Largest addend of the addition task (two addends from 10 up to it).
    pub addition_max: u32,
}

impl Default for MaterialsConfig {
    fn default() -> Self {
        Self {
            dir: None,
            transcription_words_per_min: 30.0,
            addition_max: 99,
        }
    }
}

/// The whole study config (`hil study serve --config study.toml`); every
/// key with its default is [`EXAMPLE_TOML`] (also in `hil study serve
/// --help` and the crate's README).
///
/// ```
/// let c = hil_study::StudyConfig::parse("[design]\ntime_scale = 60\n", "s.toml".as_ref()).unwrap();
/// assert_eq!(c.design.intervals_min, vec![1, 2]);
/// let e = hil_study::StudyConfig::parse("[design]\nintervals_min = [3]\n", "s.toml".as_ref());
/// assert!(e.unwrap_err().to_string().contains("s.toml:2"));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StudyConfig {
    /// The design.
    pub design: DesignConfig,
    /// The server.
    pub server: ServerConfig,
    /// The materials.
    pub materials: MaterialsConfig,
}

/// Every key of the study config with its default and what it does: shown
/// by `hil study serve --help` and in the README (tests keep the three
/// and the structs' fields the same).
pub const EXAMPLE_TOML: &str = include_str!("../assets/study.toml");

/// The most conditions (and baselines) a design may have.
pub const MAX_CONDITIONS: usize = 64;

impl StudyConfig {
    /// Reads, parses and validates a config file; relative paths
    /// (`materials.dir`, `server.tls_cert`, `server.tls_key`) are resolved
    /// against the file's folder.
    pub fn load(path: &Path) -> Result<Self> {
        let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
        let mut c = Self::parse(&text, path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        for file in [
            &mut c.materials.dir,
            &mut c.server.tls_cert,
            &mut c.server.tls_key,
        ] {
            if let Some(p) = file
                && p.is_relative()
            {
                *p = base.join(&*p);
            }
        }
        Ok(c)
    }

    /// Parses and validates config text; `path` only names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let c: Self = parse_toml(text, path)?;
        for (section, check) in [
            ("design", c.design.validate()),
            ("server", c.server.validate()),
            ("materials", c.materials.validate()),
        ] {
            if let Err(e) = check {
                return Err(hil_config::error_in_section(text, path, &[section], e).into());
            }
        }
        Ok(c)
    }
}

fn check_minutes(name: &str, value: f64) -> Result<()> {
    check_seconds(name, value * 60.0).map_err(|_| {
        HilError::invalid_parameter(name, value, "must be a positive number of minutes")
    })
}

/// Every entry of the list `name` differs from the others; the error shows
/// the list and the repeated entry as the config spells them (`"easy"`,
/// not Rust's `Easy`).
fn check_distinct<T: PartialEq + Serialize>(name: &str, values: &[T]) -> Result<()> {
    if values.is_empty() {
        return Err(HilError::invalid_parameter(name, "[]", "must not be empty"));
    }
    for (i, v) in values.iter().enumerate() {
        if values[..i].contains(v) {
            return Err(HilError::invalid_parameter(
                name,
                spell(values),
                format!("lists {} twice", spell(v)),
            ));
        }
    }
    Ok(())
}

/// A value as JSON, which for the study's lists reads as in TOML.
fn spell(value: &(impl Serialize + ?Sized)) -> String {
    serde_json::to_string(value).unwrap_or_else(|_| "?".into())
}

impl DesignConfig {
    /// Checks every field and that the design has at least one query.
    pub fn validate(&self) -> Result<()> {
        check_minutes("condition_min", self.condition_min)?;
        check_distinct("difficulties", &self.difficulties)?;
        check_distinct("distractions", &self.distractions)?;
        check_distinct("intervals_min", &self.intervals_min)?;
        check_distinct("response_types", &self.response_types)?;
        if let Some(bad) = self.intervals_min.iter().find(|i| !matches!(i, 1 | 2)) {
            return Err(HilError::invalid_parameter(
                "intervals_min",
                bad,
                "must be 1 or 2 (the intervals the study CSV format holds)",
            ));
        }
        for (i, b) in self.baselines.iter().enumerate() {
            if *b == Distraction::None {
                return Err(HilError::invalid_parameter(
                    "baselines",
                    "none",
                    "a baseline condition needs a distraction task (it has no robot queries)",
                ));
            }
            if self.baselines[..i].contains(b) {
                return Err(HilError::invalid_parameter(
                    "baselines",
                    b.as_str(),
                    "is listed twice (condition ids must be unique)",
                ));
            }
        }
        let n = self.difficulties.len() * self.distractions.len() * self.intervals_min.len();
        if n + self.baselines.len() > MAX_CONDITIONS {
            return Err(HilError::invalid_parameter(
                "difficulties",
                n,
                format!("the design has more than {MAX_CONDITIONS} conditions"),
            ));
        }
        if !(self.first_query_min.is_finite() && self.first_query_min >= 0.0) {
            return Err(HilError::invalid_parameter(
                "first_query_min",
                self.first_query_min,
                "must be a number of minutes >= 0",
            ));
        }
        if !(self.last_query_margin_min.is_finite() && self.last_query_margin_min >= 0.0) {
            return Err(HilError::invalid_parameter(
                "last_query_margin_min",
                self.last_query_margin_min,
                "must be a number of minutes >= 0",
            ));
        }
        if self.first_query_min > self.condition_min - self.last_query_margin_min {
            return Err(HilError::invalid_parameter(
                "first_query_min",
                self.first_query_min,
                "leaves no time for a query: it must be at most condition_min - last_query_margin_min",
            ));
        }
        if !(self.time_scale.is_finite() && (0.01..=3600.0).contains(&self.time_scale)) {
            return Err(HilError::invalid_parameter(
                "time_scale",
                self.time_scale,
                "must be in [0.01, 3600] study minutes per real minute",
            ));
        }
        Ok(())
    }
}

impl ServerConfig {
    /// Checks the host names, the away time, and that a certificate comes
    /// with its key.
    pub fn validate(&self) -> Result<()> {
        hil_http::guard::check_allowed_hosts(&self.allowed_hosts)?;
        check_seconds("away_after_s", self.away_after_s)?;
        self.check_https_available()?;
        match (&self.tls_cert, &self.tls_key) {
            (Some(_), None) => Err(HilError::invalid_parameter(
                "tls_cert",
                "set",
                "needs tls_key, the certificate's private key",
            )),
            (None, Some(_)) => Err(HilError::invalid_parameter(
                "tls_key",
                "set",
                "needs tls_cert, the certificate it belongs to",
            )),
            _ => Ok(()),
        }
    }

    /// Without the feature `https`, a config that asks for HTTPS is an
    /// error naming the key that asks, never a silent fall back to plain
    /// HTTP: beyond loopback that would carry the tokens in clear.
    fn check_https_available(&self) -> Result<()> {
        if HTTPS || !self.uses_https() {
            return Ok(());
        }
        let (key, value) = if !self.bind.is_loopback() {
            ("bind", self.bind.to_string())
        } else if self.https {
            ("https", "true".to_string())
        } else {
            ("tls_cert", "set".to_string())
        };
        Err(HilError::invalid_parameter(
            key,
            value,
            "needs HTTPS, which this build leaves out (hil-study's cargo feature `https`): \
             build `hil` with `--features https` (`scripts/hil study ...` does)",
        ))
    }
}

/// Whether this build serves HTTPS (the cargo feature `https`).
pub const HTTPS: bool = cfg!(feature = "https");

impl MaterialsConfig {
    /// Checks the pace and the addends (the folder is read when serving).
    pub fn validate(&self) -> Result<()> {
        let w = self.transcription_words_per_min;
        if !(w.is_finite() && (1.0..=600.0).contains(&w)) {
            return Err(HilError::invalid_parameter(
                "transcription_words_per_min",
                w,
                "must be in [1, 600]",
            ));
        }
        if !(20..=100_000).contains(&self.addition_max) {
            return Err(HilError::invalid_parameter(
                "addition_max",
                self.addition_max,
                "must be in [20, 100000]",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The keys [`EXAMPLE_TOML`] shows in `[section]`, set or commented out.
    fn shown_keys(section: &str) -> Vec<String> {
        let mut keys = Vec::new();
        let mut current = "";
        for line in EXAMPLE_TOML.lines() {
            let line = line.trim();
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                current = name;
            } else if current == section
                && let Some((key, _)) = line.trim_start_matches("# ").split_once(" = ")
                && key.bytes().all(|b| b.is_ascii_lowercase() || b == b'_')
            {
                keys.push(key.to_string());
            }
        }
        keys.sort();
        keys
    }

    /// The example names every field of every section, no other, and its
    /// values are the defaults.
    #[test]
    fn the_example_shows_every_field_with_its_default() {
        let fields = serde_json::to_value(StudyConfig::default()).unwrap();
        let fields = fields.as_object().unwrap();
        for (section, value) in fields {
            let mut want: Vec<String> = value.as_object().unwrap().keys().cloned().collect();
            want.sort();
            assert_eq!(shown_keys(section), want, "[{section}]");
        }
        assert_eq!(fields.len(), 3);
        let parsed = StudyConfig::parse(EXAMPLE_TOML, "study.toml".as_ref()).unwrap();
        assert_eq!(parsed, StudyConfig::default());
    }

    /// The crate's README shows the example as it is.
    #[test]
    fn the_readme_shows_the_example() {
        let readme = include_str!("../README.md");
        assert!(
            readme.contains(&format!("```toml\n{EXAMPLE_TOML}```")),
            "hil-study/README.md must show assets/study.toml verbatim"
        );
    }
}
