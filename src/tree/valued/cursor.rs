//! Point location in a valued tree that remembers its last path: a point near the previous one (the next
//! voxel of a ray, a neighbour) is found from their deepest common ancestor instead of from the root, and
//! a point in the last leaf reads nothing. [`ValueStorage::try_leaf_at`] is the descent from the root it
//! replaces.
//!
//! ```
//! use ktree::tree::valued::{ValueCursor, ValueStorage};
//! use ktree::KTree;
//! let dense: Vec<Option<u8>> = (0..64u8).map(|i| (i % 3 != 0).then_some(i / 8)).collect();
//! let tree = KTree::<2, u8>::from_dense_values(3, &dense).unwrap();
//! let mut cursor = ValueCursor::new(&tree);
//! for p in [[0, 0], [1, 0], [7, 7], [6, 7], [9, 0]] {
//!     assert_eq!(cursor.leaf_at(p), tree.try_leaf_at(p));
//! }
//! ```

use super::walk::{LeafValue, ValueStorage};

/// The depth of the deepest node a path can hold (the largest universe level) plus one.
const PATH: usize = 33;

/// Point location that remembers its last path from the root (see the module's notes); gives what
/// [`ValueStorage::try_leaf_at`] gives, on any storage.
#[derive(Debug, Clone)]
pub struct ValueCursor<'a, const K: usize, T: ValueStorage<K>> {
    tree: &'a T,
    level: u32,
    /// For each depth above the last leaf: the first child of the last path's node there and its
    /// children's codes.
    children: [(usize, u32); PATH],
    /// The last point located, the depth of its leaf and the answer; `None` before the first.
    last: Option<([u32; K], usize, LeafValue<T::Value>)>,
}

impl<'a, const K: usize, T: ValueStorage<K>> ValueCursor<'a, K, T> {
    /// A cursor over `tree` that has located nothing yet (it reads nothing until asked).
    pub fn new(tree: &'a T) -> Self {
        Self {
            tree,
            level: tree.level(),
            children: [(0, 0); PATH],
            last: None,
        }
    }

    /// The leaf holding voxel `point` — the log of its side and its value (`None`: empty) — or `None`
    /// outside the universe.
    ///
    /// # Errors
    /// The storage's read error.
    #[inline]
    pub fn leaf_at(&mut self, point: [u32; K]) -> Result<Option<LeafValue<T::Value>>, T::Error> {
        // Outside the universe: a coordinate with a bit at or above the level.
        if point.iter().fold(0u64, |or, &c| or | u64::from(c)) >> self.level != 0 {
            return Ok(None);
        }
        let level = self.level as usize;
        let (mut depth, mut first, mut codes);
        match self.last {
            Some((last, leaf_depth, answer)) => {
                // The paths part at the depth of the highest bit in which a coordinate differs.
                let changed = (0..K).fold(0u32, |or, a| or | (last[a] ^ point[a]));
                let common = level - (32 - changed.leading_zeros()) as usize;
                if common >= leaf_depth {
                    self.last = Some((point, leaf_depth, answer));
                    return Ok(Some(answer));
                }
                depth = common;
                (first, codes) = self.children[depth];
            }
            None => {
                let code = self.tree.root_code()?;
                if code < 2 {
                    return Ok(Some(self.settle(point, 0, 0, code)?));
                }
                depth = 0;
                first = self.tree.children(0, 0)?;
                codes = self.tree.codes(1, first)?;
            }
        }
        loop {
            self.children[depth] = (first, codes);
            let bit = (level - depth - 1) as u32;
            let child = (0..K).fold(0, |c, a| c | ((point[a] >> bit & 1) as usize) << a);
            let code = (codes >> (2 * child)) & 3;
            depth += 1;
            let index = first + child;
            if code < 2 {
                return Ok(Some(self.settle(point, depth, index, code)?));
            }
            first = self.tree.children(depth, index)?;
            codes = self.tree.codes(depth + 1, first)?;
        }
    }

    /// Remembers the leaf `index` of level `depth`, of code `code` (empty or full), as `point`'s.
    fn settle(
        &mut self,
        point: [u32; K],
        depth: usize,
        index: usize,
        code: u32,
    ) -> Result<LeafValue<T::Value>, T::Error> {
        let value = if code == 1 {
            Some(self.tree.value(depth, index)?)
        } else {
            None
        };
        let answer = (self.level - depth as u32, value);
        self.last = Some((point, depth, answer));
        Ok(answer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::KTree;
    use proptest::prelude::*;

    /// Walks of neighbours and jumps, checked against the descent from the root.
    fn check<const K: usize>(level: u32, dense: &[Option<u8>], moves: &[(usize, bool, u32)]) {
        let tree = KTree::<K, u8>::from_dense_values(level, dense).unwrap();
        let mut cursor = ValueCursor::new(&tree);
        let side = 1u32 << level;
        let mut p = [0u32; K];
        for &(axis, up, jump) in moves {
            let a = axis % K;
            if jump > 0 {
                p[a] = jump % (side + 2); // now and then outside the universe
            } else if up {
                p[a] = p[a].wrapping_add(1);
            } else {
                p[a] = p[a].wrapping_sub(1);
            }
            assert_eq!(cursor.leaf_at(p), tree.try_leaf_at(p), "at {p:?}");
        }
    }

    fn moves() -> impl Strategy<Value = Vec<(usize, bool, u32)>> {
        proptest::collection::vec(
            (
                0usize..4,
                any::<bool>(),
                prop_oneof![4 => Just(0u32), 1 => 1u32..20],
            ),
            1..120,
        )
    }

    fn values(len: usize) -> impl Strategy<Value = Vec<Option<u8>>> {
        proptest::collection::vec(
            prop_oneof![3 => Just(None), 2 => Just(Some(1u8)), 1 => Just(Some(2u8))],
            len,
        )
    }

    proptest! {
        #[test]
        fn gives_the_descent_from_the_root_k1(d in values(16), m in moves()) { check::<1>(4, &d, &m); }
        #[test]
        fn gives_the_descent_from_the_root_k2(d in values(64), m in moves()) { check::<2>(3, &d, &m); }
        #[test]
        fn gives_the_descent_from_the_root_k3(d in values(512), m in moves()) { check::<3>(3, &d, &m); }
        #[test]
        fn gives_the_descent_from_the_root_k4(d in values(256), m in moves()) { check::<4>(2, &d, &m); }
    }

    #[test]
    fn a_uniform_tree_is_one_leaf() {
        let tree = KTree::<3, u8>::from_dense_values(2, &[Some(7); 64]).unwrap();
        let mut cursor = ValueCursor::new(&tree);
        assert_eq!(cursor.leaf_at([3, 3, 3]), Ok(Some((2, Some(7)))));
        assert_eq!(cursor.leaf_at([0, 1, 2]), Ok(Some((2, Some(7)))));
        assert_eq!(cursor.leaf_at([4, 0, 0]), Ok(None));
    }
}
