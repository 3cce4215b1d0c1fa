//! Other tools' grid formats: binvox, OctoMap's `.bt` and OpenVDB's `.vdb`, all octrees, and NIfTI volumes out, placed in a ktree
//! universe by a shared [`GridPlacement`] (ktree voxel = grid index + offset) with their world metadata
//! ([`GridMeta`]).
//!
//! # OpenVDB level sets
//! [`write_vdb_level_set`] writes an octree's narrow band of signed distances as a level set, and
//! [`read_vdb`] reads a level set (a `FloatGrid` or `DoubleGrid` of class `level set`, OpenVDB's or
//! ktree's) as its interior: every voxel of a leaf, tile of an internal node and tile of the root whose value
//! is below zero, active or not — a level set stores only a narrow band as active voxels, and its deep
//! interior as inactive tiles and voxels of value −background. The threshold is OpenVDB's
//! `tools::sdfInteriorMask`'s: `min(0, background − ε)` (ε = 10⁻⁸ for floats, 10⁻¹⁵ for doubles), 0 for a
//! valid level set. Where the two differ: `sdfInteriorMask` builds its mask from the leaves holding an
//! interior voxel and then fills the tiles of the internal nodes it made, so it leaves out root tiles (whole
//! 4096³ blocks inside, which `ktree distance` writes for universes of level 13 and more) and internal nodes
//! with inside tiles but no inside leaf voxel; ktree takes every tile below zero. For the level sets OpenVDB
//! and ktree write below 4096³ the two are the same voxel for voxel (checked by the tests against
//! `sdfInteriorMask`). A level set written by ktree carries its universe's level and offset as metadata, so
//! that reading it gives back the tree it was written from.

mod binvox;
mod grid;
#[cfg(feature = "volume")]
mod nifti;
mod octomap;
mod octomap_map;
mod vdb;

pub use binvox::{read_binvox, write_binvox, BINVOX_MAX_DIM};
pub use grid::{
    max_grid_nodes, GridFileError, GridFileErrorKind, GridMeta, GridPlacement, PlacedTree,
};
#[cfg(feature = "volume")]
pub use nifti::{write_nifti_file, NiftiWriteError};
pub use octomap::{read_bt, write_bt, BT_DEPTH, BT_HEADER};
pub use octomap_map::{
    read_bt_map, read_color_ot_map, read_ot_map, read_ot_map_with_colours, write_bt_map,
    write_color_ot_map, write_ot_map, OT_HEADER,
};
pub use vdb::{
    read_vdb, read_vdb_values, read_vdb_values_within, read_vdb_within, vdb_holds_values,
    write_any_valued_vdb, write_vdb, write_vdb_level_set, write_vdb_values, PlacedValues,
};
