//! `hil plugins list PATH...` and `hil plugins check PATH`: inspect plugin
//! libraries and run hil-core's conformance suites on every type they
//! register.

use std::path::PathBuf;

use hil_core::TaskContext;
use hil_core::plugin::{self, ComponentInfo, ComponentKind, Params, PluginInfo};
use hil_core::testing::{
    ConformanceReport, check_environment, check_policy, check_query_channel, check_workload_model,
};
use hil_core::{ActionSpace, BuildContext, HilError};

/// Arguments of `hil plugins`.
#[derive(Debug, clap::Args)]
pub struct PluginsArgs {
    #[command(subcommand)]
    pub command: PluginsCommand,
}

/// What to do with plugin libraries.
#[derive(Debug, clap::Subcommand)]
pub enum PluginsCommand {
    /// Show what each library declares: its build facts and registered types.
    List {
        /// Plugin libraries (`.so`, `.dylib`, `.dll`).
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Run the conformance suite of its trait on every type a library registers.
    Check {
        /// The plugin library.
        path: PathBuf,
        /// Parameters for a type, `NAME=TEXT`: TOML (`alpha = 0.5`) or, if
        /// TEXT starts with `{`, JSON. Types without it get no parameters.
        #[arg(long = "params", value_name = "NAME=TEXT")]
        params: Vec<String>,
        /// Context dimension policies are built for.
        #[arg(long, default_value_t = 8)]
        dim: usize,
        /// Queries asked of each query channel.
        #[arg(long, default_value_t = 60)]
        queries: usize,
        /// Attempts per item when checking environments.
        #[arg(long, default_value_t = 3)]
        attempts: u32,
    },
}

pub fn run(args: PluginsArgs) -> hil_core::Result<()> {
    match args.command {
        PluginsCommand::List { paths, json } => list(&paths, json),
        PluginsCommand::Check {
            path,
            params,
            dim,
            queries,
            attempts,
        } => check(&path, &params, dim, queries, attempts),
    }
}

fn list(paths: &[PathBuf], json: bool) -> hil_core::Result<()> {
    let mut failed = 0;
    let mut out = Vec::new();
    for p in paths {
        match plugin::load(p) {
            Ok(info) => {
                if json {
                    out.push(info_json(&info));
                } else {
                    print_info(&info);
                }
            }
            Err(e) => {
                failed += 1;
                if json {
                    out.push(serde_json::json!({ "path": p, "error": e.to_string() }));
                } else {
                    eprintln!("error: {e}");
                }
            }
        }
    }
    if json {
        let text =
            serde_json::to_string_pretty(&out).map_err(|e| HilError::serde("plugin list", e))?;
        println!("{text}");
    }
    if failed > 0 {
        return Err(HilError::invalid_input(
            "plugins",
            format!("{failed} of {} libraries could not be loaded", paths.len()),
        ));
    }
    Ok(())
}

fn info_json(info: &PluginInfo) -> serde_json::Value {
    serde_json::json!({
        "path": info.path,
        "abi_version": info.abi_version,
        "build": info.build.iter().cloned().collect::<std::collections::BTreeMap<_, _>>(),
        "components": info.components.iter().map(|c| serde_json::json!({
            "kind": c.kind.as_str(),
            "name": c.name,
            "description": c.description,
        })).collect::<Vec<_>>(),
    })
}

fn print_info(info: &PluginInfo) {
    println!("{}", info.path.display());
    println!("  ABI version: {}", info.abi_version);
    for (k, v) in &info.build {
        println!("  {k}: {v}");
    }
    if info.components.is_empty() {
        println!("  (registers no types)");
    }
    for c in &info.components {
        println!("  {:<14} {:<20} {}", c.kind.as_str(), c.name, c.description);
    }
}

fn parse_params(specs: &[String], info: &PluginInfo) -> hil_core::Result<Vec<(String, Params)>> {
    specs
        .iter()
        .map(|s| {
            let (name, text) = s
                .split_once('=')
                .ok_or_else(|| HilError::invalid_parameter("--params", s, "expected NAME=TEXT"))?;
            if !info.components.iter().any(|c| c.name == name) {
                let names: Vec<&str> = info.components.iter().map(|c| c.name.as_str()).collect();
                return Err(HilError::invalid_parameter(
                    "--params",
                    s,
                    format!(
                        "the library registers no type `{name}`; closest: {}",
                        plugin::closest(name, names).join(", ")
                    ),
                ));
            }
            let params = if text.trim_start().starts_with('{') {
                Params::json(text)
            } else {
                Params::toml(text)
            };
            Ok((name.to_string(), params))
        })
        .collect()
}

fn check(
    path: &std::path::Path,
    specs: &[String],
    dim: usize,
    queries: usize,
    attempts: u32,
) -> hil_core::Result<()> {
    if dim == 0 {
        return Err(HilError::invalid_parameter(
            "--dim",
            0,
            "must be at least 1",
        ));
    }
    let info = plugin::load(path)?;
    let params = parse_params(specs, &info)?;
    print_info(&info);
    let mut failed = 0;
    for c in &info.components {
        let p = params
            .iter()
            .rev()
            .find(|(n, _)| *n == c.name)
            .map_or_else(Params::empty, |(_, p)| p.clone());
        match check_one(c, &p, dim, queries, attempts) {
            Ok(report) => {
                println!(
                    "ok    {} `{}`: passed {}",
                    c.kind,
                    c.name,
                    report.passed.join(", ")
                );
                for (check, why) in &report.skipped {
                    println!("      skipped {check}: {why}");
                }
            }
            Err(why) => {
                failed += 1;
                println!("FAIL  {} `{}`: {why}", c.kind, c.name);
            }
        }
    }
    if failed > 0 {
        return Err(HilError::Plugin {
            path: info.path,
            why: format!(
                "{failed} of {} types failed their conformance suite",
                info.components.len()
            ),
        });
    }
    println!("all {} types conform", info.components.len());
    Ok(())
}

fn check_one(
    c: &ComponentInfo,
    params: &Params,
    dim: usize,
    queries: usize,
    attempts: u32,
) -> Result<ConformanceReport, String> {
    let ctx = TaskContext::new(
        BuildContext::new(".", 0),
        ActionSpace::clone(hil_envs::feeding::FeedingTask::bundled().action_space()),
        dim,
    );
    let name = c.name.as_str();
    let r = match c.kind {
        ComponentKind::Policy => check_policy(&|| plugin::build_policy(name, params, &ctx)),
        ComponentKind::Environment => check_environment(
            &|| plugin::build_environment(name, params, ctx.base()),
            attempts,
        ),
        ComponentKind::WorkloadModel => {
            let m = plugin::build_workload_model(name, params, ctx.base())
                .map_err(|e| e.to_string())?;
            check_workload_model(m.as_ref())
        }
        ComponentKind::QueryChannel => {
            let mut ch =
                plugin::build_query_channel(name, params, &ctx).map_err(|e| e.to_string())?;
            check_query_channel(ch.as_mut(), queries)
        }
    };
    r.map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::testing::cdylib::{build_cdylibs, cdylib_path};

    fn libs() -> PathBuf {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .parent()
            .expect("hil-cli sits in the workspace root")
            .to_path_buf();
        build_cdylibs(
            &root,
            &[
                "hil-example-plugin-guide",
                "hil-test-plugin-panicky",
                "hil-test-plugin-mismatched-abi",
            ],
        )
        .unwrap()
    }

    #[test]
    fn check_passes_a_conforming_plugin_and_fails_a_broken_one() {
        let dir = libs();
        let guide = cdylib_path(&dir, "hil-example-plugin-guide");
        check(&guide, &["ask_first_items=n_ask = 1".into()], 8, 30, 3).unwrap();
        // Without its required parameter the factory refuses: a failure.
        let e = check(&guide, &[], 8, 30, 3).unwrap_err();
        assert!(e.to_string().contains("1 of 1 types failed"), "{e}");
        // The panicky test plugin's components do not validate their inputs.
        let e = check(&cdylib_path(&dir, "hil-test-plugin-panicky"), &[], 8, 30, 3).unwrap_err();
        assert!(
            e.to_string()
                .contains("types failed their conformance suite"),
            "{e}"
        );
        // Parameters for a type the library does not register.
        let e = check(&guide, &["ask_first_item=n_ask = 1".into()], 8, 30, 3).unwrap_err();
        assert!(e.to_string().contains("closest: ask_first_items"), "{e}");
    }

    #[test]
    fn list_reports_every_library_and_fails_if_any_is_refused() {
        let dir = libs();
        list(&[cdylib_path(&dir, "hil-example-plugin-guide")], true).unwrap();
        let e = list(
            &[
                cdylib_path(&dir, "hil-example-plugin-guide"),
                cdylib_path(&dir, "hil-test-plugin-mismatched-abi"),
            ],
            false,
        )
        .unwrap_err();
        assert!(e.to_string().contains("1 of 2 libraries"), "{e}");
    }
}
