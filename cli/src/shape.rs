//! `ktree morph FILE dilate|erode|open|close --radius R [--shape ball|box|cross] --out OUT` and
//! `ktree components FILE [--connectivity C] [--out-dir D] [--json]`: morphology and connected components
//! of a tree file (a version 2 `.ktree` read in place through its memory map, any other format read into
//! memory); and the measures (`surface_area`, `euler_number`) that `stats` and `mass` report.

use crate::common::error::{read_error, CliError, CliResult};
use crate::outln;

use std::path::{Path, PathBuf};

use ktree::io::{FileTree, ReadOptions};
use ktree::shape::{self, Element};
use ktree::tree::TreeStorage;
use ktree::{with_tree, AnyTree};
use serde::Serialize;

use crate::common::tree_file::write;

/// Opens a tree file: a version 2 `.ktree` through its memory map, any other format read into memory.
fn open(path: &Path) -> CliResult<FileTree> {
    ktree::input::open_tree(path, &ReadOptions::default()).map_err(CliError::caused)
}

/// Arguments of `ktree morph`.
#[derive(Debug, clap::Args)]
pub struct MorphArgs {
    /// The tree file.
    tree: PathBuf,
    /// The operation: dilate, erode, open (dilation of the erosion) or close (erosion of the dilation).
    #[arg(value_parser = ["dilate", "erode", "open", "close"])]
    operation: String,
    /// The element's radius in voxels (a real number ≥ 0).
    #[arg(long)]
    radius: f64,
    /// The element: ball (|d|² ≤ r²), box (max |d_i| ≤ r) or cross (Σ |d_i| ≤ r).
    #[arg(long, default_value = "ball")]
    shape: Element,
    #[command(flatten)]
    out: crate::common::args::TreeOut,
}

fn morph<const K: usize, T: TreeStorage<K> + Sync>(t: &T, args: &MorphArgs) -> CliResult {
    let (r, e) = (args.radius, args.shape);
    let out = match args.operation.as_str() {
        "dilate" => shape::dilate(t, r, e),
        "erode" => shape::erode(t, r, e),
        "open" => shape::opening(t, r, e),
        _ => shape::closing(t, r, e),
    }
    .map_err(|err| CliError::in_file(&args.tree, err))?;
    write(&args.out.out, &out)
}

/// Runs `ktree morph`.
pub fn run_morph(args: MorphArgs) -> CliResult {
    if !(args.radius.is_finite() && args.radius >= 0.0) {
        return Err(format!("--radius must be a number ≥ 0, got {}", args.radius).into());
    }
    let tree = open(&args.tree)?;
    with_tree!(&tree, t => morph(t, &args))
}

