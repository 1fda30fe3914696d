//! The web page driven in headless Chromium through chromedriver (WebDriver
//! over HTTP on loopback): answering a multiple-choice question by touch
//! and by keyboard, a bounding box by drawing and by region buttons, an
//! open-ended question by typing, and one by single-switch scanning; plus
//! label and contrast checks on the live page.
//!
//! Needs Debian's `chromium` and `chromium-driver` (installed by
//! `scripts/test-setup-chromium`, which `scripts/test` and CI run first). The
//! test fails if they are missing, unless HIL_SKIP_BROWSER_TESTS=1.

use std::path::Path;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use hil_channels::{WebChannel, WebChannelConfig};
use hil_core::{
    Answer, ArmId, BoundingBox, Context, Difficulty, Distraction, Item, Query, QueryChannel,
    QueryKind, Response, ResponseType,
};
use serde_json::json;

use hil_http::testing::browser::{Browser, contrast, tools_present};

fn query(t: u64, response: ResponseType) -> Query {
    Query::new(
        t,
        Item::new(t as usize, "baby_carrot").with_description("a baby carrot lying flat"),
        QueryKind {
            response,
            difficulty: Difficulty::Hard,
            distraction: Distraction::Easy,
        },
        hil_envs::feeding::action_space(),
        Context::new(vec![0.0]).unwrap(),
    )
    .with_oracle_best(ArmId(5))
}

fn ask_async(mut ch: WebChannel, q: Query) -> JoinHandle<(WebChannel, Response)> {
    std::thread::spawn(move || {
        let r = ch.ask(&q).unwrap();
        (ch, r)
    })
}

