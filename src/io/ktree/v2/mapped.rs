//! A `.ktree` version 2 file read as a tree in place: a [`TreeStorage`] whose every read is checked, so
//! every walk, query, operation, picture and export of the crate runs on its memory map as on a tree in
//! memory, for trees larger than memory.

use super::layout::NODES_PER_WORD;
use super::KtreeView;
use crate::io::{KtreeFileError, KtreeFileErrorKind};
use crate::space::Universe;
use crate::tree::storage::TreeStorage;
use crate::tree::{words, LevelCounts, NodeState, StorageError};

/// A `K`-dimensional tree read in place through a [`KtreeView`] (a clone of it, sharing its map): a
/// [`TreeStorage`] whose every read is checked against the shape found when the file was opened, each
/// first child found from the file's rank samples (at most 64 word pop-counts) instead of an index in
/// memory. A file changed since it was opened gives an error naming the file and a byte offset within
/// the level read, never a read past the map, a panic or a wrong answer from the walk that noticed.
///
/// The questions of [`query::Query`](crate::query::Query) are asked of it as of a tree in memory:
///
/// ```
/// use ktree::query::Query;
/// use ktree::tree::cursor::TryLeaves;
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_file(&path, &tree).unwrap();
/// let mapped = io::MappedTree::<2>::open(&path).unwrap();
/// let leaves: Vec<_> = TryLeaves::new(&mapped).collect::<Result<_, _>>().unwrap();
/// assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
/// assert_eq!(mapped.contains_many(&[[0, 0], [1, 0]]).unwrap(), [true, false]);
/// assert_eq!(mapped.bounding_box().unwrap(), tree.bounding_box());
/// ```
#[derive(Debug, Clone)]
pub struct MappedTree<const K: usize> {
    view: KtreeView,
    universe: Universe<K>,
}

impl<const K: usize> MappedTree<K> {
    /// The tree of `view` (which it clones: the two share the map).
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn new(view: &KtreeView) -> Result<Self, KtreeFileError> {
        Ok(Self {
            view: view.clone(),
            universe: view.universe::<K>()?,
        })
    }

    /// Opens, checks and maps the version 2 file `path` ([`KtreeView::open`]).
    ///
    /// # Errors
    /// As [`KtreeView::open`]; [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn open(path: &std::path::Path) -> Result<Self, KtreeFileError> {
        Self::new(&KtreeView::open(path)?)
    }

    /// The view the tree is read through.
    pub fn view(&self) -> &KtreeView {
        &self.view
    }

    /// The error for nodes `index …` of level `depth` that the shape says exist but the file does not
    /// hold as it did: the offset is that of the level's last word read, within the file.
    fn changed(&self, depth: usize, index: u64) -> KtreeFileError {
        let depth = depth.min(self.view.depth_count().saturating_sub(1));
        let last = index.min(self.view.level_nodes(depth).saturating_sub(1));
        let mut error = self.view.changed(depth, last);
        error.kind = KtreeFileErrorKind::Tree(format!(
            "node {index} of level {depth} is missing or has the code 11: the file was changed after it was opened"
        ));
        error
    }

    /// The `n ≤ 32` states of level `depth` from `first`, checked to be in the level and to hold no
    /// unused code.
    #[inline]
    fn read(&self, depth: usize, first: u64, n: u64) -> Result<u64, KtreeFileError> {
        let nodes = self.view.level_nodes(depth);
        if first.saturating_add(n) > nodes {
            return Err(self.changed(depth, first));
        }
        let words = nodes.div_ceil(NODES_PER_WORD);
        let (j, off) = (first / NODES_PER_WORD, first % NODES_PER_WORD);
        let mut word = self.view.level_word(depth, j)? >> (2 * off);
        if off > 0 && j + 1 < words {
            word |= self.view.level_word(depth, j + 1)? << (2 * (NODES_PER_WORD - off));
        }
        let word = word & words::slots_mask(n as usize);
        // A code 11 is not a state: the bytes are not the file's any more.
        if words::unused_mask(word) != 0 {
            return Err(self.changed(depth, first));
        }
        Ok(word)
    }
}

impl From<KtreeFileError> for StorageError {
    fn from(e: KtreeFileError) -> Self {
        StorageError::new(e)
    }
}

impl<const K: usize> TreeStorage<K> for MappedTree<K> {
    type Error = KtreeFileError;

    fn universe(&self) -> Universe<K> {
        self.universe
    }

    fn depth_count(&self) -> usize {
        self.view.depth_count()
    }

    fn level_len(&self, depth: usize) -> usize {
        self.view.level_nodes(depth) as usize
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.view.counts_per_level()
    }

    fn root_state(&self) -> Result<NodeState, KtreeFileError> {
        self.view.checked_state(0, 0)
    }

    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, KtreeFileError> {
        let index = index as u64;
        let nodes = self.view.level_nodes(depth);
        if index > nodes || depth >= self.view.depth_count() {
            return Err(self.changed(depth, index));
        }
        if index == nodes {
            // The rank of the level's end: that of its last node plus the last node's own.
            let last = index.checked_sub(1).map_or(Ok(0), |i| {
                let own = u64::from(self.view.checked_state(depth, i)? == NodeState::Partial);
                Ok::<_, KtreeFileError>(self.view.partial_rank(depth, i)? + own)
            })?;
            return Ok(last as usize);
        }
        Ok(self.view.partial_rank(depth, index)? as usize)
    }

