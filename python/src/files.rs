//! Tree files in and out through the library's dispatch by extension (`ktree::io::read_tree` and
//! `ktree::io::write_tree` with their default options): `.ktree`, `.rays`, binvox, OctoMap `.bt` and OpenVDB
//! `.vdb`, and meshes and volumes as inputs. Errors of the file system become `OSError`, the others
//! `ValueError`.

use std::path::Path;

use ktree::io::{
    AnyTree, IoError, KtreeFileErrorKind, RaysTextErrorKind, ReadOptions, WriteOptions,
};

use crate::failure::Failure;

fn failure(e: IoError) -> Failure {
    let os = match &e {
        IoError::Ktree(k) => matches!(k.kind, KtreeFileErrorKind::Io(_)),
        IoError::Rays(r) => matches!(r.kind, RaysTextErrorKind::Io(_)),
        IoError::Write(_) => true,
        _ => false,
    };
    if os {
        Failure::Os(e.to_string())
    } else {
        Failure::value(e)
    }
}

/// Reads a tree from a file of any format the library reads, chosen by extension.
pub(crate) fn read_tree(path: &Path) -> Result<AnyTree, Failure> {
    ktree::io::read_tree(path, &ReadOptions::default()).map_err(failure)
}

/// Writes a tree atomically in the format its extension names.
pub(crate) fn write_tree(path: &Path, tree: &AnyTree) -> Result<(), Failure> {
    ktree::io::write_tree(path, tree, &WriteOptions::default()).map_err(failure)
}
