//! Where the commands that make trees or rays put them: a `.ktree` (built out of core, in either format
//! version) or a ray file, by the output's extension; and their one-line summaries.

use crate::common::error::CliResult;
use crate::outln;

use std::path::Path;

use ktree::io::write_rays_file;
use ktree::{LevelCounts, RaySet};

use super::memory::BuildArgs;

/// Writes rays as text, or stacks them into a `.ktree` file, by the output's extension; returns a summary.
/// A tree is built out of core in the budget of `build` less what the rays hold (see
/// [`crate::common::memory`]), across the MPI ranks of the run if several: every rank holds the rays whole, rank 0
/// alone writes and returns the summary (the others return an empty one). The format version written
/// (`--format-version`) does not change how the tree is built.
pub fn write_output<const K: usize>(
    rays: &RaySet<K>,
    out: &Path,
    threads: Option<usize>,
    build: &BuildArgs,
) -> Result<String, String> {
    if is_tree_file(out) {
        let budget = build
            .budget
            .left_after("the rays", crate::common::memory::ray_bytes(rays))?;
        let counts = match crate::distributed::build_to_file(rays, out, threads, build, budget)? {
            Some(report) => report.counts_per_level,
            None => return Ok(String::new()),
        };
        let c = LevelCounts::total(rays.level(), &counts);
        Ok(format!(
            "{}: K = {K}, L = {}, {} rays, {} voxels -> {} nodes ({} full, {} empty, {} partial)",
            out.display(),
            rays.level(),
            rays.len(),
            rays.voxel_count(),
            c.nodes(),
            c.full,
            c.empty,
            c.partial
        ))
    } else if !crate::distributed::ranks().is_root() {
        Ok(String::new())
    } else {
        write_rays_file(out, rays).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        Ok(format!(
            "{}: K = {K}, L = {}, {} rays, {} voxels",
            out.display(),
            rays.level(),
            rays.len(),
            rays.voxel_count()
        ))
    }
}

/// Whether an output path names a tree file (`.ktree`) rather than a ray file.
pub fn is_tree_file(out: &Path) -> bool {
    out.extension().is_some_and(|e| e == "ktree")
}

/// Prints a command's summary line, if it has one (ranks other than 0 of an MPI run have none).
pub fn print_summary(summary: &str) -> CliResult {
    if !summary.is_empty() {
        outln!("{summary}");
    }
    Ok(())
}
