//! The arguments several commands share, defined once and flattened into each command
//! (`#[command(flatten)]`): `--out`, `--threads` and the volume's `--threshold`/`--label`. The build
//! options (`--threads`, `--max-memory`, `--temp-dir`, `--progress`) are [`crate::common::memory::BuildArgs`];
//! vectors are parsed by [`crate::common::vector`].

use std::path::PathBuf;

use ktree::solid::volume::Select;

/// `--threads N`: the worker threads of a command that stacks or combines trees.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct ThreadsArg {
    /// Worker threads (default: all cores). The output is the same for any number.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}

/// `--out FILE` of a command that makes rays or a tree, by the name's extension.
#[derive(Debug, Clone, clap::Args)]
pub struct RaysOrTreeOut {
    /// Output: rays in the text format, or a tree if the name ends in .ktree (written to a temporary file,
    /// then renamed).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// `--out FILE` of a command that writes a tree.
#[derive(Debug, Clone, clap::Args)]
pub struct TreeOut {
    /// The tree file to write (written to a temporary file, then renamed).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// `--threshold T | --label V`: which samples of a volume are inside.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct VolumeArgs {
    /// Volume: samples with value ≥ this are inside.
    #[arg(long, conflicts_with = "label", allow_negative_numbers = true)]
    pub threshold: Option<f64>,
    /// Volume: samples equal to this label are inside.
    #[arg(long, allow_negative_numbers = true)]
    pub label: Option<f64>,
}

impl VolumeArgs {
    /// The selection asked for, if any.
    pub fn select(&self) -> Option<Select> {
        match (self.threshold, self.label) {
            (Some(t), _) => Some(Select::AtLeast(t)),
            (None, Some(l)) => Some(Select::Label(l)),
            (None, None) => None,
        }
    }
}
