//! Building a valued tree from a dense volume read slab by slab along the last axis, in memory bounded by
//! one slab and the tree: a volume too large to hold (a segmentation of tens of gigabytes) is read once,
//! front to back, as it lies in its file.
//!
//! A slab is `2^s` voxels thick along the last axis; it is cut into cells of side `2^s` (depth `m = L −
//! s`), each built apart on the rayon pool as [`KTree::from_dense_background`] builds its cells. The cells
//! of one slab form a *layer*, in the Morton order of their coordinates along the other axes. Two layers of
//! one depth that are the lower and upper halves of the layer of the depth above join into it: the parent
//! of the cells `2^(K−1)·q … 2^(K−1)·q + 2^(K−1) − 1` of each is cell `q` of the joined layer, its children
//! in code order the lower layer's ones then the upper's (a child code's last bit is the upper half along
//! the last axis). Layers join like the digits of a binary counter as slabs arrive, so at most one layer of
//! each depth waits, and the last join is the root. A layer with nothing in it is kept as "all empty"
//! without its cells.

use std::ops::Range;

use rayon::prelude::*;

use super::dense_values::{row_offset, BoxRows, Dense};
use crate::rays::RayError;
use crate::space::{morton_decode, Universe};
use crate::tree::top_down::Subtree;
use crate::tree::valued::ValueState;
use crate::value::Value;
use crate::KTree;

/// At most `2^(K · m)` cells are built apart: `m ≤ MAX_CELL_BITS / K` (about 16 million cells).
pub(crate) const MAX_CELL_BITS: u32 = 24;

/// The cells of one slab (or of the joined slabs of a cell of the depth above): `None` when all are empty.
struct Layer<V> {
    depth: u32,
    cells: Option<Vec<Subtree<V>>>,
}

impl<const K: usize, V: Value> KTree<K, V> {
    /// The minimal valued tree of level `level` whose voxels inside `region` (a box: one range a
    /// coordinate, axis 0 first) hold the values `read` gives, `background` meaning empty, and whose voxels
    /// outside it are empty. The box is read slab by slab along the last axis, front to back:
    /// `read(range, out)` fills `out` with the values of the box's voxels whose last coordinate is in
    /// `range` (axis 0 fastest, as the box lies in a file: `out.len()` is the box's area across the last
    /// axis times `range.len()`). Each slab is as thick as fits in `slab_bytes` (a power of two; at least
    /// one voxel, and thick enough that at most about 16 million cells are built apart). Equal, node for
    /// node, to [`KTree::from_dense_background`] of the whole universe's array.
    ///
    /// ```
    /// use ktree::KTree;
    /// // A 6 × 5 box of labels at (1, 2) in a quadtree of level 3, read two rows at a time.
    /// let label = |x: u32, y: u32| ((x / 2 + y) % 3) as u8;
    /// let tree = KTree::<2, u8>::from_value_slabs(3, [1..7, 2..7], 0, 12, |rows, out| {
    ///     out.extend(rows.flat_map(|y| (1..7).map(move |x| label(x, y))));
    ///     Ok::<_, ktree::rays::RayError>(())
    /// })
    /// .unwrap();
    /// let dense: Vec<u8> = (0..64u32)
    ///     .map(|i| (i % 8, i / 8))
    ///     .map(|(x, y)| if (1..7).contains(&x) && (2..7).contains(&y) { label(x, y) } else { 0 })
    ///     .collect();
    /// assert_eq!(tree, KTree::from_dense_background(3, &dense, 0).unwrap());
    /// ```
    ///
    /// # Errors
    /// The first error of `read`; [`RayError::Space`] (through `From`) for a level beyond the largest or a
    /// box reaching outside the universe; [`RayError::Value`] for a NaN (`index` the voxel's position in the
    /// universe, axis 0 fastest); [`RayError::SlabLength`] for a slab of another length than its box.
    pub fn from_value_slabs<E: From<RayError>>(
        level: u32,
        region: [Range<u32>; K],
        background: V,
        slab_bytes: usize,
        read: impl FnMut(Range<u32>, &mut Vec<V>) -> Result<(), E>,
    ) -> Result<Self, E>
    where
        V: Send + Sync,
    {
        let slabs = ValueSlabs {
            level,
            region,
            background,
            slab_bytes,
        };
        let universe = slabs.check_box()?;
        let (mut read, mut slab) = (read, Vec::new());
        let root = slabs.join_slabs(|b| slabs.read_slab(universe, b, &mut read, &mut slab))?;
        Ok(root.into_tree(universe))
    }
}

