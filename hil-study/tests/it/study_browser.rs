//! A scripted participant takes a shortened workload study in headless
//! Chromium, by keyboard only: a baseline (addition task) and two query
//! conditions (easy and hard queries, transcription task) with the time
//! scale at 60 (a study minute lasts a second). They answer every query
//! type and every survey, start the last part by single-switch scanning,
//! and midway close the page and open their link again. The pages are
//! served over HTTPS with the data folder's self-signed certificate, which
//! the browser trusts by its pinned public key (on loopback). The live page
//! passes the accessibility checks; the researcher's page shows the
//! progress and enrols; the export passes the study loader, has the
//! expected pairs and fits a model.

use std::time::{Duration, Instant};

use hil_http::testing::browser::{Browser, contrast, tools_present};
use hil_study::{StudyConfig, StudyServer, export};
use hil_workload::bundle::StudySummary;
use hil_workload::datasets::{Dataset, DatasetId};
use hil_workload::models::GrangerVariant;
use hil_workload::select::{Candidate, SelectOptions, fit_on_all};
use hil_workload::study::Population;
use serde_json::{Value, json};

const CONFIG: &str = r#"
[design]
difficulties = ["easy", "hard"]
distractions = ["hard"]
intervals_min = [1]
baselines = ["easy"]
time_scale = 60

[server]
https = true
"#;

const TAB: &str = "\u{E004}";
const ENTER: &str = "\u{E007}";
const SPACE: &str = " ";
const RIGHT: &str = "\u{E014}";

/// Which part of the study the page shows now.
fn page_state(b: &Browser) -> Value {
    b.script(
        r#"const vis = (id) => !document.getElementById(id).hidden;
           const kind = !vis('query') ? null : (vis('q-mcq') ? 'mcq' : vis('q-box') ? 'bounding_box' : vis('q-text') ? 'open_ended' : null);
           return {intro: vis('intro'), query: kind, survey: vis('survey') && document.querySelectorAll('#survey-questions input').length === 25,
                   done: vis('done'), addition: vis('task') && vis('addition'), transcription: vis('task') && vis('transcription'),
                   focus: document.activeElement ? document.activeElement.id : '',
                   sum: document.getElementById('sum-question').textContent,
                   passage: document.getElementById('passage').textContent,
                   first_legend: (document.querySelector('#survey-questions legend') || {}).textContent || ''};"#,
    )
}

/// Types `text` with key presses.
fn type_text(b: &Browser, text: &str) {
    let keys: Vec<String> = text.chars().map(|c| c.to_string()).collect();
    let refs: Vec<&str> = keys.iter().map(String::as_str).collect();
    b.keys(&refs);
}

/// Waits until the element with id `id` has the focus (generously: a loaded
/// machine can take seconds to run the page's script).
fn wait_focus(b: &Browser, ids: &[&str]) -> bool {
    let deadline = Instant::now() + Duration::from_secs(20);
    while Instant::now() < deadline {
        let f = b.script("return document.activeElement ? document.activeElement.id : '';");
        if ids.iter().any(|id| f == json!(id)) {
            return true;
        }
        std::thread::sleep(Duration::from_millis(30));
    }
    false
}

/// Contrast, labels, target sizes and reflow on what the page shows now.
fn audit(b: &Browser, what: &str) {
    let audit = b.script(
        r#"const out = {unnamed: [], colours: [], small: []};
           const shown = (e) => e.offsetParent !== null && !e.closest('[hidden]');
           document.querySelectorAll('button, input, select, textarea, canvas').forEach(e => {
             if (!shown(e) && e.type !== 'radio') return;
             const id = e.id;
             const label = e.getAttribute('aria-label') || (e.tagName === 'BUTTON' && e.textContent.trim()) ||
               (id && document.querySelector('label[for="' + id + '"]')) || e.closest('label');
             if (!label) out.unnamed.push(e.outerHTML.slice(0, 80));
           });
           document.querySelectorAll('main button, main label, main h2, main p, main legend, main span').forEach(e => {
             if (!shown(e) || !e.textContent.trim()) return;
             const s = getComputedStyle(e);
             let bg = s.backgroundColor, p = e;
             while ((bg === 'rgba(0, 0, 0, 0)' || bg === 'transparent') && p.parentElement) {
               p = p.parentElement; bg = getComputedStyle(p).backgroundColor;
             }
             out.colours.push([e.tagName + '#' + e.id + ' ' + e.textContent.trim().slice(0, 20), s.color, bg]);
           });
           document.querySelectorAll('main button, .scale label, main input[type=text]').forEach(e => {
             if (!shown(e)) return;
             const r = e.getBoundingClientRect();
             if (r.height < 44 || r.width < 44) out.small.push(e.id || e.textContent.trim());
           });
           out.overflow = document.documentElement.scrollWidth > window.innerWidth;
           return out;"#,
    );
    assert_eq!(
        audit["unnamed"],
        json!([]),
        "{what}: controls without a label"
    );
    assert_eq!(
        audit["small"],
        json!([]),
        "{what}: touch targets under 44 px"
    );
    assert_eq!(
        audit["overflow"],
        json!(false),
        "{what}: horizontal scrolling on a phone"
    );
    for c in audit["colours"].as_array().unwrap() {
        let ratio = contrast(c[1].as_str().unwrap(), c[2].as_str().unwrap());
        assert!(ratio >= 4.5, "{what}: {} contrast {ratio:.2}", c[0]);
    }
}

