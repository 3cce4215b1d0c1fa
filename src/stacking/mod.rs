//! Building a tree from rays. [`Builder`] is the one entry point, and [`KTree::from_rays`] runs it: the
//! universe is cut into cells stacked apart on all threads (by default each through a bitmap pyramid of
//! its voxels) and joined level by level — in memory ([`Builder::build`]) or out of core in bounded memory,
//! the subtrees spilled as they are stacked and the tree written level after level
//! ([`Builder::build_into`] any [`PieceStore`] and [`LevelOrderSink`]; [`Builder::to_file`] a `.ktree`
//! file through spill files, which `io` implements), also in parts that run apart, as the ranks of a
//! distributed run do ([`Builder::stack_part`], [`SpilledPart`]).
//!
//! Akman & Franklin's stacking itself — rays to maximal rows, combined and split through the
//! dimension-level lists — is in [`paper`], in memory, with the lists as files, and as a pipeline; the
//! builder can stack each cell with it ([`CellStacking::Lists`]). Every way builds the same tree, node for
//! node.
//!
//! ```
//! use ktree::{rays::ball_rays, reference::DensePyramid, stacking::Builder};
//! let ball = ball_rays::<3>(5, [32, 32, 32], 40).unwrap(); // radius 20 in a 32³ universe
//! let tree = Builder::new(&ball).build().unwrap();
//! assert_eq!(tree, DensePyramid::from_rays(&ball).unwrap().to_tree());
//! assert_eq!(tree.voxel_count(), ball.voxel_count());
//! ```
//!
//! # Out of core
//! ## How it runs
//! The cells of depth `m` are stacked slab by slab exactly as in [`Builder::build`],
//! but no finished subtree is kept: the levels `1, 2, …` of each partial cell's subtree are appended to
//! a [`PieceStore`] as one *piece* per level (word-aligned; slab after slab in the order they finish,
//! each slab's cells in Morton order), and only a small index (the cell's Morton index and its node count
//! per level) and the states of the cells of depth `m` (see *Memory*) stay in memory. At the end the tree
//! is written level by level to a [`LevelOrderSink`]: the top levels `0 … m` (from the cells' states; a
//! uniform top collapses), then each level `m + j` as the concatenation, in Morton order of the cells, of
//! the subtrees' levels `j` read back from the store (the sink shifts each piece into place). The builder
//! knows nothing else of where the pieces wait and where the tree goes. [`Builder::to_file`] gives it
//! `io`'s spill files (one per level, see *Temporary files*) and the `.ktree` writer over a temporary
//! file renamed over the target, so the file's bytes are exactly those of the tree built in memory and
//! written by [`write_ktree`](crate::io::write_ktree), for any number of threads.
//!
//! ## In parts
//! The two phases also run apart, as the ranks of a distributed run do: [`Builder::stack_part`] stacks some of the
//! slabs (a share cut by [`balanced_parts`] from the costs [`Builder::slab_cost`] estimates) into spill files of its
//! own; one part takes the others' indexes ([`SpilledPart::index_words`], [`SpilledPart::add_part`]: the
//! cells' states and the stacked cells' Morton indexes and node counts) and writes the file
//! ([`SpilledPart::write`]), walking the stacked cells of all parts in Morton order and taking each
//! piece from its own spill files or from the stream of words the owning part sends in its own Morton
//! order ([`SpilledPart::stream_levels`]). The bytes are those of [`Builder::to_file`], which is one part
//! of every slab. ([`Builder::stack_part_into`] and [`SpilledPart::write_into`] do the same with any store
//! and sink.)
//!
//! ## Memory
//! The budget (`max_memory` of [`Builder::to_file`]) is kept by accounting, not by measuring the process:
//! 64 bytes per run of each slab being stacked (its copies and the subtrees made from it, until
//! they are spilled), 48 bytes per block of the full cells of depth `m` — kept reduced, as the top of the
//! tree is: `2^K` full siblings are one block of their parent, so a solid's interior costs a few blocks,
//! not one entry per cell — 24 plus 8 per level for each stacked cell, and the I/O buffers (64 KiB per
//! level of spilled pieces, one for the output, one for reading back). A budget below the buffers fails
//! before any slab is made. The first slab runs alone; then rounds of up to as many slabs as the rayon pool has
//! threads run at once, as many as the largest slab seen so far allows in what is left of the budget; a
//! slab whose rays turn out not to fit beside those already admitted is set aside (its rays dropped) for
//! the next round. Only these rays, made before their size is known, are held beyond the accounted
//! figure. A slab that does not fit even alone ends the build at once with
//! [`BuildError::BudgetTooSmall`], naming what is known to be needed then (what is held plus the
//! largest slab seen): a build given it gets at least as far, and a later, larger slab may ask for more.
//! When the stacking ends, the index of the stacked cells is checked against the budget; the budget it
//! names then (what the build holds at its end plus its largest slab) is enough for the whole build.
//!
//! ## Temporary files
//! (Of [`Builder::to_file`] and [`Builder::stack_part`].) The spill files live in a hidden folder `.NAME.XXXXXX.PID.ktree-spill` in [`Builder::temp_dir`] (by
//! default the output's folder), removed when the build ends, whether it succeeds or fails; a process
//! killed mid-build leaves it behind, and the next build of the same output removes the folders of
//! processes that no longer run.
//!
//! **Disk.** The spill files hold what the levels below `m` will take in the output, so a build holds about
//! twice the output's size if the files are kept to the end. They are not: the pieces read back into the
//! output are punched out of their spill file (`fallocate` with `FALLOC_FL_PUNCH_HOLE`, on Linux), a block
//! once every piece in it is read, in holes of at least 256 KiB, and each spill file is emptied once its
//! level is written. As each slab's part of a file is in Morton order, the order it is read in, its blocks
//! go back nearly as fast as the output grows: the build needs about the output's size of disk, plus up
//! to 256 KiB per slab (the column *disk peak* of `results/performance/scale-large.md`). On other
//! systems or file systems without holes the spill files keep their blocks until their level is written.
//!
//! ```
//! use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
//! use ktree::stacking::Builder;
//! let ball = Solid::Quadric(Quadric::<3>::ball([Rational::int(16); 3], Rational::int(11), Frame::Voxel).unwrap());
//! let source = SolidSource::new(&ball, 5, Sample::Centre).unwrap();
//! let dir = tempfile::tempdir().unwrap();
//! let out = dir.path().join("ball.ktree");
//! let builder = Builder::new(&source).split_depth(2);
//! let report = builder.to_file(&out, 1 << 30).unwrap();
//! let tree = builder.build().unwrap();
//! assert_eq!(ktree::io::read_ktree_file(&out).unwrap(), ktree::AnyTree::K3(tree.clone()));
//! assert_eq!(report.counts_per_level, tree.counts_per_level());
//! ```
//!
//! [`KTree::from_rays`]: crate::KTree::from_rays

mod any;
mod bitmap;
mod builder;
mod cells;
mod dense_values;
mod out_of_core;
pub mod paper;
mod partition;
// The one instruction that is `unsafe` to call here: a hint to the cache, see its SAFETY comment.
#[allow(unsafe_code)]
mod prefetch;
mod solids;
mod value_parts;
mod value_run_slabs;
mod value_slabs;
mod value_spill;
mod values;

pub use builder::{Builder, CellStacking};
pub(crate) use out_of_core::BUFFER_BYTES;
pub use out_of_core::{
    balanced_parts, BuildError, LevelOrderSink, LevelPieces, OutOfCoreReport, PieceStore, Progress,
    SpilledPart, Stage, StoredPieces, MAX_PARTS,
};
pub use partition::default_split_depth;
pub use value_parts::ValuePart;
pub use value_slabs::ValueSlabs;
pub use value_spill::{ValueSlabsReport, ValuedLevelSink};
