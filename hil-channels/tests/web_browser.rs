//! The web page driven in headless Chromium through chromedriver (WebDriver
//! over HTTP on loopback): answering a multiple-choice question by touch
//! and by keyboard, a bounding box by drawing and by region buttons, an
//! open-ended question by typing, and one by single-switch scanning; plus
//! label and contrast checks on the live page.
//!
//! Needs Debian's `chromium` and `chromium-driver` (installed by
//! `scripts/test-setup-chromium`, which `scripts/test` and CI run first). The
//! test fails if they are missing, unless HIL_SKIP_BROWSER_TESTS=1.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use hil_channels::{WebChannel, WebChannelConfig};
use hil_core::{
    Answer, ArmId, Context, Difficulty, Distraction, Item, Query, QueryChannel, QueryKind,
    Response, ResponseType,
};
use serde_json::{Value, json};

const CHROMIUM: &str = "/usr/bin/chromium";
const CHROMEDRIVER: &str = "/usr/bin/chromedriver";
const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// A minimal HTTP/1.1 client for the WebDriver wire protocol.
fn http(port: u16, method: &str, path: &str, body: Option<&Value>) -> Value {
    let body = body.map(Value::to_string).unwrap_or_default();
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    // chromedriver keeps connections alive: read exactly Content-Length.
    let mut out = Vec::new();
    let mut chunk = [0u8; 8192];
    let (head_end, length) = loop {
        let n = s.read(&mut chunk).unwrap();
        assert!(n > 0, "{method} {path}: connection closed early");
        out.extend_from_slice(&chunk[..n]);
        if let Some(p) = out.windows(4).position(|w| w == b"\r\n\r\n") {
            let head = String::from_utf8_lossy(&out[..p]).to_ascii_lowercase();
            let length = head
                .lines()
                .find_map(|l| l.strip_prefix("content-length:"))
                .map(|v| v.trim().parse::<usize>().unwrap())
                .unwrap_or(0);
            break (p + 4, length);
        }
    };
    while out.len() < head_end + length {
        let n = s.read(&mut chunk).unwrap();
        assert!(n > 0, "{method} {path}: body cut short");
        out.extend_from_slice(&chunk[..n]);
    }
    let text = String::from_utf8_lossy(&out[head_end..head_end + length]).to_string();
    let payload = text.as_str();
    serde_json::from_str(payload).unwrap_or_else(|e| panic!("{method} {path}: {e}: {text}"))
}

struct Browser {
    driver: Child,
    port: u16,
    session: String,
    profile: PathBuf,
}

