//! `ktree stats FILE | --rays FILE [--json] [--measures]`: node counts, voxels and bounding box of a tree
//! or of the tree a ray file stacks to. A version 2 tree file is checked and counted through a memory map
//! (the counts come from its directory; the bounding box from one walk that descends only where a face of
//! the box may lie); a file of another format `ktree` reads (`.vdb`, `.bt`, binvox, …) is read into memory.
//! With `--measures`, the surface area and the Euler number (`surface_area`, `euler_number`) too, measured
//! on the file as it is read (in place for a version 2 file): the surface area on the nodes alone, the
//! Euler number on the tree's runs when they fit the memory budget. A `.ktree` with values gives the counts
//! of its own nodes, its value type (`dtype`) and, per value (`values`), the voxels, bounding box, centroid
//! and surface area. A `.ktree` that keeps where its voxels are in the world gives it too (`world_frame`:
//! `voxel_size` and `origin`, voxel 0's lower corner).

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::PathBuf;

use ktree::io::{read_rays_file, FileTree};
use ktree::query::{stats, TreeStats};
use ktree::with_tree;

use crate::common::error::read_error;
use crate::common::tree_file::frame_text;

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
    /// Also measure the surface area (faces between full and empty voxels) and the Euler number (JSON
    /// keys `surface_area`, `euler_number`): a pass over the tree's nodes, and for the Euler number over its
    /// runs, longer than the counts.
    #[arg(long)]
    measures: bool,
}

/// Prints the statistics.
pub fn run(args: Args) -> CliResult {
    if let Some(path) = args.tree.as_deref().filter(|p| crate::values::is_valued(p)) {
        if args.measures {
            return Err(format!(
                "{}: --measures is for trees without values; a tree with values gives each value's surface area under `values`",
                path.display()
            )
            .into());
        }
        return crate::values::print_valued_stats(path, args.json);
    }
    // The JSON keys are the fields of `TreeStats`, which users' scripts rely on.
    let mut frame = None;
    let (stats, measures) = match (&args.tree, &args.rays) {
        (Some(path), None) => {
            let file = ktree::input::open_tree(path, &ktree::io::ReadOptions::default())
                .map_err(CliError::caused)?;
            // A version 2 `.ktree` may keep where its voxels are in the world.
            if let FileTree::Mapped(mapped) = &file {
                frame = mapped.view().frame();
            }
            let stats = with_tree!(&file, t => stats(t, None).map_err(read_error))?;
            let measures = if args.measures {
                Some(crate::shape::measures(&file)?)
            } else {
                None
            };
            (stats, measures)
        }
        (None, Some(path)) => {
            let rays = read_rays_file(path).map_err(CliError::caused)?;
            let tree = rays.build();
            let measures = if args.measures {
                Some(crate::shape::measures_in_memory(&tree)?)
            } else {
                None
            };
            (tree.stats(Some(rays.len() as u64)), measures)
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
            #[serde(skip_serializing_if = "Option::is_none")]
            world_frame: Option<ktree::space::WorldFrame>,
        }
        let out = Out {
            stats: &stats,
            measures,
            world_frame: frame,
        };
        outln!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(CliError::caused)?
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
    outln!("voxels   {}", stats.voxels);
    match &stats.bounding_box {
        Some([lo, hi]) => outln!("box      {lo:?} to {hi:?} (upper bound excluded)"),
        None => outln!("box      - (the object is empty)"),
    }
    if let Some(frame) = &frame {
        outln!("world    {}", frame_text(frame));
    }
    outln!("bytes    {} (at 2 bits/node)", stats.bytes_at_2_bits);
    outln!(
        "memory   {} bytes navigable in memory ({:.3} bits/node)",
        stats.memory_bytes,
        stats.memory_bytes as f64 * 8.0 / stats.nodes as f64
    );
    if let Some(m) = measures {
        outln!("surface  {} faces", m.surface_area);
        if let Some(e) = m.euler_number {
            outln!("euler    {e} (connectivity {})", stats.k);
        }
        if m.euler_skipped {
            outln!(
                "euler    - (not measured: the tree's runs are large next to the memory budget)"
            );
        }
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
