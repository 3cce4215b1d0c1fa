//! `ktree stats FILE.ktree | --rays FILE [--json]`: node counts of a tree or of the tree a ray file stacks to.

use std::path::PathBuf;

use ktree::io::{read_ktree_file, read_rays_file, AnyTree};

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
    // The JSON keys are the fields of `TreeStats`, which users' scripts rely on.
    let stats = tree.stats(rays);
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
    println!("level        full       empty     partial");
    for l in &stats.per_level {
        println!(
            "{:>5} {:>11} {:>11} {:>11}",
            l.level, l.full, l.empty, l.partial
        );
    }
    Ok(())
}
