//! Building a valued tree straight from a dense array of values: a cell whose voxels all hold one value
//! (or all the background) is a leaf; any other cell is built from its `2^K` children.
//! The array is read once in its own order (streamed, not visited cell by cell, the rows 16 KiB ahead
//! asked of memory while one is read), a row of bricks — cells of about 4096 voxels — at a time: which bricks
//! hold one value is noted, and the voxels of each other brick are gathered in Morton order as they are
//! read, from the first that differs from the brick's first voxel (all before it held that value); its
//! subtree is built bottom up once the row is read (each level settled from the one below). The cells
//! of bricks are then settled from their bricks, depth first, the bricks' subtrees copied in. The tree is
//! minimal by construction. The same tree as [`KTree::from_value_runs`] of the array's runs, without
//! making the runs.
//!
//! ```
//! use ktree::rays::ValueRuns;
//! use ktree::KTree;
//! let dense: Vec<u8> = (0..64u32).map(|i| if i % 5 == 0 { 0 } else { (i / 16) as u8 }).collect();
//! let tree = KTree::<3, u8>::from_dense_background(2, &dense, 0).unwrap();
//! let runs = ValueRuns::<3, u8>::from_dense_background(2, &dense, 0).unwrap();
//! assert_eq!(tree, KTree::from_value_runs(&runs));
//! ```

use std::sync::Mutex;

use rayon::prelude::*;

use super::prefetch::prefetch;
use crate::rays::source::default_split_depth;
use crate::rays::valued::check_dense_len;
use crate::rays::RayError;
use crate::space::{spread_bits, Cell, Universe};
use crate::tree::top_down::Subtree;
use crate::tree::valued::{combine, ValueState, ValuedLevel};
use crate::tree::words::{
    children_mask, full_count, EMPTY_CODE, FULL_CODE, MIXED_CODE, PARTIAL_CODE,
};
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

/// A dense array of values, the value that means empty, which of its bricks (cells of side
/// `2^brick_log`) hold one value throughout, and the subtrees of the others.
pub(super) struct Dense<'a, const K: usize, V> {
    universe: Universe<K>,
    dense: &'a [V],
    background: V,
    brick_log: u32,
    /// Each brick's value if all its voxels hold it, axis 0 fastest over the grid of bricks.
    bricks: Vec<Option<V>>,
    /// The subtree of each brick of several values, in the same order (`None` for a brick of one
    /// value, and for one holding a value [`Value::check`] refuses: that one is built cell by cell).
    trees: Vec<BrickSlot<V>>,
}

impl<'a, const K: usize, V: Value> Dense<'a, K, V> {
    /// The array's bricks read once, on the rayon pool: bricks of about 4096 voxels (no larger than the
    /// universe).
    pub(super) fn new(universe: Universe<K>, dense: &'a [V], background: V) -> Self {
        let brick_log = (12 / K as u32).min(universe.level());
        let (bricks, trees) = read_bricks::<K, V>(dense, universe.level(), brick_log, background);
        Self {
            universe,
            dense,
            background,
            brick_log,
            bricks,
            trees,
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
            return Ok(Subtree::from_chunks(root, levels));
        }
        let kids = (0..1usize << K)
            .into_par_iter()
            .map(|code| self.subtree(cell.child(code), split))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Subtree::join(kids))
    }

    /// Builds the subtree of `cell` (at `depth`): returns its state, its children (if any) pushed onto
    /// the level below in `levels` (each level a list of chunks, the last one open); a brick of several
    /// values as it was built when it was read, its levels appended to the open chunks.
    fn node(
        &self,
        cell: Cell<K>,
        depth: usize,
        levels: &mut [Vec<ValuedLevel<V>>],
    ) -> Result<ValueState<V>, RayError> {
        if let Some(leaf) = self.leaf(cell)? {
            return Ok(leaf);
        }
        if cell.log_side() == self.brick_log {
            let grid = (self.universe.side() >> self.brick_log) as usize;
            let index = cell
                .origin()
                .iter()
                .rev()
                .fold(0, |i, &c| i * grid + (c >> self.brick_log) as usize);
            let tree = self.trees[index]
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .take();
            if let Some(tree) = tree {
                let root = tree.root;
                tree.append_to::<K>(&mut levels[depth + 1..]);
                return Ok(root);
            }
        }
        let n = 1usize << K;
        let mut kids = [ValueState::Empty; 16];
        for (code, kid) in kids.iter_mut().enumerate().take(n) {
            *kid = self.node(cell.child(code), depth + 1, levels)?;
        }
        let state = combine(&kids[..n]);
        if state.has_children() {
            let level = &mut levels[depth + 1];
            match level.last_mut() {
                Some(chunk) => chunk.extend_from_slice(&kids[..n]),
                None => level.push(ValuedLevel::from_states(&kids[..n])),
            }
        }
        Ok(state)
    }
}

