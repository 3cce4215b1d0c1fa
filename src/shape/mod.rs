//! Shape operations on trees, for every `K`, exact (integer arithmetic): morphology with ball, box and cross
//! elements of any real radius ([`KTree::dilate`], [`KTree::erode`], [`KTree::opening`], [`KTree::closing`]),
//! connected components ([`KTree::components`]), the surface area ([`KTree::surface_area`]) and the Euler
//! number ([`KTree::euler_number`]). The definitions are `scipy.ndimage`'s and scikit-image's.
//!
//! Everything works on the tree's runs along the last axis ([`KTree::to_rays`]), never on a dense array.
//!
//! ```
//! use ktree::{rays::ball_rays, shape::Element, KTree};
//! let tree = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 4).unwrap());
//! let grown = tree.dilate(2.0, Element::Ball).unwrap();
//! assert_eq!(grown.erode(2.0, Element::Ball).unwrap().voxel_count(), tree.voxel_count());
//! assert_eq!(tree.components(1).unwrap().len(), 1);
//! ```
//!
//! [`KTree`]: crate::KTree
//! [`KTree::dilate`]: crate::KTree::dilate
//! [`KTree::erode`]: crate::KTree::erode
//! [`KTree::opening`]: crate::KTree::opening
//! [`KTree::closing`]: crate::KTree::closing
//! [`KTree::components`]: crate::KTree::components
//! [`KTree::surface_area`]: crate::KTree::surface_area
//! [`KTree::euler_number`]: crate::KTree::euler_number
//! [`KTree::to_rays`]: crate::KTree::to_rays

mod components;
pub mod distance;
mod element;
mod error;
mod euler;
mod morphology;
mod runs;
mod surface;

pub use components::Component;
pub use distance::NarrowBand;
pub use element::Element;
pub use error::ShapeError;
pub use morphology::BALL_BY_DISTANCE_FROM;
