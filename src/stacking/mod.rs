//! Akman & Franklin's stacking: the fast path from a [`RaySet`](crate::RaySet) to the minimal reduced
//! [`KTree`](crate::KTree), through maximal rows and the dimension-level lists.

mod distribute;
mod partition;
mod radix;
mod stack;

pub use distribute::{balanced_slabs, join_parts, slab_rays};
pub use partition::{
    default_split_depth, join_subtrees, stack_partitioned, stack_source, RaySource, SlabRuns,
};
pub use radix::radix_sort;
pub use stack::{stack, stack_with_stats, StackingStats};
