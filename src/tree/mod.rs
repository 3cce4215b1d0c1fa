//! The compact k-tree: node states, the level-order `KTree<K>`, assembling one from a depth-first stream of
//! nodes or from full cells, and its Boolean operators.

mod assemble;
mod error;
mod ktree;
mod operators;
mod states;

pub(crate) use assemble::TreeAssembler;
pub use error::TreeError;
pub use ktree::{heap_bytes_for_levels, Bintree, KTree, Leaves, LevelCounts, NodeRef, Octree, Quadtree, Tree4};
pub use states::{NodeState, PackedStates};