impl Browser {
    fn start() -> Self {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let driver = Command::new(CHROMEDRIVER)
            .arg(format!("--port={port}"))
            .arg("--allowed-ips=127.0.0.1")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromedriver starts");
        let deadline = Instant::now() + Duration::from_secs(30);
        while TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(Instant::now() < deadline, "chromedriver did not start");
            std::thread::sleep(Duration::from_millis(50));
        }
        let profile =
            std::env::temp_dir().join(format!("hil-chromium-{}-{port}", std::process::id()));
        let _ = std::fs::remove_dir_all(&profile);
        std::fs::create_dir_all(&profile).unwrap();
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {
                "binary": CHROMIUM,
                "args": [
                    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                    "--no-first-run", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync",
                    format!("--user-data-dir={}", profile.display()),
                    // A phone-sized window: the page must work there.
                    "--window-size=412,915",
                ]
            }
        }}});
        let mut b = Self {
            driver,
            port,
            session: String::new(),
            profile,
        };
        let r = http(port, "POST", "/session", Some(&caps));
        b.session = r["value"]["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("no session: {r}"))
            .to_string();
        b
    }

    fn cmd(&self, method: &str, path: &str, body: Value) -> Value {
        let r = http(
            self.port,
            method,
            &format!("/session/{}{path}", self.session),
            Some(&body),
        );
        if let Some(err) = r["value"].get("error") {
            panic!("{method} {path}: {err}: {}", r["value"]["message"]);
        }
        r["value"].clone()
    }

    fn goto(&self, url: &str) {
        self.cmd("POST", "/url", json!({ "url": url }));
    }

    /// Waits for a displayed element matching `css` and returns its id.
    fn find(&self, css: &str) -> String {
        let deadline = Instant::now() + Duration::from_secs(20);
        loop {
            let r = http(
                self.port,
                "POST",
                &format!("/session/{}/element", self.session),
                Some(&json!({"using": "css selector", "value": css})),
            );
            if let Some(id) = r["value"][ELEMENT].as_str() {
                // The page rebuilds its controls for each question: an
                // element found a moment ago may be gone (stale); retry.
                let shown = http(
                    self.port,
                    "GET",
                    &format!("/session/{}/element/{id}/displayed", self.session),
                    None,
                );
                if shown["value"] == json!(true) {
                    return id.to_string();
                }
            }
            assert!(Instant::now() < deadline, "{css} never appeared");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Waits until the page has taken its last answer down. The channel
    /// returns as soon as the server has the answer, a moment before the
    /// page hears back; a next question's controls must not be confused
    /// with the previous question's, still on screen.
    fn wait_until_no_question(&self) {
        let deadline = Instant::now() + Duration::from_secs(20);
        while self.script("return document.getElementById('query').hidden;") != json!(true) {
            assert!(
                Instant::now() < deadline,
                "the answered question stayed on screen"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn click(&self, css: &str) {
        let id = self.find(css);
        self.cmd("POST", &format!("/element/{id}/click"), json!({}));
    }

    fn type_into(&self, css: &str, text: &str) {
        let id = self.find(css);
        self.cmd(
            "POST",
            &format!("/element/{id}/value"),
            json!({ "text": text }),
        );
    }

    fn script(&self, script: &str) -> Value {
        self.cmd(
            "POST",
            "/execute/sync",
            json!({ "script": script, "args": [] }),
        )
    }

    fn keys(&self, keys: &[&str]) {
        let mut actions = Vec::new();
        for k in keys {
            actions.push(json!({"type": "keyDown", "value": k}));
            actions.push(json!({"type": "keyUp", "value": k}));
        }
        self.cmd(
            "POST",
            "/actions",
            json!({"actions": [{"type": "key", "id": "keyboard", "actions": actions}]}),
        );
        self.cmd("DELETE", "/actions", json!({}));
    }

    /// Drags with a touch pointer across `css` from one offset to another
    /// (offsets relative to the element's centre, in CSS pixels).
    fn drag(&self, css: &str, from: (i64, i64), to: (i64, i64)) {
        let id = self.find(css);
        let origin = json!({ ELEMENT: id });
        self.cmd(
            "POST",
            "/actions",
            json!({"actions": [{"type": "pointer", "id": "finger", "parameters": {"pointerType": "touch"},
                "actions": [
                    {"type": "pointerMove", "origin": origin, "x": from.0, "y": from.1},
                    {"type": "pointerDown", "button": 0},
                    {"type": "pointerMove", "origin": origin, "x": (from.0 + to.0) / 2, "y": (from.1 + to.1) / 2, "duration": 50},
                    {"type": "pointerMove", "origin": origin, "x": to.0, "y": to.1, "duration": 50},
                    {"type": "pointerUp", "button": 0}
                ]}]}),
        );
        self.cmd("DELETE", "/actions", json!({}));
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = TcpStream::connect(("127.0.0.1", self.port)).map(|_| {
                http(
                    self.port,
                    "DELETE",
                    &format!("/session/{}", self.session),
                    None,
                )
            });
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

fn query(t: u64, response: ResponseType) -> Query {
    Query {
        t,
        item: Item {
            index: t as usize,
            label: "baby_carrot".into(),
            description: Some("a baby carrot lying flat".into()),
        },
        kind: QueryKind {
            response,
            difficulty: Difficulty::Hard,
            distraction: Distraction::Easy,
        },
        actions: hil_envs::feeding::action_space(),
        context: Context::new(vec![0.0]).unwrap(),
        oracle_best: Some(ArmId(5)),
    }
}

fn ask_async(mut ch: WebChannel, q: Query) -> JoinHandle<(WebChannel, Response)> {
    std::thread::spawn(move || {
        let r = ch.ask(&q).unwrap();
        (ch, r)
    })
}

fn tools_present() -> bool {
    if Path::new(CHROMIUM).exists() && Path::new(CHROMEDRIVER).exists() {
        return true;
    }
    if std::env::var_os("HIL_SKIP_BROWSER_TESTS").is_some() {
        eprintln!("SKIPPED: chromium/chromedriver missing and HIL_SKIP_BROWSER_TESTS is set");
        return false;
    }
    panic!("{CHROMIUM} and {CHROMEDRIVER} are needed: run scripts/test-setup-chromium");
}

/// WCAG relative luminance contrast of two `rgb(...)` colours.
fn contrast(a: &str, b: &str) -> f64 {
    let lum = |c: &str| {
        let v: Vec<f64> = c
            .trim_start_matches("rgba(")
            .trim_start_matches("rgb(")
            .trim_end_matches(')')
            .split(',')
            .take(3)
            .map(|x| x.trim().parse::<f64>().unwrap() / 255.0)
            .map(|x| {
                if x <= 0.03928 {
                    x / 12.92
                } else {
                    ((x + 0.055) / 1.055).powf(2.4)
                }
            })
            .collect();
        0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]
    };
    let (la, lb) = (lum(a), lum(b));
    (la.max(lb) + 0.05) / (la.min(lb) + 0.05)
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
    browser.wait_until_no_question();
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
    browser.wait_until_no_question();
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
    let (ch, r) = asking.join().unwrap();
    browser.wait_until_no_question();
    let Answer::BoundingBox { bbox } = r.answer else {
        panic!("{:?}", r.answer)
    };
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
    let (ch, r) = asking.join().unwrap();
    browser.wait_until_no_question();
    let Answer::BoundingBox { bbox } = r.answer else {
        panic!("{:?}", r.answer)
    };
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
    let (ch, r) = asking.join().unwrap();
    browser.wait_until_no_question();
    let Answer::BoundingBox { bbox } = r.answer else {
        panic!("{:?}", r.answer)
    };
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
    browser.wait_until_no_question();
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
    browser.wait_until_no_question();
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
