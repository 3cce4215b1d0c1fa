//! Where the commands that make trees or rays put them, and their one-line summaries.
//!
//! [`TreeOutput::write`] is the one step that builds and writes a tree (`ktree rays`, `ktree build` and
//! `ktree voxelize` all end in it): a ray source goes to a `.ktree` file out of core, in the budget of
//! `--max-memory` less what the command holds for the source (see [`crate::common::memory`]), on
//! `--threads` worker threads, in the format version asked for (a version 1 file is built as version 2
//! and streamed into version 1: [`crate::common::tree_file::as_version_1`]). In one process it builds here;
//! with the `mpi` feature, in a run of several ranks, the same step is taken by every rank together
//! ([`crate::distributed`]). [`write_output`] writes rays as text or as a tree, by the output's extension.

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::{Path, PathBuf};

use ktree::fs::SpillError;
use ktree::io::write_rays_file;
use ktree::rays::RaySource;
use ktree::space::WorldFrame;
use ktree::stacking::{BuildError, Builder, OutOfCoreReport};
use ktree::{LevelCounts, RaySet};

use super::memory::BuildArgs;

/// Where and how a command writes the tree it builds: the output (`--out`), the worker threads
/// (`--threads`, all cores when `None`) and the build options (`--max-memory`, `--temp-dir`,
/// `--progress`).
#[derive(Debug, Clone, Copy)]
pub struct TreeOutput<'a> {
    /// The `.ktree` file written.
    pub out: &'a Path,
    /// Worker threads per process.
    pub threads: Option<usize>,
    /// Budget, spill folder, progress bar.
    pub args: &'a BuildArgs,
    /// Where the voxels are in the world, kept in the file.
    pub frame: Option<WorldFrame>,
}

/// A tree built and written by [`TreeOutput::write`]: what its summary says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Built {
    out: PathBuf,
    k: usize,
    level: u32,
    counts: Vec<LevelCounts>,
}

impl<'a> TreeOutput<'a> {
    /// The output `out`, with the build options `args` (worker threads, budget, spill folder, progress).
    pub fn new(out: &'a Path, args: &'a BuildArgs) -> Self {
        Self {
            out,
            threads: args.threads.threads,
            args,
            frame: None,
        }
    }

    /// The output keeping where the voxels are in the world.
    pub fn framed(self, frame: Option<WorldFrame>) -> Self {
        Self { frame, ..self }
    }

    /// Builds the tree of `source` and writes it to the output: out of core in the budget less what the
    /// command holds (`held`: what it is, for the message, and its bytes), in the format version asked
    /// for, across the MPI ranks of the run if several. Returns what was built on the process that wrote
    /// it (`None` on the other ranks, which print nothing).
    ///
    /// # Errors
    /// What is held does not fit in the budget, or the build failed (naming the output).
    pub fn write<const K: usize, S>(
        &self,
        source: &S,
        held: Option<(&str, u64)>,
    ) -> CliResult<Option<Built>>
    where
        S: RaySource<K>,
        S::Error: std::error::Error + Send + Sync + 'static,
    {
        let budget = match held {
            Some((what, bytes)) => self.args.budget.left_after(what, bytes)?,
            None => self.args.budget.budget(),
        };
        let report = if crate::common::tree_file::version() == 1 {
            crate::common::tree_file::as_version_1(self.out, |v2| {
                self.build_version_2(source, v2, budget)
            })?
        } else {
            self.build_version_2(source, self.out, budget)?
        };
        Ok(report.map(|report| Built {
            out: self.out.to_path_buf(),
            k: K,
            level: source.universe().level(),
            counts: report.counts_per_level,
        }))
    }

    /// Builds the tree of `source` into the version 2 file `path`, in `budget` bytes per process: here,
    /// or across the ranks of an MPI run.
    fn build_version_2<const K: usize, S>(
        &self,
        source: &S,
        path: &Path,
        budget: u64,
    ) -> CliResult<Option<OutOfCoreReport>>
    where
        S: RaySource<K>,
        S::Error: std::error::Error + Send + Sync + 'static,
    {
        #[cfg(feature = "mpi")]
        if crate::distributed::ranks().size > 1 {
            return crate::distributed::build_across_ranks(self, source, path, budget);
        }
        let pool = crate::common::threads::thread_pool(self.threads)?;
        let bar = crate::common::progress::progress_bar(self.args.progress, "stacking");
        let progress = |p| crate::common::progress::report_progress(bar.as_ref(), p);
        let report = pool.install(|| {
            self.builder(source)
                .progress(&progress)
                .to_file(path, budget)
        });
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
        report.map(Some).map_err(|e| describe(path, e, 0))
    }

