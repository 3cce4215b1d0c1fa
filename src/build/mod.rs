//! Building k-trees: Akman & Franklin's stacking (the fast path), and two reference builders for the
//! tests — naive voxel insertion into a pointer tree, and a dense bottom-up pyramid.

pub mod dense;
mod naive;
mod radix;
mod stacking;

pub use dense::DensePyramid;
pub use naive::{Dim, Fanout, NaiveTree};
pub use radix::radix_sort;
pub use stacking::{stack, stack_with_stats, StackingStats};
