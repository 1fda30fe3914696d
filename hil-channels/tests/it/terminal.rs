//! The terminal channel with a scripted person on the other end (the pty
//! test in hil-cli drives it through a real pseudo-terminal).

use hil_channels::TerminalChannel;
use hil_conformance::check_query_channel;
use hil_core::{
    Answer, ArmId, BoundingBox, Context, Difficulty, Distraction, Item, Query, QueryChannel,
    QueryKind, ResponseType,
};

fn query(response: ResponseType) -> Query {
    Query::new(
        4,
        Item::new(2, "bell_pepper").with_description("a strip of bell pepper"),
        QueryKind {
            response,
            difficulty: Difficulty::Hard,
            distraction: Distraction::Easy,
        },
        hil_envs::feeding::action_space(),
        Context::new(vec![0.5, 0.5]).unwrap(),
    )
    .with_oracle_best(ArmId(5))
}

fn ask(input: &str, response: ResponseType) -> (hil_core::Result<hil_core::Response>, String) {
    let mut out = Vec::new();
    let r = TerminalChannel::new(input.as_bytes(), &mut out).ask(&query(response));
    (r, String::from_utf8(out).unwrap())
}

#[test]
fn conforms_with_a_scripted_person() {
    // The suite asks MCQ, bounding box, open-ended in turn.
    let mut script = String::new();
    for i in 0..12 {
        script.push_str(&format!("{}\n", i % 6 + 1));
        script.push_str(if i % 2 == 0 {
            "0.1 0.2 0.6 0.9\n"
        } else {
            "?\n"
        });
        script.push_str(if i % 3 == 0 {
            "use TV90 please\n"
        } else {
            "too slippery\n"
        });
    }
    let mut out = Vec::new();
    let mut ch = TerminalChannel::new(script.as_bytes(), &mut out);
    check_query_channel(&mut ch, 36).unwrap();
}

#[test]
fn mcq_by_number_or_name_after_invalid_tries() {
    let (r, out) = ask("\n0\nfoo\nta90\n", ResponseType::Mcq);
    let r = r.unwrap();
    assert_eq!(r.answer, Answer::Action { arm: ArmId(5) });
    assert_eq!(r.expert_arm, Some(ArmId(5)));
    assert!(r.response_time_s.unwrap() >= 0.0);
    // The prompt shows the item, the query kind and the numbered choices,
    // never the oracle's answer.
    assert!(out.contains("bell pepper: a strip of bell pepper"), "{out}");
    assert!(
        out.contains("multiple choice · hard question · easy distraction"),
        "{out}"
    );
    assert!(out.contains("1) VS0") && out.contains("6) TA90"), "{out}");
    assert_eq!(out.matches("not one of the choices").count(), 2, "{out}");
    assert!(out.contains("please type an answer"), "{out}");
}

#[test]
fn bounding_box_is_validated() {
    let (r, out) = ask(
        "1 2 3\n0.5 0.5 0.4 0.9\n0.2 0.3 1.5 0.4\n0.2, 0.3, 0.7, 0.8\n",
        ResponseType::BoundingBox,
    );
    let r = r.unwrap();
    assert_eq!(
        r.answer,
        Answer::BoundingBox {
            bbox: BoundingBox::new(0.2, 0.3, 0.7, 0.8)
        }
    );
    assert_eq!(
        r.expert_arm, None,
        "a box names no action: the fallback is used"
    );
    assert!(out.contains("four numbers"), "{out}");
    assert!(out.contains("left of and above"), "{out}");
    assert!(out.contains("between 0 and 1"), "{out}");
}

#[test]
fn open_ended_text_may_name_an_action() {
    let (r, _) = ask("tilt it, TA0\n", ResponseType::OpenEnded);
    let r = r.unwrap();
    assert_eq!(
        r.answer,
        Answer::Text {
            text: "tilt it, TA0".into()
        }
    );
    assert_eq!(r.expert_arm, Some(ArmId(4)));
    let (r, _) = ask("it is slippery\n", ResponseType::OpenEnded);
    assert_eq!(r.unwrap().expert_arm, None);
    let (r, _) = ask("VS0 or TA0\n", ResponseType::OpenEnded);
    assert_eq!(r.unwrap().expert_arm, None, "two actions named: ambiguous");
}

#[test]
fn decline_end_of_input_and_quit() {
    let (r, _) = ask("?\n", ResponseType::BoundingBox);
    let r = r.unwrap();
    assert_eq!(r.answer, Answer::Declined);
    assert_eq!(r.expert_arm, None);

    let (r, _) = ask("nonsense\n", ResponseType::Mcq);
    let err = r.unwrap_err().to_string();
    assert!(
        err.contains("input ended") && err.contains("--resume"),
        "{err}"
    );

    let (r, _) = ask("q\n", ResponseType::OpenEnded);
    let err = r.unwrap_err().to_string();
    assert!(err.contains("stopped"), "{err}");
}
