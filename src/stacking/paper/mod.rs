//! Akman & Franklin's stacking, as the paper describes it: a ray set cut into maximal rows, combined and
//! split through the dimension-level lists ι(D, l) into the minimal reduced k-tree — single-threaded in
//! memory ([`stack`], [`stack_with_stats`]), with the lists as sequential disk files sorted in bounded
//! memory ([`stack_with_file_lists`]), or as a pipeline of one thread per stage ([`stack_pipelined`]). All
//! three run the same combine and split steps and build the same tree.
//!
//! These are the subject of the paper's reproductions and of the property tests that stacking equals
//! naive insertion. The fast path ([`Builder`](super::Builder), which [`KTree::from_rays`] runs) cuts
//! the universe into cells stacked apart on all threads, each by default through a bitmap pyramid
//! ([`CellStacking`](super::CellStacking)).
//!
//! ```
//! use ktree::{rays::ball_rays, reference::DensePyramid, stacking::paper::stack_with_stats};
//! let ball = ball_rays::<3>(5, [32, 32, 32], 40).unwrap(); // radius 20 in a 32³ universe
//! let (tree, stats) = stack_with_stats(&ball);
//! assert_eq!(tree, DensePyramid::from_rays(&ball).unwrap().to_tree());
//! assert_eq!(stats.rays, ball.len() as u64);
//! assert_eq!(tree.voxel_count(), ball.voxel_count());
//! ```
//!
//! [`KTree::from_rays`]: crate::KTree::from_rays

mod file_lists;
pub(crate) mod lists;
mod pipeline;

pub use file_lists::{stack_with_file_lists, FileListStats};
pub use lists::{stack, stack_with_stats, StackingStats};
pub use pipeline::stack_pipelined;
