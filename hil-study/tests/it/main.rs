//! The integration tests of `hil-study`, linked into one test binary (one
//! link instead of one per file).

// The browser test serves over HTTPS, as a study on a tablet does.
#[cfg(feature = "https")]
mod study_browser;
mod study_http;
#[cfg(not(feature = "https"))]
mod without_https;
