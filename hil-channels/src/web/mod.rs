//! A query channel served as a web page, for the person being fed: on a
//! phone or tablet next to the robot, by touch, keyboard or single switch.

use hil_config::TaskContext;
pub(crate) mod http;
pub mod urls;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use rand::Rng;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use hil_config::QueryChannelConfig;
use hil_core::{Answer, ArmId, HilError, Query, QueryChannel, Response, Result};

use crate::present::{describe_item, describe_kind, question, validate_answer};
use http::{Limits, Occupancy, Request, Response as HttpResponse, Server, Service};

const PAGE_HTML: &str = include_str!("page.html");
const PAGE_JS: &str = include_str!("page.js");
/// The page's style sheet; the study's pages share it.
pub(crate) const PAGE_CSS: &str = include_str!("page.css");

/// The default time a person has to answer before the policy acts alone.
pub const DEFAULT_TIMEOUT_S: f64 = 120.0;

fn default_bind() -> IpAddr {
    IpAddr::V4(Ipv4Addr::LOCALHOST)
}

fn default_timeout() -> f64 {
    DEFAULT_TIMEOUT_S
}

/// Config of the web channel, `type = "web"`:
///
/// ```toml
/// [channel]
/// type = "web"
/// bind = "127.0.0.1"     # default; "0.0.0.0" to reach it from a tablet on the LAN
///                        # (then the machine's addresses are printed, one URL each)
/// port = 8765            # default 0: any free port (the URL is printed)
/// timeout_s = 120        # then the robot acts on its own (recorded as timed_out)
/// allowed_hosts = []     # host names besides IP addresses and localhost
/// images = "pictures"    # optional: <item label>.png/.jpg/.jpeg/.webp shown with the question
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WebChannelConfig {
    /// Address to listen on.
    #[serde(default = "default_bind")]
    pub bind: IpAddr,
    /// Port to listen on; 0 picks a free one.
    #[serde(default)]
    pub port: u16,
    /// Seconds a person has to answer (> 0).
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// Extra host names the page may be reached by (the `Host` header);
    /// IP addresses and `localhost` are always accepted.
    #[serde(default)]
    pub allowed_hosts: Vec<String>,
    /// Directory of item pictures, named by item label (`banana.jpg`);
    /// relative paths resolve against the config's directory. Items without
    /// a picture are shown by their description.
    #[serde(default)]
    pub images: Option<std::path::PathBuf>,
}

impl Default for WebChannelConfig {
    fn default() -> Self {
        Self {
            bind: default_bind(),
            port: 0,
            timeout_s: DEFAULT_TIMEOUT_S,
            allowed_hosts: Vec::new(),
            images: None,
        }
    }
}

#[typetag::serde(name = "web")]
impl QueryChannelConfig for WebChannelConfig {
    fn validate(&self) -> Result<()> {
        // The rest (hosts, bind) needs the network stack: `start` checks it.
        hil_config::limits::check_seconds("timeout_s", self.timeout_s)
    }

    fn build(&self, ctx: &TaskContext) -> Result<Box<dyn QueryChannel>> {
        let mut config = self.clone();
        config.images = config.images.map(|d| ctx.resolve(&d));
        Ok(Box::new(WebChannel::start(config)?))
    }
}

