//! What [`KTree::check`](super::KTree::check) finds wrong with a tree.

use thiserror::Error;

use super::NodeState;

/// A broken invariant of a level-order tree: the first one [`KTree::check`](super::KTree::check) finds.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum TreeError {
    /// Level 0 does not hold exactly one node, the root.
    #[error("level 0 must hold exactly the root")]
    NoRoot,
    /// More levels are stored than a universe of this level has.
    #[error("{levels} levels stored for a level-{level} universe")]
    TooManyLevels {
        /// Levels stored.
        levels: usize,
        /// The universe level.
        level: u32,
    },
    /// A level's size is not `2^K` times the partial nodes of the level above.
    #[error("level {depth} has {partial} partial nodes but level {} has {next} nodes", depth + 1)]
    LevelSize {
        /// The level above.
        depth: usize,
        /// Its partial nodes.
        partial: usize,
        /// The nodes of the level below.
        next: usize,
    },
    /// A partial node at the voxel level, where nodes cannot be split.
    #[error("partial nodes at the voxel level {depth}")]
    PartialAtVoxelLevel {
        /// The voxel level.
        depth: usize,
    },
    /// A partial node whose children are all the same leaf: the tree is not reduced.
    #[error(
        "not reduced: the children of partial node {parent} of level {depth} are all {state:?}"
    )]
    NotReduced {
        /// The parent's level.
        depth: usize,
        /// The parent's rank among the partial nodes of its level.
        parent: usize,
        /// The children's common state.
        state: NodeState,
    },
}
