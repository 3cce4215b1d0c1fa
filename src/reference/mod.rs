//! The reference builders the tests compare every fast path against: naive voxel insertion into a
//! pointer tree ([`NaiveTree`]) and a dense bottom-up pyramid ([`DensePyramid`]). Both are the simplest
//! correct constructions, not fast ones.

pub mod dense;
mod naive;

pub use dense::DensePyramid;
pub use naive::{Dim, Fanout, NaiveTree};
