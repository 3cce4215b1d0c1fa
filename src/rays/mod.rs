//! Objects as rays: `RaySet<K>` (sorted, disjoint runs along the last axis per column) and the maximal rows
//! of a run.

mod ball;
mod csg;
mod rayset;
mod rows;
mod split;

pub use ball::ball_rays;
pub use csg::CsgError;
pub use rayset::{ColumnGroups, Normal, Ray, RayError, RaySet};
pub use rows::{maximal_rows, MaximalRows, Row};
