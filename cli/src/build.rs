//! `ktree build --rays FILE --out FILE.ktree [--threads N] [--max-memory SIZE] [--temp-dir DIR]
//! [--progress]`: stack a ray file into a tree file (out of core: see [`crate::common::memory`]).

use crate::common::error::{CliError, CliResult};

use std::path::PathBuf;

use ktree::io::{open_rays_file, RaysFile, RaysFileSource};
use ktree::RaySet;

use crate::common::output::TreeOutput;

/// Arguments of `ktree build`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The ray file (text format: `# ktree rays v1`, then `K L`, then one run per line).
    #[arg(long)]
    rays: PathBuf,
    #[command(flatten)]
    out: crate::common::args::TreeOut,
    #[command(flatten)]
    build: crate::common::memory::BuildArgs,
}

/// Reads the rays, stacks them, writes the tree, and prints a one-line summary (in a run over several
/// MPI ranks, every rank reads the whole ray file; rank 0 alone writes and prints).
pub fn run(args: Args) -> CliResult {
    // A sorted file is read slab by slab as the cells are stacked; another is read whole.
    let summary = match open_rays_file(&args.rays).map_err(CliError::caused)? {
        RaysFile::Sorted(source) => {
            ktree::with_dim!(&source, AnyRaysFileSource, s => build_source(s, &args))?
        }
        RaysFile::Whole(rays) => ktree::with_dim!(&rays, AnyRaySet, r => build_rays(r, &args))?,
    };
    crate::common::output::print_summary(&summary)
}

/// Stacks rays read whole straight into the output; returns the summary (empty on ranks other than 0).
fn build_rays<const K: usize>(rays: &RaySet<K>, args: &Args) -> CliResult<String> {
    let what = format!("the rays of {}", args.rays.display());
    let held = (what.as_str(), crate::common::memory::ray_bytes(rays));
    let built = TreeOutput::new(&args.out.out, &args.build).write(rays, Some(held))?;
    Ok(built
        .map(|b| b.summary_with_size(rays.len() as u64))
        .unwrap_or_default())
}

/// Stacks a ray file read slab by slab straight into the output (across the MPI ranks of the run, if
/// several, each reading its slabs' lines); returns the summary (empty on ranks other than 0).
fn build_source<const K: usize>(source: &RaysFileSource<K>, args: &Args) -> CliResult<String> {
    let what = format!("the index of {}", args.rays.display());
    let held = (what.as_str(), source.heap_bytes());
    let built = TreeOutput::new(&args.out.out, &args.build).write(source, Some(held))?;
    Ok(built
        .map(|b| b.summary_with_size(source.runs()))
        .unwrap_or_default())
}
