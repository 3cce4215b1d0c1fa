//! Which `.ktree` format version the commands that write trees use (`--format-version`, default 2).

use std::path::Path;
use std::sync::OnceLock;

use ktree::fs::write_atomic_with;
use ktree::io::{write_ktree_file, write_ktree_v1};
use ktree::KTree;

static VERSION: OnceLock<u16> = OnceLock::new();

/// The option, shared by every subcommand.
#[derive(Debug, clap::Args)]
pub struct FormatArgs {
    /// The `.ktree` format version written: 2 (a checksummed section per level; `stats` reads it through
    /// a memory map) or 1 (one body, for older readers).
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
/// Any I/O error, naming the path.
pub fn write<const K: usize>(path: &Path, tree: &KTree<K>) -> std::io::Result<()> {
    match version() {
        1 => write_atomic_with(path, |w| write_ktree_v1(w, tree)),
        _ => write_ktree_file(path, tree),
    }
}
