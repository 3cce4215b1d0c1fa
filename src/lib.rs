//! # ktree — k-trees from rays, for any dimension
//!
//! Bintrees (K = 1), quadtrees (K = 2), octrees (K = 3) and 4-D time-space trees (K = 4) from one
//! const-generic code base, built by Akman & Franklin's *stacking* algorithm and checked against naive
//! references.
//!
//! ```text
//!  solids & data            1-D                 K-D
//!  ray file ──► RaySet<K> ─► maximal rows ─► stacking ─► KTree<K> ─► stats, .ktree files
//!               (z-runs per    (1-D trees)   (combine/split
//!                column)                      per dim & level)
//!  reference builders (tests): naive voxel insertion, dense pyramid ──► KTree<K>
//! ```
//!
//! * [`space`]: the universe (level `L`, side `U = 2^L`), aligned cells, Morton keys.
//! * [`rays`]: [`RaySet`], an object as sorted disjoint runs along the last axis, and maximal rows.
//! * [`stacking`]: [`stacking::stack`], Akman & Franklin's stacking.
//! * [`reference`](mod@reference): the reference builders the tests compare against (naive insertion, dense pyramid).
//! * [`solid`]: quadrics, boxes, triangle meshes and volumes to rays, exactly (with [`rays`] Boolean operations).
//! * [`tree`]: [`KTree`], level-order, 2 bits a node, navigable without pointers.
//! * [`io`]: files, one module per format — `.ktree` (version 2 written, streamed and memory-mapped; version 1
//!   read), the ray text, binvox, OctoMap `.bt`, OpenVDB `.vdb`.
//! * [`fs`]: atomic writes and spill folders, below everything that writes.
//! * [`ops`]: Meagher's operations — Booleans, translation, scaling, rotations, affine maps, interference,
//!   mass properties, complexity.
//! * [`query`]: questions asked of a map — batch point queries, boxes and counts, ray casting, the
//!   nearest full voxel — on trees in memory and on mapped files.
//! * [`display`]: hidden-surface images, line drawings with hidden lines removed, quadtree and 4-D pictures.
//!
//! # Layers
//! Each layer imports only those below it, with the exceptions listed after the picture:
//! ```text
//!  io/                files by format: .ktree (v1 read, v2 written and mapped), interop grids, ray text;
//!                     read_tree / write_tree by extension (meshes and volumes voxelized on the way in)
//!  ops/  display/     operations; Booleans are one merge visitor over the storage trait, into a level sink;
//!  query/             the questions asked of a map (points, boxes, rays, nearest), over the storage trait
//!  stacking/          the builders (the paper's list stacking; the partition, in memory or out of core)
//!  solid/             quadrics, meshes, volumes → rays, slab by slab
//!  tree/              KTree, AnyTree, the storage trait, the walks, the level sink, packed 2-bit words
//!  rays/   space   fs (atomic writes, spill folders)
//! ```
//! Not yet so: `KTree::from_rays` calls the builder (tree → stacking); the ray sources of `solid/` implement
//! `stacking::RaySource` (solid → stacking); the out-of-core builder and the streamed Booleans write their
//! output through `io::KtreeWriter` and read their inputs through `io::KtreeView` (stacking, ops → io).
//!
//! # Example
//! ```
//! use ktree::{stacking::stack, Ray, RaySet};
//! // Akman & Franklin's Fig. 3 ray in an octree universe of level 7.
//! let rays = RaySet::<3>::from_rays(7, [Ray::new([1, 1, 17], 93)]).unwrap();
//! let tree = stack(&rays);
//! tree.assert_well_formed();
//! assert_eq!(tree.voxel_count(), 76);
//! assert_eq!(tree.counts().full, 76); // a one-voxel-thick ray is all voxels in an octree
//! ```
#![deny(missing_docs)]
// The one exception, a read-only memory map, is `io::mmap` (allowed there, with its soundness argument).
#![deny(unsafe_code)]

pub mod display;
pub mod fs;
pub mod io;
pub mod ops;
pub mod query;
pub mod rays;
pub mod reference;
pub mod solid;
pub mod space;
pub mod stacking;
pub mod tree;

pub use rays::{AnyRaySet, Ray, RaySet};
pub use space::{max_level, Cell, Universe, MAX_K};
pub use tree::{AnyTree, KTree, LevelCounts, NodeState, Octree, Quadtree};
