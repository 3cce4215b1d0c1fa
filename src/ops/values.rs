//! Operations on valued trees ([`KTree`] with a [`Value`] type): selecting the voxels of a value or a range
//! (a binary tree), masking by a binary tree, overlaying and combining two valued trees by a [`Rule`],
//! mapping values (a relabelling, a threshold), and per-value statistics in one walk.
//!
//! Every operation that makes a tree descends its inputs together and builds a minimal tree from the top
//! down ([`build_top_down`]); its cost is the nodes of the inputs it reads, and a subtree an input leaf
//! decides is never visited.
//!
//! ```
//! use ktree::ops::values::Rule;
//! use ktree::KTree;
//! let a = KTree::<1, u8>::from_dense_values(2, &[Some(1), Some(1), None, Some(4)]).unwrap();
//! let b = KTree::<1, u8>::from_dense_values(2, &[None, Some(3), Some(3), Some(2)]).unwrap();
//! assert_eq!(a.select(1), KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap());
//! let max = a.combine(&b, Rule::Max).unwrap();
//! assert_eq!(max.to_dense_values().unwrap(), [Some(1), Some(3), Some(3), Some(4)]);
//! assert_eq!(a.overlay(&b).unwrap().to_dense_values().unwrap(), [Some(1), Some(3), Some(3), Some(2)]);
//! ```

use std::collections::BTreeMap;

use super::OpsError;
use crate::rays::ValueRuns;
use crate::space::Cell;
use crate::tree::storage::infallible;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::{BinaryValues, ValueState, ValueStorage};
use crate::tree::{TreeError, Value};
use crate::KTree;
use crate::Ray;

/// How [`KTree::combine`] makes a voxel's value where both trees have one (where only one has a value, the
/// voxel takes it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rule {
    /// The first tree's value.
    First,
    /// The smaller value (channel by channel for colours).
    Min,
    /// The larger value.
    Max,
    /// The sum, saturating for integers.
    Sum,
}

impl Rule {
    /// The rule of a name: `first`, `min`, `max` or `sum`.
    pub fn parse(name: &str) -> Option<Rule> {
        Some(match name {
            "first" => Rule::First,
            "min" => Rule::Min,
            "max" => Rule::Max,
            "sum" => Rule::Sum,
            _ => return None,
        })
    }

    /// Both values combined.
    #[inline]
    pub fn apply<V: Value>(self, a: V, b: V) -> V {
        match self {
            Rule::First => a,
            Rule::Min => a.min_value(b),
            Rule::Max => a.max_value(b),
            Rule::Sum => a.sum_value(b),
        }
    }
}

/// A leaf's value as a decision, or `None` where the node has children.
#[inline]
fn leaf<V: Copy>(state: ValueState<V>) -> Option<Option<V>> {
    match state {
        ValueState::Empty => Some(None),
        ValueState::Full(v) => Some(Some(v)),
        ValueState::Partial | ValueState::Mixed => None,
    }
}

/// The binary tree of the voxels of `tree` whose value `keep` accepts, on any valued storage.
///
/// # Errors
/// The storage's read error.
pub fn select_where<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    keep: impl Fn(T::Value) -> bool,
) -> Result<KTree<K>, T::Error> {
    let out = build_top_down::<K, (), _, Failure<T::Error>>(
        tree.level(),
        InputNode::root(tree)?,
        |_, node| {
            Ok(match leaf(node.state) {
                Some(v) => Decision::Leaf(v.filter(|&v| keep(v)).map(|_| ())),
                None => Decision::Split,
            })
        },
        |node, code| node.child(tree, code).map_err(Failure::Read),
    );
    out.map_err(Failure::into_read)
}

