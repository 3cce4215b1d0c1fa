//! Building a valued tree straight from a dense array of values, depth first: a cell whose voxels all
//! hold one value (or all the background) is a leaf; any other cell is built from its `2^K` children.
//! The array is first read once in its own order (streamed, not visited cell by cell), noting which
//! bricks — cells of about 4096 voxels — hold one value; a cell of bricks is then settled from its
//! bricks, and a cell inside a brick of several values by comparing its rows of the fastest axis with its
//! first voxel (the first voxel that differs ends the comparison). So a volume of regions is read about
//! twice at most, and the tree is minimal by construction.
//! The same tree as [`KTree::from_value_runs`] of the array's runs, without making the runs.
//!
//! ```
//! use ktree::rays::ValueRuns;
//! use ktree::KTree;
//! let dense: Vec<u8> = (0..64u32).map(|i| if i % 5 == 0 { 0 } else { (i / 16) as u8 }).collect();
//! let tree = KTree::<3, u8>::from_dense_background(2, &dense, 0).unwrap();
//! let runs = ValueRuns::<3, u8>::from_dense_background(2, &dense, 0).unwrap();
//! assert_eq!(tree, KTree::from_value_runs(&runs));
//! ```

use rayon::prelude::*;

use crate::rays::source::default_split_depth;
use crate::rays::valued::check_dense_len;
use crate::rays::RayError;
use crate::space::{Cell, Universe};
use crate::tree::top_down::Subtree;
use crate::tree::valued::{combine, ValueState};
use crate::value::Value;
use crate::KTree;

impl<const K: usize, V: Value> KTree<K, V> {
    /// The minimal valued tree of a dense array of values (axis 0 fastest, see
    /// [`Universe::dense_index`]) where `background` means empty — a numpy or NIfTI volume as it is
    /// stored — built from the array directly on the threads of the current rayon pool (with more than
    /// one, the subtrees of cells of about 2^18 voxels apart). Equal to [`KTree::from_value_runs`] of
    /// [`ValueRuns::from_dense_background`](crate::rays::ValueRuns::from_dense_background).
    ///
    /// # Errors
    /// [`RayError::Space`] for a level beyond the largest, a universe beyond the dense limit or an array
    /// of another length; [`RayError::Value`] for a NaN (at the first voxel of the region holding it).
    pub fn from_dense_background(level: u32, dense: &[V], background: V) -> Result<Self, RayError> {
        let universe = Universe::<K>::new(level)?;
        check_dense_len(universe, dense.len())?;
        let split = if rayon::current_num_threads() > 1 {
            default_split_depth(K, level)
        } else {
            0
        };
        Self::from_dense_background_split(universe, dense, background, split)
    }

    /// [`KTree::from_dense_background`] of an array of the right length, the cells of depth `split`
    /// built apart.
    fn from_dense_background_split(
        universe: Universe<K>,
        dense: &[V],
        background: V,
        split: u32,
    ) -> Result<Self, RayError> {
        let source = Dense::new(universe, dense, background);
        Ok(source.subtree(universe.root(), split)?.into_tree(universe))
    }
}

/// A dense array of values, the value that means empty, and which of its bricks (cells of side
/// `2^brick_log`) hold one value throughout.
pub(super) struct Dense<'a, const K: usize, V> {
    universe: Universe<K>,
    dense: &'a [V],
    background: V,
    brick_log: u32,
    /// Each brick's value if all its voxels hold it, axis 0 fastest over the grid of bricks.
    bricks: Vec<Option<V>>,
}

impl<'a, const K: usize, V: Value> Dense<'a, K, V> {
    /// The array's bricks read once, on the rayon pool: bricks of about 4096 voxels (no larger than the
    /// universe).
    pub(super) fn new(universe: Universe<K>, dense: &'a [V], background: V) -> Self {
        let brick_log = (12 / K as u32).min(universe.level());
        let bricks = uniform_bricks::<K, V>(dense, universe.side() as usize, brick_log);
        Self {
            universe,
            dense,
            background,
            brick_log,
            bricks,
        }
    }