/// Where a brick's subtree waits, from the read of its row until the depth-first build reaches its
/// cell (on whichever thread).
type BrickSlot<V> = Mutex<Option<BrickTree<V>>>;

/// The subtree of a brick of several values: its root's state, the 2-bit codes of each level below it
/// in level order (the root's children first), each level from a word of its own, and the values of
/// their full nodes, level after level — two allocations however deep the brick.
struct BrickTree<V> {
    root: ValueState<V>,
    words: Vec<u64>,
    values: Vec<V>,
}

impl<V: Value> BrickTree<V> {
    /// Appends each level below the root to the last chunk of the matching level of `levels` (the
    /// root's children to `levels[0]`). A level's length is found from the one above: `2^K` nodes for
    /// each node with children.
    fn append_to<const K: usize>(self, levels: &mut [Vec<ValuedLevel<V>>]) {
        let (mut nodes, mut word, mut value) = (1usize << K, 0, 0);
        for level in levels {
            if nodes == 0 {
                break;
            }
            let words = &self.words[word..word + (2 * nodes).div_ceil(64)];
            let full: usize = words.iter().map(|&w| full_count(w) as usize).sum();
            let values = if V::STORED {
                &self.values[value..value + full]
            } else {
                &[]
            };
            if level.is_empty() {
                level.push(ValuedLevel::new());
            }
            if let Some(chunk) = level.last_mut() {
                chunk.append_words(words, nodes, values);
            }
            word += words.len();
            value += values.len();
            nodes = words
                .iter()
                .map(|&w| children_mask(w).count_ones() as usize)
                .sum::<usize>()
                << K;
        }
    }
}

