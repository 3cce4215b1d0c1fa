//! Trees whose dimension is known only at run time (read from a file): [`AnyTree`].

use crate::tree::{KTree, LevelCounts};

/// A [`KTree`] of any supported dimension, as read from a file whose header names `K`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AnyTree {
    /// A bintree.
    K1(KTree<1>),
    /// A quadtree.
    K2(KTree<2>),
    /// An octree.
    K3(KTree<3>),
    /// A 4-D tree.
    K4(KTree<4>),
}

/// A tree of another dimension than the one asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a tree of dimension K = {expected} was expected, this one has K = {found}")]
pub struct DimensionMismatch {
    /// The dimension asked for.
    pub expected: usize,
    /// The tree's dimension.
    pub found: usize,
}

impl<const K: usize> TryFrom<AnyTree> for KTree<K> {
    type Error = DimensionMismatch;

    /// The tree as `KTree<K>`.
    ///
    /// ```
    /// use ktree::{AnyTree, KTree};
    /// let any = AnyTree::from(KTree::<2>::full(3).unwrap());
    /// assert!(KTree::<2>::try_from(any.clone()).is_ok());
    /// let e = KTree::<3>::try_from(any).unwrap_err();
    /// assert_eq!((e.expected, e.found), (3, 2));
    /// ```
    fn try_from(tree: AnyTree) -> Result<Self, DimensionMismatch> {
        let found = tree.k();
        tree.into_dim::<K>()
            .map_err(|_| DimensionMismatch { expected: K, found })
    }
}

impl AnyTree {
    /// The tree as `KTree<K>`, or `self` back if it has another dimension.
    ///
    /// # Errors
    /// `Err(self)` when the dimension differs.
    pub fn into_dim<const K: usize>(self) -> Result<KTree<K>, Self> {
        let boxed: Box<dyn std::any::Any> = match self {
            AnyTree::K1(t) if K == 1 => Box::new(t),
            AnyTree::K2(t) if K == 2 => Box::new(t),
            AnyTree::K3(t) if K == 3 => Box::new(t),
            AnyTree::K4(t) if K == 4 => Box::new(t),
            other => return Err(other),
        };
        Ok(*boxed.downcast::<KTree<K>>().expect("K matched above"))
    }

    /// The tree as `&KTree<K>`, or `None` if it has another dimension.
    pub fn as_dim<const K: usize>(&self) -> Option<&KTree<K>> {
        with_dim!(self, AnyTree, t => (t as &dyn std::any::Any).downcast_ref::<KTree<K>>())
    }

    /// The dimension `K`.
    pub fn k(&self) -> usize {
        match self {
            Self::K1(_) => 1,
            Self::K2(_) => 2,
            Self::K3(_) => 3,
            Self::K4(_) => 4,
        }
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        with_dim!(self, AnyTree, t => t.level())
    }

    /// Node counts per level.
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        with_dim!(self, AnyTree, t => t.counts_per_level())
    }

    /// Total node counts.
    pub fn counts(&self) -> LevelCounts {
        with_dim!(self, AnyTree, t => t.counts())
    }

    /// Bytes at 2 bits a node.
    pub fn bytes_at_two_bits(&self) -> u64 {
        with_dim!(self, AnyTree, t => t.bytes_at_two_bits())
    }

    /// Bytes of memory held by the navigable tree (see [`crate::KTree::heap_bytes`]).
    pub fn heap_bytes(&self) -> usize {
        with_dim!(self, AnyTree, t => t.heap_bytes())
    }
}

crate::dim::from_typed!(KTree, AnyTree);
