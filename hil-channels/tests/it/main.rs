//! The integration tests of `hil-channels`, linked into one test binary (one
//! link instead of one per file); each module was a file of its own.

mod web_support;

mod simulated;
mod terminal;
mod web_browser;
mod web_fuzz;
mod web_http;
mod web_slow_clients;
