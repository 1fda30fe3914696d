//! `hil plugins list PATH...` and `hil plugins check PATH`: inspect plugin
//! libraries and run hil-core's conformance suites on every type they
//! register.

use crate::out::{note, outln};
use std::path::PathBuf;

use hil_conformance::{
    CheckOptions, ConformanceFailure, ConformanceReport, check_environment_with, check_policy_with,
    check_query_channel_with, check_workload_model_built_with,
};
use hil_core::{ActionSpace, HilError};
use hil_plugin::{self as plugin, BuildFacts, ComponentInfo, ComponentKind, Params, PluginInfo};

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
        /// Parameters for a type, `NAME=TEXT`: TEXT is TOML, one `key = value`
        /// per line (`NAME='alpha = 0.5'`), or, if it starts with `{`, JSON,
        /// the form for several keys on one line
        /// (`NAME='{"alpha": 0.5, "beta": 2}'`). Types without it get no
        /// parameters.
        #[arg(long = "params", value_name = "NAME=TEXT")]
        params: Vec<String>,
        /// Action names policies are built for and channels are asked over,
        /// comma-separated (default: six task-neutral names, `a` to `f`).
        #[arg(long, value_delimiter = ',', value_name = "NAME,NAME,...")]
        actions: Option<Vec<String>>,
        /// Context dimension policies are built for and channels are shown.
        #[arg(long, default_value_t = 8)]
        dim: usize,
        /// Queries asked of each query channel.
        #[arg(long, default_value_t = 36)]
        queries: usize,
        /// Attempts per item when checking environments.
        #[arg(long, default_value_t = 3)]
        attempts: u32,
    },
    /// Print this host's build facts: a plugin loads only if it was built
    /// with the same ones (build it with the profile and toolchain shown).
    Abi {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
}

pub fn run(args: PluginsArgs) -> hil_core::Result<()> {
    match args.command {
        PluginsCommand::List { paths, json } => list(&paths, json),
        PluginsCommand::Check {
            path,
            params,
            actions,
            dim,
            queries,
            attempts,
        } => {
            let opts = options(actions, dim, queries, attempts)?;
            check(&path, &params, &opts)
        }
        PluginsCommand::Abi { json } => abi(json),
    }
}

/// `result` of a command, failed if a plugin object's destructor panicked
/// while it ran (every component has been dropped when a command returns;
/// PLUGINS.md promises the panic is reported). The first error is
/// returned, for `main` to print; any others are printed here. The same
/// panic of many objects of one type (a reproduction builds a policy per
/// run) is one error, with the count.
pub fn with_destructor_panics(result: hil_core::Result<()>) -> hil_core::Result<()> {
    let mut panics: Vec<(HilError, usize)> = Vec::new();
    for e in plugin::take_destructor_panics() {
        match panics
            .iter_mut()
            .find(|(p, _)| p.to_string() == e.to_string())
        {
            Some((_, n)) => *n += 1,
            None => panics.push((e, 1)),
        }
    }
    let counted = panics.into_iter().map(|(e, n)| match e {
        HilError::Plugin { path, why } if n > 1 => HilError::Plugin {
            path,
            why: format!("{why}\n(the same panic in the destructors of {n} objects)"),
        },
        e => e,
    });
    let mut errors = result.err().into_iter().chain(counted);
    let Some(first) = errors.next() else {
        return Ok(());
    };
    for e in errors {
        note!("error: {e}");
    }
    Err(first)
}

/// The conformance options of `hil plugins check`.
fn options(
    actions: Option<Vec<String>>,
    dim: usize,
    queries: usize,
    attempts: u32,
) -> hil_core::Result<CheckOptions> {
    let mut opts = CheckOptions::default()
        .with_context_dim(dim)
        .with_queries(queries)
        .with_attempts(attempts);
    if let Some(names) = actions {
        let space = ActionSpace::new(names.iter().map(|n| n.trim().to_string())).map_err(|e| {
            HilError::invalid_parameter("--actions", names.join(","), e.to_string())
        })?;
        opts = opts.with_actions(space);
    }
    opts.validate().map_err(|e| {
        super::as_flag(e, |name| match name {
            "context_dim" => "--dim".into(),
            other => format!("--{other}"),
        })
    })?;
    Ok(opts)
}

