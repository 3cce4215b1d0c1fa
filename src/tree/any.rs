//! Trees whose dimension is known only at run time (read from a file): [`AnyTree`].

use crate::tree::{KTree, LevelCounts};

/// The statistics of a tree: its dimension, level, node counts and size. With the `serde` feature these
/// are the keys of `ktree stats --json`.
///
/// ```
/// use ktree::{AnyTree, KTree};
/// let tree = AnyTree::from(KTree::<2>::from_dense(1, &[true, false, false, false]).unwrap());
/// let s = tree.stats(None);
/// assert_eq!((s.k, s.level, s.nodes, s.full, s.partial), (2, 1, 5, 1, 1));
/// assert_eq!(s.per_level.len(), 2);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TreeStats {
    /// The dimension `K`.
    pub k: usize,
    /// The universe level `L`.
    pub level: u32,
    /// Runs of the ray set the tree was stacked from, where there was one.
    pub rays: Option<u64>,
    /// Full nodes.
    pub full: u64,
    /// Empty nodes.
    pub empty: u64,
    /// Partial nodes.
    pub partial: u64,
    /// All nodes.
    pub nodes: u64,
    /// Bytes at 2 bits a node.
    pub bytes_at_2_bits: u64,
    /// Heap bytes of the navigable tree in memory (states and rank index, [`crate::KTree::heap_bytes`]).
    pub memory_bytes: u64,
    /// Node counts per level, the root's first.
    pub per_level: Vec<LevelCounts>,
}

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

/// Runs an expression on the typed value inside an [`AnyTree`] or a [`RaySet`](crate::AnyRaySet):
/// `with_dim!(any, AnyTree, t => t.node_count())`. The expression is compiled once per `K`.
#[macro_export]
macro_rules! with_dim {
    ($value:expr, AnyTree, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::tree::AnyTree, $name => $body)
    };
    ($value:expr, AnyRaySet, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::rays::AnyRaySet, $name => $body)
    };
    ($value:expr, AnyRaysFileSource, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::io::AnyRaysFileSource, $name => $body)
    };
    (@match $value:expr, $($kind:ident)::+, $name:ident => $body:expr) => {
        match $value {
            $($kind)::+::K1($name) => $body,
            $($kind)::+::K2($name) => $body,
            $($kind)::+::K3($name) => $body,
            $($kind)::+::K4($name) => $body,
        }
    };
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

    /// The statistics, with `rays` the number of runs the tree was stacked from (if it was).
    pub fn stats(&self, rays: Option<u64>) -> TreeStats {
        let c = self.counts();
        TreeStats {
            k: self.k(),
            level: self.level(),
            rays,
            full: c.full,
            empty: c.empty,
            partial: c.partial,
            nodes: c.nodes(),
            bytes_at_2_bits: self.bytes_at_two_bits(),
            memory_bytes: self.heap_bytes() as u64,
            per_level: self.counts_per_level(),
        }
    }
}

/// `From<$typed<K>>` for an enum of the four dimensions, by downcasting to the one `K` that matches.
macro_rules! from_typed {
    ($typed:ident, $any:ident) => {
        impl<const K: usize> From<$typed<K>> for $any {
            fn from(value: $typed<K>) -> Self {
                let boxed: Box<dyn std::any::Any> = Box::new(value);
                let boxed = match boxed.downcast::<$typed<1>>() {
                    Ok(v) => return Self::K1(*v),
                    Err(b) => b,
                };
                let boxed = match boxed.downcast::<$typed<2>>() {
                    Ok(v) => return Self::K2(*v),
                    Err(b) => b,
                };
                let boxed = match boxed.downcast::<$typed<3>>() {
                    Ok(v) => return Self::K3(*v),
                    Err(b) => b,
                };
                match boxed.downcast::<$typed<4>>() {
                    Ok(v) => Self::K4(*v),
                    Err(_) => unreachable!("K is checked to be 1..=4 when the value is made"),
                }
            }
        }
    };
}

pub(crate) use from_typed;

from_typed!(KTree, AnyTree);
