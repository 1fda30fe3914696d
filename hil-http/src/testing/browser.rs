//! Headless Chromium driven through chromedriver (WebDriver over HTTP on
//! loopback), shared by the browser test suites; plus the WCAG contrast
//! ratio the accessibility checks use.
//!
//! Every call panics on failure: these are test helpers.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// Where `scripts/test-setup-chromium` installs Chromium.
pub const CHROMIUM: &str = "/usr/bin/chromium";
/// Where `scripts/test-setup-chromium` installs chromedriver.
pub const CHROMEDRIVER: &str = "/usr/bin/chromedriver";
/// The key under which WebDriver returns an element's id.
pub const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// A minimal HTTP/1.1 client for the WebDriver wire protocol: one request,
/// its JSON answer.
pub fn http(port: u16, method: &str, path: &str, body: Option<&Value>) -> Value {
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

/// A headless Chromium session with a phone-sized window, ended (and its
/// profile removed) on drop.
pub struct Browser {
    driver: Child,
    port: u16,
    session: String,
    profile: PathBuf,
}

impl std::fmt::Debug for Browser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Browser")
            .field("port", &self.port)
            .field("session", &self.session)
            .finish()
    }
}

impl Browser {
    /// Starts chromedriver on a free loopback port and opens a session.
    pub fn start() -> Self {
        Self::start_with(&[])
    }

    /// As [`start`](Self::start), trusting the HTTPS server whose
    /// certificate has this public key (Chromium pins it by the SHA-256 of
    /// its SubjectPublicKeyInfo, [`Tls::public_key_sha256`]); any other
    /// certificate error still stops the page.
    ///
    /// [`Tls::public_key_sha256`]: crate::tls::Tls::public_key_sha256
    #[cfg(feature = "tls")]
    pub fn start_trusting(public_key_sha256: [u8; 32]) -> Self {
        use base64::Engine;
        let pin = base64::engine::general_purpose::STANDARD.encode(public_key_sha256);
        Self::start_with(&[format!("--ignore-certificate-errors-spki-list={pin}")])
    }

    fn start_with(extra_args: &[String]) -> Self {
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
        let mut args: Vec<String> = [
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            // A phone-sized window: the page must work there.
            "--window-size=412,915",
        ]
        .into_iter()
        .map(String::from)
        .collect();
        args.push(format!("--user-data-dir={}", profile.display()));
        args.extend(extra_args.iter().cloned());
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": { "binary": CHROMIUM, "args": args }
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

    /// Sends one WebDriver command of this session; its `value`.
    pub fn cmd(&self, method: &str, path: &str, body: Value) -> Value {
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

    /// Opens `url`.
    pub fn goto(&self, url: &str) {
        self.cmd("POST", "/url", json!({ "url": url }));
    }

    /// Waits for a displayed element matching `css` and returns its id.
    pub fn find(&self, css: &str) -> String {
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

    /// Clicks the displayed element matching `css` (waiting for it).
    pub fn click(&self, css: &str) {
        let id = self.find(css);
        self.cmd("POST", &format!("/element/{id}/click"), json!({}));
    }

    /// Types `text` into the displayed element matching `css`.
    pub fn type_into(&self, css: &str, text: &str) {
        let id = self.find(css);
        self.cmd(
            "POST",
            &format!("/element/{id}/value"),
            json!({ "text": text }),
        );
    }

    /// Runs `script` in the page; what it returns.
    pub fn script(&self, script: &str) -> Value {
        self.cmd(
            "POST",
            "/execute/sync",
            json!({ "script": script, "args": [] }),
        )
    }

    /// Presses and releases each key in turn (WebDriver key codes).
    pub fn keys(&self, keys: &[&str]) {
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
    pub fn drag(&self, css: &str, from: (i64, i64), to: (i64, i64)) {
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

/// Whether Chromium and chromedriver are installed. Missing, they fail the
/// test, unless `HIL_SKIP_BROWSER_TESTS` is set (then: false, and the test
/// skips itself).
pub fn tools_present() -> bool {
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
pub fn contrast(a: &str, b: &str) -> f64 {
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