/// `hil plugins abi`: the facts a plugin must share with this host.
fn abi(json: bool) -> hil_core::Result<()> {
    let facts = BuildFacts::current();
    if json {
        let mut map = serde_json::Map::new();
        map.insert("abi_version".into(), plugin::ABI_VERSION.into());
        for (k, v) in facts.fields() {
            map.insert(k.into(), v.into());
        }
        return outln!("{}", serde_json::Value::Object(map));
    }
    outln!("ABI version: {}", plugin::ABI_VERSION)?;
    for (k, v) in facts.fields() {
        outln!("{k}: {v}")?;
    }
    let release = facts.profile.to_string_lossy() == "release";
    outln!(
        "build plugins for this host with `cargo build{}` using {}, against this hil-core and with this workspace's Cargo.lock",
        if release { " --release" } else { "" },
        facts.rustc_version.to_string_lossy()
    )
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
                    print_info(&info)?;
                }
            }
            Err(e) => {
                failed += 1;
                if json {
                    out.push(serde_json::json!({ "path": p, "error": e.to_string() }));
                } else {
                    note!("error: {e}");
                }
            }
        }
    }
    if json {
        let text =
            serde_json::to_string_pretty(&out).map_err(|e| HilError::serde("plugin list", e))?;
        outln!("{text}")?;
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

fn print_info(info: &PluginInfo) -> hil_core::Result<()> {
    outln!("{}", info.path.display())?;
    outln!("  ABI version: {}", info.abi_version)?;
    for (k, v) in &info.build {
        outln!("  {k}: {v}")?;
    }
    if info.components.is_empty() {
        outln!("  (registers no types)")?;
    }
    for c in &info.components {
        outln!("  {:<14} {:<20} {}", c.kind.as_str(), c.name, c.description)?;
    }
    Ok(())
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

/// The outcome of each registered type's suite, in registration order.
type Outcomes = Vec<(ComponentInfo, Result<ConformanceReport, ConformanceFailure>)>;

/// Loads the library and runs every registered type's suite.
fn run_checks(
    path: &std::path::Path,
    specs: &[String],
    opts: &CheckOptions,
) -> hil_core::Result<(PluginInfo, Outcomes)> {
    let info = plugin::load(path)?;
    let params = parse_params(specs, &info)?;
    let outcomes = info
        .components
        .iter()
        .map(|c| {
            let p = params
                .iter()
                .rev()
                .find(|(n, _)| *n == c.name)
                .map_or_else(Params::empty, |(_, p)| p.clone());
            (c.clone(), check_one(c, &p, opts))
        })
        .collect();
    Ok((info, outcomes))
}

fn check(path: &std::path::Path, specs: &[String], opts: &CheckOptions) -> hil_core::Result<()> {
    let (info, outcomes) = run_checks(path, specs, opts)?;
    print_info(&info)?;
    outln!(
        "  checked over {} actions ({}), context dimension {}",
        opts.actions().len(),
        opts.actions().names().join(", "),
        opts.context_dim()
    )?;
    let mut failed = 0;
    for (c, outcome) in &outcomes {
        match outcome {
            Ok(report) => {
                outln!(
                    "ok    {} `{}`: passed {}",
                    c.kind,
                    c.name,
                    report.passed_names()
                )?;
                for (check, why) in &report.skipped {
                    outln!("      skipped {check}: {why}")?;
                }
            }
            Err(f) => {
                failed += 1;
                outln!("FAIL  {} `{}`: property `{}`: {f}", c.kind, c.name, f.check)?;
            }
        }
    }
    if failed > 0 {
        return Err(HilError::Plugin {
            path: info.path,
            why: format!(
                "{failed} of {} types failed their conformance suite",
                outcomes.len()
            ),
        });
    }
    outln!("all {} types conform", outcomes.len())?;
    Ok(())
}

/// Runs the suite of `c`'s trait on objects built from `params` and the
/// options' contexts. Every suite builds its own objects and drops them,
/// so a destructor that panics fails the check (`drop does not panic`).
fn check_one(
    c: &ComponentInfo,
    params: &Params,
    opts: &CheckOptions,
) -> Result<ConformanceReport, ConformanceFailure> {
    let (ctx, task) = (opts.build_context(), opts.task_context());
    let name = c.name.as_str();
    match c.kind {
        ComponentKind::Policy => {
            check_policy_with(&|| plugin::build_policy(name, params, &task), opts)
        }
        ComponentKind::Environment => {
            check_environment_with(&|| plugin::build_environment(name, params, &ctx), opts)
        }
        ComponentKind::WorkloadModel => check_workload_model_built_with(
            &|| plugin::build_workload_model(name, params, &ctx),
            opts,
        ),
        ComponentKind::QueryChannel => {
            check_query_channel_with(&|| plugin::build_query_channel(name, params, &task), opts)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_conformance::Check;
    use hil_conformance::cdylib::{build_cdylibs, cdylib_path};

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
                "hil-test-plugin-unchecked-context",
            ],
        )
        .unwrap()
    }

    fn opts() -> CheckOptions {
        options(None, 8, 30, 3).unwrap()
    }

    #[test]
    #[ignore = "e2e: needs a nested cargo build of the test plugins; bash scripts/test runs it"]
    fn check_passes_a_conforming_plugin_and_fails_a_broken_one() {
        let dir = libs();
        let guide = cdylib_path(&dir, "hil-example-plugin-guide");
        check(&guide, &["ask_first_items=n_ask = 1".into()], &opts()).unwrap();
        // Without its required parameter the factory refuses: a build failure.
        let (_, outcomes) = run_checks(&guide, &[], &opts()).unwrap();
        assert_eq!(outcomes[0].1.as_ref().unwrap_err().check, Check::Build);
        assert!(matches!(
            check(&guide, &[], &opts()),
            Err(HilError::Plugin { .. })
        ));
        // The panicky test plugin's policy is 2-armed whatever the context.
        let (_, outcomes) =
            run_checks(&cdylib_path(&dir, "hil-test-plugin-panicky"), &[], &opts()).unwrap();
        let policy = outcomes
            .iter()
            .find(|(c, _)| c.kind == ComponentKind::Policy)
            .unwrap();
        assert_eq!(policy.1.as_ref().unwrap_err().check, Check::PolicyShape);
        // Parameters for a type the library does not register.
        let e = check(&guide, &["ask_first_item=n_ask = 1".into()], &opts()).unwrap_err();
        assert!(
            matches!(&e, HilError::InvalidParameter { name, .. } if name == "--params"),
            "{e}"
        );
    }

    #[test]
    #[ignore = "e2e: needs a nested cargo build of the test plugins; bash scripts/test runs it"]
    fn a_type_whose_destructor_panics_fails_naming_the_destructor() {
        let dir = libs();
        let lib = cdylib_path(&dir, "hil-test-plugin-panicky");
        let drop = |name: &str| format!("{name}=panic_in = \"drop\"");
        let specs = [drop("panicky_workload"), drop("panicky_channel")];
        // The policy fails its shape first (2 arms whatever the context),
        // the environment its end (its episodes never end).
        let conforming = |c: &ComponentInfo| {
            matches!(
                c.kind,
                ComponentKind::WorkloadModel | ComponentKind::QueryChannel
            )
        };
        let (_, outcomes) = run_checks(&lib, &specs, &opts()).unwrap();
        for (c, outcome) in outcomes.iter().filter(|(c, _)| conforming(c)) {
            let f = outcome.as_ref().unwrap_err();
            assert_eq!(
                (f.check, f.panicked_in.as_deref()),
                (Check::Destructor, Some("drop")),
                "{}: {f}",
                c.name
            );
        }
        // Without the panic the same types pass, destructor included.
        let (_, outcomes) = run_checks(&lib, &[], &opts()).unwrap();
        for (c, outcome) in outcomes.iter().filter(|(c, _)| conforming(c)) {
            let report = outcome.as_ref().unwrap();
            assert!(report.passed.contains(&Check::Destructor), "{}", c.name);
        }
        assert!(matches!(
            check(&lib, &specs, &opts()),
            Err(HilError::Plugin { .. })
        ));
    }

    #[test]
    #[ignore = "e2e: needs a nested cargo build of the test plugins; bash scripts/test runs it"]
    fn a_policy_that_panics_on_a_longer_context_fails_naming_the_property() {
        let dir = libs();
        let lib = cdylib_path(&dir, "hil-test-plugin-unchecked-context");
        let (_, outcomes) = run_checks(&lib, &[], &opts()).unwrap();
        let failure = outcomes[0].1.as_ref().unwrap_err();
        assert_eq!(failure.check, Check::RejectsWrongDimension, "{failure}");
        assert!(matches!(
            check(&lib, &[], &opts()),
            Err(HilError::Plugin { .. })
        ));
    }

    #[test]
    fn a_command_fails_once_for_the_same_destructor_panic_of_many_objects() {
        let panic = |name: &str| HilError::Plugin {
            path: "libp.so".into(),
            why: format!("`{name}` panicked in drop: boom in drop"),
        };
        // Other tests of this binary drop no plugin objects.
        assert!(with_destructor_panics(Ok(())).is_ok());
        for _ in 0..12 {
            plugin::report_drop_panic(panic("p"));
        }
        let e = with_destructor_panics(Ok(())).unwrap_err();
        assert!(
            matches!(&e, HilError::Plugin { why, .. } if why.contains("12 objects")),
            "{e}"
        );
        assert!(with_destructor_panics(Ok(())).is_ok(), "taken once");
        // The command's own error comes first; the panic is still taken.
        plugin::report_drop_panic(panic("q"));
        let e = with_destructor_panics(Err(HilError::state("run", "failed"))).unwrap_err();
        assert!(matches!(e, HilError::State { .. }));
        assert!(plugin::take_destructor_panics().is_empty());
    }

    #[test]
    fn options_come_from_the_flags_and_are_validated() {
        let o = options(Some(vec!["grasp".into(), " lift".into()]), 3, 5, 2).unwrap();
        assert_eq!(o.actions().names(), ["grasp", "lift"]);
        assert_eq!(o.context_dim(), 3);
        for bad in [
            options(None, 0, 5, 2),
            options(None, 3, 0, 2),
            options(Some(vec!["a".into(), "a".into()]), 3, 5, 2),
        ] {
            assert!(
                matches!(bad, Err(HilError::InvalidParameter { ref name, .. }) if name.starts_with("--")),
                "{bad:?}"
            );
        }
    }

    #[test]
    #[ignore = "e2e: needs a nested cargo build of the test plugins; bash scripts/test runs it"]
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