    /// The leaf `cell` is when all its voxels hold its first voxel's value (found from the bricks for a
    /// cell of bricks); `None` when it has children.
    fn leaf(&self, cell: Cell<K>) -> Result<Option<ValueState<V>>, RayError> {
        let origin = cell.origin().map(|c| c as usize);
        let value = if cell.log_side() >= self.brick_log {
            let grid = (self.universe.side() >> self.brick_log) as usize;
            let at = origin.map(|c| c >> self.brick_log);
            let side = (cell.side() >> self.brick_log) as usize;
            let same =
                |a: &Option<V>, b: &Option<V>| matches!((a, b), (Some(a), Some(b)) if a.same(*b));
            first_if_uniform(&self.bricks, grid, at, side, same).flatten()
        } else {
            let stride = self.universe.side() as usize;
            let side = cell.side() as usize;
            first_if_uniform(self.dense, stride, origin, side, |a, b| a.same(*b))
        };
        let Some(first) = value else {
            return Ok(None);
        };
        if first.same(self.background) {
            return Ok(Some(ValueState::Empty));
        }
        first.check().map_err(|error| RayError::Value {
            index: self.universe.dense_index(cell.origin()),
            error,
        })?;
        Ok(Some(ValueState::Full(first)))
    }

    /// The subtree of `cell`: its state and the states of each level below it (in level order), built
    /// apart on the rayon pool down to the cells of depth `split`.
    pub(super) fn subtree(&self, cell: Cell<K>, split: u32) -> Result<Subtree<V>, RayError>
    where
        V: Sync,
    {
        if let Some(leaf) = self.leaf(cell)? {
            return Ok(Subtree::leaf(leaf));
        }
        if cell.level() >= split {
            let mut levels = vec![Vec::new(); cell.log_side() as usize + 1];
            let root = self.node(cell, 0, &mut levels)?;
            levels.remove(0);
            return Ok(Subtree::new(root, levels));
        }
        let kids = (0..1usize << K)
            .into_par_iter()
            .map(|code| self.subtree(cell.child(code), split))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Subtree::join(kids))
    }

    /// Builds the subtree of `cell` (at `depth`): returns its state, its children (if any) pushed onto
    /// the level below in `levels`.
    fn node(
        &self,
        cell: Cell<K>,
        depth: usize,
        levels: &mut [Vec<ValueState<V>>],
    ) -> Result<ValueState<V>, RayError> {
        if let Some(leaf) = self.leaf(cell)? {
            return Ok(leaf);
        }
        let n = 1usize << K;
        let mut kids = [ValueState::Empty; 16];
        for (code, kid) in kids.iter_mut().enumerate().take(n) {
            *kid = self.node(cell.child(code), depth + 1, levels)?;
        }
        let state = combine(&kids[..n]);
        if state.has_children() {
            levels[depth + 1].extend_from_slice(&kids[..n]);
        }
        Ok(state)
    }
}

/// For each brick of side `2^brick_log` of a dense array of side `side` (axis 0 fastest; the bricks in the
/// same order), its first voxel's value if every voxel of the brick holds it. The array is read once in
/// its own order — each row's pieces compared with the first voxels of their bricks — so that memory is
/// streamed rather than visited brick by brick; slabs of bricks along the last axis run on the rayon pool.
fn uniform_bricks<const K: usize, V: Value>(
    dense: &[V],
    side: usize,
    brick_log: u32,
) -> Vec<Option<V>> {
    let brick = 1usize << brick_log;
    let grid = side >> brick_log;
    let uniform = |piece: &[V]| piece.iter().all(|v| v.same(piece[0])).then_some(piece[0]);
    if K == 1 {
        return dense.par_chunks(brick).map(uniform).collect();
    }
    // Bricks a slab (one brick thick along the last axis) and voxels a slab.
    let slab_bricks = grid.pow(K as u32 - 1);
    let slab_voxels = side.pow(K as u32 - 1) * brick;
    let mut bricks: Vec<(V, bool)> = vec![(dense[0], true); grid.pow(K as u32)];
    bricks
        .par_chunks_mut(slab_bricks)
        .zip(dense.par_chunks(slab_voxels))
        .for_each(|(bricks, voxels)| {
            for (r, row) in voxels.chunks_exact(side).enumerate() {
                // The row's coordinates along axes 1 … K − 1 (axis K − 1 within the slab).
                let (mut rest, mut first_row, mut brick_row, mut stride) = (r, true, 0, 1);
                for _ in 1..K {
                    let c = rest % side;
                    rest /= side;
                    first_row &= c & (brick - 1) == 0;
                    brick_row += (c >> brick_log) * stride;
                    stride *= grid;
                }
                let row_bricks = &mut bricks[brick_row * grid..(brick_row + 1) * grid];
                for ((first, uniform), piece) in row_bricks.iter_mut().zip(row.chunks_exact(brick))
                {
                    if first_row {
                        *first = piece[0];
                    }
                    let f = *first;
                    *uniform &= piece.iter().fold(true, |all, v| all & v.same(f));
                }
            }
        });
    bricks
        .into_iter()
        .map(|(first, uniform)| uniform.then_some(first))
        .collect()
}

