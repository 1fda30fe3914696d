//! Scripted choices shared by the session tests.

use hil_core::{ArmId, Choice, QueryKind};

/// Act with arm `a`.
pub fn act(a: usize) -> Choice {
    Choice::Act { arm: ArmId(a) }
}

/// Ask, falling back to arm `fallback` if no answer comes.
pub fn query(fallback: usize) -> Choice {
    Choice::Query {
        kind: QueryKind::default(),
        fallback: ArmId(fallback),
    }
}
