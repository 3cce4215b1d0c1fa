//! Morton-partitioned stacking: a tree is its top `m` levels plus, level by level, the concatenation of the
//! subtrees of the cells of depth `m`; each subtree is stacked from its cell's rays alone.
//!
//! # Why it works
//! In level order, the nodes of the subtree under a cell of depth `m` are contiguous at every level, and the
//! subtrees of consecutive cells (Morton order) follow one another. So the level `m + j` of the tree is the
//! concatenation, in Morton order of the cells, of the levels `j` of their subtrees; the top `m` levels
//! follow from the cells' root states alone (a node whose `2^K` children are all full, or all empty, is a
//! leaf: a uniform top collapses). The rays of a cell are its columns' runs clipped to the cell's range
//! along the last axis ([`RaySet::cell_rays`]).
//!
//! # How it runs
//! The columns are cut into *slabs* along axis 0 (one cell wide) and each slab into *blocks* (one cell wide
//! along every column axis); the runs of a block are cut along the last axis into its `2^m` cells in one
//! pass: a cell all of whose columns cross it entirely is a full leaf and a cell no run meets is an empty
//! one — neither is stacked nor even receives its runs. Only the cells the object's boundary passes through
//! are stacked, each in lists sized to fit in cache. Slabs are independent and run on all threads of the
//! current rayon pool; the result does not depend on the number of threads. Levels are joined by bulk,
//! bit-shifted copies of the 2-bit words.
//!
//! Sources other than a whole [`RaySet`] (solids generating their rays slab by slab) implement
//! [`RaySource`].

use rayon::prelude::*;

use super::bitmap::stack_bitmap;
use super::cells::{top_levels_of_blocks, CellBlock};
use super::paper::stack;
use super::CellStacking;
pub use crate::rays::source::default_split_depth;
use crate::rays::{ColumnKeys, RaySet, RaySource, SlabRuns};
use crate::space::{morton_encode, Universe};
use crate::tree::words::LevelWords;
use crate::tree::{KTree, NodeState, PackedStates};

/// Builds the tree of `source` from the subtrees of its cells of depth `depth` (clamped to `L`), each
/// stacked apart as `cells` says, on the threads of the current rayon pool. Equal, node for node, to
/// [`paper::stack`](super::paper::stack) of the same rays.
///
/// # Errors
/// The first error of the source (in slab order).
pub(crate) fn stack_source<const K: usize, S: RaySource<K>>(
    source: &S,
    depth: u32,
    cells: CellStacking,
) -> Result<KTree<K>, S::Error> {
    let universe = source.universe();
    let level = universe.level();
    let m = depth.min(level);
    let slabs = if K == 1 {
        vec![0]
    } else {
        source.occupied_slabs(m)
    };
    let pieces = slabs
        .into_par_iter()
        .map(|b0| stack_slab(source, m, b0, cells))
        .collect::<Result<Vec<_>, _>>()?;
    let mut pieces: Vec<(u64, Piece<K>)> = pieces.into_iter().flatten().collect();
    pieces.sort_unstable_by_key(|p| p.0);
    Ok(join_pieces(universe, m, pieces))
}

/// A non-empty cell of depth `m`: wholly full, or a stacked subtree.
#[derive(Debug)]
pub(super) enum Piece<const K: usize> {
    Full,
    Tree(KTree<K>),
}

/// Stacks the cells of slab `b0` (all of them for `K = 1`); returns the non-empty ones with their Morton
/// index among the cells of depth `m`.
fn stack_slab<const K: usize, S: RaySource<K>>(
    source: &S,
    m: u32,
    b0: u32,
    cells: CellStacking,
) -> Result<Vec<(u64, Piece<K>)>, S::Error> {
    let level = source.universe().level();
    let t = level - m;
    let side = 1u32 << t;
    let slab = source.slab(b0 * side..(b0 + 1) * side)?;
    Ok(slab_pieces(&slab, level, m, b0, cells))
}