/// The query on the page, and its answer once given.
struct Pending {
    id: u64,
    query: Query,
    asked_at: Instant,
    deadline: Instant,
    answer: Option<(Answer, Option<ArmId>)>,
    /// The item's picture and its content type, if there is one.
    image: Option<(Vec<u8>, &'static str)>,
}

#[derive(Default)]
struct State {
    current: Option<Pending>,
    next_id: u64,
    /// What the page says between queries (a thank-you, a timeout).
    notice: Option<String>,
}

struct Shared {
    token: String,
    /// The bound port, set once the server is listening.
    port: std::sync::OnceLock<u16>,
    allowed_hosts: Vec<String>,
    timeout: Duration,
    images: Option<std::path::PathBuf>,
    state: Mutex<State>,
    answered: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        // A poisoned lock only means a handler panicked mid-update; the
        // state itself is always consistent between statements.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// Serves queries on a local web page and waits for the person's answer.
///
/// - The server listens on 127.0.0.1 by default; every URL carries a
///   per-session random token (`http://127.0.0.1:PORT/TOKEN/`): without it,
///   or with a wrong one, every request gets 403. Bound to `0.0.0.0`, it
///   gives one URL per address of the machine ([`urls`](Self::urls)).
/// - Clients without the token cannot lock the person out: each request
///   must arrive whole within 10 s, and requests carrying the token have
///   connection slots of their own (the server's limits are listed in
///   `hil-channels/src/web/http/mod.rs`).
/// - Answers are accepted only from the page's own origin (`Origin` must
///   match `Host`, a JSON body is required, `Host` must be an IP address,
///   `localhost` or an allowed name), so another web site open in the same
///   browser cannot answer.
/// - The page shows the item, the kind of question, and large buttons
///   (multiple choice), a drawing area with a keyboard- and switch-friendly
///   alternative (bounding box) or a text field (open-ended); "I don't
///   know" is always offered.
/// - If nobody answers within `timeout_s`, the answer is
///   [`Answer::TimedOut`] and the policy's fallback arm is executed; the
///   interaction record stores that.
///
/// ```no_run
/// use hil_channels::{WebChannel, WebChannelConfig};
/// use hil_core::QueryChannel;
/// let ch = WebChannel::start(WebChannelConfig::default()).unwrap();
/// println!("open {}", ch.endpoint().unwrap());
/// ```
pub struct WebChannel {
    shared: Arc<Shared>,
    server: Server,
    /// Never empty: `start` refuses to run without an address to print.
    urls: Vec<String>,
}

impl std::fmt::Debug for WebChannel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WebChannel")
            .field("addr", &self.server.addr())
            .finish()
    }
}

/// Every extra name a page may be reached by (`allowed_hosts`, of the query
/// page and of the study) must be a plain host name.
pub(crate) fn check_allowed_hosts(hosts: &[String]) -> Result<()> {
    for h in hosts {
        if h.is_empty()
            || !h
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'.' || b == b'-')
        {
            return Err(HilError::invalid_parameter(
                "allowed_hosts",
                h,
                "must be a host name (letters, digits, dots, dashes)",
            ));
        }
    }
    Ok(())
}

impl WebChannel {
    /// Validates `config`, binds the server and starts serving.
    pub fn start(config: WebChannelConfig) -> Result<Self> {
        config.validate()?;
        check_allowed_hosts(&config.allowed_hosts)?;
        if let Some(dir) = &config.images
            && !dir.is_dir()
        {
            return Err(HilError::invalid_parameter(
                "images",
                dir.display(),
                "is not a directory",
            ));
        }
        let token: String = rand::rng()
            .random::<[u8; 16]>()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        let bind = SocketAddr::new(config.bind, config.port);
        // The handler needs the bound port, known only after binding: it
        // reads it from `Shared`, filled in right after.
        let shared = Arc::new(Shared {
            token,
            port: std::sync::OnceLock::new(),
            allowed_hosts: config
                .allowed_hosts
                .iter()
                .map(|h| h.to_ascii_lowercase())
                .collect(),
            timeout: Duration::from_secs_f64(config.timeout_s),
            images: config.images.clone(),
            state: Mutex::new(State::default()),
            answered: Condvar::new(),
        });
        let channel_error = |why: String| HilError::channel("web", why);
        let server = Server::start(bind, Arc::new(Page(shared.clone())), Limits::default())
            .map_err(|e| channel_error(format!("cannot listen on {bind}: {e}")))?;
        let addr = server.addr();
        let _ = shared.port.set(addr.port());
        let hosts = urls::reachable_hosts(addr.ip()).map_err(|e| {
            channel_error(format!(
                "listening on {addr}, but cannot list this machine's addresses to print \
                 the page's URL ({e}); set `bind` to the address to use"
            ))
        })?;
        if hosts.is_empty() {
            return Err(channel_error(format!(
                "listening on {addr}, but this machine has no address of that kind to open \
                 the page at; set `bind` to the address to use"
            )));
        }
        let urls = hosts
            .into_iter()
            .map(|ip| urls::page_url(ip, addr.port(), &shared.token))
            .collect();
        Ok(Self {
            shared,
            server,
            urls,
        })
    }

