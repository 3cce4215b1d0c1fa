//! Akman & Franklin's stacking: the fast path from a [`RaySet`](crate::RaySet) to the minimal reduced
//! [`KTree`](crate::KTree), through maximal rows and the dimension-level lists; and the same tree built
//! cell by cell ([`stack_partitioned`], [`stack_source`]): cache-sized subtrees on all threads, joined level
//! by level.
//!
//! ```
//! use ktree::{rays::ball_rays, reference::DensePyramid, stacking::stack_with_stats};
//! let ball = ball_rays::<3>(5, [32, 32, 32], 40).unwrap(); // radius 20 in a 32³ universe
//! let (tree, stats) = stack_with_stats(&ball);
//! assert_eq!(tree, DensePyramid::from_rays(&ball).unwrap().to_tree());
//! assert_eq!(stats.rays, ball.len() as u64);
//! assert_eq!(tree.voxel_count(), ball.voxel_count());
//! ```

mod partition;
mod radix;
mod stack;

pub use partition::{
    default_split_depth, join_subtrees, stack_partitioned, stack_source, RaySource, SlabRuns,
};
pub use radix::radix_sort;
pub use stack::{stack, stack_with_stats, StackingStats};
