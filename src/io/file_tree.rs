//! A tree from a file of any format, of the dimension the file names, over the storage that suits it: a
//! `.ktree` version 2 file read in place through its memory map, any other file read into memory.
//! [`with_tree!`](crate::with_tree) runs generic code over [`TreeStorage`](crate::tree::storage::TreeStorage)
//! on either, so a command never matches the dimension or the storage by hand.

use std::path::Path;

use super::dispatch::{read_tree, IoError, ReadOptions};
use super::ktree::{ktree_file_version, AnyMappedTree, VERSION};
use crate::tree::AnyTree;

/// A tree of a file: in memory, or read in place from a `.ktree` version 2 file.
///
/// ```
/// use ktree::query::Query;
/// use ktree::tree::StorageError;
/// use ktree::{io, with_tree, KTree};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_file(&path, &KTree::<2>::full(3).unwrap()).unwrap();
/// let file = io::FileTree::open(&path, &io::ReadOptions::default()).unwrap();
/// assert!(matches!(file, io::FileTree::Mapped(_)));
/// // Written once, generic over the storage and the dimension.
/// fn origin_inside<const K: usize, T: Query<K>>(tree: &T) -> Result<bool, StorageError> {
///     Ok(tree.contains([0; K]).map_err(Into::into)?)
/// }
/// // Compiled for each dimension and storage: `t` is a `&KTree<K>` or a `&MappedTree<K>`.
/// assert!(with_tree!(&file, t => origin_inside(t))?);
/// # Ok::<(), StorageError>(())
/// ```
#[derive(Debug, Clone)]
pub enum FileTree {
    /// Read into memory.
    Memory(AnyTree),
    /// Read in place through the file's memory map.
    Mapped(AnyMappedTree),
}

impl FileTree {
    /// The tree of the file `path`: a `.ktree` of the current version mapped in place (checked when
    /// opened), any other tree file read by [`read_tree`] with `options` (meshes and volumes, which are
    /// voxelized: [`crate::input::open_tree`]).
    ///
    /// # Errors
    /// As [`read_tree`].
    pub fn open(path: &Path, options: &ReadOptions) -> Result<Self, IoError> {
        if ktree_file_version(path).is_ok_and(|v| v == VERSION) {
            return Ok(Self::Mapped(AnyMappedTree::open(path)?));
        }
        Ok(Self::Memory(read_tree(path, options)?))
    }

    /// The dimension `K`.
    pub fn k(&self) -> usize {
        match self {
            Self::Memory(t) => t.k(),
            Self::Mapped(t) => t.k(),
        }
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        match self {
            Self::Memory(t) => t.level(),
            Self::Mapped(t) => t.level(),
        }
    }
}

/// Runs an expression on the tree inside a [`FileTree`](crate::io::FileTree) (or a reference to one):
/// `with_tree!(&file, t => body)`, with `t` a `&KTree<K>` or a `&MappedTree<K>`. The body is compiled
/// once per dimension and storage, so it is written once: usually a call of a function generic over
/// [`TreeStorage`](crate::tree::storage::TreeStorage) or [`Query`](crate::query::Query) (in the body
/// itself, a [`KTree`](crate::KTree)'s own methods, which cannot fail, come before the traits' of the same
/// names: call those by their path). The reads' errors convert into
/// [`StorageError`](crate::tree::StorageError).
#[macro_export]
macro_rules! with_tree {
    ($value:expr, $name:ident => $body:expr) => {
        match $value {
            $crate::io::FileTree::Memory(any) => $crate::with_dim!(any, AnyTree, $name => $body),
            $crate::io::FileTree::Mapped(any) => $crate::with_dim!(any, AnyMappedTree, $name => $body),
        }
    };
}
