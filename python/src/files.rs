//! Tree files in and out through the library's dispatch by extension (`ktree::io::read_tree` and
//! `ktree::io::write_tree` with their default options): `.ktree`, `.rays`, binvox, OctoMap `.bt` and OpenVDB
//! `.vdb`, meshes (voxelized when read; the tree's boundary when written, with `.glb` and `.svg`), VTK
//! files (`.vtu`, `.htg`) as outputs and volumes as inputs. Errors of the file system become `OSError`, the others
//! `ValueError`; an `OSError` is of the subclass its kind names (`FileNotFoundError`,
//! `PermissionError`, …) with `filename` set.

use std::path::Path;

use ktree::io::{ReadOptions, WriteOptions};
use ktree::AnyTree;

use crate::failure::Failure;

/// Reads a tree from a file of any format the library reads, chosen by extension.
pub(crate) fn read_tree(path: &Path) -> Result<AnyTree, Failure> {
    ktree::io::read_tree(path, &ReadOptions::default()).map_err(|e| Failure::of_error(&e, path))
}

/// Writes a tree atomically in the format its extension names.
pub(crate) fn write_tree(path: &Path, tree: &AnyTree) -> Result<(), Failure> {
    ktree::io::write_tree(path, tree, &WriteOptions::default())
        .map_err(|e| Failure::of_error(&e, path))
}