/// The valued tree of `f` applied to every value of `tree` (`None`: the voxel becomes empty), on any
/// valued storage.
///
/// # Errors
/// [`MapError::Read`] for the storage's read error; [`MapError::Tree`] for a value no voxel may hold (a
/// NaN).
pub fn map_values<const K: usize, T: ValueStorage<K>, W: Value>(
    tree: &T,
    f: impl Fn(T::Value) -> Option<W>,
) -> Result<KTree<K, W>, MapError<T::Error>> {
    let out = build_top_down::<K, W, _, Failure<T::Error>>(
        tree.level(),
        InputNode::root(tree).map_err(MapError::Read)?,
        |_, node| {
            Ok(match leaf(node.state) {
                Some(v) => Decision::Leaf(v.and_then(&f)),
                None => Decision::Split,
            })
        },
        |node, code| node.child(tree, code).map_err(Failure::Read),
    );
    out.map_err(Failure::into_map)
}

/// Why an operation over a storage failed: a read or the tree it made.
#[derive(Debug, thiserror::Error)]
pub enum MapError<E> {
    /// The storage's read error.
    #[error(transparent)]
    Read(E),
    /// A value no voxel may hold, or another tree error.
    #[error(transparent)]
    Tree(#[from] TreeError),
}

/// The builder's error inside an operation: a read of an input or the tree's.
#[derive(Debug)]
pub(crate) enum Failure<E> {
    Read(E),
    Tree(TreeError),
}

impl<E> From<TreeError> for Failure<E> {
    fn from(e: TreeError) -> Self {
        Failure::Tree(e)
    }
}

impl<E> Failure<E> {
    /// The read error of an operation whose tree cannot be refused (its values are its input's).
    pub(crate) fn into_read(self) -> E {
        match self {
            Failure::Read(e) => e,
            Failure::Tree(e) => unreachable!("a tree of input values or none is valid: {e}"),
        }
    }

    fn into_map(self) -> MapError<E> {
        match self {
            Failure::Read(e) => MapError::Read(e),
            Failure::Tree(e) => MapError::Tree(e),
        }
    }
}

impl<const K: usize, V: Value> KTree<K, V> {
    /// The binary tree of the voxels holding `value`.
    pub fn select(&self, value: V) -> KTree<K> {
        infallible(select_where(self, |v| v.same(value)))
    }

    /// The binary tree of the voxels whose value lies in `[lo, hi]` (both included; on every channel for
    /// colours).
    pub fn select_range(&self, lo: V, hi: V) -> KTree<K> {
        infallible(select_where(self, |v| v.in_range(lo, hi)))
    }

    /// The values of `f` applied to every value (`None`: the voxel becomes empty): a relabelling, a
    /// quantization, a threshold to a binary tree (`W = ()`).
    ///
    /// ```
    /// use ktree::KTree;
    /// let density = KTree::<1, f32>::from_dense_values(1, &[Some(0.2), Some(0.9)]).unwrap();
    /// let dense: KTree<1> = density.map_values(|d| (d > 0.5).then_some(())).unwrap();
    /// assert_eq!(dense, KTree::<1>::from_dense(1, &[false, true]).unwrap());
    /// ```
    ///
    /// # Errors
    /// [`TreeError::Value`] if `f` gives a NaN.
    pub fn map_values<W: Value>(
        &self,
        f: impl Fn(V) -> Option<W>,
    ) -> Result<KTree<K, W>, TreeError> {
        map_values(self, f).map_err(|e| match e {
            MapError::Read(never) => match never {},
            MapError::Tree(e) => e,
        })
    }

    /// Each value replaced by its entry of `table` (keyed by [`Value::key`]); a value without one is kept.
    ///
    /// ```
    /// use std::collections::HashMap;
    /// use ktree::KTree;
    /// let labels = KTree::<1, u8>::from_dense_values(1, &[Some(1), Some(2)]).unwrap();
    /// let merged = labels.relabel(&HashMap::from([(2, Some(1))])).unwrap();
    /// assert_eq!(merged.node_count(), 1);
    /// ```
    ///
    /// # Errors
    /// [`TreeError::Value`] for a NaN in the table.
    pub fn relabel(
        &self,
        table: &std::collections::HashMap<V::Key, Option<V>>,
    ) -> Result<KTree<K, V>, TreeError> {
        self.map_values(|v| table.get(&v.key()).copied().unwrap_or(Some(v)))
    }

