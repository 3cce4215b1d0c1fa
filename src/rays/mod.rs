//! Objects as rays: `RaySet<K>` (sorted, disjoint runs along the last axis per column), the maximal rows
//! of a run, and the one toolkit every list of runs of the crate is handled with: the column keys
//! ([`ColumnKeys`], and [`SignedColumnKeys`] for columns past the universe), the columns of two lists side
//! by side ([`join_columns`]) and the one merge of two lists of runs by a truth table ([`merge_runs`],
//! [`TruthTable`], its [`stretches`]).
//!
//! ```
//! use ktree::{rays::maximal_rows, Ray, RaySet};
//! // One run in column x = 2 of a level-3 quadtree universe, covering z = 1 ..= 6.
//! let rays = RaySet::<2>::from_rays(3, [Ray::new([2, 1], 7)]).unwrap();
//! assert!(rays.contains([2, 6]) && !rays.contains([2, 7]));
//! assert_eq!(rays.voxel_count(), 6);
//! // Its maximal rows: the largest aligned pieces, (start, length).
//! let rows: Vec<_> = maximal_rows(1, 7).map(|r| (r.z, r.len())).collect();
//! assert_eq!(rows, [(1, 1), (2, 2), (4, 2), (6, 1)]);
//! ```

mod any;
mod ball;
pub mod column;
mod csg;
mod gather;
pub mod merge;
mod rayset;
mod rows;
pub mod source;
mod split;
pub mod valued;

pub use any::AnyRaySet;
pub use ball::ball_rays;
pub use column::{join_columns, ColumnJoin, ColumnKeys, SignedColumnKeys};
pub use csg::CsgError;
pub(crate) use gather::RunGatherer;
pub use merge::{joined, merge_runs, stretches, Cause, Joined, Stretch, Stretches, TruthTable};
pub use rayset::{ColumnGroups, Normal, Ray, RayError, RaySet};
pub use rows::{maximal_rows, MaximalRows, Row};
pub use source::{RaySource, SlabRuns};
pub use valued::{ValueRun, ValueRuns};
