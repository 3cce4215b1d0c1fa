//! `ktree repro [NAME]`: regenerate reproductions into results/.

use crate::common::error::CliResult;
use crate::outln;

use std::path::PathBuf;

/// Arguments of `ktree repro`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which reproduction: `all` (default) or one of the names listed by `--list`.
    #[arg(default_value = "all")]
    name: String,
    /// The results directory.
    #[arg(long, default_value = "results")]
    out: PathBuf,
}

/// Runs the chosen reproductions and prints what each wrote.
pub fn run(args: Args) -> CliResult {
    let names: Vec<&str> = if args.name == "all" {
        ktree_repro::NAMES.to_vec()
    } else if ktree_repro::NAMES.contains(&args.name.as_str()) {
        vec![args.name.as_str()]
    } else {
        return Err(format!(
            "unknown reproduction '{}': choose one of all, {}",
            args.name,
            ktree_repro::NAMES.join(", ")
        )
        .into());
    };
    for name in names {
        let report = ktree_repro::run(name, &args.out).map_err(|e| format!("{name}: {e}"))?;
        outln!("{report}");
    }
    Ok(())
}
