//! `ktree collide A B [--time-axis N] [--json]`: interference detection between two `.ktree` files, with
//! the minimum separation when they do not overlap.

use crate::outln;

use std::path::PathBuf;

use ktree::ops;
use ktree::AnyTree;
use ktree::KTree;
use serde::Serialize;

use crate::op::{read, with_pair};

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

/// What is reported, with these JSON keys.
#[derive(Debug, Serialize)]
struct Report {
    collide: bool,
    overlap_cells: usize,
    overlap_voxels: u128,
    first_contact: Option<u32>,
    /// Smallest distance between voxel centres of the two objects (voxels); null if one is empty.
    min_separation: Option<f64>,
}

fn report<const K: usize>(
    a: &KTree<K>,
    b: &KTree<K>,
    time_axis: Option<usize>,
) -> Result<Report, String> {
    let collide = ops::interferes(a, b).map_err(|e| e.to_string())?;
    let overlap = ops::intersection(a, b).map_err(|e| e.to_string())?;
    let first_contact = match time_axis {
        Some(axis) => ops::first_contact(a, b, axis).map_err(|e| e.to_string())?,
        None => None,
    };
    let min_separation = if collide {
        Some(0.0)
    } else {
        ops::min_separation(a, b).map_err(|e| e.to_string())?
    };
    Ok(Report {
        min_separation,
        collide,
        overlap_cells: overlap.full_cells().count(),
        overlap_voxels: overlap.voxel_count(),
        first_contact,
    })
}

/// Prints whether the objects overlap, and where.
pub fn run(args: Args) -> Result<(), String> {
    let (ta, tb) = (read(&args.a)?, read(&args.b)?);
    let r = with_pair!(&ta, &tb, (&args.a, &args.b), (x, y) => report(x, y, args.time_axis))?;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&r).map_err(|e| e.to_string())?
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
