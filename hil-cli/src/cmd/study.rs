//! `hil study …`: run the querying-workload study in the browser, follow
//! the participants' progress, export the study CSV for `hil workload`.

use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;

use hil_core::Result;
use hil_study::log::{Event, read};
use hil_study::server::{participant_logs, stored_design};
use hil_study::session::tally;
use hil_study::{Design, StudyConfig, StudyServer, export_all};
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
    Serve {
        /// Study config (TOML; default: the paper's design on loopback).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Data folder (created if missing; resumed if it has data).
        #[arg(long)]
        data: PathBuf,
        /// Listen on every address, for a tablet on the LAN (prints them).
        #[arg(long)]
        lan: bool,
        /// Port (default: the config's, 0 = any free port).
        #[arg(long)]
        port: Option<u16>,
        /// Enrol a participant of this population now and print their link
        /// (repeatable): no_limitation, mobility_limitation, occupational_therapist.
        #[arg(long, value_parser = parse_population)]
        enrol: Vec<Population>,
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

fn parse_population(s: &str) -> std::result::Result<Population, String> {
    serde_json::from_value(serde_json::Value::String(s.to_string())).map_err(|_| {
        format!("`{s}` is not a population: no_limitation, mobility_limitation or occupational_therapist")
    })
}

/// Runs `hil study`.
pub fn run(args: StudyArgs) -> Result<()> {
    match args.command {
        StudyCommand::Serve {
            config,
            data,
            lan,
            port,
            enrol,
            for_s,
        } => {
            let mut cfg = match &config {
                Some(p) => StudyConfig::load(p)?,
                None => StudyConfig::default(),
            };
            if lan {
                cfg.server.bind = IpAddr::V4(Ipv4Addr::UNSPECIFIED);
            }
            if let Some(p) = port {
                cfg.server.port = p;
            }
            let server = StudyServer::start(cfg, &data)?;
            println!("Study data: {}", data.display());
            println!("Researcher's page (keep this link to yourself):");
            for u in server.researcher_urls() {
                println!("  {u}");
            }
            for pop in enrol {
                let (id, urls) = server.enrol(pop)?;
                println!("Participant {id} ({}):", pop.as_str());
                for u in urls {
                    println!("  {u}");
                }
            }
            println!("Serving; stop with Ctrl-C (answers are saved as they come).");
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
                println!(
                    "{participant} {}: {}/{} conditions, {} surveys ({} in the study CSV, \
                     {} at the end of a query condition)",
                    population.as_str(),
                    t.conditions_done,
                    t.conditions,
                    t.surveys,
                    t.surveys - t.end_of_condition_surveys,
                    t.end_of_condition_surveys
                );
            }
            Ok(())
        }
        StudyCommand::Export { data, out } => {
            let export = export_all(&data)?;
            let end = export.write(&out)?;
            println!(
                "wrote {} surveys: {} to {} (read it with `hil workload summary --data {}`), \
                 {} end-of-condition surveys to {}",
                export.surveys(),
                export.study.records().len(),
                out.display(),
                out.display(),
                export.end_of_condition.len(),
                end.display()
            );
            Ok(())
        }
    }
}
