//! The integration tests of `hil-channels`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod browser_support;
mod web_support;

mod simulated;
mod study_browser;
mod study_http;
mod terminal;
mod web_browser;
mod web_http;
