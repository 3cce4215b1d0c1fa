//! `ktree`: the command-line tool. Thin: parses arguments, calls the library, reports. Each subcommand lives
//! in its own module here.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod repro;

/// k-trees (bintrees, quadtrees, octrees, 4-D trees) from rays by stacking.
#[derive(Debug, Parser)]
#[command(name = "ktree", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Regenerate the paper reproductions into results/ (all of them by default).
    Repro(repro::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Repro(args) => repro::run(args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("ktree: {e:#}");
            ExitCode::FAILURE
        }
    }
}
