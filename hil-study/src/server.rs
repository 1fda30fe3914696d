//! Serving the study: a data folder held by one server, one page per
//! participant behind their own token, and a researcher's page behind
//! another.
//!
//! Data folder layout: `design.json` (the design the data were collected
//! under; serving it again with another design is refused),
//! `participants/<id>.jsonl` (each participant's event log),
//! `researcher.token` (the researcher's link, readable by its owner only,
//! so the link stays the same across restarts), `port` (the last run's
//! port, taken again when the config asks for any free one), `tls-cert.pem` and
//! `tls-key.pem` (the self-signed certificate of HTTPS without the lab's
//! own, kept so its fingerprint stays the same) and `study.lock` (held
//! while a server runs, so two servers never write the same logs).

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
use crate::materials::{self, Materials};
use crate::session::{Participant, Phase, Refused, Submitted};
use hil_http::guard::{
    Site, forbidden, random_token, refuse_foreign_post, same_token, split_token,
};
use hil_http::page::{CSS, HTML, JS, PAGE_CSS, SCAN_JS, assemble, asset, find_picture};
use hil_http::secrets::stored_token;
use hil_http::tls::Tls;
use hil_http::{Limits, Request, Response, Scheme, Server, Service, urls};

/// The participant's page, with the pages' shared head and header.
static STUDY_HTML: LazyLock<String> =
    LazyLock::new(|| assemble(include_str!("../assets/study.html")));
const STUDY_JS: &str = include_str!("../assets/study.js");
const STUDY_CSS: &str = include_str!("../assets/study.css");
/// The researcher's page, with the pages' shared head and header.
static RESEARCHER_HTML: LazyLock<String> =
    LazyLock::new(|| assemble(include_str!("../assets/researcher.html")));
const RESEARCHER_JS: &str = include_str!("../assets/researcher.js");

/// The file in the data folder that keeps the port of the last run.
pub const PORT_FILE: &str = "port";

/// The port the last run listened on, if it left one.
fn last_port(path: &Path) -> Result<Option<u16>> {
    if !path.exists() {
        return Ok(None);
    }
    let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
    match text.trim().parse::<u16>() {
        Ok(p) if p > 0 => Ok(Some(p)),
        _ => Err(hil_textdata::data_error(
            path,
            1,
            "port",
            "must be a port number from 1 to 65535 (delete the file to take any free port)",
        )),
    }
}

/// The file in the data folder that keeps the researcher's token.
pub const RESEARCHER_TOKEN_FILE: &str = "researcher.token";

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
    /// The certificate, when served over HTTPS.
    tls: Option<Tls>,
    /// The last run's port, when it was taken and another one is used.
    moved_from: Option<u16>,
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
        // Again: flags (`--lan`, a certificate) change it after loading.
        config.server.validate().map_err(|e| e.within("server"))?;
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
            researcher_token: stored_token(&dir.join(RESEARCHER_TOKEN_FILE))?,
            site: Site::new(&config.server.allowed_hosts),
            away: Duration::from_secs_f64(config.server.away_after_s),
            participants: Mutex::new(participants),
        });
        let bind = SocketAddr::new(config.server.bind, config.server.port);
        let channel_error = |why: String| HilError::channel("study", why);
        let hosts = urls::hosts_to_print(bind).map_err(channel_error)?;
        let tls = tls_for(&config, dir, &hosts)?;
        let listen = |port: u16| {
            let at = SocketAddr::new(bind.ip(), port);
            let pages = Arc::new(Pages(shared.clone()));
            match &tls {
                Some(tls) => Server::start_tls(at, pages, Limits::default(), tls),
                None => Server::start(at, pages, Limits::default()),
            }
        };
        // Any free port was asked for: the last run's, if it is still
        // free, so that the links printed then still open.
        let port_path = dir.join(PORT_FILE);
        let last_port = match config.server.port {
            0 => last_port(&port_path)?,
            _ => None,
        };
        let (server, moved_from) = match last_port {
            Some(p) => match listen(p) {
                Ok(s) => (Ok(s), None),
                Err(_) => (listen(0), Some(p)),
            },
            None => (listen(bind.port()), None),
        };
        let server = server.map_err(|e| channel_error(format!("cannot listen on {bind}: {e}")))?;
        let port = server.addr().port();
        std::fs::write(&port_path, format!("{port}\n"))
            .map_err(|e| HilError::io("writing", &port_path, e))?;
        shared.site.set_port(port);
        Ok(Self {
            shared,
            server,
            moved_from,
            hosts,
            tls,
            _lock: lock,
        })
    }

    /// The address the server listens on.
    pub fn addr(&self) -> SocketAddr {
        self.server.addr()
    }

    /// The port of the last run on this data folder, when it was taken by
    /// something else and the server listens on another: the links
    /// printed before no longer open.
    pub fn moved_from(&self) -> Option<u16> {
        self.moved_from
    }

    /// The certificate the pages are served with over HTTPS (`None`: plain
    /// HTTP, on loopback only), for its fingerprint.
    pub fn tls(&self) -> Option<&Tls> {
        self.tls.as_ref()
    }

    fn links(&self, token: &str) -> Vec<String> {
        let port = self.server.addr().port();
        let scheme = if self.tls.is_some() {
            Scheme::Https
        } else {
            Scheme::Http
        };
        self.hosts
            .iter()
            .map(|&ip| urls::page_url_over(scheme, ip, port, token))
            .collect()
    }

    /// The researcher's page, one URL per reachable address.
    pub fn researcher_urls(&self) -> Vec<String> {
        self.links(&self.shared.researcher_token)
    }

    /// Enrols a participant of `population` under the next free id
    /// (`p001`, `p002`, …; the researcher page's button): their id and the
    /// URLs of their page.
    pub fn enrol(&self, population: Population) -> Result<(String, Vec<String>)> {
        let (id, token) = enrol(&self.shared, None, population)?;
        Ok((id, self.links(&token)))
    }

    /// Enrols participant `id` of `population`, unless `id` is enrolled
    /// already with that population: then nothing changes
    /// ([`Enrolment::Already`]), so a serve command that names its
    /// participants can be run again after a restart without enrolling
    /// anyone twice. An id enrolled with another population is refused.
    /// The URLs of their page either way.
    pub fn enrol_as(&self, id: &str, population: Population) -> Result<(Enrolment, Vec<String>)> {
        check_participant_id(id)?;
        let known = {
            let ps = self.shared.lock();
            ps.values()
                .find(|p| p.id == id)
                .map(|p| (p.population, p.token.clone()))
        };
        match known {
            Some((was, token)) if was == population => Ok((Enrolment::Already, self.links(&token))),
            Some((was, _)) => Err(HilError::invalid_parameter(
                "enrol",
                format!("{id}={}", population.as_str()),
                format!(
                    "participant {id} is enrolled already as {}; give a new id to enrol \
                     someone else",
                    was.as_str()
                ),
            )),
            None => {
                let (_, token) = enrol(&self.shared, Some(id), population)?;
                Ok((Enrolment::New, self.links(&token)))
            }
        }
    }

    /// The URLs of participant `id`'s page.
    pub fn participant_urls(&self, id: &str) -> Option<Vec<String>> {
        let ps = self.shared.lock();
        ps.values()
            .find(|p| p.id == id)
            .map(|p| self.links(&p.token))
    }
}