    /// The address the server listens on.
    pub fn addr(&self) -> SocketAddr {
        self.server.addr()
    }

    /// The page's URL, token included: the first of [`urls`](Self::urls).
    pub fn url(&self) -> &str {
        &self.urls[0]
    }

    /// Every URL the page can be opened at, token included: one per
    /// address the server listens on (for `bind = "0.0.0.0"`, the
    /// machine's addresses, those other devices can use first, loopback
    /// last; see [`urls::reachable_hosts`]).
    pub fn urls(&self) -> &[String] {
        &self.urls
    }

    /// How many connections the server holds now, by pool (strangers,
    /// token holders): to watch for a flood of connections.
    pub fn occupancy(&self) -> Occupancy {
        self.server.occupancy()
    }
}

impl QueryChannel for WebChannel {
    fn name(&self) -> &str {
        "web"
    }

    /// The page's URLs, one per line (see [`WebChannel::urls`]).
    fn endpoint(&self) -> Option<String> {
        Some(self.urls.join("\n"))
    }

    fn ask(&mut self, query: &Query) -> Result<Response> {
        let image = match &self.shared.images {
            Some(dir) => load_image(dir, &query.item.label)?,
            None => None,
        };
        let mut state = self.shared.lock();
        let id = state.next_id;
        state.next_id += 1;
        let asked_at = Instant::now();
        let deadline = asked_at + self.shared.timeout;
        state.notice = None;
        state.current = Some(Pending {
            id,
            query: query.clone(),
            asked_at,
            deadline,
            answer: None,
            image,
        });
        loop {
            let answered = state
                .current
                .as_mut()
                .filter(|p| p.id == id)
                .and_then(|p| p.answer.take());
            if let Some((answer, expert_arm)) = answered {
                let elapsed = asked_at.elapsed().as_secs_f64();
                state.current = None;
                state.notice = Some(match expert_arm {
                    Some(arm) => format!(
                        "Thank you. The robot will use {}.",
                        query.actions.name(arm).unwrap_or("your choice")
                    ),
                    None => "Thank you. The robot will choose on its own.".to_string(),
                });
                return Ok(Response::new(answer, expert_arm, Some(elapsed)));
            }
            let now = Instant::now();
            if now >= deadline {
                state.current = None;
                state.notice = Some("No answer in time: the robot chose on its own.".to_string());
                return Ok(Response::without_action(Answer::TimedOut)
                    .with_response_time(self.shared.timeout.as_secs_f64()));
            }
            state = self
                .shared
                .answered
                .wait_timeout(state, deadline - now)
                .unwrap_or_else(|p| p.into_inner())
                .0;
        }
    }
}

/// The picture of item `label` in `dir`, if there is one. Labels that are
/// not plain names (letters, digits, `_`, `-`) never map to a file. SVG is
/// not served: it can carry scripts. A picture that is not a regular file
/// or is larger than `hil_core::files::limits::ASSET` is an error (naming
/// the file), not a question without its picture.
fn load_image(dir: &std::path::Path, label: &str) -> Result<Option<(Vec<u8>, &'static str)>> {
    if label.is_empty()
        || !label
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
    {
        return Ok(None);
    }
    for (ext, content_type) in [
        ("png", "image/png"),
        ("jpg", "image/jpeg"),
        ("jpeg", "image/jpeg"),
        ("webp", "image/webp"),
    ] {
        let path = dir.join(format!("{label}.{ext}"));
        if !path.exists() {
            continue;
        }
        let bytes = hil_core::files::read_bytes(&path, hil_core::files::limits::ASSET)?;
        return Ok(Some((bytes, content_type)));
    }
    Ok(None)
}

