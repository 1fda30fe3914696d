//! Tests of the server's private parts: the request parser under fuzzing,
//! and servers built directly from [`super::Server`] against slow clients.
//! (Unit tests: the HTTP server is private to the crate; they share the
//! integration tests' `web_support` helpers, see the crate root.)

mod fuzz;
mod slow_clients;