/// The certificate to serve with: none on loopback unless asked (plain
/// HTTP never leaves the machine), the lab's if given, else the data
/// folder's self-signed one (made for `hosts` and the allowed host names
/// at the first start).
fn tls_for(config: &StudyConfig, dir: &Path, hosts: &[IpAddr]) -> Result<Option<Tls>> {
    let server = &config.server;
    if !server.uses_https() {
        return Ok(None);
    }
    Ok(Some(match (&server.tls_cert, &server.tls_key) {
        (Some(cert), Some(key)) => Tls::from_pem_files(cert, key)?,
        _ => {
            let names: Vec<String> = hosts
                .iter()
                .map(IpAddr::to_string)
                .chain(server.allowed_hosts.iter().cloned())
                .collect();
            Tls::self_signed_in(dir, &names)?
        }
    }))
}

/// Whether [`StudyServer::enrol_as`] enrolled someone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Enrolment {
    /// A new participant, with the next counterbalancing row.
    New,
    /// The id was enrolled already with that population: nothing changed.
    Already,
}

/// A participant id is a pseudonym that names their log file: 1 to 16
/// lower-case letters, digits, `-` or `_`, starting with a letter (`p001`).
pub fn check_participant_id(id: &str) -> Result<()> {
    let ok = (1..=16).contains(&id.len())
        && id.starts_with(|c: char| c.is_ascii_lowercase())
        && id
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-' || b == b'_');
    if ok {
        Ok(())
    } else {
        Err(HilError::invalid_parameter(
            "participant id",
            id,
            "must be 1 to 16 lower-case letters, digits, `-` or `_`, starting with a letter \
             (a pseudonym such as p001, never a name)",
        ))
    }
}

/// Enrols a participant as `id` (or the first free `p001`, `p002`, …),
/// with the next counterbalancing row; their id and token.
fn enrol(shared: &Shared, id: Option<&str>, population: Population) -> Result<(String, String)> {
    let mut ps = shared.lock();
    let number = ps.len();
    let taken = |id: &str| ps.values().any(|p| p.id == id);
    let id = match id {
        Some(id) if taken(id) => {
            return Err(HilError::invalid_parameter(
                "participant id",
                id,
                "is enrolled already",
            ));
        }
        Some(id) => id.to_string(),
        None => (1..)
            .map(|n| format!("p{n:03}"))
            .find(|id| !taken(id))
            .expect("an unbounded range has a free id"),
    };
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
        ("GET", "") => asset(RESEARCHER_HTML.as_str(), HTML),
        ("GET", "researcher.js") => asset(RESEARCHER_JS, JS),
        ("GET", "scan.js") => asset(SCAN_JS, JS),
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
            match enrol(shared, None, parsed.population) {
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