    fn first_child(&self, depth: usize, index: usize) -> Result<usize, KtreeFileError> {
        // The node was read as partial from its parent's block: its children must be a whole block of
        // the level below.
        let index = index as u64;
        if depth + 1 >= self.view.depth_count() {
            return Err(self.changed(depth, index));
        }
        let first = self.view.partial_rank(depth, index)?.saturating_mul(1 << K);
        if first.saturating_add(1 << K) > self.view.level_nodes(depth + 1) {
            return Err(self.changed(depth + 1, first));
        }
        Ok(first as usize)
    }

    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, KtreeFileError> {
        Ok(self.read(depth, first as u64, 1 << K)? as u32)
    }

    fn slots(&self, depth: usize, first: usize, n: usize) -> Result<u64, KtreeFileError> {
        self.read(depth, first as u64, n as u64)
    }
}

/// A [`MappedTree`] of the dimension its file names: the mapped twin of [`AnyTree`](crate::AnyTree). Run
/// generic code on it with [`with_dim!`](crate::with_dim) (`with_dim!(&m, AnyMappedTree, t => …)`), or on
/// either twin with [`with_tree!`](crate::with_tree).
///
/// ```
/// use ktree::tree::storage::TreeStorage;
/// use ktree::{io, with_dim, KTree};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_file(&path, &KTree::<3>::full(2).unwrap()).unwrap();
/// let mapped = io::AnyMappedTree::open(&path).unwrap();
/// assert_eq!(mapped.k(), 3);
/// assert_eq!(with_dim!(&mapped, AnyMappedTree, t => t.voxel_count()), 64);
/// ```
#[derive(Debug, Clone)]
pub enum AnyMappedTree {
    /// A bintree.
    K1(MappedTree<1>),
    /// A quadtree.
    K2(MappedTree<2>),
    /// An octree.
    K3(MappedTree<3>),
    /// A 4-D tree.
    K4(MappedTree<4>),
}

impl AnyMappedTree {
    /// The tree of `view`, of the dimension its header names.
    ///
    /// # Errors
    /// None in practice (the view's `K` was checked when it was opened); the signature matches
    /// [`MappedTree::new`].
    pub fn new(view: &KtreeView) -> Result<Self, KtreeFileError> {
        Ok(match view.k() {
            1 => Self::K1(MappedTree::new(view)?),
            2 => Self::K2(MappedTree::new(view)?),
            3 => Self::K3(MappedTree::new(view)?),
            _ => Self::K4(MappedTree::new(view)?),
        })
    }

    /// Opens, checks and maps the version 2 file `path` ([`KtreeView::open`]).
    ///
    /// # Errors
    /// As [`KtreeView::open`].
    pub fn open(path: &std::path::Path) -> Result<Self, KtreeFileError> {
        Self::new(&KtreeView::open(path)?)
    }

    /// The view the tree is read through.
    pub fn view(&self) -> &KtreeView {
        crate::with_dim!(self, AnyMappedTree, t => t.view())
    }

    /// The dimension `K`.
    pub fn k(&self) -> usize {
        self.view().k()
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        self.view().level()
    }
}

crate::dim::from_typed!(MappedTree, AnyMappedTree);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;
    use crate::tree::cursor::TryLeaves;

    /// A file rewritten in place (same inode) with a smaller, different tree after it was opened: walks
    /// and queries give errors naming offsets inside the file, never a panic.
    #[test]
    fn a_file_rewritten_in_place_after_opening_gives_errors_not_panics() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ktree");
        let big = stack(&ball_rays::<3>(6, [30, 33, 35], 50).unwrap());
        crate::io::write_ktree_file(&path, &big).unwrap();
        let len = std::fs::metadata(&path).unwrap().len();
        let view = KtreeView::open(&path).unwrap();
        // Rewrite in place (the same inode, so the map shows the new bytes): first another, smaller tree
        // over the start with the rest all ones, then all ones.
        let mut small = Vec::new();
        crate::io::write_ktree(
            &mut small,
            &stack(&ball_rays::<3>(6, [10, 12, 14], 9).unwrap()),
        )
        .unwrap();
        small.resize(len as usize, 0xFF);
        std::fs::write(&path, &small).unwrap();
        let mapped = MappedTree::<3>::new(&view).unwrap();
        let leaves = |m: &MappedTree<3>| TryLeaves::new(m).collect::<Result<Vec<_>, _>>();
        if let Err(e) = leaves(&mapped) {
            assert!(e.offset().is_some_and(|o| o < len), "{e}");
        }
        std::fs::write(&path, vec![0xFF; len as usize]).unwrap();
        let mapped = MappedTree::<3>::new(&view).unwrap();
        let e = leaves(&mapped).expect_err("a changed file read without an error");
        assert!(e.offset().is_some_and(|o| o < len), "{e}");
        assert!(e.to_string().contains("changed after it was opened"), "{e}");
        for p in [[0u32, 0, 0], [30, 33, 35], [63, 63, 63], [31, 40, 20]] {
            if let Err(e) = view.contains(p) {
                assert!(e.offset().is_some_and(|o| o < len), "{e}");
            }
        }
        let _ = view.for_each_leaf::<3>(|_, _| {});
        let _ = view.to_tree::<3>();
    }
}