/// The non-empty cells of slab `b0` (all cells for `K = 1`) from its runs, with their Morton index among
/// the cells of depth `m`, the mixed cells stacked.
pub(super) fn slab_pieces<const K: usize>(
    slab: &SlabRuns<'_>,
    level: u32,
    m: u32,
    b0: u32,
    cells: CellStacking,
) -> Vec<(u64, Piece<K>)> {
    let t = level - m;
    let side = 1u32 << t;
    let (keys, runs) = (&slab.keys[..], &slab.runs[..]);
    let mut out = Vec::new();
    if runs.is_empty() {
        return out;
    }
    if K == 1 {
        let block = Block {
            keys: vec![0; runs.len()],
            runs: runs.to_vec(),
        };
        split_block::<K>(&block, m, t, [0; K], cells, &mut out);
        return out;
    }
    // Bucket the slab's runs by block (the cell coordinates along axes 1 … K−2), keeping their order, with
    // column keys made local to the block.
    let columns = ColumnKeys::<K>::new(level);
    let local_mask = u64::from(side) - 1;
    let blocks_per_slab = 1usize << ((K - 2) as u32 * m);
    if blocks_per_slab > runs.len().max(64) {
        return stack_sparse_slab(keys, runs, level, m, b0, cells);
    }
    let mut block_of = Vec::with_capacity(runs.len());
    let mut counts = vec![0usize; blocks_per_slab + 1];
    for &key in keys {
        let mut b = 0usize;
        for a in 1..K - 1 {
            b = b << m | (columns.axis(key, a) >> t) as usize;
        }
        block_of.push(b);
        counts[b + 1] += 1;
    }
    for i in 0..blocks_per_slab {
        counts[i + 1] += counts[i];
    }
    let starts = counts.clone();
    let mut local = vec![(0u64, (0u32, 0u32)); runs.len()];
    for (i, (&key, &run)) in keys.iter().zip(runs).enumerate() {
        let mut lk = 0u64;
        for a in 0..K - 1 {
            lk = lk << t | (u64::from(columns.axis(key, a)) & local_mask);
        }
        let at = &mut counts[block_of[i]];
        local[*at] = (lk, run);
        *at += 1;
    }
    let mut block = Block::default();
    for b in 0..blocks_per_slab {
        let part = &local[starts[b]..starts[b + 1]];
        if part.is_empty() {
            continue;
        }
        block.keys.clear();
        block.runs.clear();
        block.keys.extend(part.iter().map(|p| p.0));
        block.runs.extend(part.iter().map(|p| p.1));
        let mut cell = [0u32; K];
        cell[0] = b0;
        for a in (1..K - 1).rev() {
            cell[a] = ((b >> ((K - 2 - a) as u32 * m)) & ((1 << m) - 1)) as u32;
        }
        split_block::<K>(&block, m, t, cell, cells, &mut out);
    }
    out
}

/// [`stack_slab`] for a slab with many more blocks than runs: the runs are sorted by block instead of
/// counted into every block.
fn stack_sparse_slab<const K: usize>(
    keys: &[u64],
    runs: &[(u32, u32)],
    level: u32,
    m: u32,
    b0: u32,
    cells: CellStacking,
) -> Vec<(u64, Piece<K>)> {
    let t = level - m;
    let columns = ColumnKeys::<K>::new(level);
    let local_mask = (1u64 << t) - 1;
    // (block coordinates on axes 1 … K−2, position) sorts by block, keeping the order within a block.
    let mut order: Vec<(u64, usize)> = keys
        .iter()
        .enumerate()
        .map(|(i, &key)| {
            let b = (1..K - 1).fold(0u64, |b, a| b << m | u64::from(columns.axis(key, a)) >> t);
            (b, i)
        })
        .collect();
    order.sort_unstable();
    let mut out = Vec::new();
    let mut block = Block::default();
    let mut at = 0;
    while at < order.len() {
        let b = order[at].0;
        block.keys.clear();
        block.runs.clear();
        while at < order.len() && order[at].0 == b {
            let i = order[at].1;
            let lk = (0..K - 1).fold(0u64, |lk, a| {
                lk << t | (u64::from(columns.axis(keys[i], a)) & local_mask)
            });
            block.keys.push(lk);
            block.runs.push(runs[i]);
            at += 1;
        }
        let mut cell = [0u32; K];
        cell[0] = b0;
        for a in (1..K - 1).rev() {
            cell[a] = ((b >> ((K - 2 - a) as u32 * m)) & ((1 << m) - 1)) as u32;
        }
        split_block::<K>(&block, m, t, cell, cells, &mut out);
    }
    out
}

