//! Shape operations, for every `K`, exact (integer arithmetic), on any storage (a tree in memory or a
//! `.ktree` file read in place, through [`TreeStorage`](crate::tree::TreeStorage)): morphology with ball,
//! box and cross elements of any real radius ([`dilate`], [`erode`], [`opening`], [`closing`]), connected
//! components ([`components`]), the surface area ([`surface_area`]) and the Euler number
//! ([`euler_number`]), and signed distances ([`distance`]: [`signed_distance_at`],
//! [`signed_distance_window`], [`narrow_band`]). The definitions are `scipy.ndimage`'s and scikit-image's.
//! [`KTree`](crate::KTree) has each as a method of the same name.
//!
//! The morphology, the components and the Euler number work on the tree's runs along the last axis (the
//! one tree → runs, [`rays_of`](crate::tree::rays_of)), never on a dense array; the distances on dense
//! windows of blocks ([`dense_window`](crate::query::dense_window)); the surface area on the nodes alone.
//! A read that fails (a mapped file changed underneath) is [`ShapeError::Storage`].
//!
//! ```
//! use ktree::{rays::ball_rays, shape::{self, Element}, KTree};
//! let tree = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 4).unwrap());
//! let grown = shape::dilate(&tree, 2.0, Element::Ball).unwrap();
//! assert_eq!(grown.erode(2.0, Element::Ball).unwrap().voxel_count(), tree.voxel_count());
//! assert_eq!(shape::components(&tree, 1).unwrap().len(), 1);
//! ```

mod components;
pub mod distance;
mod element;
mod error;
mod euler;
mod input;
mod morphology;
mod runs;
mod surface;

pub use components::{component_sizes, components, largest_component, Component};
pub use distance::{
    dilate_ball_by_distance, erode_ball_by_distance, narrow_band, signed_distance_at,
    signed_distance_window, NarrowBand,
};
pub use element::Element;
pub use error::ShapeError;
pub use euler::euler_number;
pub use morphology::{closing, dilate, erode, opening, BALL_BY_DISTANCE_FROM};
pub use surface::{faces_per_axis, run_count, surface_area};