/// A box of values in a universe, read slab by slab along the last axis, front to back: what
/// [`KTree::from_value_slabs`] builds a tree of in memory, and what [`ValueSlabs::build_into`] (and `io`'s
/// `ValueSlabs::write_file`) writes level by level with the cells' subtrees spilled, for trees larger
/// than memory.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueSlabs<const K: usize, V> {
    /// The universe's level.
    pub level: u32,
    /// The box read (one range a coordinate, axis 0 first); the voxels outside it are empty.
    pub region: [Range<u32>; K],
    /// The value meaning empty.
    pub background: V,
    /// The most bytes of values read at once (a slab is as thick as fits, a power of two; at least one
    /// voxel, and thick enough that at most about 16 million cells are built apart).
    pub slab_bytes: usize,
}

impl<const K: usize, V: Value + Send + Sync> ValueSlabs<K, V> {
    /// The depth `m` of the cells built apart (each of side `2^(L − m)`, one slab thick).
    pub(crate) fn cell_depth(&self) -> u32 {
        self.level - slab_log::<K, V>(self.level, &self.region, self.slab_bytes)
    }

    /// The number of slabs the universe is cut into along the last axis (`2^m`); slab `b` holds the
    /// voxels whose last coordinate is in `b · 2^(L − m) … (b + 1) · 2^(L − m) − 1`.
    pub fn slab_count(&self) -> u32 {
        1 << self.cell_depth()
    }

    /// The slabs that meet the box (the others are empty and never read).
    pub fn slabs_in_box(&self) -> Range<u32> {
        let s = self.level - self.cell_depth();
        let r = &self.region[K - 1];
        if self.region.iter().any(|r| r.is_empty()) {
            return 0..0;
        }
        (r.start >> s)..((r.end - 1) >> s) + 1
    }

    /// Refuses a box reaching outside the universe (or a level beyond the largest).
    pub(crate) fn check_box(&self) -> Result<Universe<K>, RayError> {
        let universe = Universe::<K>::new(self.level)?;
        let side = universe.side();
        let region = &self.region;
        if let Some(axis) =
            (0..K).find(|&a| region[a].start > region[a].end || u64::from(region[a].end) > side)
        {
            return Err(crate::space::SpaceError::OutOfUniverse {
                axis,
                value: u64::from(region[axis].end),
                side,
            }
            .into());
        }
        Ok(universe)
    }

    /// The cells of slab `b` (in the Morton order of their coordinates along the other axes), its rows of
    /// the box read into `slab` by `read`; `None` if the slab does not meet the box.
    pub(crate) fn read_slab<X: From<RayError>>(
        &self,
        universe: Universe<K>,
        b: u32,
        read: &mut impl FnMut(Range<u32>, &mut Vec<V>) -> Result<(), X>,
        slab: &mut Vec<V>,
    ) -> Result<Option<Vec<Subtree<V>>>, X> {
        let region = &self.region;
        let s = self.level - self.cell_depth();
        let z = (b << s)..((b + 1) << s);
        let rows = z.start.max(region[K - 1].start)..z.end.min(region[K - 1].end);
        if rows.is_empty() || region.iter().any(|r| r.is_empty()) {
            return Ok(None);
        }
        let area: usize = region[..K - 1].iter().map(|r| r.len()).product();
        slab.clear();
        let first = rows.start;
        read(rows.clone(), slab)?;
        if slab.len() != area * rows.len() {
            return Err(RayError::SlabLength {
                first,
                expected: area * rows.len(),
                got: slab.len(),
            }
            .into());
        }
        let view = SlabView {
            universe,
            region,
            rows,
            values: slab,
            background: self.background,
        };
        Ok(Some(view.cells(s, b)?))
    }