#[test]
#[ignore = "e2e: needs Chromium; bash scripts/test runs it"]
fn a_person_answers_every_kind_of_query_in_chromium() {
    if !tools_present() {
        return;
    }
    let ch = WebChannel::start(WebChannelConfig {
        timeout_s: 60.0,
        images: Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")),
        ..Default::default()
    })
    .unwrap();
    let url = ch.url().to_string();
    let browser = Browser::start();
    browser.goto(&url);
    browser.find("#status");

    // 1. Multiple choice, by touch/click on a large button.
    let asking = ask_async(ch, query(1, ResponseType::Mcq));
    browser.find("#choice-3");
    let shown = browser.script("return document.getElementById('kind').textContent + ' | ' + document.getElementById('item').textContent;");
    let shown = shown.as_str().unwrap();
    assert!(
        shown.contains("multiple choice · hard question · easy distraction"),
        "{shown}"
    );
    assert!(
        shown.contains("baby carrot: a baby carrot lying flat"),
        "{shown}"
    );
    // The item's picture is shown, loaded, and described for screen readers.
    let id = browser.find("#item-image");
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let img = browser.script(
            "const i = document.getElementById('item-image'); return [i.complete, i.naturalWidth, i.alt];",
        );
        if img[0] == json!(true) && img[1] == json!(1) {
            assert_eq!(
                img[2],
                "Picture of the baby carrot: a baby carrot lying flat"
            );
            break;
        }
        assert!(
            Instant::now() < deadline,
            "picture not loaded: {img} ({id})"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    // Accessibility on the live page: every control has a name, contrast
    // is at least 4.5:1, targets are large.
    let audit = browser.script(
        r#"const out = {unnamed: [], colours: [], small: []};
           document.querySelectorAll('button, input, select, textarea').forEach(e => {
             const id = e.id;
             const label = e.getAttribute('aria-label') || e.textContent.trim() ||
               (id && document.querySelector('label[for="' + id + '"]')) || e.closest('label');
             if (!label) out.unnamed.push(e.outerHTML.slice(0, 80));
           });
           const pairs = ['#choice-0', '#decline', '#question', '#kind', '#status'];
           pairs.forEach(sel => {
             const e = document.querySelector(sel);
             const s = getComputedStyle(e);
             let bg = s.backgroundColor, p = e;
             while ((bg === 'rgba(0, 0, 0, 0)' || bg === 'transparent') && p.parentElement) {
               p = p.parentElement; bg = getComputedStyle(p).backgroundColor;
             }
             out.colours.push([sel, s.color, bg]);
           });
           document.querySelectorAll('#choices button, #decline').forEach(e => {
             const r = e.getBoundingClientRect();
             if (r.height < 44 || r.width < 44) out.small.push(e.id);
           });
           out.overflow = document.documentElement.scrollWidth > window.innerWidth;
           return out;"#,
    );
    assert_eq!(audit["unnamed"], json!([]), "controls without a label");
    assert_eq!(audit["small"], json!([]), "touch targets under 44 px");
    assert_eq!(
        audit["overflow"],
        json!(false),
        "horizontal scrolling on a phone"
    );
    for c in audit["colours"].as_array().unwrap() {
        let ratio = contrast(c[1].as_str().unwrap(), c[2].as_str().unwrap());
        assert!(ratio >= 4.5, "{} contrast {ratio:.2}", c[0]);
    }
    browser.click("#choice-3");
    let (ch, r) = asking.join().unwrap();
    wait_until_no_question(&browser);
    assert_eq!(r.answer, Answer::Action { arm: ArmId(3) });
    assert_eq!(r.expert_arm, Some(ArmId(3)));

    // 2. Multiple choice by keyboard only: focus starts on the first
    // choice; two Tabs reach the third; Enter answers.
    let asking = ask_async(ch, query(2, ResponseType::Mcq));
    browser.find("#choice-0");
    let deadline = Instant::now() + Duration::from_secs(10);
    while browser.script("return document.activeElement.id;") != json!("choice-0") {
        assert!(
            Instant::now() < deadline,
            "focus did not move to the first choice"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    browser.keys(&["\u{E004}", "\u{E004}", "\u{E007}"]);
    let (ch, r) = asking.join().unwrap();
    wait_until_no_question(&browser);
    assert_eq!(r.answer, Answer::Action { arm: ArmId(2) });

    // 3. Bounding box drawn with a finger on the canvas.
    let asking = ask_async(ch, query(3, ResponseType::BoundingBox));
    browser.find("#bbox-canvas");
    browser.drag("#bbox-canvas", (-60, -40), (50, 30));
    let readout = browser.script("return document.getElementById('bbox-readout').textContent;");
    assert!(
        readout.as_str().unwrap().starts_with("Box: left"),
        "{readout}"
    );
    browser.click("#send-box");
    let (ch, r, bbox) = box_answer(asking, &browser);
    // Dragged from left of and above the centre to right of and below it.
    assert!(
        bbox.x0 < 0.5 && bbox.x1 > 0.5 && bbox.y0 < 0.5 && bbox.y1 > 0.5,
        "{bbox:?}"
    );
    assert!(
        bbox.x1 - bbox.x0 > 0.1 && bbox.y1 - bbox.y0 > 0.1,
        "{bbox:?}"
    );
    assert_eq!(r.expert_arm, None);

    // 4. Bounding box without drawing: a region button (keyboard/switch friendly).
    let asking = ask_async(ch, query(4, ResponseType::BoundingBox));
    browser.click("#region-8");
    browser.click("#send-box");
    let (ch, _, bbox) = box_answer(asking, &browser);
    assert!(
        (bbox.x0 - 2.0 / 3.0).abs() < 1e-9 && (bbox.y1 - 1.0).abs() < 1e-9,
        "{bbox:?}"
    );

    // 4b. Bounding box by keyboard on the drawing area: arrows move a
    // default box (0.4..0.6) by 2% a press, Shift+arrows resize it.
    let asking = ask_async(ch, query(7, ResponseType::BoundingBox));
    browser.find("#bbox-canvas");
    browser.script("document.getElementById('bbox-canvas').focus();");
    browser.keys(&["\u{E014}", "\u{E014}", "\u{E014}"]); // ArrowRight ×3
    browser.click("#send-box");
    let (ch, _, bbox) = box_answer(asking, &browser);
    assert!(
        (bbox.x0 - 0.46).abs() < 1e-6 && (bbox.x1 - 0.66).abs() < 1e-6,
        "{bbox:?}"
    );
    assert!(
        (bbox.y0 - 0.4).abs() < 1e-6 && (bbox.y1 - 0.6).abs() < 1e-6,
        "{bbox:?}"
    );

    // 5. Open-ended: typed text naming an action.
    let asking = ask_async(ch, query(5, ResponseType::OpenEnded));
    browser.type_into("#answer-text", "It rolls; try TV90");
    browser.click("#send-text");
    let (ch, r) = asking.join().unwrap();
    wait_until_no_question(&browser);
    assert_eq!(
        r.answer,
        Answer::Text {
            text: "It rolls; try TV90".into()
        }
    );
    assert_eq!(r.expert_arm, Some(ArmId(3)));

    // 6. Single-switch scanning: the highlight moves by itself; one press
    // of the switch (Space) selects the highlighted control.
    browser.script("document.getElementById('scan-speed').value = '4000';");
    browser.click("#scan-toggle");
    let asking = ask_async(ch, query(6, ResponseType::Mcq));
    browser.find("#choice-0.scan-focus");
    browser.keys(&[" "]);
    let (ch, r) = asking.join().unwrap();
    wait_until_no_question(&browser);
    assert_eq!(r.answer, Answer::Action { arm: ArmId(0) });

    // The page says the answer was received and waits for the next one.
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let s = browser.script("return document.getElementById('status').textContent;");
        if s.as_str().unwrap().contains("Thank you") {
            break;
        }
        assert!(Instant::now() < deadline, "no confirmation: {s}");
        std::thread::sleep(Duration::from_millis(50));
    }
    drop(ch);
}

/// The answer `asking` gets, once the page has taken the question down;
/// it must be a bounding box.
fn box_answer(
    asking: JoinHandle<(WebChannel, Response)>,
    browser: &Browser,
) -> (WebChannel, Response, BoundingBox) {
    let (ch, r) = asking.join().unwrap();
    wait_until_no_question(browser);
    let Answer::BoundingBox { bbox } = r.answer else {
        panic!("{:?}", r.answer)
    };
    (ch, r, bbox)
}

/// Waits until the page has taken its last answer down. The channel
/// returns as soon as the server has the answer, a moment before the page
/// hears back; a next question's controls must not be confused with the
/// previous question's, still on screen.
fn wait_until_no_question(browser: &Browser) {
    let deadline = Instant::now() + Duration::from_secs(20);
    while browser.script("return document.getElementById('query').hidden;") != json!(true) {
        assert!(
            Instant::now() < deadline,
            "the answered question stayed on screen"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}
