//! Workspace-level integration and property suites live in `tests/tests/`.
