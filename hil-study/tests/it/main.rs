//! The integration tests of `hil-study`, linked into one test binary (one
//! link instead of one per file).

mod study_browser;
mod study_http;
