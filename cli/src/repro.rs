//! `ktree repro [NAME]`: regenerate reproductions into results/.

use crate::common::error::CliResult;
use crate::outln;

use std::path::PathBuf;

/// Arguments of `ktree repro`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which reproduction: `all`, or one by name.
    #[arg(default_value = "all", value_parser = names())]
    name: String,
    /// The results directory.
    #[arg(long, default_value = "results")]
    out: PathBuf,
}

/// `all` and the name of each reproduction, as the values `NAME` takes.
fn names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        std::iter::once("all").chain(ktree_repro::NAMES.iter().copied()),
    )
}

/// Runs the chosen reproductions and prints what each wrote.
pub fn run(args: Args) -> CliResult {
    // Clap has checked the name against `names()`.
    let names: Vec<&str> = if args.name == "all" {
        ktree_repro::NAMES.to_vec()
    } else {
        vec![args.name.as_str()]
    };
    for name in names {
        let report = ktree_repro::run(name, &args.out).map_err(|e| format!("{name}: {e}"))?;
        outln!("{report}");
    }
    Ok(())
}
