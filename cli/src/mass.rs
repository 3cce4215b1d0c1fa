//! `ktree mass A [--tolerance t] [--json]`: volume, centroid and second moments of a `.ktree` file; with
//! `--tolerance`, Meagher's progressive bounds level by level, stopping when the tolerance is met. The
//! exact properties of a version 2 file are summed from its memory map, leaf by leaf, so a tree larger
//! than memory is measured without being loaded.

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::PathBuf;

use ktree::io::{ktree_file_version, AnyMappedTree, VERSION};
use ktree::ops;
use ktree::tree::storage::{infallible, TreeStorage};
use serde::Serialize;

use crate::common::tree_file::read;

/// Arguments of `ktree mass`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The tree file.
    tree: PathBuf,
    /// Relative tolerance for the progressive computation: stop at the first level where
    /// `upper − lower ≤ t · (upper + lower)/2`.
    #[arg(long)]
    tolerance: Option<f64>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct Level {
    level: u32,
    lower: u128,
    upper: u128,
    nodes_touched: u64,
}

#[derive(Debug, Serialize)]
struct Report {
    k: usize,
    volume: u128,
    centroid: Vec<f64>,
    central_moments: Vec<Vec<f64>>,
    inertia_tensor: Vec<Vec<f64>>,
    nodes: u64,
    progressive: Option<Vec<Level>>,
    estimate: Option<f64>,
    #[serde(flatten)]
    measures: Option<crate::shape::Measures>,
}

impl Report {
    /// The exact properties of a tree of `nodes` nodes, without progressive bounds.
    fn exact<const K: usize>(m: &ops::MassProperties<K>, nodes: u64) -> Self {
        Self {
            k: K,
            volume: m.volume,
            centroid: m.centroid.to_vec(),
            central_moments: m.central_moments.iter().map(|r| r.to_vec()).collect(),
            inertia_tensor: m.inertia_tensor().iter().map(|r| r.to_vec()).collect(),
            nodes,
            progressive: None,
            estimate: None,
            measures: None,
        }
    }
}

/// The properties of a tree in any storage, with the progressive bounds if a tolerance is given.
fn report<const K: usize, T: TreeStorage<K>>(
    t: &T,
    tolerance: Option<f64>,
) -> Result<Report, T::Error> {
    let progressive = tolerance
        .map(|tol| ops::mass_progressive(t, tol))
        .transpose()?;
    Ok(Report {
        estimate: progressive.as_ref().map(|p| p.estimate),
        progressive: progressive.map(|p| {
            p.levels
                .iter()
                .map(|l| Level {
                    level: l.level,
                    lower: l.lower,
                    upper: l.upper,
                    nodes_touched: l.nodes_touched,
                })
                .collect()
        }),
        ..Report::exact(&ops::mass_properties(t)?, t.node_count())
    })
}

/// Prints the mass properties.
pub fn run(args: Args) -> CliResult {
    if let Some(t) = args.tolerance {
        if !(t.is_finite() && t >= 0.0) {
            return Err(format!("--tolerance must be a number ≥ 0, got {t}").into());
        }
    }
    let mapped = ktree_file_version(&args.tree).map_err(CliError::caused)? == VERSION;
    let mut r = if mapped {
        let tree = AnyMappedTree::open(&args.tree).map_err(CliError::caused)?;
        ktree::with_dim!(&tree, AnyMappedTree, t => report(t, args.tolerance))
            .map_err(CliError::caused)?
    } else {
        let tree = read(&args.tree)?;
        ktree::with_dim!(&tree, AnyTree, t => infallible(report(t, args.tolerance)))
    };
    r.measures = crate::shape::measures_of_file(&args.tree)?;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&r).map_err(CliError::caused)?
        );
        return Ok(());
    }
    if let Some(levels) = &r.progressive {
        outln!("level        lower        upper  nodes touched");
        for l in levels {
            outln!(
                "{:>5} {:>12} {:>12} {:>14}",
                l.level,
                l.lower,
                l.upper,
                l.nodes_touched
            );
        }
        outln!(
            "estimate {:.1} (exact {}), {} of {} nodes touched",
            r.estimate.unwrap_or(f64::NAN),
            r.volume,
            levels.last().map_or(0, |l| l.nodes_touched),
            r.nodes
        );
        return Ok(());
    }
    outln!("K         {}", r.k);
    outln!("volume    {} voxels", r.volume);
    outln!("centroid  {:?}", r.centroid);
    let name = if r.k == 3 { "inertia   " } else { "moments   " };
    let rows = if r.k == 3 {
        &r.inertia_tensor
    } else {
        &r.central_moments
    };
    for (i, row) in rows.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:.6e}")).collect();
        outln!(
            "{}{}",
            if i == 0 { name } else { "          " },
            cells.join("  ")
        );
    }
    if let Some(m) = r.measures {
        outln!("surface   {} faces", m.surface_area);
        if let Some(e) = m.euler_number {
            outln!("euler     {e} (connectivity {})", r.k);
        }
    }
    Ok(())
}
