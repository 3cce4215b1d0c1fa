//! The compact k-tree: node states, the level-order `KTree<K>`, assembling one from a depth-first stream of
//! nodes or from full cells.
//!
//! ```
//! use ktree::{stacking::paper::stack, NodeState, Ray, RaySet};
//! // The lower half (z < 4) of column x = 0 of an 8 × 8 quadtree universe.
//! let tree = stack(&RaySet::<2>::from_rays(3, [Ray::new([0, 0], 4)]).unwrap());
//! assert_eq!(tree.root_state(), NodeState::Partial);
//! assert_eq!(tree.voxel_count(), 4);
//! assert!(tree.contains([0, 3]) && !tree.contains([1, 3]));
//! assert_eq!(tree.bytes_at_two_bits(), tree.node_count().div_ceil(4));
//! let children: Vec<_> = tree.children(&tree.root()).map(|c| c.state()).collect();
//! assert_eq!(children.len(), 4);
//! ```

mod any;
mod any_valued;
mod assemble;
pub mod cursor;
mod error;
mod ktree;
pub mod locate;
pub mod sink;
mod states;
pub mod storage;
mod to_rays;
pub mod top_down;
/// The values a voxel can hold (defined below the tree, in [`crate::value`]).
pub use crate::value;
pub mod valued;
pub(crate) mod words;

pub use any::{AnyTree, DimensionMismatch};
pub use any_valued::AnyValuedTree;
pub(crate) use assemble::{LevelWriter, TreeAssembler};
pub use cursor::Leaves;
pub use error::{StorageError, TreeError};
pub use ktree::{
    heap_bytes_for_levels, voxels_of_levels, Bintree, KTree, LevelCounts, NodeRef, Octree,
    Quadtree, Tree4,
};
pub use states::{NodeState, PackedStates};
pub use storage::TreeStorage;
pub use to_rays::rays_of;
pub use value::{Dtype, Rgb, Value};
pub use valued::{ValueState, ValueStorage};
