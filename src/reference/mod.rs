//! The reference builders the tests compare every fast path against: naive voxel insertion into a
//! pointer tree ([`NaiveTree`]) and a dense bottom-up pyramid ([`DensePyramid`]). Both are the simplest
//! correct constructions, not fast ones.
//!
//! ```
//! use ktree::reference::{DensePyramid, NaiveTree};
//! use ktree::{stacking::paper::stack, Ray, RaySet};
//! let rays = RaySet::<3>::from_rays(3, [Ray::new([1, 2, 0], 8), Ray::new([2, 2, 3], 5)]).unwrap();
//! let fast = stack(&rays);
//! assert_eq!(NaiveTree::from_rays(&rays).unwrap().to_tree(), fast);
//! assert_eq!(DensePyramid::from_rays(&rays).unwrap().to_tree(), fast);
//! ```

pub mod dense;
mod naive;

pub use dense::DensePyramid;
pub use naive::{Dim, Fanout, NaiveTree};
