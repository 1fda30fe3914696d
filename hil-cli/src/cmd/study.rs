//! `hil study …`: run the querying-workload study in the browser, follow
//! the participants' progress, export the study CSV for `hil workload`.

use crate::out::outln;
use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;

use hil_core::Result;
use hil_study::log::{Event, read};
use hil_study::server::{Enrolment, participant_logs, stored_design};
use hil_study::session::tally;
use hil_study::{CertSource, Design, StudyConfig, StudyServer, export_all};
use hil_workload::study::Population;

/// Arguments of `hil study`.
#[derive(Debug, clap::Args)]
pub struct StudyArgs {
    #[command(subcommand)]
    command: StudyCommand,
}

#[derive(Debug, clap::Subcommand)]
enum StudyCommand {
    /// Serve the study (until Ctrl-C); the data folder keeps every answer.
    #[command(
        after_help = "Every config key with its default: hil study serve --help",
        after_long_help = SERVE_HELP.as_str()
    )]
    Serve {
        /// Study config (TOML; default: the paper's design on loopback).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Data folder (created if missing; resumed if it has data).
        #[arg(long)]
        data: PathBuf,
        /// Listen on every address, for a tablet on the LAN (prints them),
        /// over HTTPS: the lab's certificate (--tls-cert, --tls-key) or a
        /// self-signed one kept in the data folder, its fingerprint printed.
        /// HTTPS needs a `hil` built with the feature `https` (`bash
        /// scripts/hil study ...` is).
        #[arg(long)]
        lan: bool,
        /// The lab's certificate chain (PEM) for HTTPS, with --tls-key.
        #[arg(long, requires = "tls_key")]
        tls_cert: Option<PathBuf>,
        /// The private key of --tls-cert (PEM).
        #[arg(long, requires = "tls_cert")]
        tls_key: Option<PathBuf>,
        /// Port (default: the config's, 0 = any free port).
        #[arg(long)]
        port: Option<u16>,
        /// Enrol participant ID of POPULATION and print their link
        /// (repeatable), e.g. `p001=mobility_limitation`; populations:
        /// no_limitation, mobility_limitation, occupational_therapist. An ID
        /// enrolled already is not enrolled again (its link is printed), so
        /// the same command can be run again after a restart.
        #[arg(long, value_name = "ID=POPULATION", value_parser = parse_enrolment)]
        enrol: Vec<(String, Population)>,
        /// Serve for this many seconds, then stop (default: until Ctrl-C).
        #[arg(long)]
        for_s: Option<f64>,
    },
    /// Print each participant's progress from the data folder.
    Status {
        /// Data folder.
        #[arg(long)]
        data: PathBuf,
    },
    /// Write the study CSV that `hil workload summary/select/fit` read, and
    /// the end-of-condition surveys of query conditions beside it
    /// (`<stem>.end_of_condition.csv`).
    Export {
        /// Data folder.
        #[arg(long)]
        data: PathBuf,
        /// Output CSV (the study CSV).
        #[arg(long)]
        out: PathBuf,
    },
}

/// The end of `hil study serve --help`: every config key with its default.
static SERVE_HELP: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    format!(
        "The config file (--config), every key with its default:\n\n{}",
        hil_study::config::EXAMPLE_TOML
    )
});

fn parse_population(s: &str) -> std::result::Result<Population, String> {
    serde_json::from_value(serde_json::Value::String(s.to_string())).map_err(|_| {
        format!("`{s}` is not a population: no_limitation, mobility_limitation or occupational_therapist")
    })
}

/// The serve command's flags over the config's `[server]`: `--lan` listens
/// on every address (and so over HTTPS), `--port`, the lab's certificate.
fn apply_flags(
    server: &mut hil_study::ServerConfig,
    lan: bool,
    port: Option<u16>,
    tls_cert: Option<PathBuf>,
    tls_key: Option<PathBuf>,
) {
    if lan {
        server.bind = IpAddr::V4(Ipv4Addr::UNSPECIFIED);
    }
    if let Some(p) = port {
        server.port = p;
    }
    if tls_cert.is_some() {
        (server.tls_cert, server.tls_key) = (tls_cert, tls_key);
    }
}

/// `ID=POPULATION`. The id is required: an enrolment that names nobody
/// would enrol someone new each time the serve command is run again.
fn parse_enrolment(s: &str) -> std::result::Result<(String, Population), String> {
    let Some((id, population)) = s.split_once('=') else {
        return Err(format!(
            "`{s}` names no participant: write ID=POPULATION (e.g. p001={s}), so that \
             running the same command again enrols nobody new"
        ));
    };
    hil_study::server::check_participant_id(id).map_err(|e| e.to_string())?;
    Ok((id.to_string(), parse_population(population)?))
}

