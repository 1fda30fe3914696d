//! The integration tests of `hil-conformance`, linked into one test binary
//! (one link instead of one per file).

mod conformance_catches;
