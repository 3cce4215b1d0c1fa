//! # ktree — k-trees from rays, for any dimension
//!
//! Bintrees (K = 1), quadtrees (K = 2), octrees (K = 3) and 4-D time-space trees (K = 4) from one
//! const-generic code base, built from rays and checked against naive references. Two algorithms build the
//! same tree, node for node: by default [`stacking::Builder`] cuts the universe into cells of about 2^18
//! voxels, builds each cell the boundary passes through from a bitmap pyramid of its voxels on all threads,
//! and joins them level by level (in memory or out of core); Akman & Franklin's *stacking* — rays to
//! maximal rows, combined and split through the dimension-level lists — is [`stacking::paper`], which the
//! reproductions run and the builder can use per cell ([`stacking::CellStacking::Lists`]).
//!
//! ```text
//!  solids & data             cells, each a bitmap pyramid, on all threads ─► join by level ─┐
//!  ray file ──► RaySet<K> ─┤                                                                 ├─► KTree<K>
//!               (z-runs per └─► maximal rows ─► stacking (combine/split per dim & level) ────┘
//!                column)
//!  reference builders (tests): naive voxel insertion, dense pyramid ──► KTree<K>
//! ```
//!
//! * [`space`]: the universe (level `L`, side `U = 2^L`), aligned cells, Morton keys.
//! * [`rays`]: [`RaySet`], an object as sorted disjoint runs along the last axis, and maximal rows.
//! * [`stacking`]: building trees — [`stacking::Builder`], the one entry point ([`KTree::from_rays`] runs it:
//!   cells stacked apart on all threads, each through a bitmap pyramid by default, in memory or out of core
//!   to a file), and [`stacking::paper`], Akman & Franklin's stacking as the paper gives it.
//! * [`reference`](mod@reference): the reference builders the tests compare against (naive insertion, dense pyramid).
//! * [`solid`]: quadrics, boxes, triangle meshes and volumes to rays, exactly (with [`rays`] Boolean operations).
//! * [`tree`]: [`KTree`], level-order, 2 bits a node, navigable without pointers; with a value per voxel
//!   (`KTree<K, V>`: labels, colours, densities; [`tree::valued`]), minimal, the values of full nodes in
//!   level order beside the bits.
//! * [`io`]: files, one module per format — `.ktree` (version 2 written, streamed and memory-mapped; version 1
//!   read; version 3 for valued trees), the ray text, binvox, OctoMap `.bt`, OpenVDB `.vdb`, point clouds and meshes in — and the spill
//!   files of trees larger than memory (one level a file), which the out-of-core builder and the streamed
//!   Booleans both write.
//! * [`input`]: any input file as a tree — tree files read by [`io`], meshes and volumes voxelized by
//!   [`solid`] on the way in ([`input::read_tree`], [`input::voxelize`], slab by slab [`input::voxel_source`]).
//! * [`fs`]: atomic writes and spill folders, below everything that writes.
//! * [`ops`]: Meagher's operations — Booleans, translation, scaling, rotations, affine maps, interference,
//!   mass properties, complexity — on trees in memory and on mapped files, the trees they make written
//!   through a level sink (into memory, or level by level to files); and those of valued trees
//!   ([`ops::values`]: select, mask, combine, overlay, map, per-value statistics).
//! * [`map`]: occupancy maps from range scans — OctoMap's semantics (sensor model, keys, key traversal),
//!   log-odds in a valued tree, the occupied, free and unknown parts as trees, a map's plane for navigation.
//! * [`query`]: questions asked of a map — batch point queries, boxes and counts, ray casting, the
//!   nearest full voxel — on trees in memory and on mapped files.
//! * [`shape`]: morphology (dilate, erode, opening, closing), connected components, surface area and Euler number, on the runs;
//!   signed distance fields and narrow bands ([`shape::distance`]).
//! * [`display`]: hidden-surface images, line drawings with hidden lines removed, quadtree and 4-D pictures.
//! * [`export`]: the boundary out to the tools that look at surfaces and volumes — an octree as a closed
//!   triangle mesh (PLY, OBJ, STL, glTF), a quadtree as closed polylines (PLY, OBJ, SVG); any tree as an
//!   interactive 3-D view in one self-contained HTML page ([`export::view`]).
//!
//! # Layers
//! Each layer imports only those below it:
//! ```text
//!  input              any input file as a tree: tree files read by io, meshes and volumes voxelized by
//!                     solid (read_tree, read_tree_placed, open_tree; voxelize, voxel_source)
//!  io/                files by format (and OctoMap's map files, scans in: io::scan): .ktree (v1 read, v2 written and mapped, v3 with values), interop
//!                     grids, ray text, point clouds and meshes in (into solid/'s PointCloud and TriangleMesh);
//!                     read_tree / write_tree of tree files by extension (meshes written through export/,
//!                     volumes as NIfTI); spill files, one level a file, and the level
//!                     sink over them; the out-of-core builder's files (Builder::to_file); the Booleans
//!                     of files larger than memory (ops' merge, mapped inputs, spilled output)
//!  export/            boundaries as meshes and outlines, and their files (over display's neighbours);
//!                     the 3-D view page (over the storage trait and display's named views)
//!  display/           pictures, line drawings
//!  map/               occupancy maps from scans (over ops, query and the valued tree)
//!  ops/               operations over the storage trait, each tree made written through a level sink
//!  query/  shape/     questions asked of a map (points, boxes, rays, nearest), over the storage trait;
//!                     morphology, components, surface area, Euler number, on the runs
//!  stacking/          Builder (cells on all threads, in memory or out of core through a piece store and
//!                     a level-order sink; KTree::from_rays), paper/
//!  solid/             quadrics, meshes, volumes → rays, slab by slab
//!  tree/              KTree (binary, or with a value per voxel: tree::value, tree::valued), AnyTree, the
//!                     storage trait, the walks, the level sink, the top-down builder, packed 2-bit words
//!  rays/   space   fs (atomic writes, spill folders)   testing (the unit tests' seeded numbers)
//! ```
//! `verify/tests/layers.rs` fails on any upward import. The operators `|`, `&`, `-`,
//! `^`, `!` on trees are defined in `ops/`, beside the Booleans they call. The streamed Booleans of files
//! are one merge in `ops/` (`ops::boolean_into`, any two storages into any level sink); `io` opens the
//! files, spills the levels and writes the `.ktree` (`io::boolean_files`). The out-of-core builder writes
//! through its own traits, `stacking::PieceStore` and `stacking::LevelOrderSink`, which `io` implements with
//! spill files and the `.ktree` writer: `Builder::to_file` is defined in `io`. Ray sources implement
//! `rays::RaySource`, below every producer and consumer of rays. `KTree::from_rays` and `KTree::from_dense`
//! are defined beside their builders, in `stacking/` and `reference/`: the tree knows no builder.
//!
//! # Example
//! ```
//! use ktree::{stacking::paper::stack, Ray, RaySet};
//! // Akman & Franklin's Fig. 3 ray in an octree universe of level 7.
//! let rays = RaySet::<3>::from_rays(7, [Ray::new([1, 1, 17], 93)]).unwrap();
//! let tree = stack(&rays);
//! tree.assert_well_formed();
//! assert_eq!(tree.voxel_count(), 76);
//! assert_eq!(tree.counts().full, 76); // a one-voxel-thick ray is all voxels in an octree
//! ```
#![deny(missing_docs)]
// Two exceptions, each allowed in its own module with its soundness argument: a read-only memory map
// (`io::mmap`), and the vector instructions that step eight or four rays of a scan at once (`map::ray_lanes`).
#![deny(unsafe_code)]

#[macro_use]
mod dim;
pub mod display;
pub mod export;
pub mod fs;
pub mod input;
pub mod io;
pub mod map;
pub mod ops;
pub mod query;
pub(crate) mod radix;
pub mod rays;
pub mod reference;
pub mod shape;
pub mod solid;
pub mod space;
pub mod stacking;
#[cfg(test)]
mod testing;
pub mod tree;
pub mod value;

/// The traits every tree storage answers through, to `use ktree::prelude::*` at once: [`TreeStorage`]
/// (the reads) and [`Query`] (the questions of [`query`]), so that a `.ktree` file read in place
/// (`io::MappedTree`) answers the same calls as a tree in memory.
///
/// [`TreeStorage`]: crate::tree::storage::TreeStorage
/// [`Query`]: crate::query::Query
pub mod prelude {
    pub use crate::query::Query;
    pub use crate::tree::storage::TreeStorage;
}

pub use rays::{AnyRaySet, Ray, RaySet};
pub use space::{max_level, Cell, Universe, MAX_K};
pub use tree::{AnyTree, AnyValuedTree, KTree, LevelCounts, NodeState, Octree, Quadtree};
