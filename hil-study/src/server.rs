//! Serving the study: a data folder held by one server, one page per
//! participant behind their own token, and a researcher's page behind
//! another.
//!
//! Data folder layout: `design.json` (the design the data were collected
//! under; serving it again with another design is refused),
//! `participants/<id>.jsonl` (each participant's event log) and
//! `study.lock` (held while a server runs, so two servers never write the
//! same logs).

use std::collections::BTreeMap;
use std::fs::File;
use std::net::{IpAddr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::{Arc, LazyLock, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use hil_core::{Answer, HilError, Result};
use hil_workload::study::Population;
use hil_workload::tlx::TlxAnswers;
use serde::Deserialize;
use serde_json::{Value, json};

use crate::config::{DesignConfig, StudyConfig};
use crate::design::Design;
use crate::materials;
use crate::session::{Participant, Phase, Refused, Submitted};
use hil_http::guard::{
    Site, forbidden, random_token, refuse_foreign_post, same_token, split_token,
};
use hil_http::page::{CSS, HTML, JS, PAGE_CSS, SCAN_JS, asset, find_picture, with_scan_settings};
use hil_http::{Limits, Request, Response, Server, Service, urls};

/// The participant's page, with the shared switch-scanning settings in its
/// header.
static STUDY_HTML: LazyLock<String> =
    LazyLock::new(|| with_scan_settings(include_str!("../assets/study.html")));
const STUDY_JS: &str = include_str!("../assets/study.js");
const STUDY_CSS: &str = include_str!("../assets/study.css");
const RESEARCHER_HTML: &str = include_str!("../assets/researcher.html");

/// The materials in use: the passage's words, its pace, the addends, the
/// lab's pictures.
#[derive(Debug)]
pub struct Materials {
    /// The transcription passage, word by word.
    pub passage: Vec<String>,
    /// Words revealed per study minute.
    pub words_per_min: f64,
    /// Largest addend.
    pub addition_max: u32,
    /// The lab's `images/` folder, if it has one.
    pub images: Option<PathBuf>,
}

impl Materials {
    /// Loads the lab's folder over the defaults.
    pub fn load(config: &StudyConfig) -> Result<Self> {
        let m = &config.materials;
        let mut passage = materials::DEFAULT_PASSAGE.to_string();
        let mut images = None;
        if let Some(dir) = &m.dir {
            if !dir.is_dir() {
                return Err(HilError::invalid_parameter(
                    "materials.dir",
                    dir.display(),
                    "is not a directory",
                ));
            }
            let p = dir.join("passage.txt");
            if p.exists() {
                passage = hil_core::files::read_text(&p, hil_core::files::limits::ASSET)?;
                if passage.split_whitespace().count() < 10 {
                    return Err(hil_textdata::data_error(
                        &p,
                        1,
                        "passage",
                        "needs at least 10 words",
                    ));
                }
            }
            let i = dir.join("images");
            if i.is_dir() {
                images = Some(i);
            }
        }
        Ok(Self {
            passage: passage.split_whitespace().map(str::to_string).collect(),
            words_per_min: m.transcription_words_per_min,
            addition_max: m.addition_max,
            images,
        })
    }

    /// Sum `index` of the addition task of condition `c` for participant
    /// number `number`.
    pub fn addition(&self, design: &Design, number: usize, c: usize, index: usize) -> (u32, u32) {
        materials::addition(
            design.config().seed,
            [number as u64, c as u64],
            index as u64,
            self.addition_max,
        )
    }
}

/// Everything the handlers share.
struct Shared {
    design: Design,
    materials: Materials,
    dir: PathBuf,
    researcher_token: String,
    site: Site,
    away: Duration,
    participants: Mutex<BTreeMap<String, Participant>>,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, BTreeMap<String, Participant>> {
        // A handler that panicked left no half-made change: every change
        // is checked, then logged, then applied.
        self.participants.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// A running study server. Stops on drop; the data stay in the folder.
///
/// ```no_run
/// use hil_study::{StudyConfig, StudyServer};
/// use hil_workload::study::Population;
/// let s = StudyServer::start(StudyConfig::default(), "study-data".as_ref()).unwrap();
/// println!("researcher: {}", s.researcher_urls()[0]);
/// let (id, urls) = s.enrol(Population::NoLimitation).unwrap();
/// println!("{id}: {}", urls[0]);
/// ```
pub struct StudyServer {
    shared: Arc<Shared>,
    server: Server,
    /// Never empty: `start` refuses to run without an address to print.
    hosts: Vec<IpAddr>,
    _lock: File,
}

impl std::fmt::Debug for StudyServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StudyServer")
            .field("addr", &self.server.addr())
            .field("dir", &self.shared.dir)
            .finish()
    }
}

/// The design a data folder was collected under (its `design.json`).
pub fn stored_design(dir: &Path) -> Result<Option<DesignConfig>> {
    let p = dir.join("design.json");
    if !p.exists() {
        return Ok(None);
    }
    let text = hil_core::files::read_text(&p, hil_core::files::limits::CONFIG)?;
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| hil_textdata::data_error(&p, e.line(), "design", e.to_string()))
}

/// The `[design]` fields in which `given` differs from the `stored` design,
/// each with both values, as in the config (`time_scale` is 1 in the folder,
/// 60 here).
fn design_differences(stored: &DesignConfig, given: &DesignConfig) -> Vec<String> {
    let as_map = |d: &DesignConfig| match serde_json::to_value(d) {
        Ok(Value::Object(m)) => m,
        _ => serde_json::Map::new(),
    };
    let (stored, given) = (as_map(stored), as_map(given));
    let mut out: Vec<String> = stored
        .iter()
        .filter(|(k, v)| given.get(*k) != Some(*v))
        .map(|(k, v)| {
            let here = given.get(k).map_or("unset".to_string(), Value::to_string);
            format!("`{k}` is {v} in the folder, {here} here")
        })
        .collect();
    if out.is_empty() {
        // Not expected: every field is serialized, so equal maps are equal designs.
        out.push("the designs differ".into());
    }
    out
}

/// Every participant log in a data folder, in id order.
pub fn participant_logs(dir: &Path) -> Result<Vec<PathBuf>> {
    let pdir = dir.join("participants");
    if !pdir.is_dir() {
        return Ok(Vec::new());
    }
    let mut out: Vec<PathBuf> = std::fs::read_dir(&pdir)
        .map_err(|e| HilError::io("listing", &pdir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "jsonl"))
        .collect();
    out.sort();
    Ok(out)
}

impl StudyServer {
    /// Opens (or creates) the data folder `dir`, replays every
    /// participant's log, and starts serving.
    pub fn start(config: StudyConfig, dir: &Path) -> Result<Self> {
        let design = Design::new(config.design.clone())?;
        config.server.validate()?;
        let materials = Materials::load(&config)?;
        std::fs::create_dir_all(dir.join("participants"))
            .map_err(|e| HilError::io("creating", dir, e))?;
        let lock_path = dir.join("study.lock");
        let lock = File::create(&lock_path).map_err(|e| HilError::io("creating", &lock_path, e))?;
        #[allow(clippy::incompatible_msrv)]
        lock.try_lock().map_err(|_| {
            HilError::io(
                "locking",
                &lock_path,
                std::io::Error::new(
                    std::io::ErrorKind::WouldBlock,
                    "another `hil study serve` is using this data folder",
                ),
            )
        })?;
        match stored_design(dir)? {
            Some(d) if d != config.design => {
                return Err(HilError::invalid_input(
                    "design",
                    format!(
                        "{} was collected under another design: {}; serve it with that design \
                         (`--config FILE` whose [design] has the folder's values, as in its \
                         design.json) or use a new folder",
                        dir.display(),
                        design_differences(&d, &config.design).join(", ")
                    ),
                ));
            }
            Some(_) => {}
            None => {
                let p = dir.join("design.json");
                let text = serde_json::to_string_pretty(&config.design)
                    .map_err(|e| HilError::serde("design", e))?;
                std::fs::write(&p, text).map_err(|e| HilError::io("writing", &p, e))?;
            }
        }
        let mut participants = BTreeMap::new();
        for path in participant_logs(dir)? {
            let p = Participant::open(&design, &path)?;
            participants.insert(p.token.clone(), p);
        }
        let shared = Arc::new(Shared {
            design,
            materials,
            dir: dir.to_path_buf(),
            researcher_token: random_token(),
            site: Site::new(&config.server.allowed_hosts),
            away: Duration::from_secs_f64(config.server.away_after_s),
            participants: Mutex::new(participants),
        });
        let bind = SocketAddr::new(config.server.bind, config.server.port);
        let channel_error = |why: String| HilError::channel("study", why);
        let server = Server::start(bind, Arc::new(Pages(shared.clone())), Limits::default())
            .map_err(|e| channel_error(format!("cannot listen on {bind}: {e}")))?;
        shared.site.set_port(server.addr().port());
        let hosts = urls::hosts_to_print(server.addr()).map_err(channel_error)?;
        Ok(Self {
            shared,
            server,
            hosts,
            _lock: lock,
        })
    }

    /// The address the server listens on.
    pub fn addr(&self) -> SocketAddr {
        self.server.addr()
    }

    fn links(&self, token: &str) -> Vec<String> {
        let port = self.server.addr().port();
        self.hosts
            .iter()
            .map(|&ip| urls::page_url(ip, port, token))
            .collect()
    }

    /// The researcher's page, one URL per reachable address.
    pub fn researcher_urls(&self) -> Vec<String> {
        self.links(&self.shared.researcher_token)
    }

    /// Enrols a participant of `population`: their pseudonymous id and
    /// the URLs of their page.
    pub fn enrol(&self, population: Population) -> Result<(String, Vec<String>)> {
        let (id, token) = enrol(&self.shared, population)?;
        Ok((id, self.links(&token)))
    }

    /// The URLs of participant `id`'s page.
    pub fn participant_urls(&self, id: &str) -> Option<Vec<String>> {
        let ps = self.shared.lock();
        ps.values()
            .find(|p| p.id == id)
            .map(|p| self.links(&p.token))
    }
}

fn enrol(shared: &Shared, population: Population) -> Result<(String, String)> {
    let mut ps = shared.lock();
    let number = ps.len();
    let id = format!("p{:03}", number + 1);
    let token = random_token();
    let path = shared.dir.join("participants").join(format!("{id}.jsonl"));
    let p = Participant::enrol(
        &shared.design,
        &path,
        id.clone(),
        population,
        number,
        token.clone(),
    )?;
    ps.insert(token.clone(), p);
    Ok((id, token))
}

/// The progress of every participant, for the researcher.
fn progress(shared: &Shared) -> Value {
    let ps = shared.lock();
    let mut rows: Vec<Value> = ps
        .values()
        .map(|p| {
            let tally = p.counts();
            json!({
                "participant": p.id,
                "population": p.population.as_str(),
                "conditions_done": tally.conditions_done,
                "conditions": tally.conditions,
                "surveys": tally.surveys,
                "end_of_condition_surveys": tally.end_of_condition_surveys,
                "phase": match p.phase(&shared.design) {
                    Phase::Intro => "before a part".to_string(),
                    Phase::Task { query: None } => "working".to_string(),
                    Phase::Task { query: Some(k) } => format!("answering query {}", k + 1),
                    Phase::Survey { query: Some(k) } => format!("survey after query {}", k + 1),
                    Phase::Survey { query: None } => "end-of-part survey".to_string(),
                    Phase::Done => "finished".to_string(),
                },
                "seen_s_ago": p.last_seen().map(|d| d.as_secs_f64()),
                "link": format!("/{}/", p.token),
            })
        })
        .collect();
    rows.sort_by(|a, b| a["participant"].as_str().cmp(&b["participant"].as_str()));
    json!({ "participants": rows })
}

struct Pages(Arc<Shared>);

impl Service for Pages {
    fn trusted(&self, path: &str) -> bool {
        let token = split_token(path).0;
        same_token(token, &self.0.researcher_token) || self.0.lock().contains_key(token)
    }

    fn handle(&self, req: &Request) -> Response {
        handle(&self.0, req)
    }
}

fn handle(shared: &Shared, req: &Request) -> Response {
    let (token, rest) = split_token(&req.path);
    if token.is_empty() {
        return forbidden("the address needs a token");
    }
    if let Err(refused) = shared.site.check_host(req) {
        return refused;
    }
    if req.method == "POST"
        && let Some(refused) = refuse_foreign_post(req)
    {
        return refused;
    }
    if same_token(token, &shared.researcher_token) {
        return researcher(shared, req, rest);
    }
    // Participant tokens are looked up in a map (not compared in constant
    // time): they are 128-bit random, so timing reveals nothing usable.
    if !shared.lock().contains_key(token) {
        return forbidden("unknown token");
    }
    participant(shared, req, token, rest)
}

fn researcher(shared: &Shared, req: &Request, rest: &str) -> Response {
    match (req.method.as_str(), rest) {
        ("GET", "") => asset(RESEARCHER_HTML, HTML),
        ("GET", "app.css") => asset(PAGE_CSS, CSS),
        ("GET", "study.css") => asset(STUDY_CSS, CSS),
        ("GET", "api/progress") => Response::json(200, &progress(shared)),
        ("POST", "api/participants") => {
            #[derive(Deserialize)]
            #[serde(deny_unknown_fields)]
            struct Enrol {
                population: Population,
            }
            let parsed: Enrol = match serde_json::from_slice(&req.body) {
                Ok(e) => e,
                Err(e) => return Response::json(400, &json!({"error": e.to_string()})),
            };
            match enrol(shared, parsed.population) {
                Ok((id, token)) => Response::json(
                    200,
                    &json!({"participant": id, "link": format!("/{token}/")}),
                ),
                Err(e) => Response::json(500, &json!({"error": e.to_string()})),
            }
        }
        _ => Response::text(404, "not found"),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Submission {
    condition: String,
    #[serde(default)]
    query: Option<usize>,
    #[serde(default)]
    index: Option<usize>,
    #[serde(default)]
    answer: Option<Answer>,
    #[serde(default)]
    text: Option<String>,
    #[serde(default)]
    tlx: Option<TlxAnswers>,
}

fn submitted(r: std::result::Result<Submitted, Refused>) -> Response {
    match r {
        Ok(s) => Response::json(
            200,
            &json!({"ok": true, "already_saved": s == Submitted::AlreadySaved}),
        ),
        Err(Refused::NotOpen(w)) => Response::json(409, &json!({"error": w})),
        Err(Refused::Invalid(w)) => Response::json(422, &json!({"error": w})),
        Err(Refused::Storage(w)) => {
            Response::json(500, &json!({"error": format!("not saved: {w}")}))
        }
    }
}

fn participant(shared: &Shared, req: &Request, token: &str, rest: &str) -> Response {
    let now = Instant::now();
    let design = &shared.design;
    match (req.method.as_str(), rest) {
        ("GET", "") => asset(STUDY_HTML.as_str(), HTML),
        ("GET", "study.js") => asset(STUDY_JS, JS),
        ("GET", "scan.js") => asset(SCAN_JS, JS),
        ("GET", "app.css") => asset(PAGE_CSS, CSS),
        ("GET", "study.css") => asset(STUDY_CSS, CSS),
        ("GET", "api/state") => {
            let mut ps = shared.lock();
            let p = ps.get_mut(token).expect("checked");
            if let Err(e) = p.tick(design, now, shared.away) {
                return Response::json(500, &json!({"error": format!("not saved: {e}")}));
            }
            Response::json(200, &p.view(design, &shared.materials))
        }
        ("GET", r) if r.starts_with("image/") => picture(shared, token, r),
        ("POST", "api/start" | "api/answer" | "api/survey" | "api/distraction") => {
            let s: Submission = match serde_json::from_slice(&req.body) {
                Ok(s) => s,
                Err(e) => return Response::json(400, &json!({"error": format!("malformed: {e}")})),
            };
            let mut ps = shared.lock();
            let p = ps.get_mut(token).expect("checked");
            let missing =
                |f: &str| Response::json(400, &json!({"error": format!("`{f}` is missing")}));
            let r = match rest {
                "api/start" => p.start(design, &s.condition, now),
                "api/answer" => {
                    let (Some(k), Some(a)) = (s.query, s.answer) else {
                        return missing("query/answer");
                    };
                    if matches!(a, Answer::TimedOut | Answer::Action { .. }) {
                        return Response::json(
                            422,
                            &json!({"error": "not an answer to a study query"}),
                        );
                    }
                    p.answer(design, &s.condition, k, a, now)
                }
                "api/survey" => {
                    let Some(tlx) = s.tlx else {
                        return missing("tlx");
                    };
                    p.survey(design, &s.condition, s.query, tlx, now)
                }
                _ => {
                    let (Some(i), Some(t)) = (s.index, s.text) else {
                        return missing("index/text");
                    };
                    p.distraction(design, &s.condition, i, t, &shared.materials)
                }
            };
            submitted(r)
        }
        _ => Response::text(404, "not found"),
    }
}

/// `image/<condition>/<query>/<picture>`: a picture of one of the
/// participant's queries (asked already or now; never a later one).
fn picture(shared: &Shared, token: &str, rest: &str) -> Response {
    let parts: Vec<&str> = rest.split('/').collect();
    let [_, cond, k, i] = parts[..] else {
        return Response::text(404, "no picture");
    };
    let (Ok(k), Ok(i)) = (k.parse::<usize>(), i.parse::<usize>()) else {
        return Response::text(404, "no picture");
    };
    let design = &shared.design;
    let ps = shared.lock();
    let p = ps.get(token).expect("checked");
    let Some((c, condition)) = design.condition(cond) else {
        return Response::text(404, "no picture");
    };
    let Some((open_k, _)) = p.open_query(design) else {
        return Response::text(404, "no picture");
    };
    if p.current() != Some(c) || open_k != k || condition.queries.is_none() {
        return Response::text(404, "no picture");
    }
    let q = p.query_at(design, c, k);
    let Some(pic) = q.pictures.get(i) else {
        return Response::text(404, "no picture");
    };
    // A lab's own picture of a single food replaces the drawn one.
    if pic.foods.len() == 1
        && let Some(dir) = &shared.materials.images
    {
        match find_picture(dir, materials::FOODS[pic.foods[0].food]) {
            Ok(Some(own)) => return own.response(),
            Ok(None) => {}
            Err(e) => return Response::text(500, e.to_string()),
        }
    }
    Response {
        status: 200,
        content_type: "image/svg+xml",
        body: materials::picture_svg(pic).into_bytes(),
    }
}
