//! The one way to build a tree from rays: [`Builder`], in memory ([`Builder::build`]) or out of core in a
//! memory budget, the subtrees spilled to any [`PieceStore`] and the tree written to any
//! [`LevelOrderSink`] ([`Builder::build_into`]; `io` gives [`Builder::to_file`], to a `.ktree` file through
//! spill files), on all threads; and the constructors of [`KTree`] that build ([`KTree::from_rays`],
//! `From<&RaySet>`).
//!
//! # What runs
//! The universe is cut into its cells of depth `m` (the *split depth*, by default
//! [`default_split_depth`]: cells of about 2^18 voxels). A cell all of whose columns cross it entirely is
//! a full leaf and a cell no run meets an empty one; each remaining cell — one the object's boundary
//! passes through — is stacked apart, on the threads of the pool, by a bitmap pyramid of its voxels
//! ([`CellStacking::Bitmap`], the default) or by the paper's list stacking ([`CellStacking::Lists`]), and
//! the subtrees are joined level by level. Any split depth, any number of threads and either way of
//! stacking a cell give the same tree, node for node, as the paper's stacking of the whole set
//! ([`paper::stack`](super::paper::stack)). `results/performance/build.md` measures the two ways of
//! stacking a cell side by side.

use std::path::{Path, PathBuf};

use super::out_of_core::{
    build_slabs, slab_cost, stack_part, BuildError, LevelOrderSink, OutOfCore, OutOfCoreReport,
    PieceStore, Progress, SpilledPart, StoreBuildError,
};
use super::partition::{default_split_depth, stack_source};
use crate::rays::RaySet;
use crate::rays::RaySource;
use crate::space::WorldFrame;
use crate::tree::KTree;

/// How each cell the object's boundary passes through is stacked (the tree is the same either way).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum CellStacking {
    /// Through a bitmap pyramid of the cell's voxels: the cell's runs are painted into a bitmap of two
    /// bits a voxel, reduced level by level (the cell has at most 2^22 voxels; a larger one falls back
    /// to [`Lists`](Self::Lists)).
    #[default]
    Bitmap,
    /// By Akman & Franklin's stacking of the cell's rays through the dimension-level lists
    /// ([`paper::stack`](super::paper::stack)).
    Lists,
}

/// Builds the tree of a ray source (a [`RaySet`], a solid, a mesh, a volume or a ray file read slab by
/// slab: anything that implements [`RaySource`]).
///
/// ```
/// use ktree::{rays::ball_rays, stacking::{Builder, CellStacking}, KTree};
/// let ball = ball_rays::<3>(6, [32, 32, 32], 20).unwrap();
/// let tree = Builder::new(&ball).threads(2).split_depth(2).build().unwrap();
/// assert_eq!(tree, KTree::from_rays(&ball));
/// let lists = Builder::new(&ball).cells(CellStacking::Lists).build().unwrap();
/// assert_eq!(lists, tree);
///
/// let dir = tempfile::tempdir().unwrap();
/// let out = dir.path().join("ball.ktree");
/// let report = Builder::new(&ball).to_file(&out, 1 << 30).unwrap();
/// assert_eq!(report.counts_per_level, tree.counts_per_level());
/// assert_eq!(ktree::io::read_ktree_file(&out).unwrap(), ktree::AnyTree::K3(tree));
/// ```
pub struct Builder<'a, const K: usize, S: RaySource<K>> {
    source: &'a S,
    threads: Option<usize>,
    split_depth: Option<u32>,
    cells: CellStacking,
    temp_dir: Option<PathBuf>,
    progress: Option<&'a (dyn Fn(Progress) + Sync)>,
    frame: Option<WorldFrame>,
}

impl<'a, const K: usize, S: RaySource<K>> Builder<'a, K, S> {
    /// A build of `source` on the threads of the current rayon pool, at the default split depth, each
    /// cell through a bitmap pyramid.
    pub fn new(source: &'a S) -> Self {
        Self {
            source,
            threads: None,
            split_depth: None,
            cells: CellStacking::default(),
            temp_dir: None,
            progress: None,
            frame: None,
        }
    }

