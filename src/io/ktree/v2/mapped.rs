//! A `.ktree` version 2 file read as a tree in place: the walks of [`cursor`](crate::tree::cursor) (and so
//! rendering) run on its memory map, for trees larger than memory.

use super::KtreeView;
use crate::io::KtreeFileError;
use crate::query;
use crate::space::Universe;
use crate::tree::cursor::LevelOrder;
use crate::tree::storage::infallible;
use crate::tree::NodeState;
use crate::KTree;
use std::convert::Infallible;
use std::sync::OnceLock;

/// A `K`-dimensional tree read through a [`KtreeView`]: what the walks need, with each first child found
/// from the file's rank samples (at most 64 word pop-counts) instead of an index in memory.
///
/// ```
/// use ktree::tree::cursor::LevelOrder;
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_file(&path, &tree).unwrap();
/// let view = io::KtreeView::open(&path).unwrap();
/// let mapped = io::MappedTree::<2>::new(&view).unwrap();
/// let mut leaves = Vec::new();
/// mapped.for_each_leaf(|cell, state| leaves.push((cell, state)));
/// assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
/// ```
#[derive(Debug)]
pub struct MappedTree<'a, const K: usize> {
    view: &'a KtreeView,
    universe: Universe<K>,
    /// The first read that found the file changed since it was opened.
    failure: OnceLock<KtreeFileError>,
}

impl<'a, const K: usize> MappedTree<'a, K> {
    /// The tree of `view`.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`](crate::io::KtreeFileErrorKind::Dimension) if the file's `K` is not `K`.
    pub fn new(view: &'a KtreeView) -> Result<Self, KtreeFileError> {
        Ok(Self {
            view,
            universe: view.universe::<K>()?,
            failure: OnceLock::new(),
        })
    }

    /// `Ok` if every read so far found the file as it was checked when opened; otherwise the first
    /// failed read's error (naming the file and a byte offset inside it). Walks over a file changed
    /// underneath read the nodes they cannot find as empty and go on: call this after a walk.
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn failure(&self) -> Result<(), KtreeFileError> {
        self.failure.get().map_or(Ok(()), |e| Err(e.clone()))
    }

    /// `value` of a read, or `fallback` after recording its error.
    fn checked<T>(&self, read: Result<T, KtreeFileError>, fallback: T) -> T {
        read.unwrap_or_else(|e| {
            let _ = self.failure.set(e);
            fallback
        })
    }
}

/// The queries of [`crate::query`] read through the map; each checks [`MappedTree::failure`] after its
/// walk, so a file changed underneath gives an error naming the file and an offset, not a wrong answer.
impl<const K: usize> MappedTree<'_, K> {
    /// The query's answer, or the first failed read's error.
    fn answer<T>(&self, value: Result<T, Infallible>) -> Result<T, KtreeFileError> {
        let value = infallible(value);
        self.failure().map(|()| value)
    }

    /// The number of voxels inside the object, from the file's per-level counts (no walk).
    pub fn voxel_count(&self) -> u128 {
        self.view.voxel_count()
    }

    /// As [`KTree::contains_many`](crate::KTree::contains_many).
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn contains_many(&self, points: &[[u32; K]]) -> Result<Vec<bool>, KtreeFileError> {
        self.answer(query::contains_many(self, points))
    }

    /// As [`KTree::bounding_box`](crate::KTree::bounding_box).
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn bounding_box(&self) -> Result<Option<query::VoxelBox<K>>, KtreeFileError> {
        self.answer(query::bounding_box(self))
    }

    /// As [`KTree::count`](crate::KTree::count).
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn count(&self, lo: [u32; K], hi: [u32; K]) -> Result<u128, KtreeFileError> {
        self.answer(query::count(self, lo, hi))
    }

    /// As [`KTree::crop`](crate::KTree::crop): the cropped tree, in memory.
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn crop(&self, lo: [u32; K], hi: [u32; K]) -> Result<KTree<K>, KtreeFileError> {
        self.answer(query::crop(self, lo, hi))
    }

    /// As [`query::cast_rays`] (ties as [`query::ray`] says).
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn cast_rays(
        &self,
        rays: &[query::RayCast<K>],
    ) -> Result<Vec<Option<query::RayHit<K>>>, KtreeFileError> {
        self.answer(query::cast_rays(self, rays))
    }

    /// As [`KTree::nearest_many`](crate::KTree::nearest_many).
    ///
    /// # Errors
    /// The first failed read's error.
    pub fn nearest_many(
        &self,
        points: &[[u32; K]],
    ) -> Result<Vec<Option<query::Nearest<K>>>, KtreeFileError> {
        self.answer(query::nearest_many(self, points))
    }
}

impl<const K: usize> LevelOrder<K> for MappedTree<'_, K> {
    fn universe(&self) -> Universe<K> {
        self.universe
    }

    fn depth_count(&self) -> usize {
        self.view.depth_count()
    }

    fn root_state(&self) -> NodeState {
        self.checked(self.view.checked_state(0, 0), NodeState::Empty)
    }

    fn first_child(&self, depth: usize, index: usize) -> usize {
        let first = self
            .view
            .partial_rank(depth, index as u64)
            .map(|rank| rank.saturating_mul(1 << K))
            .and_then(|first| {
                // The whole block of children must be in the level below.
                if first.saturating_add(1 << K) <= self.view.level_nodes(depth + 1) {
                    Ok(first as usize)
                } else {
                    Err(self.view.changed(depth + 1, first))
                }
            });
        self.checked(first, 0)
    }

    fn block_codes(&self, depth: usize, first: usize) -> u32 {
        // `2^K` divides 32: the block lies in one word.
        let first = first as u64;
        let block = if first.saturating_add(1 << K) <= self.view.level_nodes(depth) {
            self.view.level_word(depth, first / 32)
        } else {
            Err(self.view.changed(depth, first))
        };
        let word = self.checked(block, 0) >> (2 * (first % 32));
        let codes = (word & ((1u64 << (2 << K)) - 1)) as u32;
        // A code 11 is no state: the bytes are not the file's any more.
        if crate::tree::words::unused_mask(u64::from(codes)) != 0 {
            let _ = self.failure.set(self.view.changed(depth, first));
            return 0;
        }
        codes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;

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
        mapped.for_each_leaf(|_, _| {});
        if let Err(e) = mapped.failure() {
            assert!(e.offset().is_some_and(|o| o < len), "{e}");
        }
        std::fs::write(&path, vec![0xFF; len as usize]).unwrap();
        let mapped = MappedTree::<3>::new(&view).unwrap();
        mapped.for_each_leaf(|_, _| {});
        let e = mapped
            .failure()
            .expect_err("a changed file read without an error");
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
