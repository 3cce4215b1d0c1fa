//! Files in and out, one module per format:
//!
//! * [`ktree`](mod@ktree): ktree's own `.ktree` format, 2 bits a node and checksummed — version 2 (written,
//!   streamed out level by level and memory-mapped in: [`KtreeWriter`], [`KtreeView`], [`MappedTree`]) and
//!   version 1 (read); Booleans of files larger than memory ([`boolean_files`], [`complement_file`]);
//! * [`rays`](mod@rays): the ray text format;
//! * [`interop`]: other tools' grids — binvox, OctoMap `.bt`, OpenVDB `.vdb`;
//! * [`cloud`](mod@cloud) and [`mesh`](mod@mesh): point clouds (PLY, PCD, XYZ/CSV, LAS/LAZ) and triangle
//!   meshes (OBJ, STL, PLY) in ([`read_cloud`], [`read_mesh`]), one PLY reader for both;
//! * [`scan`](mod@scan): range scans for occupancy maps — OctoMap's scan graphs and logs, lists of point
//!   files with their poses ([`read_scans`]);
//! * [`read_tree`] and [`write_tree`] choose among all of them by the file's extension (meshes and NIfTI
//!   volumes written; meshes and volumes are read by voxelizing them, in [`crate::input`]).
//! * [`write_valued_tree`] writes a tree with values to the formats that keep them.
//!
//! Every output is written atomically ([`crate::fs`]).
//!
//! ```
//! use ktree::io::{read_ktree, read_rays, write_ktree, write_rays};
//! use ktree::{stacking::paper::stack, AnyRaySet, Ray, RaySet};
//! let rays = RaySet::<3>::from_rays(4, [Ray::new([1, 1, 2], 9)]).unwrap();
//! let mut text = Vec::new();
//! write_rays(&mut text, &rays).unwrap();
//! assert_eq!(read_rays(&text[..], "mem").unwrap(), AnyRaySet::K3(rays.clone()));
//! let tree = stack(&rays);
//! let mut bytes = Vec::new();
//! write_ktree(&mut bytes, &tree).unwrap();
//! assert_eq!(read_ktree::<3>(&bytes, "mem").unwrap(), tree);
//! ```

#[cfg(feature = "cloud")]
pub mod cloud;
mod dispatch;
mod file_tree;
#[cfg(any(feature = "cloud", feature = "mesh"))]
pub(crate) mod geometry_file;
pub mod interop;
pub mod ktree;
mod location;
#[cfg(feature = "mesh")]
pub mod mesh;
#[allow(unsafe_code)]
mod mmap;
mod out_of_core;
#[cfg(any(feature = "cloud", feature = "mesh"))]
mod ply;
pub mod rays;
#[cfg(any(feature = "cloud", feature = "mesh"))]
mod scalar;
#[cfg(feature = "cloud")]
pub mod scan;
pub(crate) mod spill;
mod write_values;

#[cfg(feature = "cloud")]
pub use cloud::{is_cloud_file, read_cloud, read_cloud_bytes, CLOUD_FORMATS};
#[cfg(any(feature = "cloud", feature = "mesh"))]
pub use geometry_file::{GeometryFileError, GeometryFileErrorKind};
#[cfg(feature = "mesh")]
pub use mesh::{read_mesh, read_mesh_bytes, read_obj_groups, read_obj_groups_bytes, MESH_FORMATS};
#[cfg(feature = "cloud")]
pub use scan::{
    read_scan_directory, read_scan_graph, read_scan_list, read_scan_log, read_scans, Pose, Scan,
    ScanNode,
};

pub(crate) use dispatch::{format_of, usage};
pub use dispatch::{
    read_tree, read_tree_placed, write_tree, Format, IoError, ReadOptions, ReadTree, WriteOptions,
};
pub use file_tree::FileTree;
pub use interop::{
    max_grid_nodes, read_binvox, read_bt, read_bt_map, read_color_ot_map, read_ot_map,
    read_ot_map_with_colours, read_vdb, read_vdb_values, read_vdb_values_within, read_vdb_within,
    vdb_holds_values, write_any_valued_vdb, write_binvox, write_bt, write_bt_map,
    write_color_ot_map, write_ot_map, write_vdb, write_vdb_level_set, write_vdb_values,
    GridFileError, GridFileErrorKind, GridMeta, GridPlacement, PlacedTree, PlacedValues,
    BINVOX_MAX_DIM, BT_DEPTH, BT_HEADER, OT_HEADER,
};
#[cfg(feature = "volume")]
pub use interop::{write_nifti_file, NiftiWriteError};
pub use ktree::v1::{write_ktree_v1, write_ktree_v1_view};
pub use ktree::{
    boolean_files, boolean_header, boolean_views, complement_file, ktree_file_version, read_ktree,
    read_ktree_any, read_ktree_file, read_ktree_file_framed, read_ktree_framed, write_ktree,
    write_ktree_file, write_ktree_file_framed, write_ktree_framed, AnyMappedTree, BooleanFileError,
    BooleanFileReport, KtreeFileError, KtreeFileErrorKind, KtreeView, KtreeWriter, MappedTree,
    Notes, ViewOperation, MAGIC, VERSION,
};
pub use location::{FileError, Location, Place, ProblemKind};
pub use out_of_core::{SpilledFiles, SpilledLevel};
pub use rays::{
    open_rays_file, read_rays, read_rays_file, write_rays, write_rays_file, write_rays_source,
    AnyRaysFileSource, RaysFile, RaysFileSource, RaysTextError, RaysTextErrorKind,
};
pub use write_values::{keeps_values, write_valued_tree, WrittenValues};
