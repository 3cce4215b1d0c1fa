//! `ktree stats FILE | --rays FILE [--json]`: node counts of a tree or of the tree a ray file stacks to.
//! A version 2 tree file is checked and counted through a memory map; a file of another format `ktree`
//! reads (`.vdb`, `.bt`, binvox, …) is read into memory; the surface area and the Euler number
//! (`surface_area`, `euler_number`) are measured on the tree read into memory, when the file is small next
//! to the memory budget.

use crate::common::error::CliResult;
use crate::outln;

use std::path::PathBuf;

use ktree::io::{ktree_file_version, read_ktree_file, read_rays_file, Format, KtreeView, VERSION};
use ktree::tree::heap_bytes_for_levels;
use ktree::tree::TreeStats;

/// Arguments of `ktree stats`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["tree", "rays"])))]
pub struct Args {
    /// A `.ktree` file, or a file of another format `ktree` reads (`.vdb`, `.bt`, `.binvox`, …).
    tree: Option<PathBuf>,
    /// A ray file instead: it is stacked into a tree first.
    #[arg(long)]
    rays: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// The statistics of a version 2 file, read through its memory map (the tree is not loaded; its memory is
/// what the navigable tree would take).
fn view_stats(view: &KtreeView) -> TreeStats {
    let c = view.counts();
    let per_level = view.counts_per_level();
    TreeStats {
        k: view.k(),
        level: view.level(),
        rays: None,
        full: c.full,
        empty: c.empty,
        partial: c.partial,
        nodes: c.nodes(),
        bytes_at_2_bits: view.bytes_at_two_bits(),
        memory_bytes: heap_bytes_for_levels(&per_level) as u64,
        per_level,
    }
}

/// Prints the statistics.
pub fn run(args: Args) -> CliResult {
    // The JSON keys are the fields of `TreeStats`, which users' scripts rely on.
    let (stats, measures) = match (&args.tree, &args.rays) {
        (Some(path), None) if Format::of(path).is_some_and(|f| f != Format::Ktree) => {
            let tree = crate::common::tree_file::read_any(path)?;
            (tree.stats(None), Some(crate::shape::measures(&tree)))
        }
        (Some(path), None) if ktree_file_version(path).map_err(|e| e.to_string())? == VERSION => (
            view_stats(&KtreeView::open(path).map_err(|e| e.to_string())?),
            crate::shape::measures_of_file(path)?,
        ),
        (Some(path), None) => {
            let tree = read_ktree_file(path).map_err(|e| e.to_string())?;
            (tree.stats(None), Some(crate::shape::measures(&tree)))
        }
        (None, Some(path)) => {
            let rays = read_rays_file(path).map_err(|e| e.to_string())?;
            let tree = rays.build();
            (
                tree.stats(Some(rays.len() as u64)),
                Some(crate::shape::measures(&tree)),
            )
        }
        _ => return Err("give either a .ktree file or --rays FILE".into()),
    };
    if args.json {
        // The fields of `TreeStats` in their order, then the measures.
        #[derive(serde::Serialize)]
        struct Out<'a> {
            #[serde(flatten)]
            stats: &'a TreeStats,
            #[serde(flatten)]
            measures: Option<crate::shape::Measures>,
        }
        let out = Out {
            stats: &stats,
            measures,
        };
        outln!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    outln!("K        {}", stats.k);
    outln!("L        {}", stats.level);
    outln!(
        "rays     {}",
        stats.rays.map_or("-".to_string(), |r| r.to_string())
    );
    outln!("full     {}", stats.full);
    outln!("empty    {}", stats.empty);
    outln!("partial  {}", stats.partial);
    outln!("nodes    {}", stats.nodes);
    outln!("bytes    {} (at 2 bits/node)", stats.bytes_at_2_bits);
    outln!(
        "memory   {} bytes navigable in memory ({:.3} bits/node)",
        stats.memory_bytes,
        stats.memory_bytes as f64 * 8.0 / stats.nodes as f64
    );
    match measures {
        Some(m) => {
            outln!("surface  {} faces", m.surface_area);
            if let Some(e) = m.euler_number {
                outln!("euler    {e} (connectivity {})", stats.k);
            }
        }
        None => outln!("surface  - (not measured: the file is large next to the memory budget)"),
    }
    outln!("level        full       empty     partial");
    for l in &stats.per_level {
        outln!(
            "{:>5} {:>11} {:>11} {:>11}",
            l.level,
            l.full,
            l.empty,
            l.partial
        );
    }
    Ok(())
}
