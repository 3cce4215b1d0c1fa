//! Shared strategies for the operations' property tests: pairs of random objects in one universe, built as
//! dense boolean arrays (unions of boxes plus scattered voxels) so that the reference is the array itself.

use std::fmt;

use ktree::{KTree, Universe};
use proptest::prelude::*;

/// Largest level of the dense objects for each K (L ≤ 5 for K ≤ 3, L ≤ 3 for K = 4): dense arrays stay
/// small enough to compare many cases.
pub const fn max_level(k: usize) -> u32 {
    if k <= 3 {
        5
    } else {
        3
    }
}

/// An object as a dense array, printed as its list of boxes and voxels so shrunk failures are readable.
#[derive(Clone)]
pub struct Obj<const K: usize> {
    /// The universe's level.
    pub level: u32,
    /// Boxes `[lo, hi)` of full voxels.
    pub boxes: Vec<([u32; K], [u32; K])>,
    /// Single full voxels.
    pub voxels: Vec<[u32; K]>,
}

impl<const K: usize> fmt::Debug for Obj<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "K={K} L={} boxes [lo,hi)={:?} voxels={:?}",
            self.level, self.boxes, self.voxels
        )
    }
}

impl<const K: usize> Obj<K> {
    /// The universe of the object's level.
    pub fn universe(&self) -> Universe<K> {
        Universe::new(self.level).unwrap()
    }

    /// The object as a dense boolean array, in [`Universe::dense_index`] order: the reference.
    pub fn dense(&self) -> Vec<bool> {
        let u = self.universe();
        let mut d = vec![false; u.voxels() as usize];
        for (i, cell) in d.iter_mut().enumerate() {
            let p = u.dense_point(i);
            *cell = self
                .boxes
                .iter()
                .any(|(lo, hi)| (0..K).all(|a| p[a] >= lo[a] && p[a] < hi[a]))
                || self.voxels.contains(&p);
        }
        d
    }

    /// The object's tree, built from the dense array and checked well formed.
    pub fn tree(&self) -> KTree<K> {
        let t = KTree::from_dense(self.level, &self.dense()).unwrap();
        t.assert_well_formed();
        t
    }
}

/// Objects in a universe of level `level`: up to 3 boxes and 11 voxels.
pub fn obj_at<const K: usize>(level: u32) -> impl Strategy<Value = Obj<K>> {
    let side = 1u32 << level;
    let bx = prop::array::uniform::<_, K>((0..side, 1..=side)).prop_map(move |b| {
        let lo: [u32; K] = std::array::from_fn(|i| b[i].0);
        let hi: [u32; K] = std::array::from_fn(|i| (b[i].0 + b[i].1).min(side));
        (lo, hi)
    });
    (
        prop::collection::vec(bx, 0..4),
        prop::collection::vec(prop::array::uniform::<_, K>(0..side), 0..12),
    )
        .prop_map(move |(boxes, voxels)| Obj {
            level,
            boxes,
            voxels,
        })
}

/// One random object at a random level.
pub fn object<const K: usize>() -> impl Strategy<Value = Obj<K>> {
    (0..=max_level(K)).prop_flat_map(obj_at::<K>)
}

/// Two random objects in one universe.
pub fn pair<const K: usize>() -> impl Strategy<Value = (Obj<K>, Obj<K>)> {
    (0..=max_level(K)).prop_flat_map(|l| (obj_at::<K>(l), obj_at::<K>(l)))
}

/// The tree of a dense array, checked well-formed.
pub fn tree_of<const K: usize>(level: u32, dense: &[bool]) -> KTree<K> {
    KTree::from_dense(level, dense).unwrap()
}