/// Arguments of `ktree components`.
#[derive(Debug, clap::Args)]
pub struct ComponentsArgs {
    /// The tree file.
    tree: PathBuf,
    /// Neighbours: 1 = the 2K face neighbours … K = all 3^K − 1 (scipy's generate_binary_structure).
    #[arg(long, default_value_t = 1)]
    connectivity: usize,
    /// Write each component to D/component-N.ktree (N = 1 for the largest).
    #[arg(long, value_name = "D")]
    out_dir: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct ComponentsReport {
    connectivity: usize,
    count: usize,
    sizes: Vec<u128>,
    files: Option<Vec<PathBuf>>,
}

fn components<const K: usize, T: TreeStorage<K>>(
    t: &T,
    args: &ComponentsArgs,
) -> CliResult<ComponentsReport> {
    let name = |err| CliError::in_file(&args.tree, err);
    let Some(dir) = &args.out_dir else {
        let sizes = shape::component_sizes(t, args.connectivity).map_err(name)?;
        return Ok(ComponentsReport {
            connectivity: args.connectivity,
            count: sizes.len(),
            sizes,
            files: None,
        });
    };
    let parts = shape::components(t, args.connectivity).map_err(name)?;
    std::fs::create_dir_all(dir).map_err(|e| {
        CliError::caused(ktree::fs::FileOpError::new(
            ktree::fs::FileOp::CreateFolder,
            dir,
            e,
        ))
    })?;
    let mut files = Vec::new();
    for (i, part) in parts.iter().enumerate() {
        let path = dir.join(format!("component-{}.ktree", i + 1));
        crate::common::tree_file::write_tree(&path, &part.tree).map_err(CliError::caused)?;
        files.push(path);
    }
    Ok(ComponentsReport {
        connectivity: args.connectivity,
        count: parts.len(),
        sizes: parts.iter().map(|p| p.size).collect(),
        files: Some(files),
    })
}

/// Runs `ktree components`.
pub fn run_components(args: ComponentsArgs) -> CliResult {
    let tree = open(&args.tree)?;
    let report = with_tree!(&tree, t => components(t, &args))?;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(CliError::caused)?
        );
        return Ok(());
    }
    outln!(
        "{} components (connectivity {})",
        report.count,
        report.connectivity
    );
    for (i, size) in report.sizes.iter().enumerate() {
        match &report.files {
            Some(files) => outln!("{:>6} {:>14} voxels  {}", i + 1, size, files[i].display()),
            None => outln!("{:>6} {:>14} voxels", i + 1, size),
        }
    }
    Ok(())
}

/// The surface area and, for K = 2 and 3, the Euler number (connectivity K, scikit-image's default) of a
/// tree file.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Measures {
    /// The count of (K − 1)-faces between full and empty voxels.
    pub surface_area: u128,
    /// The Euler number, K = 2 and 3 only, when the tree's runs fit the memory budget.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub euler_number: Option<i64>,
    /// Whether the Euler number was left out because the tree's runs are large next to the memory budget.
    #[serde(skip)]
    pub euler_skipped: bool,
}

/// Bytes a run of the tree takes while the Euler number walks the runs (its column key and ends, and its
/// share of the pieces gathered), with room to spare.
const BYTES_PER_RUN: u128 = 48;

fn measures_of<const K: usize, T: TreeStorage<K>>(t: &T, budget: u64) -> CliResult<Measures> {
    // The surface area walks the nodes alone; the Euler number holds the runs, counted first.
    let surface_area = shape::surface_area(t).map_err(read_error)?;
    let fits = || -> CliResult<bool> {
        let runs = shape::run_count(t).map_err(read_error)?;
        Ok(runs.saturating_mul(BYTES_PER_RUN) <= u128::from(budget))
    };
    let (euler_number, euler_skipped) = if matches!(K, 2 | 3) && fits()? {
        let e = shape::euler_number(t, K).map_err(CliError::caused)?;
        (Some(e), false)
    } else {
        (None, matches!(K, 2 | 3))
    };
    Ok(Measures {
        surface_area,
        euler_number,
        euler_skipped,
    })
}

/// The measures of a tree file (read in place or in memory): the surface area, and the Euler number
/// when the tree's runs fit the memory budget.
pub fn measures(tree: &FileTree) -> CliResult<Measures> {
    let budget = crate::common::memory::default_budget();
    with_tree!(tree, t => measures_of(t, budget))
}

/// [`measures`] of a tree in memory.
pub fn measures_in_memory(tree: &AnyTree) -> CliResult<Measures> {
    let budget = crate::common::memory::default_budget();
    ktree::with_dim!(tree, AnyTree, t => measures_of(t, budget))
}

/// The measures of a tree file if it is small next to the memory budget (at most 1/16 of it), `None` for
/// a larger file, which `mass` then reports without them (they take a pass over the whole tree).
pub fn measures_of_file(path: &Path) -> CliResult<Option<Measures>> {
    let size = std::fs::metadata(path)
        .map_err(|e| CliError::in_file(path, e))?
        .len();
    if size > crate::common::memory::default_budget() / 16 {
        return Ok(None);
    }
    Ok(Some(measures(&open(path)?)?))
}
