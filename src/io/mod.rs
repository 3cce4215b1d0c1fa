//! Files in and out: the ray text format, the `.ktree` tree format (2 bits a node, checksummed), atomic
//! writes, and trees and ray sets whose dimension is read from the file ([`AnyTree`], [`AnyRaySet`]).

mod any;
mod atomic;
mod ktree_file;
mod rays_text;

pub use any::TreeStats;
pub use any::{AnyRaySet, AnyTree};
pub use atomic::{write_atomic, write_atomic_with};
pub use ktree_file::{
    read_ktree, read_ktree_any, read_ktree_file, write_ktree, write_ktree_file, KtreeFileError,
    KtreeFileErrorKind, MAGIC, VERSION,
};
pub use rays_text::{
    read_rays, read_rays_file, write_rays, write_rays_file, RaysTextError, RaysTextErrorKind,
};
