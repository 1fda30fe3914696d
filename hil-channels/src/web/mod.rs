//! A query channel served as a web page, for the person being fed: on a
//! phone or tablet next to the robot, by touch, keyboard or single switch.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::{Arc, Condvar, LazyLock, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use hil_config::{QueryChannelConfig, TaskContext};
use hil_core::{Answer, ArmId, HilError, Query, QueryChannel, Response, Result};
use hil_envs::feeding::FeedingTask;
use hil_http::guard::{
    Site, check_allowed_hosts, forbidden, random_token, refuse_foreign_post, same_token,
    split_token,
};
use hil_http::page::{CSS, HTML, JS, PAGE_CSS, Picture, SCAN_JS, assemble, asset, find_picture};
use hil_http::{Limits, Occupancy, Request, Response as HttpResponse, Server, Service, urls};

use crate::present::{describe_item, describe_kind, question, validate_answer};

/// The page, with the pages' shared head and header (switch scanning).
static PAGE_HTML: LazyLock<String> = LazyLock::new(|| assemble(include_str!("page.html")));
const PAGE_JS: &str = include_str!("page.js");

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
    /// The item's picture, if there is one.
    image: Option<Picture>,
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
    /// The names and (once listening) the port the page answers to.
    site: Site,
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
///   the `hil_http` crate's documentation).
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
        let token = random_token();
        let bind = SocketAddr::new(config.bind, config.port);
        // The handler needs the bound port, known only after binding: it
        // reads it from `Shared`, filled in right after.
        let shared = Arc::new(Shared {
            token,
            site: Site::new(&config.allowed_hosts),
            timeout: Duration::from_secs_f64(config.timeout_s),
            images: config.images.clone(),
            state: Mutex::new(State::default()),
            answered: Condvar::new(),
        });
        let channel_error = |why: String| HilError::channel("web", why);
        let server = Server::start(bind, Arc::new(Page(shared.clone())), Limits::default())
            .map_err(|e| channel_error(format!("cannot listen on {bind}: {e}")))?;
        let addr = server.addr();
        shared.site.set_port(addr.port());
        let urls = urls::hosts_to_print(addr)
            .map_err(channel_error)?
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
            Some(dir) => find_picture(dir, &query.item.label)?,
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

/// What a feeding action does, shown under its name; other tasks' actions
/// have no hint.
fn action_hint(name: &str) -> Option<&'static str> {
    FeedingTask::bundled().action_description(name)
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

fn handle(shared: &Shared, req: &Request) -> HttpResponse {
    let (token, rest) = split_token(&req.path);
    if token.is_empty() {
        return forbidden("the address needs the session token");
    }
    if !same_token(token, &shared.token) {
        return forbidden("wrong session token");
    }
    if let Err(refused) = shared.site.check_host(req) {
        return refused;
    }
    match (req.method.as_str(), rest) {
        ("GET", "") => asset(PAGE_HTML.as_str(), HTML),
        ("GET", "app.js") => asset(PAGE_JS, JS),
        ("GET", "scan.js") => asset(SCAN_JS, JS),
        ("GET", "app.css") => asset(PAGE_CSS, CSS),
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
                Some(Pending {
                    id,
                    image: Some(picture),
                    ..
                }) if r == format!("image/{id}") => picture.response(),
                _ => HttpResponse::text(404, "no picture"),
            }
        }
        (_, "" | "app.js" | "scan.js" | "app.css" | "api/query" | "api/answer") => {
            HttpResponse::text(405, "method not allowed")
        }
        _ => HttpResponse::text(404, "not found"),
    }
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
