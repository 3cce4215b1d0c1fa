//! Akman & Franklin's stacking: the fast path from a [`RaySet`](crate::RaySet) to the minimal reduced
//! [`KTree`](crate::KTree), through maximal rows and the dimension-level lists — in memory ([`stack`]), with
//! the lists as sequential disk files ([`stack_with_file_lists`]), or as a pipeline of one thread per stage
//! ([`stack_pipelined`]); all three build the same tree from the same combine and split steps. The same
//! tree is also built cell by cell ([`stack_partitioned`], [`stack_source`]): cache-sized subtrees on all
//! threads, joined level by level; or out of core, straight to a `.ktree` file in bounded memory with the
//! subtrees spilled to temporary files ([`stack_to_file`]) — also in parts that run apart, as the ranks of
//! a distributed run do, each stacking its share of the slabs ([`balanced_parts`], [`stack_part`]) and one
//! writing the file from all of them ([`SpilledPart`]).
//!
//! ```
//! use ktree::{rays::ball_rays, reference::DensePyramid, stacking::stack_with_stats};
//! let ball = ball_rays::<3>(5, [32, 32, 32], 40).unwrap(); // radius 20 in a 32³ universe
//! let (tree, stats) = stack_with_stats(&ball);
//! assert_eq!(tree, DensePyramid::from_rays(&ball).unwrap().to_tree());
//! assert_eq!(stats.rays, ball.len() as u64);
//! assert_eq!(tree.voxel_count(), ball.voxel_count());
//! ```

mod any;
mod bitmap;
mod cells;
mod out_of_core;
mod partition;
mod pipeline;
mod radix;
mod sequential;
mod stack;

pub use bitmap::{stack_bitmap, MAX_BITMAP_VOXELS};
pub use out_of_core::{
    balanced_parts, build_slabs, slab_cost, stack_part, stack_to_file, OutOfCore, OutOfCoreError,
    OutOfCoreReport, Progress, SpilledPart, Stage, BUFFER_BYTES, MAX_PARTS, RUN_BYTES,
    SUBTREE_BYTES,
};
pub use partition::{
    default_split_depth, join_subtrees, stack_partitioned, stack_source, RaySource, SlabRuns,
};
pub use pipeline::stack_pipelined;
pub use radix::radix_sort;
pub use sequential::{stack_with_file_lists, FileListStats};
pub use stack::{stack, stack_with_stats, StackingStats};
