//! What can be wrong with a tree given from outside the crate.

use thiserror::Error;

use super::NodeState;
use crate::space::SpaceError;

/// Why raw levels, words or cells do not make a well-formed tree.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum TreeError {
    /// The universe level is out of range.
    #[error(transparent)]
    Space(#[from] SpaceError),
    /// The number of words does not match the number of nodes.
    #[error("{words} words cannot hold exactly {len} nodes (2 bits each, 32 a word)")]
    WordCount {
        /// Words given.
        words: usize,
        /// Nodes asked for.
        len: usize,
    },
    /// A slot holds the unused code `11`.
    #[error("node {node} has the unused code 11")]
    UnusedCode {
        /// The node's index in its level.
        node: usize,
    },
    /// Bits beyond the last node of a level are set.
    #[error("bits after node {len} are set")]
    StrayBits {
        /// The number of nodes.
        len: usize,
    },
    /// Level 0 does not hold exactly one node, the root.
    #[error("level 0 must hold exactly the root, not {nodes} nodes")]
    Root {
        /// Nodes at level 0.
        nodes: usize,
    },
    /// More levels than the universe has.
    #[error("{levels} levels stored for a level-{level} universe")]
    TooDeep {
        /// Levels given.
        levels: usize,
        /// The universe level.
        level: u32,
    },
    /// A level's size is not `2^K` times the partial nodes above it.
    #[error("level {depth} has {partial} partial nodes but level {} has {next} nodes", depth + 1)]
    LevelSize {
        /// The level above.
        depth: usize,
        /// Its partial nodes.
        partial: usize,
        /// Nodes of the level below.
        next: usize,
    },
    /// A partial node at the voxel level (a voxel has no children).
    #[error("partial nodes at the voxel level {depth}")]
    PartialVoxel {
        /// The level.
        depth: usize,
    },
    /// A partial node whose children are all full or all empty.
    #[error(
        "not reduced: the children of partial node {index} of level {depth} are all {state:?}"
    )]
    NotReduced {
        /// The partial node's level.
        depth: usize,
        /// Its index among the partial nodes of that level.
        index: usize,
        /// The children's common state.
        state: NodeState,
    },
    /// A valued tree's node with children whose children could be one leaf (all empty, or all full of one
    /// value), or whose code does not fit its children (a partial node all of whose voxels hold values, a
    /// mixed node with an empty voxel).
    #[error("not minimal: node {index} of level {depth} does not fit its children")]
    NotMinimal {
        /// The node's level.
        depth: usize,
        /// Its index in the level.
        index: usize,
    },
    /// A level of a valued tree holds another number of values than of full nodes.
    #[error("level {depth} has {full} full nodes but {values} values")]
    ValueCount {
        /// The level.
        depth: usize,
        /// Its full nodes.
        full: usize,
        /// Its values.
        values: usize,
    },
    /// A value no voxel may hold.
    #[error(transparent)]
    Value(crate::value::ValueError),
    /// A cell belongs to a universe of another level.
    #[error("cell {index} belongs to a level-{found} universe, not level {expected}")]
    CellUniverse {
        /// The cell's position in the input.
        index: usize,
        /// The universe level expected.
        expected: u32,
        /// The cell's universe level.
        found: u32,
    },
    /// Cells are not in Morton order or overlap.
    #[error("cell {index} overlaps or precedes the cell before it in Morton order")]
    CellOrder {
        /// The cell's position in the input.
        index: usize,
    },
}

/// Why a read of a stored tree failed: a tree read in place from a file found the file changed since it
/// was opened (the error names the file and a byte offset inside it). A tree in memory never fails; its
/// read error is [`Infallible`](std::convert::Infallible), which converts into this one.
///
/// Every operation that reads a tree through [`TreeStorage`](super::TreeStorage) and has errors of its
/// own keeps a storage error as a variant whose source is this one.
///
/// ```
/// use ktree::tree::StorageError;
/// let e = StorageError::new(std::io::Error::other("map.ktree: byte 64: the file changed"));
/// assert_eq!(e.to_string(), "map.ktree: byte 64: the file changed");
/// assert!(e.downcast_ref::<std::io::Error>().is_some());
/// ```
#[derive(Debug)]
pub struct StorageError(Box<dyn std::error::Error + Send + Sync + 'static>);

/// The storage's own error, shown as it is (its source is the storage error's source).
impl std::fmt::Display for StorageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for StorageError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

impl StorageError {
    /// A storage's read error.
    pub fn new(error: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self(Box::new(error))
    }

    /// The storage's own error, if it is an `E`.
    pub fn downcast_ref<E: std::error::Error + 'static>(&self) -> Option<&E> {
        self.0.downcast_ref::<E>()
    }
}

impl From<std::convert::Infallible> for StorageError {
    fn from(never: std::convert::Infallible) -> Self {
        match never {}
    }
}
