//! Akman & Franklin's stacking: the fast path from a [`RaySet`](crate::RaySet) to the minimal reduced
//! [`KTree`](crate::KTree), through maximal rows and the dimension-level lists; and the same tree built
//! cell by cell ([`stack_partitioned`], [`stack_source`]): cache-sized subtrees on all threads, joined level
//! by level.

mod partition;
mod radix;
mod stack;

pub use partition::{
    default_split_depth, join_subtrees, stack_partitioned, stack_source, RaySource, SlabRuns,
};
pub use radix::radix_sort;
pub use stack::{stack, stack_with_stats, StackingStats};