    /// The values of the voxels inside `mask`; the others empty.
    pub fn mask(&self, mask: &KTree<K>) -> KTree<K, V> {
        let out = build_top_down::<K, V, _, TreeError>(
            self.level(),
            (
                infallible(InputNode::root(self)),
                infallible(InputNode::root(&BinaryValues(mask))),
            ),
            |_, (node, m)| {
                Ok(match (m.state, leaf(node.state)) {
                    (ValueState::Empty, _) | (_, Some(None)) => Decision::Leaf(None),
                    (ValueState::Full(()), Some(v)) => Decision::Leaf(v),
                    _ => Decision::Split,
                })
            },
            |(node, m), code| {
                Ok((
                    infallible(node.child(self, code)),
                    infallible(m.child(&BinaryValues(mask), code)),
                ))
            },
        );
        out.expect("a tree of the input's values is valid")
    }

    /// The two trees' values voxel by voxel: where both hold a value, `rule` makes it; where one does, the
    /// voxel takes that one.
    ///
    /// # Errors
    /// [`OpsError::LevelMismatch`] for trees of different levels; [`OpsError::Value`] if a sum of floats is
    /// a NaN (`inf + -inf`).
    pub fn combine(&self, other: &KTree<K, V>, rule: Rule) -> Result<KTree<K, V>, OpsError> {
        if other.level() != self.level() {
            return Err(OpsError::LevelMismatch {
                left: self.level(),
                right: other.level(),
            });
        }
        let out = build_top_down::<K, V, _, TreeError>(
            self.level(),
            (
                infallible(InputNode::root(self)),
                infallible(InputNode::root(other)),
            ),
            |_, (a, b)| {
                Ok(match (leaf(a.state), leaf(b.state)) {
                    (Some(x), Some(y)) => Decision::Leaf(match (x, y) {
                        (Some(x), Some(y)) => Some(rule.apply(x, y)),
                        (x, y) => x.or(y),
                    }),
                    // The first tree's full leaf over the other's subtree decides it alone.
                    (Some(Some(x)), None) if rule == Rule::First => Decision::Leaf(Some(x)),
                    _ => Decision::Split,
                })
            },
            |(a, b), code| {
                Ok((
                    infallible(a.child(self, code)),
                    infallible(b.child(other, code)),
                ))
            },
        );
        out.map_err(|e| match e {
            TreeError::Value(e) => OpsError::Value(e),
            e => unreachable!("a combination of two trees' values is a valid tree: {e}"),
        })
    }

    /// `other`'s values where it has them, this tree's elsewhere.
    ///
    /// # Errors
    /// [`OpsError::LevelMismatch`] for trees of different levels.
    pub fn overlay(&self, other: &KTree<K, V>) -> Result<KTree<K, V>, OpsError> {
        other.combine(self, Rule::First)
    }

    /// The values at `points` (`None` where a voxel is empty or outside the universe), on the threads of
    /// the current rayon pool.
    ///
    /// ```
    /// use ktree::KTree;
    /// let t = KTree::<1, u8>::from_dense_values(2, &[Some(5), Some(5), None, Some(6)]).unwrap();
    /// assert_eq!(t.values_at(&[[0], [2], [3], [9]]), [Some(5), None, Some(6), None]);
    /// ```
    pub fn values_at(&self, points: &[[u32; K]]) -> Vec<Option<V>> {
        crate::tree::storage::infallible(crate::query::values_at(self, points))
    }