/// Short explanations of the feeding actions, shown under their names.
fn action_hint(name: &str) -> Option<String> {
    let (pitch, roll) = name.split_at(name.len().min(2));
    let pitch = match pitch {
        "VS" => "fork straight down",
        "TV" => "fork tilted, coming down vertically",
        "TA" => "fork tilted, coming in at an angle",
        _ => return None,
    };
    let roll = match roll {
        "0" => "tines along the food",
        "90" => "tines across the food",
        _ => return None,
    };
    Some(format!("{pitch}; {roll}"))
}

fn query_view(p: &Pending) -> Value {
    let q = &p.query;
    let remaining = p.deadline.saturating_duration_since(Instant::now());
    json!({
        "state": "query",
        "id": p.id,
        "t": q.t,
        "item": {
            "label": q.item.label.replace('_', " "),
            "description": q.item.description,
            "text": describe_item(q),
        },
        "kind": q.kind,
        "kind_text": describe_kind(&q.kind),
        "question": question(q),
        "actions": q.actions.names().iter().enumerate().map(|(i, n)| json!({
            "arm": i, "name": n, "hint": action_hint(n),
        })).collect::<Vec<_>>(),
        "image": p.image.as_ref().map(|_| format!("image/{}", p.id)),
        "remaining_s": remaining.as_secs_f64(),
        "elapsed_s": p.asked_at.elapsed().as_secs_f64(),
    })
}

pub(crate) fn forbidden(why: &str) -> HttpResponse {
    HttpResponse::text(403, format!("forbidden: {why}"))
}