/// The subtree of a brick of side `2^log` from its voxels in Morton order (so that a cell's `2^K`
/// children are consecutive), built bottom up: each level's cells settled from their children, then the
/// nodes of the tree taken top down, in `scratch` (kept from one brick to the next). Each cell is kept
/// as its 2-bit code and a value, so that settling and writing a node take no branch on its state.
/// `None` when a value is refused ([`Value::check`]).
fn brick_tree<const K: usize, V: Value>(
    voxels: &[V],
    log: usize,
    background: V,
    scratch: &mut BrickScratch<V>,
) -> Option<BrickTree<V>> {
    let n = 1usize << K;
    let BrickScratch {
        codes,
        values,
        words,
        full,
        parents,
        next,
    } = scratch;
    // The cells of side 2, then each level above appended after the one below it; `starts[j]` where
    // level j begins (level 0, the voxels, is `voxels`). A cell is settled by [`combine`]'s rule, on the
    // codes and values of its children rather than their states: a voxel's code is its state's,
    // `EMPTY_CODE` (0) or `FULL_CODE` (1), and `PARTIAL_CODE + 1` is `MIXED_CODE`.
    codes.clear();
    values.clear();
    codes.extend(voxels.chunks_exact(n).map(|kids| {
        let first = kids[0];
        let same = kids.iter().fold(true, |all, v| all & v.same(first));
        let any_empty = kids.iter().fold(false, |any, v| any | v.same(background));
        if same {
            u8::from(!first.same(background))
        } else {
            PARTIAL_CODE + u8::from(!any_empty)
        }
    }));
    values.extend(voxels.chunks_exact(n).map(|kids| kids[0]));
    let mut starts = [0usize; 32];
    for j in 2..=log {
        let below = starts[j - 1];
        starts[j] = codes.len();
        for i in (below..starts[j]).step_by(n) {
            let (kid_codes, kid_values) = (&codes[i..i + n], &values[i..i + n]);
            let first = kid_values[0];
            let all_full = kid_codes
                .iter()
                .fold(true, |all, &c| all & (c == FULL_CODE));
            let same = kid_values.iter().fold(true, |all, v| all & v.same(first));
            let empty = kid_codes
                .iter()
                .fold(true, |all, &c| all & (c == EMPTY_CODE));
            // Full or mixed: every voxel holds a value.
            let valued = kid_codes.iter().fold(true, |all, &c| all & (c & 1 == 1));
            codes.push(if all_full && same {
                FULL_CODE
            } else if empty {
                EMPTY_CODE
            } else if valued {
                MIXED_CODE
            } else {
                PARTIAL_CODE
            });
            values.push(first);
        }
    }
    let root = match codes[starts[log]] {
        EMPTY_CODE => ValueState::Empty,
        FULL_CODE => ValueState::Full(values[starts[log]]),
        PARTIAL_CODE => ValueState::Partial,
        _ => ValueState::Mixed,
    };
    // Top down: the children of the nodes with children, level by level, each child's code and (if it
    // is full) value written in place and counted in or not, rather than branched on. A block of
    // siblings' codes (`2n` bits, which divides 64) lies within one word.
    let bits = 2 * n;
    words.clear();
    parents.clear();
    parents.push(0);
    let mut kept = 0;
    for j in (0..log).rev() {
        let start = words.len();
        words.resize(start + (parents.len() * bits).div_ceil(64), 0);
        let level_words = &mut words[start..];
        if full.len() < kept + parents.len() * n {
            full.resize(kept + parents.len() * n, background);
        }
        if j == 0 {
            for (i, &p) in parents.iter().enumerate() {
                let mut packed = 0;
                for (c, &v) in voxels[p * n..p * n + n].iter().enumerate() {
                    let is_full = !v.same(background);
                    packed |= u64::from(is_full) << (2 * c);
                    full[kept] = v;
                    kept += usize::from(is_full);
                }
                level_words[i * bits / 64] |= packed << (i * bits % 64);
            }
        } else {
            next.clear();
            next.resize(parents.len() * n, 0);
            let mut with_children = 0;
            for (i, &p) in parents.iter().enumerate() {
                let at = starts[j] + p * n;
                let mut packed = 0;
                for (c, (&code, &v)) in codes[at..at + n]
                    .iter()
                    .zip(&values[at..at + n])
                    .enumerate()
                {
                    packed |= u64::from(code) << (2 * c);
                    full[kept] = v;
                    kept += usize::from(code == FULL_CODE);
                    next[with_children] = p * n + c;
                    with_children += usize::from(code >= PARTIAL_CODE);
                }
                level_words[i * bits / 64] |= packed << (i * bits % 64);
            }
            next.truncate(with_children);
        }
        std::mem::swap(parents, next);
        if j == 0 || parents.is_empty() {
            break;
        }
    }
    // Copied out of the scratch, which the next brick reuses.
    let full_values = if V::STORED {
        full[..kept].to_vec()
    } else {
        Vec::new()
    };
    if V::REFUSES {
        for v in &full_values {
            v.check().ok()?;
        }
    }
    Some(BrickTree {
        root,
        words: words.to_vec(),
        values: full_values,
    })
}

/// The memory a thread reads its rows of bricks in, kept from one row to the next: for each brick of
/// the row, where its voxels are copied (in Morton order) once it is found to hold several values, those
/// voxels, and the memory [`brick_tree`] works in.
struct RowScratch<V> {
    /// Each brick's place in `voxels` once one of its voxels differs from its first.
    mixed: Vec<Option<usize>>,
    /// The voxels of the row's bricks of several values, a brick after another.
    voxels: Vec<V>,
    brick: BrickScratch<V>,
}

impl<V> RowScratch<V> {
    fn new() -> Self {
        Self {
            mixed: Vec::new(),
            voxels: Vec::new(),
            brick: BrickScratch::new(),
        }
    }
}

/// The memory [`brick_tree`] works in, kept from one brick to the next: the cells above the voxels,
/// level after level (each one's code, and its value — the first voxel's, meaningful when it is full),
/// the subtree's codes and the values of its full nodes as they are found, and the nodes with children
/// of a level and of the next.
struct BrickScratch<V> {
    codes: Vec<u8>,
    values: Vec<V>,
    words: Vec<u64>,
    full: Vec<V>,
    parents: Vec<usize>,
    next: Vec<usize>,
}

impl<V> BrickScratch<V> {
    fn new() -> Self {
        Self {
            codes: Vec::new(),
            values: Vec::new(),
            words: Vec::new(),
            full: Vec::new(),
            parents: Vec::new(),
            next: Vec::new(),
        }
    }
}

