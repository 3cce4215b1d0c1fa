//! `ktree`: the command-line tool. Thin: parses arguments, calls the library, reports. Each subcommand lives
//! in its own module here.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod build;
mod lines;
mod render;
mod repro;
mod stats;

/// k-trees (bintrees, quadtrees, octrees, 4-D trees) from rays by stacking.
#[derive(Debug, Parser)]
#[command(name = "ktree", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Stack a ray file into a .ktree file.
    Build(build::Args),
    /// Print node counts (K, L, rays, full, empty, partial, nodes, per level) of a tree or a ray file.
    Stats(stats::Args),
    /// Draw a hidden-surface image of a tree (octree; quadtree picture; 4-D strip of time slices) as PNG.
    Render(render::Args),
    /// Draw an octree as lines with hidden lines removed (SVG or PNG).
    Lines(lines::Args),
    /// Regenerate the paper reproductions into results/ (all of them by default).
    Repro(repro::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Build(args) => build::run(args),
        Command::Stats(args) => stats::run(args),
        Command::Render(args) => render::run(args),
        Command::Lines(args) => lines::run(args),
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
