//! Files in and out: the ray text format, the `.ktree` tree format (2 bits a node, checksummed; version 2 in
//! word-aligned sections per level, streamed out and memory-mapped in), atomic
//! writes, and trees and ray sets whose dimension is read from the file ([`AnyTree`], [`AnyRaySet`]).
//! [`read_tree`] and [`write_tree`] choose among every format by extension, the grid formats of other tools
//! included: binvox, OctoMap `.bt` and OpenVDB `.vdb`.
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
mod binvox;
mod formats;
mod grid;
mod ktree_file;
mod ktree_v2;
mod mapped_tree;
#[allow(unsafe_code)]
mod mmap;
mod octomap_bt;
mod rays_source;
mod rays_text;
mod vdb;

pub use any::TreeStats;
pub use any::{AnyRaySet, AnyTree};
pub(crate) use atomic::spill_folder;
pub use atomic::{write_atomic, write_atomic_with};
pub use binvox::{read_binvox, write_binvox, BINVOX_MAX_DIM};
pub use formats::{
    read_tree, read_tree_placed, voxelize, write_tree, Format, IoError, ReadOptions, ReadTree,
    Voxelized, WriteOptions,
};
#[cfg(any(feature = "mesh", feature = "volume"))]
pub use formats::{voxel_source, VoxelSource, VoxelizedSource};
pub use grid::{tree_rays, GridFileError, GridFileErrorKind, GridMeta, GridPlacement, PlacedTree};
pub use ktree_file::{
    read_ktree, read_ktree_any, read_ktree_file, write_ktree, write_ktree_file, KtreeFileError,
    KtreeFileErrorKind, MAGIC, VERSION,
};
pub use ktree_v2::{
    ktree_file_version, write_ktree_v2, write_ktree_v2_file, KtreeView, KtreeWriter,
    VERSION as VERSION_2,
};
pub(crate) use ktree_v2::{slots_mask, WordPacker, LOW_BITS, NODES_PER_WORD};
pub use mapped_tree::MappedTree;
pub use octomap_bt::{read_bt, write_bt, BT_DEPTH, BT_HEADER};
pub use rays_source::{open_rays_file, AnyRaysFileSource, RaysFile, RaysFileSource};
pub use rays_text::{
    read_rays, read_rays_file, write_rays, write_rays_file, write_rays_source, RaysTextError,
    RaysTextErrorKind,
};
pub use vdb::{read_vdb, write_vdb};
