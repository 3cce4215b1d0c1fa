//! What the subcommands share: worker threads, progress bars, the memory budget and out-of-core builds,
//! the `.ktree` format version written, and where outputs go.

pub mod args;
pub mod error;
pub mod memory;
pub mod output;
pub mod picture;
pub mod progress;
pub mod threads;
pub mod tree_file;
pub mod vector;