/// The runs of one block of columns: keys local to the block (`t` bits an axis), global `z`.
#[derive(Debug, Default)]
struct Block {
    keys: Vec<u64>,
    runs: Vec<(u32, u32)>,
}

/// Cuts a block's runs into its `2^m` cells along the last axis and stacks the mixed ones. `cell` holds the block's cell coordinates on the column axes.
fn split_block<const K: usize>(
    block: &Block,
    m: u32,
    t: u32,
    mut cell: [u32; K],
    cells: CellStacking,
    out: &mut Vec<(u64, Piece<K>)>,
) {
    let columns = 1u64 << (t as usize * (K - 1));
    let (full, mixed) = classify_cells(&block.runs, m, t, columns);
    for j in full {
        cell[K - 1] = j as u32;
        out.push((morton_encode(cell), Piece::Full));
    }
    let low = (1u32 << t) - 1;
    if mixed.is_empty() {
        return;
    }
    // Hand each mixed cell its clipped runs, in order.
    let mut parts: Vec<Block> = (0..mixed.len()).map(|_| Block::default()).collect();
    for (&key, &(z1, z2)) in block.keys.iter().zip(&block.runs) {
        let (a, b) = ((z1 >> t) as usize, ((z2 - 1) >> t) as usize);
        let from = mixed.partition_point(|&j| j < a);
        for (i, &j) in mixed[from..].iter().enumerate() {
            if j > b {
                break;
            }
            let lo = (j as u32) << t;
            let part = &mut parts[from + i];
            part.keys.push(key);
            part.runs.push((z1.max(lo) - lo, z2.min(lo + low + 1) - lo));
        }
    }
    let universe = Universe::<K>::new(t).expect("a cell's level is a valid level");
    for (&j, part) in mixed.iter().zip(parts) {
        let rays = RaySet::from_sorted_parts(universe, part.keys, part.runs, None);
        let tree = match cells {
            CellStacking::Bitmap => stack_bitmap(&rays),
            CellStacking::Lists => stack(&rays),
        };
        cell[K - 1] = j as u32;
        out.push((morton_encode(cell), Piece::Tree(tree)));
    }
}