#[test]
#[ignore = "e2e: needs chromium and chromedriver; bash scripts/test runs it"]
fn a_scripted_participant_completes_a_shortened_study_by_keyboard() {
    if !tools_present() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("hil-study-browser-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let config = StudyConfig::parse(CONFIG, "study.toml".as_ref()).unwrap();
    let server = StudyServer::start(config, &dir).unwrap();
    let (id, urls) = server.enrol(Population::MobilityLimitation).unwrap();
    assert_eq!(id, "p001");
    assert!(urls[0].starts_with("https://127.0.0.1:"), "{urls:?}");

    let b = Browser::start_trusting(server.tls().unwrap().public_key_sha256());
    b.goto(&urls[0]);
    let mut seen = std::collections::BTreeSet::new();
    let mut surveys = 0;
    let mut intros = 0;
    let mut audited = std::collections::BTreeSet::new();
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        assert!(
            Instant::now() < deadline,
            "the study did not finish; seen {seen:?}"
        );
        let s = page_state(&b);
        let mut check = |what: &str| {
            if audited.insert(what.to_string()) {
                audit(&b, what);
            }
        };
        if s["done"] == json!(true) {
            break;
        } else if s["intro"] == json!(true) {
            check("intro");
            intros += 1;
            if intros == 3 {
                // Single-switch scanning: the highlight comes to Start by
                // itself; one press of the switch (Space) starts.
                b.script("document.getElementById('scan-speed').value = '1000'; document.getElementById('scan-toggle').click();");
                b.find("#start.scan-focus");
                b.keys(&[SPACE]);
            } else {
                assert!(
                    wait_focus(&b, &["start"]),
                    "focus is on Start: {}",
                    page_state(&b)
                );
                b.keys(&[ENTER]);
            }
            let until = Instant::now() + Duration::from_secs(10);
            while page_state(&b)["intro"] == json!(true) && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(30));
            }
            assert_eq!(page_state(&b)["intro"], json!(false), "the part started");
            if intros == 3 {
                b.script("document.getElementById('scan-toggle').click();");
            }
        } else if s["survey"] == json!(true) {
            check("survey");
            let legend = s["first_legend"].as_str().unwrap();
            assert!(legend.contains("mentally or physically"), "{legend}");
            assert!(
                wait_focus(&b, &["tlx-mental-1"]),
                "focus is on the first answer"
            );
            // Answer 1..5 as Space then ArrowRight × (v − 1), Tab to the next.
            for (i, v) in [3usize, 2, 4, 3, 1].iter().enumerate() {
                let mut keys = vec![SPACE];
                keys.extend(std::iter::repeat_n(RIGHT, v - 1));
                keys.push(TAB);
                b.keys(&keys);
                let checked = b.script(&format!(
                    "const e = document.querySelector('#survey-questions fieldset:nth-child({}) input:checked'); return e ? e.value : null;",
                    i + 1
                ));
                assert_eq!(checked, json!(v.to_string()), "survey answer {i}");
            }
            assert!(wait_focus(&b, &["survey-send"]));
            b.keys(&[ENTER]);
            surveys += 1;
            if surveys == 2 {
                // The participant closes the page mid-condition and opens
                // the link again: they continue where they were.
                b.goto("about:blank");
                std::thread::sleep(Duration::from_millis(500));
                b.goto(&urls[0]);
            }
            // Wait for the survey to go.
            let until = Instant::now() + Duration::from_secs(10);
            while page_state(&b)["survey"] == json!(true) && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(30));
            }
        } else if let Some(kind) = s["query"].as_str() {
            check(kind);
            seen.insert(kind.to_string());
            match kind {
                "mcq" => {
                    assert!(wait_focus(&b, &["option-0"]));
                    b.keys(&[TAB, ENTER]); // the second choice
                }
                "bounding_box" => {
                    assert!(wait_focus(&b, &["box-canvas"]));
                    b.keys(&[RIGHT, RIGHT]); // moves the default box (40%..60%) 2% a press
                    let readout =
                        b.script("return document.getElementById('box-readout').textContent;");
                    assert!(
                        readout.as_str().unwrap().starts_with("Box: left 44%"),
                        "{readout}"
                    );
                    let tabs: Vec<&str> = std::iter::repeat_n(TAB, 10).collect();
                    b.keys(&tabs);
                    assert!(wait_focus(&b, &["send-box"]));
                    b.keys(&[ENTER]);
                }
                _ => {
                    assert!(wait_focus(&b, &["q-text-answer"]));
                    type_text(&b, "It is slippery; go in at an angle");
                    b.keys(&[TAB, ENTER]);
                }
            }
            let until = Instant::now() + Duration::from_secs(10);
            while page_state(&b)["query"].is_string()
                && page_state(&b)["survey"] != json!(true)
                && Instant::now() < until
            {
                std::thread::sleep(Duration::from_millis(30));
            }
        } else if s["addition"] == json!(true) && s["focus"] == json!("sum-answer") {
            check("addition");
            let q = s["sum"].as_str().unwrap();
            let nums: Vec<u64> = q
                .trim_start_matches("What is ")
                .trim_end_matches('?')
                .split(" + ")
                .map(|n| n.parse().unwrap())
                .collect();
            type_text(&b, &(nums[0] + nums[1]).to_string());
            b.keys(&[ENTER]);
            std::thread::sleep(Duration::from_millis(150));
        } else if s["transcription"] == json!(true) && s["focus"] == json!("transcript") {
            check("transcription");
            let words = s["passage"].as_str().unwrap().to_string();
            if !words.is_empty() {
                type_text(&b, words.split(' ').next_back().unwrap());
                b.keys(&[ENTER]);
            }
            std::thread::sleep(Duration::from_millis(200));
        } else {
            std::thread::sleep(Duration::from_millis(50));
        }
    }
    assert_eq!(
        seen.into_iter().collect::<Vec<_>>(),
        ["bounding_box", "mcq", "open_ended"]
    );
    // 5 queries in each of 2 conditions, each with a survey, and one
    // survey at the end of each of the 3 conditions.
    assert_eq!(surveys, 13);

    // The researcher's page (its script is a file: the security policy
    // runs no inline script) shows the progress and enrols over HTTPS.
    b.goto(&server.researcher_urls()[0]);
    b.find("#scan-toggle");
    let row = b.find("#rows tr");
    let text = b.cmd("GET", &format!("/element/{row}/text"), json!({}));
    assert!(
        text.as_str()
            .unwrap()
            .starts_with("p001 mobility_limitation 3 / 3"),
        "{text}"
    );
    b.click("#enrol");
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let said = b.script("return document.getElementById('enrolled').textContent;");
        if said
            .as_str()
            .unwrap()
            .starts_with("Enrolled p002: https://127.0.0.1:")
        {
            break;
        }
        assert!(Instant::now() < deadline, "{said}");
        std::thread::sleep(Duration::from_millis(50));
    }
    drop(b);
    drop(server);

    let study = export(&dir).unwrap();
    // The query surveys and the baseline survey; the end-of-condition
    // surveys of query conditions stay in the raw log.
    assert_eq!(study.records().len(), 11);
    let csv = dir.join("study.csv");
    study.write(&csv).unwrap();
    let loaded = hil_workload::study::Study::load(&csv).unwrap();
    let unlined = |s: &hil_workload::study::Study| {
        s.records()
            .iter()
            .cloned()
            .map(|mut r| {
                r.line = 0;
                r
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(unlined(&loaded), unlined(&study));
    let summary = StudySummary::of(&loaded).unwrap();
    let pairs: Vec<(DatasetId, usize)> = summary.datasets.iter().map(|d| (d.0, d.1)).collect();
    assert_eq!(pairs, vec![(DatasetId::D2, 10), (DatasetId::D12, 10)]);
    let d12 = Dataset::build(&loaded, DatasetId::D12).unwrap();
    let (spec, _) = fit_on_all(
        &d12,
        Candidate::Granger {
            variant: GrangerVariant::Nonnegative,
            h: 1,
        },
        &SelectOptions::default(),
    )
    .unwrap();
    let _ = spec;
    // Every survey has a logged time; every query row its kind.
    for r in loaded.records() {
        assert!(r.survey_time_s.is_some());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
