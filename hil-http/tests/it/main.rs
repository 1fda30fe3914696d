//! The integration tests of `hil-http`, linked into one test binary.

mod slow_clients;
mod tls;
