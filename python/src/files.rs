//! Tree files in and out, the format chosen by the file's extension.
//!
//! TO BE REPLACED by the library's dispatch over every format (`ktree::io::read_tree(path,
//! &ReadOptions::default())` and `ktree::io::write_tree(path, &tree, &WriteOptions::default())`, for
//! `.ktree`, `.rays`, `.binvox`, `.bt` and `.vdb`): until the library has it, this module reads and writes
//! the two formats the library has (`.ktree` and the ray text), and is the only place that chooses a
//! format.

use std::path::Path;

use ktree::io::{
    read_ktree_file, read_rays_file, write_ktree_file, write_rays_file, AnyTree,
    KtreeFileErrorKind, RaysTextErrorKind,
};
use ktree::with_dim;

use crate::failure::Failure;
use crate::rays::tree_rays;

/// The formats this module reads and writes, for error messages.
const FORMATS: &str = ".ktree or .rays";

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// Reads a tree: `.ktree` as is, `.rays` stacked.
pub(crate) fn read_tree(path: &Path) -> Result<AnyTree, Failure> {
    match extension(path).as_str() {
        "ktree" => read_ktree_file(path).map_err(|e| match e.kind {
            KtreeFileErrorKind::Io(_) => Failure::Os(e.to_string()),
            _ => Failure::value(e),
        }),
        "rays" => read_rays_file(path)
            .map(|rays| rays.stack())
            .map_err(|e| match e.kind {
                RaysTextErrorKind::Io(_) => Failure::Os(e.to_string()),
                _ => Failure::value(e),
            }),
        other => Err(Failure::Value(format!(
            "{}: cannot read files ending in '.{other}' (give {FORMATS})",
            path.display()
        ))),
    }
}

/// Writes a tree atomically: `.ktree` as is, `.rays` as the runs of its voxels along the last axis.
pub(crate) fn write_tree(path: &Path, tree: &AnyTree) -> Result<(), Failure> {
    let written = match extension(path).as_str() {
        "ktree" => with_dim!(tree, AnyTree, t => write_ktree_file(path, t)),
        "rays" => with_dim!(tree, AnyTree, t => write_rays_file(path, &tree_rays(t)?)),
        other => {
            return Err(Failure::Value(format!(
                "{}: cannot write files ending in '.{other}' (give {FORMATS})",
                path.display()
            )))
        }
    };
    written.map_err(|e| Failure::Os(format!("cannot write {}: {e}", path.display())))
}
