//! # hil-study
//!
//! The querying-workload study of the paper, run in the browser: a lab
//! collects its own NASA-TLX data and gets the CSV that `hil workload`
//! fits models from (`hil study serve`, `status`, `export`). The pages are
//! served by `hil-http`, the small server the web query channel uses too.
//!
//! - [`StudyConfig`]: the design (12 query conditions — difficulty ×
//!   distraction × interval — and 2 baselines by default), server and
//!   materials, read from TOML with located errors; every key with its
//!   default is [`config::EXAMPLE_TOML`].
//! - [`Design`]: the conditions, their counterbalanced order per
//!   participant (Williams balanced Latin square) and the query schedule.
//! - [`StudyServer`]: one data folder, one page per participant behind a
//!   token, a researcher's progress page; every answer is appended to the
//!   participant's log and fsync'ed before the page is told it is saved,
//!   and a restarted server or reopened page resumes where it was. The
//!   researcher's link, the port and a self-signed certificate are kept
//!   in the data folder, so links stay the same across restarts; beyond
//!   loopback the pages are served over HTTPS only.
//! - [`export()`]: the logs as the study CSV, validated by the loader.
//! - [`materials`]: the drawn food pictures, the queries built on them,
//!   the addition task and the transcription passage.
//! - [`tlx`]: the modified NASA-TLX questions, worded by population.
//!
//! Nothing identifying is asked: participants get pseudonymous ids
//! (`p001`, ...) and a population; open-ended queries ask about the food.

pub mod config;
pub mod design;
pub mod export;
pub mod log;
pub mod materials;
pub mod server;
pub mod session;
pub mod tlx;

pub use config::{DesignConfig, MaterialsConfig, ServerConfig, StudyConfig};
pub use design::{Condition, Design};
pub use export::{Export, export, export_all};
/// The certificate of HTTPS (`StudyServer::tls`), from the server crate.
pub use hil_http::tls::{CertSource, Tls};
pub use server::StudyServer;
