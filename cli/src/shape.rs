//! `ktree morph FILE dilate|erode|open|close --radius R [--shape ball|box|cross] --out OUT` and
//! `ktree components FILE [--connectivity C] [--out-dir D] [--json]`: morphology and connected components
//! of a `.ktree` file; and the measures (`surface_area`, `euler_number`) that `stats` and `mass` report.

use crate::common::error::CliResult;
use crate::outln;

use std::path::{Path, PathBuf};

use ktree::shape::Element;
use ktree::{AnyTree, KTree};
use serde::Serialize;

use crate::common::tree_file::{read, write};

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
    /// The tree file to write.
    #[arg(long)]
    out: PathBuf,
}

fn morph<const K: usize>(t: &KTree<K>, args: &MorphArgs) -> CliResult {
    let (r, e) = (args.radius, args.shape);
    let out = match args.operation.as_str() {
        "dilate" => t.dilate(r, e),
        "erode" => t.erode(r, e),
        "open" => t.opening(r, e),
        _ => t.closing(r, e),
    }
    .map_err(|err| format!("{}: {err}", args.tree.display()))?;
    write(&args.out, &out)
}

/// Runs `ktree morph`.
pub fn run_morph(args: MorphArgs) -> CliResult {
    if !(args.radius.is_finite() && args.radius >= 0.0) {
        return Err(format!("--radius must be a number ≥ 0, got {}", args.radius).into());
    }
    let tree = read(&args.tree)?;
    ktree::with_dim!(&tree, AnyTree, t => morph(t, &args))
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

fn components<const K: usize>(
    t: &KTree<K>,
    args: &ComponentsArgs,
) -> Result<ComponentsReport, String> {
    let name = |err: ktree::shape::ShapeError| format!("{}: {err}", args.tree.display());
    let Some(dir) = &args.out_dir else {
        let sizes = t.component_sizes(args.connectivity).map_err(name)?;
        return Ok(ComponentsReport {
            connectivity: args.connectivity,
            count: sizes.len(),
            sizes,
            files: None,
        });
    };
    let parts = t.components(args.connectivity).map_err(name)?;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut files = Vec::new();
    for (i, part) in parts.iter().enumerate() {
        let path = dir.join(format!("component-{}.ktree", i + 1));
        crate::common::tree_file::write_tree(&path, &part.tree)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
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
    let tree = read(&args.tree)?;
    let report = ktree::with_dim!(&tree, AnyTree, t => components(t, &args))?;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
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
    /// The Euler number, K = 2 and 3 only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub euler_number: Option<i64>,
}

fn measures_of<const K: usize>(t: &KTree<K>) -> Measures {
    Measures {
        surface_area: t.surface_area(),
        euler_number: matches!(K, 2 | 3).then(|| t.euler_number(K).expect("connectivity K")),
    }
}

/// The measures of a loaded tree.
pub fn measures(tree: &AnyTree) -> Measures {
    ktree::with_dim!(tree, AnyTree, t => measures_of(t))
}

/// The measures of a tree file, read into memory if it is small next to the memory budget (at most 1/16 of
/// it: the runs the measures walk take more than the tree); `None` for a larger file, which `stats` and
/// `mass` then read through its memory map alone.
pub fn measures_of_file(path: &Path) -> Result<Option<Measures>, String> {
    let size = std::fs::metadata(path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .len();
    if size > crate::common::memory::default_budget() / 16 {
        return Ok(None);
    }
    Ok(Some(measures(&read(path)?)))
}