    /// Joins the layers of the slabs `0, 1, …` (`layer(b)`: slab `b`'s cells, `None` if all are empty)
    /// into the root's subtree ([`join_slabs`] at the cell depth).
    pub(crate) fn join_slabs<X>(
        &self,
        layer: impl FnMut(u32) -> Result<Option<Vec<Subtree<V>>>, X>,
    ) -> Result<Subtree<V>, X> {
        join_slabs::<K, V, X>(self.cell_depth(), layer)
    }
}

/// Joins the layers of the `2^m` slabs `0, 1, …` of cells of depth `m` (`layer(b)`: slab `b`'s cells in
/// the Morton order of their coordinates along the other axes, `None` if all are empty) into the root's
/// subtree, like the digits of a binary counter.
pub(crate) fn join_slabs<const K: usize, V: Value + Send, X>(
    m: u32,
    mut layer: impl FnMut(u32) -> Result<Option<Vec<Subtree<V>>>, X>,
) -> Result<Subtree<V>, X> {
    let mut pending: Vec<Layer<V>> = Vec::new();
    for b in 0..1u32 << m {
        pending.push(Layer {
            depth: m,
            cells: layer(b)?,
        });
        while pending.len() >= 2
            && pending[pending.len() - 2].depth == pending[pending.len() - 1].depth
        {
            let upper = pending.pop().expect("two layers");
            let lower = pending.pop().expect("two layers");
            pending.push(join_layers::<K, V>(lower, upper));
        }
    }
    let root = pending.pop().expect("the layers join into the root");
    debug_assert!(pending.is_empty() && root.depth == 0);
    Ok(match root.cells {
        None => Subtree::leaf(ValueState::Empty),
        Some(mut cells) => cells.pop().expect("the root layer holds one cell"),
    })
}

/// The thickness `2^s` of a slab: the largest that fits in `slab_bytes`, but no thinner than keeps the
/// cells built apart to `2^MAX_CELL_BITS`.
fn slab_log<const K: usize, V>(level: u32, region: &[Range<u32>; K], slab_bytes: usize) -> u32 {
    let area: u128 = region[..K - 1]
        .iter()
        .map(|r| r.len().max(1) as u128)
        .product();
    let row_bytes = area * std::mem::size_of::<V>().max(1) as u128;
    let mut s = 0;
    while s < level && row_bytes << (s + 1) <= slab_bytes as u128 {
        s += 1;
    }
    s.max(level.saturating_sub(MAX_CELL_BITS / K as u32))
}

/// One slab of the box held in memory: the rows `rows` along the last axis.
struct SlabView<'a, const K: usize, V> {
    universe: Universe<K>,
    region: &'a [Range<u32>; K],
    rows: Range<u32>,
    values: &'a [V],
    background: V,
}

