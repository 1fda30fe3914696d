//! The modified NASA-TLX as the participant sees it: five questions on a
//! 5-point scale, the first worded by population.

use hil_workload::study::Population;
use serde::Serialize;

/// One survey question.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Question {
    /// The answer's field (`mental`, `temporal`, `performance`, `effort`,
    /// `frustration`, as in the study CSV).
    pub key: &'static str,
    /// The question.
    pub text: &'static str,
    /// What 1 means.
    pub low: &'static str,
    /// What 5 means.
    pub high: &'static str,
}

/// The five questions for a participant of `population`: the first asks
/// about mental *or physical* demand for people with a mobility limitation
/// and the therapists simulating one, about mental demand otherwise (the
/// wording of the paper's appendix).
///
/// ```
/// use hil_study::tlx::questions;
/// use hil_workload::study::Population;
/// assert!(questions(Population::MobilityLimitation)[0].text.contains("physically"));
/// assert!(!questions(Population::NoLimitation)[0].text.contains("physically"));
/// ```
pub fn questions(population: Population) -> [Question; 5] {
    let mental = if population.is_limited() {
        "How mentally or physically demanding was the task?"
    } else {
        "How mentally demanding was the task?"
    };
    [
        Question {
            key: "mental",
            text: mental,
            low: "Very low",
            high: "Very high",
        },
        Question {
            key: "temporal",
            text: "How hurried or rushed was the pace of the task?",
            low: "Very low",
            high: "Very high",
        },
        Question {
            key: "performance",
            text: "How successful were you in accomplishing what you were asked to do?",
            low: "Not at all successful",
            high: "Completely successful",
        },
        Question {
            key: "effort",
            text: "How hard did you have to work to accomplish your level of performance?",
            low: "Very low",
            high: "Very high",
        },
        Question {
            key: "frustration",
            text: "How irritated, stressed, and annoyed were you?",
            low: "Very low",
            high: "Very high",
        },
    ]
}
