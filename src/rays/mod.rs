//! Objects as rays: `RaySet<K>` (sorted, disjoint runs along the last axis per column) and the maximal rows
//! of a run.
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
mod csg;
mod rayset;
mod rows;
pub mod source;
mod split;

pub use any::AnyRaySet;
pub use ball::ball_rays;
pub use csg::CsgError;
pub use rayset::{ColumnGroups, Normal, Ray, RayError, RaySet};
pub use rows::{maximal_rows, MaximalRows, Row};
pub use source::{RaySource, SlabRuns};
