//! `ktree stats FILE.ktree | --rays FILE [--json]`: node counts of a tree or of the tree a ray file stacks to.
//! A version 2 tree file is checked and counted through a memory map, in memory independent of its size.

use std::path::PathBuf;

use ktree::io::{ktree_file_version, read_ktree_file, read_rays_file, KtreeView, VERSION_2};
use ktree::tree::heap_bytes_for_levels;
use ktree::LevelCounts;
use serde::Serialize;

/// Arguments of `ktree stats`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["tree", "rays"])))]
pub struct Args {
    /// A `.ktree` file.
    tree: Option<PathBuf>,
    /// A ray file instead: it is stacked into a tree first.
    #[arg(long)]
    rays: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// The statistics printed, with the JSON keys users' scripts rely on.
#[derive(Debug, Serialize)]
struct Stats {
    k: usize,
    level: u32,
    /// Runs in the ray file; `null` for a tree file.
    rays: Option<u64>,
    full: u64,
    empty: u64,
    partial: u64,
    nodes: u64,
    bytes_at_2_bits: u64,
    /// Heap bytes of the navigable tree in memory (states and rank index).
    memory_bytes: u64,
    per_level: Vec<LevelCounts>,
}

impl Stats {
    fn new(
        k: usize,
        rays: Option<u64>,
        c: LevelCounts,
        bytes: u64,
        memory_bytes: u64,
        per_level: Vec<LevelCounts>,
    ) -> Self {
        Self {
            k,
            level: c.level,
            rays,
            full: c.full,
            empty: c.empty,
            partial: c.partial,
            nodes: c.nodes(),
            bytes_at_2_bits: bytes,
            memory_bytes,
            per_level,
        }
    }
}

/// Prints the statistics.
pub fn run(args: Args) -> Result<(), String> {
    let stats = match (&args.tree, &args.rays) {
        (Some(path), None) if ktree_file_version(path).map_err(|e| e.to_string())? == VERSION_2 => {
            let view = KtreeView::open(path).map_err(|e| e.to_string())?;
            Stats::new(
                view.k(),
                None,
                view.counts(),
                view.bytes_at_two_bits(),
                heap_bytes_for_levels(&view.counts_per_level()) as u64,
                view.counts_per_level(),
            )
        }
        (Some(path), None) => {
            let tree = read_ktree_file(path).map_err(|e| e.to_string())?;
            Stats::new(
                tree.k(),
                None,
                tree.counts(),
                tree.bytes_at_two_bits(),
                tree.heap_bytes() as u64,
                tree.counts_per_level(),
            )
        }
        (None, Some(path)) => {
            let rays = read_rays_file(path).map_err(|e| e.to_string())?;
            let tree = rays.stack();
            let n = Some(rays.len() as u64);
            Stats::new(
                tree.k(),
                n,
                tree.counts(),
                tree.bytes_at_two_bits(),
                tree.heap_bytes() as u64,
                tree.counts_per_level(),
            )
        }
        _ => return Err("give either a .ktree file or --rays FILE".into()),
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    println!("K        {}", stats.k);
    println!("L        {}", stats.level);
    println!(
        "rays     {}",
        stats.rays.map_or("-".to_string(), |r| r.to_string())
    );
    println!("full     {}", stats.full);
    println!("empty    {}", stats.empty);
    println!("partial  {}", stats.partial);
    println!("nodes    {}", stats.nodes);
    println!("bytes    {} (at 2 bits/node)", stats.bytes_at_2_bits);
    println!(
        "memory   {} bytes navigable in memory ({:.3} bits/node)",
        stats.memory_bytes,
        stats.memory_bytes as f64 * 8.0 / stats.nodes as f64
    );
    println!("level        full       empty     partial");
    for l in &stats.per_level {
        println!(
            "{:>5} {:>11} {:>11} {:>11}",
            l.level, l.full, l.empty, l.partial
        );
    }
    Ok(())
}
