//! Other tools' grid formats: binvox, OctoMap's `.bt` and OpenVDB's `.vdb`, all octrees, placed in a ktree
//! universe by a shared [`GridPlacement`] (ktree voxel = grid index + offset) with their world metadata
//! ([`GridMeta`]).

mod binvox;
mod blosc;
mod grid;
mod octomap;
mod vdb;
mod vdb_level_set;
mod vdb_values;

pub use binvox::{read_binvox, write_binvox, BINVOX_MAX_DIM};
pub use grid::{GridFileError, GridFileErrorKind, GridMeta, GridPlacement, PlacedTree};
pub use octomap::{read_bt, write_bt, BT_DEPTH, BT_HEADER};
pub use vdb::{read_vdb, write_vdb};
pub use vdb_level_set::write_vdb_level_set;
