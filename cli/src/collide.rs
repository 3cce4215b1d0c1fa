//! `ktree collide A B [--time-axis N] [--json]`: interference detection between two `.ktree` files, with
//! the minimum separation when they do not overlap (JSON keys: those of [`ktree::ops::Collision`]).

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::PathBuf;

use crate::common::tree_file::{pair_error, read};

/// Arguments of `ktree collide`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// First tree file.
    a: PathBuf,
    /// Second tree file (same K and level).
    b: PathBuf,
    /// Treat this axis as time and report the first time step at which the objects overlap
    /// (e.g. 3 for 4-D space-time trees (x, y, z, t)).
    #[arg(long)]
    time_axis: Option<usize>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Prints whether the objects overlap, and where.
pub fn run(args: Args) -> CliResult {
    let (ta, tb) = (read(&args.a)?, read(&args.b)?);
    let r = ta
        .collision(&tb, args.time_axis)
        .map_err(|e| pair_error(&args.a, &args.b, e))?;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&r).map_err(CliError::caused)?
        );
        return Ok(());
    }
    outln!("collide        {}", if r.collide { "yes" } else { "no" });
    outln!("overlap cells  {}", r.overlap_cells);
    outln!("overlap voxels {}", r.overlap_voxels);
    match r.min_separation {
        Some(d) => outln!("separation     {d} (between voxel centres)"),
        None => outln!("separation     - (an object is empty)"),
    }
    if let Some(axis) = args.time_axis {
        match r.first_contact {
            Some(t) => outln!("first contact  {t} (axis {axis})"),
            None => outln!("first contact  never (axis {axis})"),
        }
    }
    Ok(())
}
