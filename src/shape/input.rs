//! How the shape operations read their input, from any storage (a tree in memory, a `.ktree` file read in
//! place): its runs (the one tree → runs, [`rays_of`]), a copy in memory, its complement read through it
//! (nothing copied), and a failed read as [`ShapeError::Storage`].

use std::marker::PhantomData;

use super::ShapeError;
use crate::rays::RaySet;
use crate::space::Universe;
use crate::tree::sink::{copy_subtree, LevelSink, MemorySink};
use crate::tree::storage::TreeStorage;
use crate::tree::words;
use crate::tree::{rays_of, KTree, LevelCounts, NodeState, StorageError};

/// A read error of the input, as a shape error.
pub(crate) fn read_error<E: Into<StorageError>>(e: E) -> ShapeError {
    ShapeError::Storage(e.into())
}

/// The runs of the input's full voxels along the last axis.
pub(crate) fn runs<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<RaySet<K>, ShapeError> {
    rays_of(tree).map_err(read_error)
}

/// A sink in memory whose (never produced) error is the input's, so that a copy fails only as a read.
struct CopySink<const K: usize, E>(MemorySink<K>, PhantomData<E>);

impl<const K: usize, E> LevelSink for CopySink<K, E> {
    type Error = E;
    type Output = KTree<K>;

    #[inline]
    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), E> {
        let Ok(()) = self.0.append(depth, word, n);
        Ok(())
    }

    fn finish(self, root: NodeState) -> Result<KTree<K>, E> {
        let Ok(tree) = self.0.finish(root);
        Ok(tree)
    }
}

/// The input as a tree in memory: its levels copied in bulk.
pub(crate) fn copied<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<KTree<K>, ShapeError> {
    let copy = || -> Result<KTree<K>, T::Error> {
        let root = tree.root_state()?;
        let mut sink = CopySink::<K, T::Error>(MemorySink::new(tree.universe()), PhantomData);
        if root == NodeState::Partial {
            copy_subtree::<K, _, _, T::Error>(&mut sink, tree, 0, 0, false)?;
        }
        sink.finish(root)
    };
    copy().map_err(read_error)
}

/// A tree read with its full and empty nodes swapped: the complement, with nothing copied.
pub(crate) struct Complement<'a, T>(pub(crate) &'a T);

impl<const K: usize, T: TreeStorage<K>> TreeStorage<K> for Complement<'_, T> {
    type Error = T::Error;

    #[inline]
    fn universe(&self) -> Universe<K> {
        self.0.universe()
    }

    #[inline]
    fn depth_count(&self) -> usize {
        self.0.depth_count()
    }

    #[inline]
    fn level_len(&self, depth: usize) -> usize {
        self.0.level_len(depth)
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.0
            .counts_per_level()
            .into_iter()
            .map(|c| LevelCounts {
                full: c.empty,
                empty: c.full,
                ..c
            })
            .collect()
    }

    #[inline]
    fn root_state(&self) -> Result<NodeState, T::Error> {
        Ok(match self.0.root_state()? {
            NodeState::Full => NodeState::Empty,
            NodeState::Empty => NodeState::Full,
            NodeState::Partial => NodeState::Partial,
        })
    }

    #[inline(always)]
    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, T::Error> {
        self.0.partial_rank(depth, index)
    }

    #[inline(always)]
    fn first_child(&self, depth: usize, index: usize) -> Result<usize, T::Error> {
        self.0.first_child(depth, index)
    }

    #[inline(always)]
    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, T::Error> {
        let codes = self.0.block_codes(depth, first)?;
        Ok(words::complement(u64::from(codes), 1 << K) as u32)
    }

    #[inline(always)]
    fn slots(&self, depth: usize, first: usize, n: usize) -> Result<u64, T::Error> {
        Ok(words::complement(self.0.slots(depth, first, n)?, n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::storage::infallible;

    #[test]
    fn the_complement_read_through_is_the_complement() {
        let dense: Vec<bool> = (0..64u32).map(|i| (i * 7 + i / 5) % 3 == 0).collect();
        let tree = KTree::<3>::from_dense(2, &dense).unwrap();
        let inverse: Vec<bool> = dense.iter().map(|&b| !b).collect();
        let view = Complement(&tree);
        assert_eq!(
            copied(&view).unwrap(),
            KTree::from_dense(2, &inverse).unwrap()
        );
        assert_eq!(
            TreeStorage::voxel_count(&view),
            64 - TreeStorage::voxel_count(&tree)
        );
        assert_eq!(
            infallible(rays_of(&view)),
            KTree::from_dense(2, &inverse).unwrap().to_rays()
        );
        assert_eq!(copied(&tree).unwrap(), tree);
        assert_eq!(
            copied(&KTree::<2>::full(3).unwrap()).unwrap(),
            KTree::full(3).unwrap()
        );
    }
}
