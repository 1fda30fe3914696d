//! What every human channel shows and accepts: the wording of a query and
//! the validation of answers, defined once for the terminal and the web.

use hil_core::{
    ActionSpace, Answer, ArmId, BoundingBox, Difficulty, Distraction, HilError, Query, QueryKind,
    ResponseType, Result,
};

/// Longest free-text answer accepted, in characters.
pub const MAX_TEXT_CHARS: usize = 1000;

/// A human-readable description of a query kind, e.g.
/// `multiple choice · hard question · easy distraction`.
pub fn describe_kind(kind: &QueryKind) -> String {
    let response = match kind.response {
        ResponseType::Mcq => "multiple choice",
        ResponseType::BoundingBox => "bounding box",
        ResponseType::OpenEnded => "open-ended",
    };
    let difficulty = match kind.difficulty {
        Difficulty::Easy => "easy question",
        Difficulty::Hard => "hard question",
    };
    let distraction = match kind.distraction {
        Distraction::None => "no distraction",
        Distraction::Easy => "easy distraction",
        Distraction::Hard => "hard distraction",
    };
    format!("{response} · {difficulty} · {distraction}")
}

/// The item as a person sees it: its label and description.
pub fn describe_item(query: &Query) -> String {
    let label = query.item.label.replace('_', " ");
    match &query.item.description {
        Some(d) => format!("{label}: {d}"),
        None => label,
    }
}

/// The question asked for the query's response type.
pub fn question(query: &Query) -> String {
    let label = query.item.label.replace('_', " ");
    match query.kind.response {
        ResponseType::Mcq => format!("Which action should the robot use to pick up the {label}?"),
        ResponseType::BoundingBox => format!("Where is the {label}? Draw a box around it."),
        ResponseType::OpenEnded => {
            format!("How should the robot pick up the {label}? Answer in your own words.")
        }
    }
}

/// Checks a bounding box: finite corners in [0, 1], left < right, top < bottom.
pub fn check_bbox(b: &BoundingBox) -> std::result::Result<(), String> {
    let all = [b.x0, b.y0, b.x1, b.y1];
    if all
        .iter()
        .any(|v| !v.is_finite() || !(0.0..=1.0).contains(v))
    {
        return Err(format!(
            "every coordinate must be between 0 and 1, got {} {} {} {}",
            b.x0, b.y0, b.x1, b.y1
        ));
    }
    if b.x0 >= b.x1 || b.y0 >= b.y1 {
        return Err("the first corner must be left of and above the second".into());
    }
    Ok(())
}

/// Checks a free-text answer: not blank, at most [`MAX_TEXT_CHARS`], no
/// control characters.
pub fn check_text(text: &str) -> std::result::Result<(), String> {
    if text.trim().is_empty() {
        return Err("the answer is empty".into());
    }
    if text.chars().count() > MAX_TEXT_CHARS {
        return Err(format!(
            "the answer is longer than {MAX_TEXT_CHARS} characters"
        ));
    }
    if text.chars().any(|c| c.is_control() && c != '\n') {
        return Err("the answer contains control characters".into());
    }
    Ok(())
}

/// The action a free-text answer names, if it names exactly one action of
/// the space (whole words, case-insensitive), e.g. "try TA0 please".
pub fn action_named_in(text: &str, actions: &ActionSpace) -> Option<ArmId> {
    let words: Vec<String> = text
        .split(|c: char| !c.is_alphanumeric() && c != '_')
        .filter(|w| !w.is_empty())
        .map(str::to_lowercase)
        .collect();
    let mut named = actions.arms().filter(|a| {
        let name = actions.names()[a.0].to_lowercase();
        words.contains(&name)
    });
    match (named.next(), named.next()) {
        (Some(a), None) => Some(a),
        _ => None,
    }
}

/// Checks that `answer` fits `query` (its response type, its action space)
/// and returns the action it implies: the chosen arm for an MCQ, the action
/// a text names, none for a box or a decline.
///
/// ```
/// use hil_core::{Answer, ArmId, Context, Item, Query, QueryKind, ResponseType};
/// let q = Query::new(
///     1,
///     Item::new(0, "grape"),
///     QueryKind { response: ResponseType::OpenEnded, ..Default::default() },
///     hil_envs::feeding::action_space(),
///     Context::new(vec![0.0]).unwrap(),
/// );
/// let e = hil_channels::present::validate_answer(&q, &Answer::Action { arm: ArmId(2) });
/// let why = e.unwrap_err().to_string();
/// assert!(why.contains(r#"cannot be answered with {"type":"action","arm":2}"#), "{why}");
/// ```
pub fn validate_answer(query: &Query, answer: &Answer) -> Result<Option<ArmId>> {
    let invalid = |why: String| HilError::invalid_input("answer", why);
    match (query.kind.response, answer) {
        (_, Answer::Declined) => Ok(None),
        (ResponseType::Mcq, Answer::Action { arm }) => {
            query
                .actions
                .check(*arm)
                .map_err(|e| invalid(e.to_string()))?;
            Ok(Some(*arm))
        }
        (ResponseType::BoundingBox, Answer::BoundingBox { bbox }) => {
            check_bbox(bbox).map_err(invalid)?;
            Ok(None)
        }
        (ResponseType::OpenEnded, Answer::Text { text }) => {
            check_text(text).map_err(invalid)?;
            Ok(action_named_in(text, &query.actions))
        }
        // The answer as it is sent (JSON), not as Rust prints it.
        (expected, got) => {
            let expected = match expected {
                ResponseType::Mcq => "multiple-choice",
                ResponseType::BoundingBox => "bounding-box",
                ResponseType::OpenEnded => "open-ended",
            };
            let got = serde_json::to_string(got).unwrap_or_else(|_| "this answer".into());
            Err(invalid(format!(
                "a {expected} query cannot be answered with {got}"
            )))
        }
    }
}