/// The bricks of side `2^brick_log` of a dense array of `2^level` voxels a side (axis 0 fastest; the
/// bricks in the same order): each brick's first voxel's value if every voxel of the brick holds it,
/// else its subtree ([`brick_tree`]). The array is read once in its own order, a row of bricks at a
/// time — each row's pieces compared with the first voxels of their bricks, so that memory is streamed
/// rather than visited brick by brick, the row at least 16 KiB ahead [`prefetch`]ed meanwhile (rows of a
/// row of bricks lie a page or more apart every `brick` rows, which the processor's own prefetching does
/// not follow; one row ahead is too little time for memory to answer when rows are short). A brick's voxels
/// are gathered in Morton order from the piece where one first differs from its first voxel (those
/// before it all held the first voxel's value), so that no voxel is read twice; the row's bricks of
/// several values are built once the row is read. Slabs of bricks along the last axis run on the rayon
/// pool.
#[allow(clippy::type_complexity)]
fn read_bricks<const K: usize, V: Value>(
    dense: &[V],
    level: u32,
    brick_log: u32,
    background: V,
) -> (Vec<Option<V>>, Vec<BrickSlot<V>>) {
    let side = 1usize << level;
    let brick = 1usize << brick_log;
    let grid = side >> brick_log;
    let log = brick_log as usize;
    let uniform = |piece: &[V]| piece.iter().all(|v| v.same(piece[0])).then_some(piece[0]);
    if K == 1 {
        // A brick of a bintree is a piece of the array, already in Morton order.
        return dense
            .par_chunks(brick)
            .map_init(BrickScratch::new, |scratch, piece| match uniform(piece) {
                Some(v) => (Some(v), Mutex::new(None)),
                None => (
                    None,
                    Mutex::new(brick_tree::<K, V>(piece, log, background, scratch)),
                ),
            })
            .unzip();
    }
    let spread: Vec<usize> = (0..brick as u32)
        .map(|c| spread_bits::<K>(c) as usize)
        .collect();
    let brick_voxels = 1usize << (log * K);
    // A brick's rows along axis 0 in memory order (axis 1 fastest): each one's offset from the brick's
    // first voxel in the array and the Morton index of its first voxel in the brick.
    let brick_rows: Vec<(usize, usize)> = BoxRows::<K>::new(brick)
        .map(|o| {
            let morton = (1..K).fold(0, |m, a| m | spread[o[a]] << a);
            (row_offset(o, side), morton)
        })
        .collect();
    // Bricks a slab (one brick thick along the last axis) and voxels a slab; a row of bricks (along
    // axis 0) within a slab has rows of voxels at `brick^(K - 1)` offsets.
    let slab_bricks = grid.pow(K as u32 - 1);
    let slab_voxels = side.pow(K as u32 - 1) * brick;
    let rows_of_bricks = slab_bricks / grid;
    // The first voxel of a row of bricks in its slab: its coordinates along axes 1 … K − 2 are those of
    // the row of bricks times the brick's side.
    let corner_of = |row_of_bricks: usize| {
        let (mut corner, mut rest, mut step) = (0, row_of_bricks, side);
        for _ in 1..K - 1 {
            corner += (rest % grid) * brick * step;
            rest /= grid;
            step *= side;
        }
        corner
    };
    // Rows are asked for far enough ahead that memory has time to answer: at least 16 KiB ahead, and
    // no further than a brick's rows.
    let row_bytes = side * std::mem::size_of::<V>().max(1);
    let distance = 16384usize.div_ceil(row_bytes).clamp(1, brick_rows.len());
    let mut bricks: Vec<(V, bool)> = vec![(dense[0], true); grid.pow(K as u32)];
    let mut trees: Vec<BrickSlot<V>> = Vec::new();
    trees.resize_with(bricks.len(), || Mutex::new(None));
    bricks
        .par_chunks_mut(slab_bricks)
        .zip(trees.par_chunks_mut(slab_bricks))
        .zip(dense.par_chunks(slab_voxels))
        .for_each_init(RowScratch::new, |scratch, ((bricks, trees), voxels)| {
            for (row_of_bricks, (bricks, trees)) in bricks
                .chunks_exact_mut(grid)
                .zip(trees.chunks_exact_mut(grid))
                .enumerate()
            {
                let corner = corner_of(row_of_bricks);
                // Where the rows `distance` ahead begin: the rows of this row of bricks, then those
                // of the next one in the slab, if any.
                let next =
                    (row_of_bricks + 1 < rows_of_bricks).then(|| corner_of(row_of_bricks + 1));
                let ahead_of = |r: usize| match (brick_rows.get(r + distance), next) {
                    (Some(&(offset, _)), _) => corner + offset,
                    (None, Some(next)) => next + brick_rows[r + distance - brick_rows.len()].0,
                    // Past the end: no hint.
                    (None, None) => voxels.len(),
                };
                scratch.mixed.clear();
                scratch.mixed.resize(grid, None);
                scratch.voxels.clear();
                for (r, &(offset, morton)) in brick_rows.iter().enumerate() {
                    let start = corner + offset;
                    let row = &voxels[start..start + side];
                    // The row `distance` ahead, asked for piece by piece while this one is read.
                    let ahead = ahead_of(r);
                    for (b, (((first, uniform), mixed), piece)) in bricks
                        .iter_mut()
                        .zip(scratch.mixed.iter_mut())
                        .zip(row.chunks_exact(brick))
                        .enumerate()
                    {
                        prefetch(voxels, ahead + b * brick);
                        let at = match *mixed {
                            Some(at) => at,
                            None => {
                                if r == 0 {
                                    *first = piece[0];
                                }
                                let f = *first;
                                if piece.iter().fold(true, |all, v| all & v.same(f)) {
                                    continue;
                                }
                                // The brick's rows read so far all held `f`.
                                *uniform = false;
                                let at = scratch.voxels.len();
                                scratch.voxels.resize(at + brick_voxels, f);
                                *mixed = Some(at);
                                at
                            }
                        };
                        let gathered = &mut scratch.voxels[at..at + brick_voxels];
                        for (&v, &x) in piece.iter().zip(&spread) {
                            gathered[morton | x] = v;
                        }
                    }
                }
                for (&mixed, tree) in scratch.mixed.iter().zip(trees.iter_mut()) {
                    if let Some(at) = mixed {
                        let gathered = &scratch.voxels[at..at + brick_voxels];
                        *tree = Mutex::new(brick_tree::<K, V>(
                            gathered,
                            log,
                            background,
                            &mut scratch.brick,
                        ));
                    }
                }
            }
        });
    let bricks = bricks
        .into_iter()
        .map(|(first, uniform)| uniform.then_some(first))
        .collect();
    (bricks, trees)
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
    BoxRows::<K>::new(side)
        .all(|offset| {
            let start = first_index + row_offset(offset, grid);
            uniform(&data[start..start + side])
        })
        .then_some(first)
}