/// Compares without revealing, by timing, how much of the token matched.
pub(crate) fn same_token(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

/// Whether the `Host` header names this server: an IP address, `localhost`
/// or an allowed name, on our port. Refusing other names defeats DNS
/// rebinding.
fn host_allowed(shared: &Shared, port: u16, host: &str) -> bool {
    host_allowed_in(&shared.allowed_hosts, port, host)
}

/// [`host_allowed`] for a list of allowed (lower-case) names.
pub(crate) fn host_allowed_in(allowed_hosts: &[String], port: u16, host: &str) -> bool {
    let host = host.to_ascii_lowercase();
    let (name, host_port) = match host.rsplit_once(':') {
        Some((n, p)) if !n.ends_with(']') || host.starts_with('[') => match p.parse::<u16>() {
            Ok(p) => (n.to_string(), p),
            Err(_) => return false,
        },
        _ => (host.clone(), 80),
    };
    if host_port != port {
        return false;
    }
    let bare = name.trim_start_matches('[').trim_end_matches(']');
    bare.parse::<IpAddr>().is_ok()
        || bare == "localhost"
        || allowed_hosts.iter().any(|h| *h == bare)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnswerRequest {
    id: u64,
    answer: Answer,
}

/// What the server serves: the page of one channel.
struct Page(Arc<Shared>);

impl Service for Page {
    fn trusted(&self, path: &str) -> bool {
        same_token(split_token(path).0, &self.0.token)
    }

    fn handle(&self, req: &Request) -> HttpResponse {
        handle(&self.0, req)
    }
}

/// Splits `/TOKEN/rest` into the token and the rest.
pub(crate) fn split_token(path: &str) -> (&str, &str) {
    let mut segments = path.trim_start_matches('/').splitn(2, '/');
    (segments.next().unwrap_or(""), segments.next().unwrap_or(""))
}

fn handle(shared: &Shared, req: &Request) -> HttpResponse {
    let (token, rest) = split_token(&req.path);
    if token.is_empty() {
        return forbidden("the address needs the session token");
    }
    if !same_token(token, &shared.token) {
        return forbidden("wrong session token");
    }
    let Some(&port) = shared.port.get() else {
        return HttpResponse::text(503, "starting");
    };
    match req.header("host") {
        Some(h) if host_allowed(shared, port, h) => {}
        _ => return forbidden("unexpected Host"),
    }
    let asset = |body: &str, content_type: &'static str| HttpResponse {
        status: 200,
        content_type,
        body: body.as_bytes().to_vec(),
    };
    match (req.method.as_str(), rest) {
        ("GET", "") => asset(PAGE_HTML, "text/html; charset=utf-8"),
        ("GET", "app.js") => asset(PAGE_JS, "text/javascript; charset=utf-8"),
        ("GET", "app.css") => asset(PAGE_CSS, "text/css; charset=utf-8"),
        ("GET", "api/query") => {
            let state = shared.lock();
            match &state.current {
                Some(p) if p.answer.is_none() => HttpResponse::json(200, &query_view(p)),
                _ => HttpResponse::json(200, &json!({"state": "waiting", "notice": state.notice})),
            }
        }
        ("POST", "api/answer") => post_answer(shared, req),
        ("GET", r) if r.starts_with("image/") => {
            let state = shared.lock();
            match &state.current {
                Some(p) if r == format!("image/{}", p.id) && p.image.is_some() => {
                    let (bytes, content_type) = p.image.as_ref().expect("checked");
                    HttpResponse {
                        status: 200,
                        content_type,
                        body: bytes.clone(),
                    }
                }
                _ => HttpResponse::text(404, "no picture"),
            }
        }
        (_, "" | "app.js" | "app.css" | "api/query" | "api/answer") => {
            HttpResponse::text(405, "method not allowed")
        }
        _ => HttpResponse::text(404, "not found"),
    }
}

/// Refuses a POST that does not come from the page itself: browsers always
/// send Origin on a POST, and a JSON body cannot be sent cross-origin
/// without a CORS preflight, which this server never grants.
pub(crate) fn refuse_foreign_post(req: &Request) -> Option<HttpResponse> {
    let host = req.header("host").unwrap_or("");
    match req.header("origin") {
        Some(o) if o.eq_ignore_ascii_case(&format!("http://{host}")) => {}
        Some(_) => {
            return Some(forbidden(
                "answers are accepted only from the page's own origin",
            ));
        }
        None => return Some(forbidden("answers need an Origin header")),
    }
    if let Some(site) = req.header("sec-fetch-site")
        && site != "same-origin"
    {
        return Some(forbidden(
            "answers are accepted only from the page's own origin",
        ));
    }
    let is_json = req.header("content-type").is_some_and(|c| {
        c.split(';')
            .next()
            .unwrap_or("")
            .trim()
            .eq_ignore_ascii_case("application/json")
    });
    if !is_json {
        return Some(HttpResponse::text(
            415,
            "the answer must be sent as application/json",
        ));
    }
    None
}

fn post_answer(shared: &Shared, req: &Request) -> HttpResponse {
    if let Some(refused) = refuse_foreign_post(req) {
        return refused;
    }
    let parsed: AnswerRequest = match serde_json::from_slice(&req.body) {
        Ok(a) => a,
        Err(e) => {
            return HttpResponse::json(400, &json!({"error": format!("malformed answer: {e}")}));
        }
    };
    let mut state = shared.lock();
    let Some(p) = state.current.as_mut() else {
        return HttpResponse::json(
            409,
            &json!({"error": "there is no open question (it may have timed out)"}),
        );
    };
    if p.id != parsed.id || p.answer.is_some() {
        return HttpResponse::json(409, &json!({"error": "this question is no longer open"}));
    }
    if matches!(parsed.answer, Answer::TimedOut) {
        return HttpResponse::json(422, &json!({"error": "a person cannot answer `timed_out`"}));
    }
    match validate_answer(&p.query, &parsed.answer) {
        Ok(arm) => {
            p.answer = Some((parsed.answer, arm));
            shared.answered.notify_all();
            HttpResponse::json(200, &json!({"ok": true}))
        }
        Err(e) => HttpResponse::json(422, &json!({"error": e.to_string()})),
    }
}
