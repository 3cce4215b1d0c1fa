//! Trees in and out of the commands: reading `.ktree` files, writing them in the format version asked for
//! (`--format-version`, default 2), and the one-line summary of a tree written.

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::Path;
use std::sync::OnceLock;

use ktree::fs::write_atomic_with;
use ktree::io::{read_ktree_file, read_ktree_file_framed, write_ktree_file_framed, Notes};
use ktree::io::{write_ktree_file, write_ktree_v1, write_ktree_v1_view, KtreeView};
use ktree::ops;
use ktree::space::WorldFrame;
use ktree::{AnyTree, KTree, LevelCounts};

static VERSION: OnceLock<u16> = OnceLock::new();

/// The option, shared by every subcommand.
#[derive(Debug, clap::Args)]
pub struct FormatArgs {
    /// The `.ktree` format version of the trees written, by the commands that write trees (the others
    /// ignore it): 2 (a checksummed section per level; `stats` reads it through a memory map) or 1 (one
    /// body, for older readers).
    #[arg(long, global = true, default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=2))]
    format_version: u16,
}

/// Records the version chosen on the command line.
pub fn set(args: &FormatArgs) {
    let _ = VERSION.set(args.format_version);
}

/// The format version chosen (2 unless set).
pub fn version() -> u16 {
    VERSION.get().copied().unwrap_or(2)
}

/// Writes a tree file atomically in the chosen format version.
///
/// # Errors
/// The file operation that failed, naming the path.
pub fn write_tree<const K: usize>(
    path: &Path,
    tree: &KTree<K>,
) -> Result<(), ktree::fs::FileOpError> {
    match version() {
        1 => write_atomic_with(path, |w| write_ktree_v1(w, tree)),
        _ => write_ktree_file(path, tree),
    }
}

/// Runs `build`, which writes a version 2 file at the path it is given, to write `out` in version 1: the
/// version 2 file is a hidden sibling of `out`, streamed into version 1 word by word through its memory map
/// ([`write_ktree_v1_view`]) by the process that wrote it (rank 0 of an MPI run), then removed. The build is
/// the same whatever the version: out of core, in the memory budget.
pub fn as_version_1<R>(
    out: &Path,
    build: impl FnOnce(&Path) -> CliResult<Option<R>>,
) -> CliResult<Option<R>> {
    let name = out
        .file_name()
        .map_or_else(|| "tree".into(), |n| n.to_string_lossy());
    let v2 = out.with_file_name(format!(".{name}.version-2.ktree"));
    let built = build(&v2)?;
    if built.is_some() {
        // This process wrote the version 2 file (the other ranks of an MPI run return `None` and leave it).
        let written = KtreeView::open(&v2)
            .map_err(CliError::caused)
            .and_then(|view| {
                write_atomic_with(out, |w| write_ktree_v1_view(w, &view)).map_err(CliError::caused)
            });
        let _ = std::fs::remove_file(&v2);
        written?;
    }
    Ok(built)
}

/// Reads a tree file, with the path in any error.
pub fn read(path: &Path) -> CliResult<AnyTree> {
    read_ktree_file(path).map_err(CliError::caused)
}

/// A tree read with the world frame and the notes its file keeps.
pub type Framed = (AnyTree, Option<WorldFrame>, Notes);

/// Reads a tree file with the world frame and notes it keeps (none in a version 1 file), with the path
/// in any error.
pub fn read_framed(path: &Path) -> CliResult<Framed> {
    read_ktree_file_framed(path).map_err(CliError::caused)
}

/// Writes a tree file and prints a one-line summary.
pub fn write<const K: usize>(path: &Path, tree: &KTree<K>) -> CliResult {
    write_framed(path, tree, None, &Notes::new())
}

/// Writes a tree file keeping a world frame and notes, and prints a one-line summary.
pub fn write_framed<const K: usize>(
    path: &Path,
    tree: &KTree<K>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> CliResult {
    write_tree_framed(path, tree, frame, notes).map_err(CliError::caused)?;
    print_summary(path, K, tree.level(), &tree.counts_per_level())
}

/// [`write_tree`] keeping a world frame and notes. A version 1 file keeps neither: a note on the standard
/// error says so when there were some.
///
/// # Errors
/// The file operation that failed, naming the path.
pub fn write_tree_framed<const K: usize>(
    path: &Path,
    tree: &KTree<K>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> Result<(), ktree::fs::FileOpError> {
    let kept = frame.is_some() || !notes.is_empty();
    if version() == 1 && kept {
        eprintln!(
            "note: {}: a version 1 file keeps no world frame and no notes (write version 2 to keep them)",
            path.display()
        );
    }
    if version() == 1 || !kept {
        write_tree(path, tree)
    } else {
        write_ktree_file_framed(path, tree, frame, notes)
    }
}

/// Prints the one-line summary of a tree written to `path`, from its counts per level.
pub fn print_summary(path: &Path, k: usize, level: u32, counts: &[LevelCounts]) -> CliResult {
    let c = LevelCounts::total(level, counts);
    let voxels = crate::common::memory::voxels(k, level, counts);
    outln!(
        "{}: K = {k}, L = {level}, {} nodes ({} full, {} empty, {} partial), {voxels} voxels",
        path.display(),
        c.nodes(),
        c.full,
        c.empty,
        c.partial,
    );
    Ok(())
}

/// The error of two input trees that cannot be combined, naming both.
pub fn pair_error(a: &Path, b: &Path, e: ops::OpsError) -> CliError {
    CliError::about(format!("{} and {}", a.display(), b.display()), e)
}

/// Where a tree's voxels are in the world, as `ktree stats` prints it.
pub fn frame_text(frame: &WorldFrame) -> String {
    format!(
        "voxels of {}, voxel 0 at {:?}",
        frame.voxel_size, frame.origin
    )
}