/// The rows along axis 0 of a cube of side `side` in `K` dimensions, in memory order (axis 1 fastest):
/// each row's offsets from the cube's corner along axes `1 … K − 1` (`[0]` is 0), counted like an
/// odometer.
pub(super) struct BoxRows<const K: usize> {
    next: Option<[usize; K]>,
    side: usize,
}

impl<const K: usize> BoxRows<K> {
    pub(super) fn new(side: usize) -> Self {
        Self {
            next: (side > 0).then_some([0; K]),
            side,
        }
    }
}

impl<const K: usize> Iterator for BoxRows<K> {
    type Item = [usize; K];

    #[inline]
    fn next(&mut self) -> Option<[usize; K]> {
        let row = self.next?;
        let mut offset = row;
        self.next = (1..K).find(|&a| offset[a] + 1 < self.side).map(|axis| {
            offset[axis] += 1;
            offset[1..axis].fill(0);
            offset
        });
        Some(row)
    }
}

/// The index, in an array of rows `stride` long (axis 0 fastest, every axis `stride` long), of the row at
/// `offset` along axes `1 … K − 1` from the array's start.
#[inline]
pub(super) fn row_offset<const K: usize>(offset: [usize; K], stride: usize) -> usize {
    (1..K).rev().fold(0, |at, a| (at + offset[a]) * stride)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ValueRuns;

    #[test]
    fn the_rows_of_a_cube_come_in_memory_order() {
        let rows: Vec<[usize; 3]> = BoxRows::<3>::new(2).collect();
        assert_eq!(rows, [[0, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1, 1]]);
        assert_eq!(BoxRows::<1>::new(8).count(), 1);
        assert_eq!(BoxRows::<4>::new(3).count(), 27);
        assert_eq!(BoxRows::<2>::new(0).count(), 0);
        assert_eq!(row_offset([0, 1, 1], 4), 4 + 16);
        assert_eq!(row_offset([0, 2, 0, 3], 5), 2 * 5 + 3 * 125);
    }

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

    /// Boxes of labels at random places over a universe of several bricks (splitmix64 from `seed`),
    /// some a single voxel, some a cube aligned to a brick: the tree of the runs, on every split.
    fn check_boxes<const K: usize>(level: u32, seed: u64) {
        let universe = Universe::<K>::new(level).unwrap();
        let side = universe.side() as u32;
        let mut state = seed;
        let mut next = move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let len = universe.side().pow(K as u32) as usize;
        let mut dense = vec![0u16; len];
        for b in 0..40 {
            let label = (next() % 4) as u16;
            let (lo, hi): ([u32; K], [u32; K]) = match b % 3 {
                0 => {
                    let p = [(); K].map(|_| (next() % u64::from(side)) as u32);
                    (p, p.map(|c| c + 1))
                }
                1 => {
                    let brick = 1 << (12 / K as u32).min(level);
                    let p = [(); K].map(|_| (next() % u64::from(side / brick)) as u32 * brick);
                    (p, p.map(|c| c + brick))
                }
                _ => {
                    let a = [(); K].map(|_| (next() % u64::from(side)) as u32);
                    let b = [(); K].map(|_| (next() % u64::from(side)) as u32);
                    (
                        std::array::from_fn(|i| a[i].min(b[i])),
                        std::array::from_fn(|i| a[i].max(b[i]) + 1),
                    )
                }
            };
            for (i, v) in dense.iter_mut().enumerate() {
                let p = universe.dense_point(i);
                if (0..K).all(|a| lo[a] <= p[a] && p[a] < hi[a]) {
                    *v = label;
                }
            }
        }
        let runs = ValueRuns::<K, u16>::from_dense_background(level, &dense, 0).unwrap();
        let want = KTree::from_value_runs(&runs);
        for split in [0, 1, 3] {
            let got = KTree::from_dense_background_split(universe, &dense, 0, split).unwrap();
            got.assert_well_formed();
            assert!(got == want, "K = {K}, seed {seed}, split {split}");
        }
    }

    #[test]
    fn boxes_over_several_bricks_are_the_tree_of_the_runs() {
        for seed in 0..6 {
            check_boxes::<1>(14, seed);
            check_boxes::<2>(7 + (seed % 2) as u32, seed);
            check_boxes::<3>(5 + (seed % 2) as u32, seed);
            check_boxes::<4>(4, seed);
        }
    }

    /// A NaN in a brick of several values is refused at the first voxel of its leaf: one voxel alone,
    /// or an aligned cube of NaNs with equal bits, whichever comes first depth first.
    #[test]
    fn nan_in_a_brick_of_several_values_is_refused_at_its_leaf() {
        let universe = Universe::<3>::new(6).unwrap();
        let len = universe.side().pow(3) as usize;
        let mut dense: Vec<f32> = (0..len).map(|i| (i % 3) as f32).collect();
        let lone = universe.dense_index([37, 21, 50]);
        dense[lone] = f32::NAN;
        let error = |dense: &[f32]| match KTree::<3, f32>::from_dense_background(6, dense, 0.0) {
            Err(RayError::Value { index, .. }) => index,
            other => panic!("a NaN accepted: {other:?}"),
        };
        assert_eq!(error(&dense), lone);
        // A cube of side 2 of NaNs ahead of it (depth first) is found first, at its origin.
        for p in [[2u32, 2, 2], [2, 2, 3], [2, 3, 2], [3, 3, 3]] {
            dense[universe.dense_index(p.map(|c| c + 16))] = f32::NAN;
        }
        for p in [[2u32, 3, 3], [3, 2, 2], [3, 2, 3], [3, 3, 2]] {
            dense[universe.dense_index(p.map(|c| c + 16))] = f32::NAN;
        }
        assert_eq!(error(&dense), universe.dense_index([18, 18, 18]));
        // As the background, NaN is no value.
        let tree = KTree::<3, f32>::from_dense_background(6, &dense, f32::NAN).unwrap();
        assert_eq!(tree.voxel_count(), len as u128 - 9);
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