    /// The build of `source` out of core: cells of the default split depth, the spill folder of
    /// `--temp-dir`.
    pub fn builder<'s, const K: usize, S: RaySource<K>>(&self, source: &'s S) -> Builder<'s, K, S> {
        let mut builder = Builder::new(source);
        if let Some(frame) = self.frame {
            builder = builder.world_frame(frame);
        }
        match &self.args.temp_dir {
            Some(dir) => builder.temp_dir(dir),
            None => builder,
        }
    }
}

impl Built {
    /// `OUT: K = k, L = l, [R rays, ]V voxels -> N nodes (F full, E empty, P partial)`, with the number
    /// of rays if the command knows it.
    pub fn summary(&self, rays: Option<u64>) -> String {
        let c = LevelCounts::total(self.level, &self.counts);
        format!(
            "{}: K = {}, L = {}, {}{} voxels -> {} nodes ({} full, {} empty, {} partial)",
            self.out.display(),
            self.k,
            self.level,
            rays.map(|r| format!("{r} rays, ")).unwrap_or_default(),
            crate::common::memory::voxels(self.k, self.level, &self.counts),
            c.nodes(),
            c.full,
            c.empty,
            c.partial
        )
    }

    /// `OUT: K = k, L = l, R rays -> N nodes (F full, E empty, P partial), B bytes at 2 bits/node`.
    pub fn summary_with_size(&self, rays: u64) -> String {
        let c = LevelCounts::total(self.level, &self.counts);
        format!(
            "{}: K = {}, L = {}, {rays} rays -> {} nodes ({} full, {} empty, {} partial), {} bytes at 2 bits/node",
            self.out.display(),
            self.k,
            self.level,
            c.nodes(),
            c.full,
            c.empty,
            c.partial,
            c.nodes().div_ceil(4),
        )
    }
}

/// The error of a failed out-of-core build of `out`, naming it once; `held` bytes were set apart from the
/// budget before the build (message buffers) and are added back to the budgets it names.
pub fn describe<E: std::error::Error + Send + Sync + 'static>(
    out: &Path,
    e: BuildError<E>,
    held: u64,
) -> CliError {
    match e {
        BuildError::BudgetTooSmall { budget, needed } => CliError::Failed(format!(
            "{}: {} (--max-memory)",
            out.display(),
            BuildError::<E>::BudgetTooSmall {
                budget: budget.saturating_add(held),
                needed: needed.saturating_add(held),
            }
        )),
        BuildError::Files(output @ SpillError::Output { .. }) => CliError::caused(output),
        other => CliError::in_file(out, other),
    }
}

/// Writes rays as text, or stacks them into a `.ktree` file ([`TreeOutput::write`], the rays held
/// counted against the budget), by the output's extension; returns the summary (empty on the ranks
/// other than 0 of an MPI run, which hold the rays whole but neither write nor print).
pub fn write_output<const K: usize>(
    rays: &RaySet<K>,
    out: &Path,
    build: &BuildArgs,
    frame: Option<WorldFrame>,
) -> CliResult<String> {
    if is_tree_file(out) {
        let held = ("the rays", crate::common::memory::ray_bytes(rays));
        let built = TreeOutput::new(out, build)
            .framed(frame)
            .write(rays, Some(held))?;
        return Ok(built
            .map(|b| b.summary(Some(rays.len() as u64)))
            .unwrap_or_default());
    }
    if !crate::distributed::ranks().is_root() {
        return Ok(String::new());
    }
    write_rays_file(out, rays).map_err(CliError::caused)?;
    Ok(format!(
        "{}: K = {K}, L = {}, {} rays, {} voxels",
        out.display(),
        rays.level(),
        rays.len(),
        rays.voxel_count()
    ))
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