/// The first item of the box of side `side` from `origin` in a grid of `grid` items a side (axis 0
/// fastest) if every item of the box is `same` as it; `None` at the first that is not. Rows along axis 0
/// are compared a chunk at a time, so that the compiler can compare a chunk's items together.
fn first_if_uniform<const K: usize, T: Copy>(
    data: &[T],
    grid: usize,
    origin: [usize; K],
    side: usize,
    same: impl Fn(&T, &T) -> bool,
) -> Option<T> {
    const CHUNK: usize = 8;
    let mut first_index = 0;
    for a in (0..K).rev() {
        first_index = first_index * grid + origin[a];
    }
    let first = data[first_index];
    let uniform = |row: &[T]| {
        let mut chunks = row.chunks_exact(CHUNK);
        let whole = chunks
            .by_ref()
            .all(|c| c.iter().fold(true, |all, v| all & same(v, &first)));
        whole && chunks.remainder().iter().all(|v| same(v, &first))
    };
    // Each row along axis 0: the other axes' offsets counted like an odometer.
    let mut offset = [0usize; K];
    loop {
        let mut start = first_index;
        let mut step = 1;
        for &o in &offset[1..] {
            step *= grid;
            start += o * step;
        }
        if !uniform(&data[start..start + side]) {
            return None;
        }
        let Some(axis) = (1..K).find(|&a| offset[a] + 1 < side) else {
            return Some(first);
        };
        offset[axis] += 1;
        offset[1..axis].fill(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ValueRuns;

    /// Regions of a few labels with scattered voxels, on every split depth: the tree of the runs.
    fn check<const K: usize>(level: u32) {
        let universe = Universe::<K>::new(level).unwrap();
        let len = universe.side().pow(K as u32) as usize;
        let dense: Vec<u16> = (0..len)
            .map(|i| {
                let p = universe.dense_point(i);
                let region = (p[0] * 2 / universe.side() as u32) as u16 + 1;
                if i.wrapping_mul(2_654_435_761) % 97 < 5 {
                    7
                } else if p[K - 1].is_multiple_of(5) {
                    0
                } else {
                    region
                }
            })
            .collect();
        let runs = ValueRuns::<K, u16>::from_dense_background(level, &dense, 0).unwrap();
        let want = KTree::from_value_runs(&runs);
        for split in 0..=level + 1 {
            let got = KTree::from_dense_background_split(universe, &dense, 0, split).unwrap();
            got.assert_well_formed();
            assert!(got == want, "K = {K}, split {split}");
        }
    }

    /// Universes of several bricks: some bricks of one value, some whose rows each hold one value but
    /// not the same one, a few scattered voxels in the first column of bricks.
    fn check_bricks<const K: usize>(level: u32) {
        let universe = Universe::<K>::new(level).unwrap();
        let bl = (12 / K as u32).min(level);
        assert!(level > bl, "more than one brick");
        let len = universe.side().pow(K as u32) as usize;
        let dense: Vec<u16> = (0..len)
            .map(|i| {
                let p = universe.dense_point(i);
                if p[0] >> bl == 0 && i.wrapping_mul(2_654_435_761) % 997 == 0 {
                    7
                } else if (p[0] >> bl).is_multiple_of(4) {
                    1 + ((p[K - 1] >> (bl - 1)) % 2) as u16
                } else if (p[0] >> bl) % 4 == 2 {
                    // The brick's first row alone differs.
                    let first = (1..K).all(|a| p[a].is_multiple_of(1 << bl));
                    5 + u16::from(first)
                } else {
                    3 + ((p[1 % K] >> bl) % 2) as u16
                }
            })
            .collect();
        let runs = ValueRuns::<K, u16>::from_dense_background(level, &dense, 0).unwrap();
        let want = KTree::from_value_runs(&runs);
        for split in [0, 2] {
            let got = KTree::from_dense_background_split(universe, &dense, 0, split).unwrap();
            got.assert_well_formed();
            assert!(got == want, "K = {K}, split {split}");
        }
    }

    #[test]
    fn bricks_of_one_value_are_found() {
        check_bricks::<1>(14);
        check_bricks::<2>(8);
        check_bricks::<3>(6);
        check_bricks::<4>(5);
    }

    #[test]
    fn every_split_builds_the_tree_of_the_runs() {
        check::<1>(7);
        check::<2>(5);
        check::<3>(4);
        check::<4>(3);
    }
}
