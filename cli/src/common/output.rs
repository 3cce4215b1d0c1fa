//! Where the commands that make trees or rays put them: a `.ktree` (built out of core, or in memory for
//! format version 1) or a ray file, by the output's extension; and their one-line summaries.

use crate::outln;

use std::path::Path;

use ktree::io::write_rays_file;
use ktree::{KTree, LevelCounts, RaySet};

use super::memory::BuildArgs;
use super::threads::with_threads;

/// Writes rays as text, or stacks them into a `.ktree` file, by the output's extension; returns a summary.
/// A tree of format version 2 is built out of core in the budget of `build` less what the rays hold (see
/// [`crate::common::memory`]), across the MPI ranks of the run if several: every rank holds the rays whole, rank 0
/// alone writes and returns the summary (the others return an empty one). Version 1 is built in memory by
/// one process.
pub fn write_output<const K: usize>(
    rays: &RaySet<K>,
    out: &Path,
    threads: Option<usize>,
    build: &BuildArgs,
) -> Result<String, String> {
    if is_tree_file(out) {
        let counts = if crate::common::memory::out_of_core() {
            let budget = build
                .budget
                .left_after("the rays", crate::common::memory::ray_bytes(rays))?;
            match crate::distributed::build_to_file(rays, out, threads, build, budget)? {
                Some(report) => report.counts_per_level,
                None => return Ok(String::new()),
            }
        } else {
            one_process_for_version_1()?;
            let tree = with_threads(threads, || KTree::from_rays(rays))?;
            crate::common::tree_file::write_tree(out, &tree)
                .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
            tree.counts_per_level()
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

/// Trees of format version 1 are built in memory by one process: an error in a run over several MPI
/// ranks.
pub fn one_process_for_version_1() -> Result<(), String> {
    if crate::distributed::ranks().size > 1 {
        return Err(
            "--format-version 1: trees of version 1 are written by one process; across MPI ranks, \
             write version 2 (and convert it with `ktree convert` if needed)"
                .into(),
        );
    }
    Ok(())
}

/// Whether an output path names a tree file (`.ktree`) rather than a ray file.
pub fn is_tree_file(out: &Path) -> bool {
    out.extension().is_some_and(|e| e == "ktree")
}

/// Prints a command's summary line, if it has one (ranks other than 0 of an MPI run have none).
pub fn print_summary(summary: &str) -> Result<(), String> {
    if !summary.is_empty() {
        outln!("{summary}");
    }
    Ok(())
}
