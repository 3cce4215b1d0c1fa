//! `ktree stats FILE.ktree | --rays FILE [--json]`: node counts of a tree or of the tree a ray file stacks to.

use std::path::PathBuf;

use ktree::io::{read_ktree_file, read_rays_file, AnyTree};
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

/// Prints the statistics.
pub fn run(args: Args) -> Result<(), String> {
    let (tree, rays): (AnyTree, Option<u64>) = match (&args.tree, &args.rays) {
        (Some(path), None) => (read_ktree_file(path).map_err(|e| e.to_string())?, None),
        (None, Some(path)) => {
            let rays = read_rays_file(path).map_err(|e| e.to_string())?;
            (rays.stack(), Some(rays.len() as u64))
        }
        _ => return Err("give either a .ktree file or --rays FILE".into()),
    };
    let c = tree.counts();
    let stats = Stats {
        k: tree.k(),
        level: tree.level(),
        rays,
        full: c.full,
        empty: c.empty,
        partial: c.partial,
        nodes: c.nodes(),
        bytes_at_2_bits: tree.bytes_at_two_bits(),
        memory_bytes: tree.heap_bytes() as u64,
        per_level: tree.counts_per_level(),
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