/// Runs `hil study`.
pub fn run(args: StudyArgs) -> Result<()> {
    match args.command {
        StudyCommand::Serve {
            config,
            data,
            lan,
            tls_cert,
            tls_key,
            port,
            enrol,
            for_s,
        } => {
            let mut cfg = match &config {
                Some(p) => StudyConfig::load(p)?,
                None => StudyConfig::default(),
            };
            apply_flags(&mut cfg.server, lan, port, tls_cert, tls_key);
            let server = StudyServer::start(cfg, &data)?;
            outln!("Study data: {}", data.display())?;
            if let Some(p) = server.moved_from() {
                outln!(
                    "Port {p} of the last run is taken: the links below are new (the tokens are not); \
                     give --port to choose one."
                )?;
            }
            if let Some(tls) = server.tls() {
                let whose = match tls.source() {
                    CertSource::Given => "the lab's certificate",
                    CertSource::SelfSignedNew => {
                        "a self-signed certificate, made now and kept in the data folder"
                    }
                    CertSource::SelfSignedKept => "the data folder's self-signed certificate",
                };
                outln!(
                    "HTTPS with {whose}; its SHA-256 fingerprint (check it in the browser before accepting):"
                )?;
                outln!("  {}", tls.fingerprint())?;
            }
            outln!("Researcher's page (keep this link to yourself):")?;
            for u in server.researcher_urls() {
                outln!("  {u}")?;
            }
            for (id, pop) in enrol {
                let (done, urls) = server.enrol_as(&id, pop)?;
                let note = match done {
                    Enrolment::New => "enrolled now",
                    Enrolment::Already => "enrolled before, not enrolled again",
                };
                outln!("Participant {id} ({}, {note}):", pop.as_str())?;
                for u in urls {
                    outln!("  {u}")?;
                }
            }
            outln!("Serving; stop with Ctrl-C (answers are saved as they come).")?;
            match for_s {
                Some(s) if s.is_finite() && s >= 0.0 => {
                    std::thread::sleep(std::time::Duration::from_secs_f64(s));
                }
                _ => loop {
                    std::thread::sleep(std::time::Duration::from_secs(3600));
                },
            }
            Ok(())
        }
        StudyCommand::Status { data } => {
            let design = stored_design(&data)?.ok_or_else(|| {
                hil_core::HilError::invalid_input(
                    "data folder",
                    format!(
                        "{} has no design.json: not a study data folder",
                        data.display()
                    ),
                )
            })?;
            let design = Design::new(design)?;
            for path in participant_logs(&data)? {
                let (lines, _) = read(&path)?;
                let t = tally(&design, &path, &lines)?;
                let Some(Event::Enrolled {
                    participant,
                    population,
                    ..
                }) = lines.first().map(|l| &l.event)
                else {
                    continue;
                };
                outln!(
                    "{participant} {}: {}/{} conditions, {} surveys ({} in the study CSV, \
                     {} at the end of a query condition)",
                    population.as_str(),
                    t.conditions_done,
                    t.conditions,
                    t.surveys,
                    t.surveys - t.end_of_condition_surveys,
                    t.end_of_condition_surveys
                )?;
            }
            Ok(())
        }
        StudyCommand::Export { data, out } => {
            let export = export_all(&data)?;
            let end = export.write(&out)?;
            outln!(
                "wrote {} surveys: {} to {} (read it with `hil workload summary --data {}`), \
                 {} end-of-condition surveys to {}",
                export.surveys(),
                export.study.records().len(),
                out.display(),
                out.display(),
                export.end_of_condition.len(),
                end.display()
            )?;
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{Args, Command};

    fn serve_help() -> String {
        let mut study = StudyArgs::augment_args(Command::new("study"));
        study.build();
        let serve = study.find_subcommand_mut("serve").unwrap();
        serve.render_long_help().to_string()
    }

    /// `--help` shows the whole config example, `[design]` with `time_scale`.
    #[test]
    fn serve_help_shows_the_config_keys() {
        let help = serve_help();
        assert!(help.contains(hil_study::config::EXAMPLE_TOML), "{help}");
        assert!(help.contains("time_scale = 1.0"), "{help}");
    }

    /// `--lan` serves HTTPS; without it the default stays plain HTTP on
    /// loopback; the lab's certificate replaces the config's.
    #[test]
    fn lan_means_https() {
        let mut server = hil_study::ServerConfig::default();
        apply_flags(&mut server, false, Some(8765), None, None);
        assert!(!server.uses_https() && server.bind.is_loopback());
        assert_eq!(server.port, 8765);
        apply_flags(&mut server, true, None, None, None);
        assert!(server.uses_https());
        let mut local = hil_study::ServerConfig::default();
        apply_flags(
            &mut local,
            false,
            None,
            Some("c.pem".into()),
            Some("k.pem".into()),
        );
        assert!(local.uses_https() && local.bind.is_loopback());
        assert_eq!(local.tls_key, Some(PathBuf::from("k.pem")));
    }

    /// An enrolment must name its participant.
    #[test]
    fn an_enrolment_names_its_participant() {
        assert_eq!(
            parse_enrolment("p001=mobility_limitation").unwrap(),
            ("p001".to_string(), Population::MobilityLimitation)
        );
        let e = parse_enrolment("mobility_limitation").unwrap_err();
        assert!(e.contains("ID=POPULATION"), "{e}");
        assert!(parse_enrolment("Jane=no_limitation").is_err());
        assert!(parse_enrolment("p001=robot").is_err());
    }
}
