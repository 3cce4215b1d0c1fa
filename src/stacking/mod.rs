//! Akman & Franklin's stacking: the fast path from a [`RaySet`](crate::RaySet) to the minimal reduced
//! [`KTree`](crate::KTree), through maximal rows and the dimension-level lists — in memory ([`stack`]), with
//! the lists as sequential disk files ([`stack_with_file_lists`]), or as a pipeline of one thread per stage
//! ([`stack_pipelined`]); all three build the same tree from the same combine and split steps.

mod pipeline;
mod radix;
mod sequential;
mod stack;

pub use pipeline::stack_pipelined;
pub use radix::radix_sort;
pub use sequential::{stack_with_file_lists, FileListStats};
pub use stack::{stack, stack_with_stats, StackingStats};