impl<const K: usize, V: Value + Send + Sync> SlabView<'_, K, V> {
    /// The subtrees of the cells of side `2^s` of slab `b`, in the Morton order of their coordinates
    /// along axes `0 … K − 2`, built on the rayon pool.
    fn cells(&self, s: u32, b: u32) -> Result<Vec<Subtree<V>>, RayError> {
        let m = self.universe.level() - s;
        let count = 1u64 << (m * (K as u32 - 1));
        (0..count)
            .into_par_iter()
            .map(|i| {
                let mut origin = [0u32; K];
                if K > 1 {
                    let across = morton_decode::<K>(spread_across::<K>(i));
                    origin[..K - 1].copy_from_slice(&across[..K - 1]);
                }
                for c in &mut origin[..K - 1] {
                    *c <<= s;
                }
                origin[K - 1] = b << s;
                self.cell(origin, s)
            })
            .collect()
    }

    /// The subtree of the cell of side `2^s` at `origin`.
    fn cell(&self, origin: [u32; K], s: u32) -> Result<Subtree<V>, RayError> {
        let side = 1u32 << s;
        let meets = (0..K).all(|a| {
            let r = if a == K - 1 {
                &self.rows
            } else {
                &self.region[a]
            };
            r.start < origin[a] + side && origin[a] < r.end
        });
        if !meets {
            return Ok(Subtree::leaf(ValueState::Empty));
        }
        let cube_universe = Universe::<K>::new(s)?;
        let cube = self.cube(origin, side as usize);
        let dense = Dense::new(cube_universe, &cube, self.background);
        dense.subtree(cube_universe.root(), 0).map_err(|e| match e {
            RayError::Value { index, error } => {
                let mut point = cube_universe.dense_point(index);
                for (p, o) in point.iter_mut().zip(origin) {
                    *p += o;
                }
                RayError::Value {
                    index: self.universe.dense_index(point),
                    error,
                }
            }
            other => other,
        })
    }

    /// The values of the cell of side `side` at `origin` (axis 0 fastest), the background outside the box.
    fn cube(&self, origin: [u32; K], side: usize) -> Vec<V> {
        let mut cube = vec![self.background; side.pow(K as u32)];
        // The box's rows of this slab, and each axis's stride in the slab's values.
        let ranges: [Range<u32>; K] = std::array::from_fn(|a| {
            if a == K - 1 {
                self.rows.clone()
            } else {
                self.region[a].clone()
            }
        });
        let mut stride = [1usize; K];
        for a in 1..K {
            stride[a] = stride[a - 1] * ranges[a - 1].len();
        }
        let x = origin[0].max(ranges[0].start)..(origin[0] + side as u32).min(ranges[0].end);
        // Each row of the cube along axis 0.
        for offset in BoxRows::<K>::new(side) {
            let inside = (1..K).all(|a| ranges[a].contains(&(origin[a] + offset[a] as u32)));
            if inside {
                let mut from = (x.start - ranges[0].start) as usize;
                for a in 1..K {
                    from += (origin[a] + offset[a] as u32 - ranges[a].start) as usize * stride[a];
                }
                let to = (x.start - origin[0]) as usize + row_offset(offset, side);
                let n = x.len();
                cube[to..to + n].copy_from_slice(&self.values[from..from + n]);
            }
        }
        cube
    }
}

/// The Morton key, among cells of `K` dimensions, of the cell whose coordinates along axes `0 … K − 2`
/// have the `K − 1`-dimensional Morton key `key` and whose last coordinate is 0.
pub(crate) fn spread_across<const K: usize>(key: u64) -> u64 {
    let d = K as u64 - 1;
    let mut out = 0u64;
    let mut bit = 0;
    while bit < 64 && key >> bit != 0 {
        let (level, axis) = (bit / d, bit % d);
        out |= ((key >> bit) & 1) << (level * K as u64 + axis);
        bit += 1;
    }
    out
}

/// The layer of the depth above two layers of one depth, the lower and the upper half along the last axis.
fn join_layers<const K: usize, V: Value + Send>(lower: Layer<V>, upper: Layer<V>) -> Layer<V> {
    let depth = lower.depth - 1;
    let across = 1usize << (K - 1);
    let count = 1usize << (depth as usize * (K - 1));
    let empty = || {
        (0..count * across)
            .map(|_| Subtree::leaf(ValueState::Empty))
            .collect()
    };
    let cells = match (lower.cells, upper.cells) {
        (None, None) => None,
        (lower, upper) => {
            let lower: Vec<Subtree<V>> = lower.unwrap_or_else(empty);
            let upper: Vec<Subtree<V>> = upper.unwrap_or_else(empty);
            let mut lower = lower.into_iter();
            let mut upper = upper.into_iter();
            let joined = (0..count)
                .map(|_| {
                    let kids: Vec<Subtree<V>> = lower
                        .by_ref()
                        .take(across)
                        .chain(upper.by_ref().take(across))
                        .collect();
                    Subtree::join(kids)
                })
                .collect();
            Some(joined)
        }
    };
    Layer { depth, cells }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreading_keeps_the_last_axis_zero() {
        assert_eq!(spread_across::<3>(0b11), 0b011);
        assert_eq!(spread_across::<3>(0b100), 0b1000);
        assert_eq!(spread_across::<2>(0b101), 0b10001);
        assert_eq!(morton_decode::<3>(spread_across::<3>(0b1110)), [2, 3, 0]);
    }
}