/// Sorts the `2^m` cells of a block (along the last axis) by what its runs make of them: returns the
/// cells all of whose `columns` columns cross them entirely (full) and those some run enters, leaves or
/// crosses without all columns doing so (mixed), each in increasing order. The other cells are empty.
fn classify_cells(runs: &[(u32, u32)], m: u32, t: u32, columns: u64) -> (Vec<usize>, Vec<usize>) {
    let low = (1u32 << t) - 1;
    // Changes of the number of columns crossing a cell entirely, and the cells a run end cuts.
    let mut changes: Vec<(usize, i64)> = Vec::with_capacity(2 * runs.len());
    let mut cuts = Vec::new();
    for &(z1, z2) in runs {
        let (a, b) = ((z1 >> t) as usize, ((z2 - 1) >> t) as usize);
        let full_from = if z1 & low == 0 { a } else { a + 1 };
        let full_to = if z2 & low == 0 { b + 1 } else { b };
        if full_from < full_to {
            changes.push((full_from, 1));
            changes.push((full_to, -1));
        }
        if z1 & low != 0 {
            cuts.push(a);
        }
        if z2 & low != 0 {
            cuts.push(b);
        }
    }
    let (mut full, mut mixed) = (Vec::new(), Vec::new());
    let cells = 1usize << m;
    if cells <= 4 * runs.len() + 64 {
        // Dense: a count per cell.
        let mut diff = vec![0i64; cells + 1];
        let mut cut = vec![false; cells];
        for &(j, d) in &changes {
            diff[j] += d;
        }
        for &j in &cuts {
            cut[j] = true;
        }
        let mut crossing = 0i64;
        for j in 0..cells {
            crossing += diff[j];
            if cut[j] || (crossing > 0 && (crossing as u64) < columns) {
                mixed.push(j);
            } else if crossing as u64 == columns {
                full.push(j);
            }
        }
        return (full, mixed);
    }
    // Sparse: sweep the sorted changes and cuts.
    changes.sort_unstable();
    cuts.sort_unstable();
    cuts.dedup();
    let mut points: Vec<usize> = changes
        .iter()
        .map(|c| c.0)
        .chain(cuts.iter().copied())
        .collect();
    points.sort_unstable();
    points.dedup();
    let (mut ci, mut ki) = (0, 0);
    let mut crossing = 0i64;
    for (p, &from) in points.iter().enumerate() {
        while ci < changes.len() && changes[ci].0 == from {
            crossing += changes[ci].1;
            ci += 1;
        }
        let is_cut = ki < cuts.len() && cuts[ki] == from;
        if is_cut {
            ki += 1;
        }
        // From `from` up to the next point the count is constant (and no cell is cut).
        let to = points.get(p + 1).copied().unwrap_or(cells).min(cells);
        if is_cut || (crossing > 0 && (crossing as u64) < columns) {
            mixed.push(from);
        } else if crossing > 0 && crossing as u64 == columns {
            full.push(from);
        }
        if crossing > 0 && (crossing as u64) < columns {
            mixed.extend(from + 1..to);
        } else if crossing > 0 && crossing as u64 == columns {
            full.extend(from + 1..to);
        }
    }
    (full, mixed)
}

/// The tree from its non-empty cells of depth `m` (sorted by Morton index).
fn join_pieces<const K: usize>(
    universe: Universe<K>,
    m: u32,
    pieces: Vec<(u64, Piece<K>)>,
) -> KTree<K> {
    let base: Vec<CellBlock> = pieces
        .iter()
        .filter_map(|(i, p)| {
            let state = match p {
                Piece::Full => NodeState::Full,
                Piece::Tree(t) => t.root_state(),
            };
            (state != NodeState::Empty).then_some(CellBlock {
                first: *i,
                depth: m,
                state,
            })
        })
        .collect();
    let mut levels = top_levels_of_blocks(K as u32, m, &base);
    // Levels m + 1 …: the concatenation of the subtrees' levels 1 …, in Morton order.
    let trees: Vec<&KTree<K>> = pieces
        .iter()
        .filter_map(|(_, p)| match p {
            Piece::Tree(t) if t.root_state() == NodeState::Partial => Some(t),
            _ => None,
        })
        .collect();
    let deepest = trees.iter().map(|t| t.depth_count()).max().unwrap_or(0);
    let deeper: Vec<PackedStates> = (1..deepest)
        .into_par_iter()
        .map(|j| {
            let mut out = LevelWords::default();
            for t in trees.iter().filter(|t| t.depth_count() > j) {
                let s = t.level_states(j);
                out.append_words(s.words(), s.len());
            }
            into_states(out)
        })
        .collect();
    levels.extend(deeper);
    KTree::from_levels(universe, levels)
}

/// The level of concatenated subtree levels.
fn into_states(level: LevelWords) -> PackedStates {
    let (words, len) = level.into_words();
    PackedStates::from_words(words, len).expect("concatenated levels hold valid 2-bit codes")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_words_concatenate_like_pushes() {
        let mut lcg = crate::testing::Lcg(7);
        let mut expected = PackedStates::new();
        let mut joined = LevelWords::default();
        for n in [0usize, 1, 31, 32, 33, 5, 64, 100, 3] {
            let mut part = PackedStates::new();
            for _ in 0..n {
                let s = NodeState::from_code(lcg.below(3) as u8).unwrap();
                part.push(s);
                expected.push(s);
            }
            part.finish();
            joined.append_words(part.words(), part.len());
        }
        expected.finish();
        assert_eq!(into_states(joined), expected);
    }
}