    /// Runs on a pool of its own of `threads` worker threads (`0`: one per core). The tree does not
    /// depend on it.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = Some(threads);
        self
    }

    /// Stacks apart the cells of depth `depth` (clamped to the level `L`); `0` stacks the whole universe
    /// as one cell. The tree does not depend on it.
    pub fn split_depth(mut self, depth: u32) -> Self {
        self.split_depth = Some(depth);
        self
    }

    /// How each cell is stacked. The tree does not depend on it.
    pub fn cells(mut self, cells: CellStacking) -> Self {
        self.cells = cells;
        self
    }

    /// The folder of the spill files of [`to_file`](Self::to_file) and [`stack_part`](Self::stack_part)
    /// (by default the output's folder; other stores ignore it).
    pub fn temp_dir(mut self, dir: impl Into<PathBuf>) -> Self {
        self.temp_dir = Some(dir.into());
        self
    }

    /// Where the voxels are in the world: kept in the header of the file [`to_file`](Self::to_file)
    /// writes (see [`io::write_ktree_framed`](crate::io::write_ktree_framed)).
    pub fn world_frame(mut self, frame: WorldFrame) -> Self {
        self.frame = Some(frame);
        self
    }

    /// The world frame given to [`world_frame`](Self::world_frame), if any.
    pub fn frame(&self) -> Option<&WorldFrame> {
        self.frame.as_ref()
    }

    /// Called on the calling thread as a build out of core stacks slabs and writes levels.
    pub fn progress(mut self, progress: &'a (dyn Fn(Progress) + Sync)) -> Self {
        self.progress = Some(progress);
        self
    }

    /// The split depth the build uses: the one given, or [`default_split_depth`]; at most `L`.
    pub fn depth(&self) -> u32 {
        let level = self.source.universe().level();
        self.split_depth
            .unwrap_or_else(|| default_split_depth(K, level))
            .min(level)
    }

    /// Builds the tree in memory.
    ///
    /// # Errors
    /// [`BuildError::Source`]: the source's first error (in slab order); [`BuildError::Threads`]: the
    /// threads asked for cannot be started.
    pub fn build(&self) -> Result<KTree<K>, BuildError<S::Error>> {
        let depth = self.depth();
        self.on_threads(|| stack_source(self.source, depth, self.cells))?
            .map_err(BuildError::Source)
    }

    /// [`build`](Self::build) on the current pool, whatever [`threads`](Self::threads) says: no error but
    /// the source's.
    pub(crate) fn build_on_current_pool(&self) -> Result<KTree<K>, S::Error> {
        stack_source(self.source, self.depth(), self.cells)
    }

    /// Builds the tree out of core, holding at most about `max_memory` bytes: the subtrees of the cells
    /// are spilled to `store` as they are stacked, then the tree is written to `output` level after level
    /// (see [`stacking`](super)'s notes on memory). Returns the finished output and the report (its
    /// `file_bytes` 0). [`to_file`](Self::to_file) is this build into spill files and a `.ktree` file;
    /// the example of [`PieceStore`] builds in memory.
    ///
    /// # Errors
    /// [`BuildError`]: the source's first error, a budget too small (at once when what is known before
    /// any slab is stacked does not fit), threads that cannot be started, the error of `store` or
    /// `output`.
    pub fn build_into<P, O>(
        &self,
        store: P,
        output: O,
        max_memory: u64,
    ) -> Result<(O::Output, OutOfCoreReport), StoreBuildError<S::Error, P>>
    where
        P: PieceStore,
        O: LevelOrderSink<Error = P::Error>,
    {
        let part = self.stack_part_into(&self.slabs(), store, max_memory)?;
        // One part of every slab: no other part sends anything.
        let nothing = |_: usize, _: &mut [u64]| -> Result<(), P::Error> {
            unreachable!("a build of one part receives no levels")
        };
        part.write_into(output, nothing, self.progress_callback())
    }

    /// The slabs (numbered along axis 0, increasing) the build stacks: the slabs of cells of the split
    /// depth that may hold runs. A build in parts cuts them into shares ([`balanced_parts`](super::balanced_parts)
    /// of their [`slab_cost`](Self::slab_cost)s) for [`stack_part`](Self::stack_part).
    pub fn slabs(&self) -> Vec<u32> {
        build_slabs(self.source, self.depth())
    }

    /// The estimated memory cost of stacking slab `b0`, in bytes: what the build accounts for its runs
    /// (the runs are made and dropped).
    ///
    /// # Errors
    /// The source's error.
    pub fn slab_cost(&self, b0: u32) -> Result<u64, S::Error> {
        slab_cost(self.source, self.depth(), b0)
    }

    /// Stacks the cells of some slabs (from [`slabs`](Self::slabs), increasing) and spills their subtrees
    /// to `store`, in a budget of `max_memory` bytes for this part alone. One part gathers the others'
    /// indexes and writes the tree ([`SpilledPart::add_part`], [`SpilledPart::write_into`]): the tree is
    /// that of [`build_into`](Self::build_into) for any cut into parts. [`stack_part`](Self::stack_part)
    /// is this into spill files.
    ///
    /// # Errors
    /// As [`build_into`](Self::build_into) (the budget covers this part alone).
    pub fn stack_part_into<P: PieceStore>(
        &self,
        slabs: &[u32],
        store: P,
        max_memory: u64,
    ) -> Result<SpilledPart<P::Stored>, StoreBuildError<S::Error, P>> {
        let options = OutOfCore {
            depth: self.depth(),
            max_memory,
            cells: self.cells,
        };
        self.on_threads(|| {
            stack_part(
                self.source,
                slabs,
                store,
                &options,
                self.progress_callback(),
            )
        })?
    }

    /// The folder given for spill files ([`temp_dir`](Self::temp_dir)), if any.
    pub(crate) fn spill_dir(&self) -> Option<&Path> {
        self.temp_dir.as_deref()
    }

    /// The levels of the subtrees of the cells below their roots: `L` less the split depth.
    pub(crate) fn subtree_levels(&self) -> usize {
        (self.source.universe().level() - self.depth()) as usize
    }

    /// The progress callback given, or one that does nothing.
    pub(crate) fn progress_callback(&self) -> &(dyn Fn(Progress) + Sync) {
        self.progress.unwrap_or(&|_| {})
    }

    /// Runs `work` on the pool asked for, or on the current one.
    fn on_threads<T: Send, F>(
        &self,
        work: impl FnOnce() -> T + Send,
    ) -> Result<T, BuildError<S::Error, F>> {
        match self.threads {
            None => Ok(work()),
            Some(threads) => rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map(|pool| pool.install(work))
                .map_err(BuildError::Threads),
        }
    }
}
impl<const K: usize> KTree<K> {
    /// The tree of a ray set, by the default build ([`Builder`]: cells of the default split depth on the
    /// threads of the current rayon pool); also `KTree::from(&rays)`.
    ///
    /// ```
    /// use ktree::{KTree, Ray, RaySet};
    /// let rays = RaySet::<2>::from_rays(2, [Ray::new([1, 0], 4)]).unwrap();
    /// let tree = KTree::from_rays(&rays);
    /// assert_eq!(tree.voxel_count(), 4);
    /// assert_eq!(tree, KTree::from(&rays));
    /// ```
    pub fn from_rays(rays: &RaySet<K>) -> Self {
        match Builder::new(rays).build_on_current_pool() {
            Ok(tree) => tree,
            Err(never) => match never {},
        }
    }
}

impl<const K: usize> From<&RaySet<K>> for KTree<K> {
    /// [`KTree::from_rays`].
    fn from(rays: &RaySet<K>) -> Self {
        Self::from_rays(rays)
    }
}
