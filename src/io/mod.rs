//! Files in and out: the ray text format, the `.ktree` tree format (2 bits a node, checksummed), atomic
//! writes, and trees and ray sets whose dimension is read from the file ([`AnyTree`], [`AnyRaySet`]).
//!
//! ```
//! use ktree::io::{read_ktree, read_rays, write_ktree, write_rays, AnyRaySet};
//! use ktree::{stacking::stack, Ray, RaySet};
//! let rays = RaySet::<3>::from_rays(4, [Ray::new([1, 1, 2], 9)]).unwrap();
//! let mut text = Vec::new();
//! write_rays(&mut text, &rays).unwrap();
//! assert_eq!(read_rays(&text[..], "mem").unwrap(), AnyRaySet::K3(rays.clone()));
//! let tree = stack(&rays);
//! let mut bytes = Vec::new();
//! write_ktree(&mut bytes, &tree).unwrap();
//! assert_eq!(read_ktree::<3>(&bytes, "mem").unwrap(), tree);
//! ```

mod any;
mod atomic;
mod ktree_file;
mod rays_text;

pub use any::{AnyRaySet, AnyTree};
pub use atomic::{write_atomic, write_atomic_with};
pub use ktree_file::{
    read_ktree, read_ktree_any, read_ktree_file, write_ktree, write_ktree_file, KtreeFileError,
    KtreeFileErrorKind, MAGIC, VERSION,
};
pub use rays_text::{
    read_rays, read_rays_file, write_rays, write_rays_file, RaysTextError, RaysTextErrorKind,
};
