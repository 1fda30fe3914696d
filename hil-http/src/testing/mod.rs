//! Test support for crates that serve pages with [`Server`](crate::Server)
//! (feature `testing`): a raw HTTP client that shows exactly what the
//! server answers, and headless Chromium driven over WebDriver.

pub mod browser;
pub mod client;
