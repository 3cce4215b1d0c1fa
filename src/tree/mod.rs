//! The compact k-tree: node states, the level-order `KTree<K>`, and assembling one from a depth-first
//! stream of nodes or from full cells.

mod assemble;
pub mod cursor;
mod error;
mod ktree;
mod states;

pub(crate) use assemble::LevelWriter;
pub use assemble::TreeAssembler;
pub use error::TreeError;
pub use ktree::{Bintree, KTree, LevelCounts, NodeRef, Octree, Quadtree, Tree4};
pub use states::{NodeState, PackedStates};