    /// [`KTree::values_at`] written into `out`, one entry a point (a buffer kept from batch to batch).
    ///
    /// ```
    /// use ktree::KTree;
    /// let t = KTree::<1, u8>::from_dense_values(1, &[Some(5), None]).unwrap();
    /// let mut out = vec![None; 2];
    /// t.values_at_into(&[[0], [1]], &mut out);
    /// assert_eq!(out, [Some(5), None]);
    /// ```
    ///
    /// # Panics
    /// If `out` and `points` differ in length.
    pub fn values_at_into(&self, points: &[[u32; K]], out: &mut [Option<V>]) {
        crate::tree::storage::infallible(crate::query::values_at_into(self, points, out));
    }

    /// The tree as valued runs along the last axis: each full leaf's columns, one run each (touching runs
    /// of one value are not joined; [`KTree::from_value_runs`] gives this tree back).
    pub fn to_value_runs(&self) -> ValueRuns<K, V> {
        let mut runs = Vec::new();
        for (cell, value) in self.value_leaves() {
            let Some(value) = value else { continue };
            let side = cell.side() as u32;
            for_each_column(&cell, |start| {
                runs.push((Ray::new(start, start[K - 1] + side), value))
            });
        }
        ValueRuns::from_runs(self.level(), runs)
            .expect("a tree's leaves are disjoint runs of valid values")
    }

    /// The tree moved by `t` voxels (any integer vector, negative allowed); voxels moved out of the
    /// universe are lost.
    ///
    /// ```
    /// use ktree::KTree;
    /// let t = KTree::<1, u8>::from_dense_values(2, &[Some(5), Some(6), None, None]).unwrap();
    /// assert_eq!(t.translate_values([1]).to_dense_values().unwrap(), [None, Some(5), Some(6), None]);
    /// assert_eq!(t.translate_values([-1]).to_dense_values().unwrap(), [Some(6), None, None, None]);
    /// ```
    pub fn translate_values(&self, t: [i64; K]) -> KTree<K, V> {
        let side = self.universe().side() as i64;
        let mut runs = Vec::new();
        for (cell, value) in self.value_leaves() {
            let Some(value) = value else { continue };
            let s = cell.side() as i64;
            // The cell's box moved and clipped to the universe; nothing left: dropped.
            let lo: [i64; K] = std::array::from_fn(|a| (i64::from(cell.origin[a]) + t[a]).max(0));
            let hi: [i64; K] =
                std::array::from_fn(|a| (i64::from(cell.origin[a]) + s + t[a]).min(side));
            if (0..K).any(|a| lo[a] >= hi[a]) {
                continue;
            }
            let origin: [u32; K] = std::array::from_fn(|a| lo[a] as u32);
            let extent: [u32; K] = std::array::from_fn(|a| (hi[a] - lo[a]) as u32);
            for_each_column_of_box(&origin, &extent, |start| {
                runs.push((Ray::new(start, start[K - 1] + extent[K - 1]), value))
            });
        }
        let runs = ValueRuns::from_runs(self.level(), runs).expect("moved leaves stay disjoint");
        KTree::from_value_runs(&runs)
    }

    /// For each value, its voxels, bounding box, centroid and surface area, in one walk of the leaves (and
    /// one selection per value for the surface area).
    pub fn value_stats(&self) -> BTreeMap<V::Key, ValueStats<K, V>> {
        let mut stats: BTreeMap<V::Key, ValueStats<K, V>> = BTreeMap::new();
        for (cell, value) in self.value_leaves() {
            if let Some(v) = value {
                stats
                    .entry(v.key())
                    .or_insert_with(|| ValueStats::new(v))
                    .add(&cell);
            }
        }
        for (key, faces) in self.faces_per_value() {
            if let Some(s) = stats.get_mut(&key) {
                s.surface_area = faces;
            }
        }
        stats
    }

