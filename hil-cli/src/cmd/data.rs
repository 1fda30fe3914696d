//! `hil data generate` and `hil data check`: the food dataset.

use crate::out::outln;
use std::path::PathBuf;

use hil_envs::dataset::FoodDataset;
use hil_envs::generate::SyntheticFoods;
use hil_envs::rates::PublishedRates;

/// Arguments of `hil data`.
#[derive(Debug, clap::Args)]
pub struct DataArgs {
    #[command(subcommand)]
    pub command: DataCommand,
}

/// `hil data` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum DataCommand {
    /// Write the bundled synthetic food dataset (or a variant) to a directory,
    /// in the documented format (dataset.toml + .npy arrays), plus its exact
    /// linear success head `readout.npy` (n_actions × d).
    Generate(GenerateArgs),
    /// Load and validate a dataset directory and summarise it.
    Check(CheckArgs),
}

/// Arguments of `hil data generate`.
#[derive(Debug, clap::Args)]
pub struct GenerateArgs {
    /// Output directory.
    #[arg(long, short)]
    pub out: PathBuf,
    /// Generator seed (the bundled dataset uses the default).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Context dimension d.
    #[arg(long)]
    pub dim: Option<usize>,
    /// Images per food and setting.
    #[arg(long)]
    pub images_per_setting: Option<usize>,
    /// Generator parameters (TOML, fields of `hil_envs::generate::SyntheticFoods`;
    /// missing fields take the bundled dataset's values). Flags override it.
    #[arg(long)]
    pub generator: Option<PathBuf>,
    /// Overwrite a non-empty output directory.
    #[arg(long)]
    pub force: bool,
}

/// Arguments of `hil data check`.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Dataset directory or its dataset.toml.
    pub path: PathBuf,
}

pub fn run(args: DataArgs) -> hil_core::Result<()> {
    match args.command {
        DataCommand::Generate(a) => generate(a),
        DataCommand::Check(a) => check(a),
    }
}

fn generate(a: GenerateArgs) -> hil_core::Result<()> {
    let mut g = match &a.generator {
        Some(p) => {
            let text = hil_core::files::read_text(p, hil_core::files::limits::CONFIG)?;
            hil_config::parse_toml::<SyntheticFoods>(&text, p)?
        }
        None => SyntheticFoods::default(),
    };
    if let Some(s) = a.seed {
        g.seed = s;
    }
    if let Some(d) = a.dim {
        g.dim = d;
    }
    if let Some(n) = a.images_per_setting {
        g.images_per_setting = n;
    }
    let written = g.write_into(&a.out, a.force)?;
    let (out, manifest, p) = (&written.generated, &written.manifest, &written.parameters);
    outln!(
        "wrote {} ({} foods, {} images, d = {}); generator parameters in {}",
        manifest.display(),
        out.dataset.foods.len(),
        out.dataset
            .foods
            .iter()
            .map(|f| f.images.len())
            .sum::<usize>(),
        g.dim,
        p.display()
    )?;
    outln!("data provenance: {}", out.dataset.provenance)?;
    Ok(())
}

fn check(a: CheckArgs) -> hil_core::Result<()> {
    let ds = FoodDataset::load(&a.path)?;
    let rates = PublishedRates::bundled()?;
    outln!(
        "{}: {} foods, d = {}, actions {}, settings {}",
        ds.name,
        ds.foods.len(),
        ds.context_dim,
        ds.actions.names().join(" "),
        ds.settings.join(" ")
    )?;
    outln!("provenance: {}", ds.provenance)?;
    outln!(
        "{:<14} {:>6}  mean s(x,a) per action (published pooled rate in brackets, where known)",
        "food",
        "images"
    )?;
    for f in &ds.foods {
        let pub_rates = rates.food(&f.name);
        let cells: Vec<String> = f
            .mean_success()
            .iter()
            .enumerate()
            .map(|(a, m)| match pub_rates {
                Some(r) if r.pooled.len() == ds.actions.len() => {
                    format!("{m:.2} [{:.2}]", r.pooled[a])
                }
                _ => format!("{m:.2}"),
            })
            .collect();
        outln!("{:<14} {:>6}  {}", f.name, f.images.len(), cells.join("  "))?;
    }
    Ok(())
}