    /// The unit faces of each value's voxels that meet a voxel of another value, an empty voxel or the
    /// universe's edge, all values at once: along each axis, every maximal run of one value (the leaves'
    /// columns along that axis, sorted and joined where they touch with the same value) has two such
    /// faces.
    fn faces_per_value(&self) -> BTreeMap<V::Key, u128> {
        let level = self.level();
        let mut faces: BTreeMap<V::Key, u128> = BTreeMap::new();
        let mut runs: Vec<(u64, u32, u32, V::Key)> = Vec::new();
        for axis in 0..K {
            runs.clear();
            for (cell, value) in self.value_leaves() {
                let Some(v) = value else { continue };
                let side = cell.side() as u32;
                let start = cell.origin[axis];
                // Every line of the cell along `axis`: an odometer over the other axes.
                let mut offset = [0u32; K];
                'lines: loop {
                    let column = (0..K).filter(|&a| a != axis).fold(0u64, |key, a| {
                        (key << level) | u64::from(cell.origin[a] + offset[a])
                    });
                    runs.push((column, start, start + side, v.key()));
                    for a in (0..K).filter(|&a| a != axis) {
                        offset[a] += 1;
                        if offset[a] < side {
                            continue 'lines;
                        }
                        offset[a] = 0;
                    }
                    break;
                }
            }
            runs.sort_unstable_by_key(|r| (r.0, r.1));
            let mut previous: Option<(u64, u32, V::Key)> = None;
            for &(column, start, end, key) in &runs {
                let joined =
                    previous.is_some_and(|(c, e, k)| c == column && e == start && k == key);
                if !joined {
                    *faces.entry(key).or_default() += 2;
                }
                previous = Some((column, end, key));
            }
        }
        faces
    }
}

/// Calls `f` with the first voxel of every column (line along the last axis) of `cell`.
fn for_each_column<const K: usize>(cell: &Cell<K>, f: impl FnMut([u32; K])) {
    let side = cell.side() as u32;
    for_each_column_of_box(&cell.origin, &[side; K], f);
}

/// Calls `f` with the first voxel of every column of the box at `origin` of sides `extent`.
fn for_each_column_of_box<const K: usize>(
    origin: &[u32; K],
    extent: &[u32; K],
    mut f: impl FnMut([u32; K]),
) {
    let mut offset = [0u32; K];
    loop {
        f(std::array::from_fn(|a| origin[a] + offset[a]));
        // Odometer over the first K − 1 axes.
        let mut axis = 0;
        loop {
            if axis + 1 >= K {
                return;
            }
            offset[axis] += 1;
            if offset[axis] < extent[axis] {
                break;
            }
            offset[axis] = 0;
            axis += 1;
        }
    }
}

/// What [`KTree::value_stats`] measures of one value.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueStats<const K: usize, V> {
    /// The value.
    pub value: V,
    /// The number of voxels holding it.
    pub voxels: u128,
    /// The box `[lo, hi)` of those voxels.
    pub bounding_box: ([u32; K], [u32; K]),
    /// The mean of their centres (voxel `v`'s centre is `v + 0.5`).
    pub centroid: [f64; K],
    /// The number of voxel faces between a voxel of the value and one without it (empty, another value or
    /// outside the universe).
    pub surface_area: u128,
    sums: [f64; K],
}

impl<const K: usize, V: Value> ValueStats<K, V> {
    fn new(value: V) -> Self {
        Self {
            value,
            voxels: 0,
            bounding_box: ([u32::MAX; K], [0; K]),
            centroid: [0.0; K],
            surface_area: 0,
            sums: [0.0; K],
        }
    }

    fn add(&mut self, cell: &Cell<K>) {
        let side = cell.side() as u32;
        let voxels = 1u128 << (K * side.trailing_zeros() as usize);
        self.voxels += voxels;
        for a in 0..K {
            self.bounding_box.0[a] = self.bounding_box.0[a].min(cell.origin[a]);
            self.bounding_box.1[a] = self.bounding_box.1[a].max(cell.origin[a] + side);
            self.sums[a] += voxels as f64 * (f64::from(cell.origin[a]) + f64::from(side) / 2.0);
        }
        let n = self.voxels as f64;
        self.centroid = std::array::from_fn(|a| self.sums[a] / n);
    }
}
