//! The states of the cells of depth `m` of a build that keeps no subtree: the top of the tree, kept
//! reduced as it is learnt.
//!
//! A cell of depth `m` is empty, full or partial (its subtree stacked and spilled). The cells arrive slab
//! by slab, out of Morton order; most of a solid's cells are full and interior. They are kept as a sorted
//! list of disjoint aligned *blocks* — a full block of depth `d ≤ m` stands for its `2^(K·(m − d))` full
//! cells — and the list is reduced as the Morton order is filled in: `2^K` sibling full blocks become
//! their parent. So the memory follows the top of the tree (the partial cells and the boundary of what
//! is full), not the volume: a ball's full interior costs a few blocks per slab of cells still to be
//! merged with its neighbours, whatever `L`.

use crate::tree::{NodeState, PackedStates};

/// Bytes accounted for each block of cells held: the block (16 bytes) and its copies while the list is
/// reduced and while the top levels are made from it at the end.
pub(crate) const CELL_BYTES: u64 = 48;

/// Cells added before the list is reduced again, at least (and at least a quarter of the list).
const MIN_PENDING: usize = 1 << 12;

/// An aligned block of cells of depth `m`, all of one state: the Morton index (among the cells of depth
/// `m`) of its first cell, its depth `d ≤ m` (it holds `2^(K·(m − d))` cells) and its state (full, or
/// partial for a single cell whose subtree was stacked).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CellBlock {
    pub(crate) first: u64,
    pub(crate) depth: u32,
    pub(crate) state: NodeState,
}

/// Two blocks of cells overlap: a cell was given twice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Overlap;

/// The full cells of depth `m`, as a reduced list of blocks plus the cells added since it was last
/// reduced (the partial cells are listed apart, with their subtrees).
#[derive(Debug)]
pub(crate) struct CellStates {
    k: u32,
    m: u32,
    /// Sorted, disjoint, reduced (no `2^K` full siblings).
    blocks: Vec<CellBlock>,
    /// Added since the last reduction, in any order.
    pending: Vec<CellBlock>,
}

impl CellStates {
    /// No cell of depth `m` (in `k` dimensions) yet.
    pub(crate) fn new(k: u32, m: u32) -> Self {
        Self {
            k,
            m,
            blocks: Vec::new(),
            pending: Vec::new(),
        }
    }

    /// The number of cells a block of depth `depth` holds.
    fn span(&self, depth: u32) -> u64 {
        1u64 << (self.k * (self.m - depth))
    }

    /// Records that cell `index` is full (it was not given before).
    ///
    /// # Panics
    /// If the cell was given before (found when the list is next reduced).
    pub(crate) fn set_full(&mut self, index: u64) {
        self.pending.push(CellBlock {
            first: index,
            depth: self.m,
            state: NodeState::Full,
        });
        if self.pending.len() >= MIN_PENDING.max(self.blocks.len() / 4) {
            self.reduce().expect("each cell is recorded once");
        }
    }

    /// Adds blocks (of another part of the same build) and reduces the list.
    ///
    /// # Errors
    /// [`Overlap`] if a block overlaps one already held; the states are then unusable.
    pub(crate) fn add_blocks(
        &mut self,
        blocks: impl IntoIterator<Item = CellBlock>,
    ) -> Result<(), Overlap> {
        self.pending.extend(blocks);
        self.reduce()
    }

    /// The blocks held (not necessarily reduced, in no particular order).
    pub(crate) fn held(&self) -> impl Iterator<Item = &CellBlock> {
        self.blocks.iter().chain(&self.pending)
    }

    /// The blocks, reduced.
    #[cfg(test)]
    fn blocks(&mut self) -> &[CellBlock] {
        self.reduce().expect("each cell is recorded once");
        &self.blocks
    }

    /// Merges the pending cells into the list and reduces it.
    fn reduce(&mut self) -> Result<(), Overlap> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let mut pending = std::mem::take(&mut self.pending);
        pending.sort_unstable_by_key(|b| b.first);
        let old = std::mem::take(&mut self.blocks);
        let mut out = Vec::with_capacity(old.len() + pending.len());
        let (mut a, mut b) = (old.into_iter().peekable(), pending.into_iter().peekable());
        loop {
            let next = match (a.peek(), b.peek()) {
                (Some(x), Some(y)) if x.first <= y.first => a.next(),
                (Some(_), None) => a.next(),
                (_, Some(_)) => b.next(),
                (None, None) => break,
            };
            self.push_reduced(&mut out, next.expect("peeked"))?;
        }
        self.blocks = out;
        Ok(())
    }

    /// Appends `block` (starting at or after the last block's start) to the sorted list `out`, merging
    /// full siblings into their parent.
    fn push_reduced(&self, out: &mut Vec<CellBlock>, block: CellBlock) -> Result<(), Overlap> {
        if let Some(last) = out.last() {
            if last.first + self.span(last.depth) > block.first {
                return Err(Overlap);
            }
        }
        out.push(block);
        let fanout = 1usize << self.k;
        loop {
            let n = out.len();
            let top = out[n - 1];
            if top.state != NodeState::Full || top.depth == 0 || n < fanout {
                return Ok(());
            }
            let parent_span = self.span(top.depth - 1);
            let first = out[n - fanout].first;
            // `2^K` disjoint full blocks of the top's depth from the parent's start to its end are its
            // children.
            let siblings = first.is_multiple_of(parent_span)
                && top.first + self.span(top.depth) - first == parent_span
                && out[n - fanout..]
                    .iter()
                    .all(|b| b.state == NodeState::Full && b.depth == top.depth);
            if !siblings {
                return Ok(());
            }
            out.truncate(n - fanout);
            out.push(CellBlock {
                first,
                depth: top.depth - 1,
                state: NodeState::Full,
            });
        }
    }

    /// The bytes accounted for the cells once `more` further cells are added.
    pub(crate) fn bytes_with(&self, more: usize) -> u64 {
        (self.blocks.len() + self.pending.len() + more) as u64 * CELL_BYTES
    }

    /// The bytes accounted for the cells.
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes_with(0)
    }

    /// The top levels `0 … m` of the tree (fewer where the top collapses), with the partial cells
    /// `partial` (Morton indexes, increasing).
    ///
    /// # Errors
    /// [`Overlap`] if a partial cell is given twice or lies in a full block.
    pub(crate) fn into_top_levels(mut self, partial: &[u64]) -> Result<Vec<PackedStates>, Overlap> {
        self.reduce()?;
        let full = std::mem::take(&mut self.blocks);
        let mut blocks = Vec::with_capacity(full.len() + partial.len());
        let (mut i, mut j) = (0, 0);
        while i < full.len() || j < partial.len() {
            let next = if j == partial.len() || (i < full.len() && full[i].first <= partial[j]) {
                i += 1;
                full[i - 1]
            } else {
                j += 1;
                CellBlock {
                    first: partial[j - 1],
                    depth: self.m,
                    state: NodeState::Partial,
                }
            };
            if let Some(last) = blocks.last() {
                let last: &CellBlock = last;
                if last.first + self.span(last.depth) > next.first {
                    return Err(Overlap);
                }
            }
            blocks.push(next);
        }
        drop(full);
        Ok(top_levels_of_blocks(self.k, self.m, &blocks))
    }
}

/// The levels `0 … m` of a tree (fewer where the top collapses), finished, from the blocks of its
/// non-empty cells of depth `m` in `k` dimensions (sorted, disjoint): a node whose `2^k` children are all
/// full is full, any other node with a non-empty child is partial, absent children are empty.
pub(crate) fn top_levels_of_blocks(k: u32, m: u32, blocks: &[CellBlock]) -> Vec<PackedStates> {
    // The non-empty nodes of each depth 0 … m, as (index at that depth, state), sorted: the blocks of that
    // depth and the parents of the nodes below.
    let mut by_depth: Vec<Vec<(u64, NodeState)>> = vec![Vec::new(); m as usize + 1];
    for b in blocks {
        by_depth[b.depth as usize].push((b.first >> (k * (m - b.depth)), b.state));
    }
    let mut pyramid: Vec<Vec<(u64, NodeState)>> = vec![Vec::new(); m as usize + 1];
    pyramid[m as usize] = std::mem::take(&mut by_depth[m as usize]);
    for d in (0..m as usize).rev() {
        let below = &pyramid[d + 1];
        let mut parents: Vec<(u64, NodeState)> = Vec::with_capacity(below.len() >> k);
        let mut at = 0;
        while at < below.len() {
            let parent = below[at].0 >> k;
            let mut end = at;
            while end < below.len() && below[end].0 >> k == parent {
                end += 1;
            }
            let full = end - at == 1 << k && below[at..end].iter().all(|c| c.1 == NodeState::Full);
            let state = if full {
                NodeState::Full
            } else {
                NodeState::Partial
            };
            parents.push((parent, state));
            at = end;
        }
        let own = std::mem::take(&mut by_depth[d]);
        let mut merged = Vec::with_capacity(parents.len() + own.len());
        let (mut i, mut j) = (0, 0);
        while i < parents.len() || j < own.len() {
            if j == own.len() || (i < parents.len() && parents[i].0 < own[j].0) {
                merged.push(parents[i]);
                i += 1;
            } else {
                merged.push(own[j]);
                j += 1;
            }
        }
        pyramid[d] = merged;
    }
    // Levels 0 … m: the root, then the children of each partial node, in order (absent ones empty).
    let mut levels = Vec::new();
    let mut root = PackedStates::with_capacity(1);
    root.push(pyramid[0].first().map_or(NodeState::Empty, |r| r.1));
    levels.push(root);
    for d in 0..m as usize {
        let mut next = PackedStates::new();
        let children = &pyramid[d + 1];
        let mut at = 0;
        for &(i, s) in &pyramid[d] {
            if s != NodeState::Partial {
                continue;
            }
            for c in i << k..(i + 1) << k {
                while at < children.len() && children[at].0 < c {
                    at += 1;
                }
                match children.get(at) {
                    Some(&(ci, cs)) if ci == c => next.push(cs),
                    _ => next.push(NodeState::Empty),
                }
            }
        }
        if next.is_empty() {
            break;
        }
        levels.push(next);
    }
    for l in &mut levels {
        l.finish();
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The top levels from every cell given singly (the reference) and from the reduced list agree, and
    /// the list of a solid block of cells reduces to one block.
    #[test]
    fn reduced_blocks_make_the_same_top_levels() {
        let (k, m) = (2u32, 4u32);
        let mut lcg = crate::testing::Lcg(11);
        for round in 0..50u64 {
            let mut single = Vec::new();
            let mut partial = Vec::new();
            for i in 0..1u64 << (k * m) {
                let x = lcg.next_u64();
                // One full quadrant; elsewhere mostly full cells, some partial and empty ones.
                let state = match (i >> 6 == round % 4, (x >> 33) % 16) {
                    (true, _) | (false, 1..=9) => NodeState::Full,
                    (false, 0) => NodeState::Partial,
                    _ => continue,
                };
                if state == NodeState::Partial {
                    partial.push(i);
                }
                single.push(CellBlock {
                    first: i,
                    depth: m,
                    state,
                });
            }
            // Given out of order.
            let mut shuffled = single.clone();
            shuffled.sort_by_key(|b| b.first.reverse_bits() ^ round);
            let mut cells = CellStates::new(k, m);
            for b in shuffled.iter().filter(|b| b.state == NodeState::Full) {
                cells.set_full(b.first);
            }
            let reduced = cells.blocks().to_vec();
            assert!(
                reduced.iter().any(|b| b.depth < m),
                "a full quadrant reduces"
            );
            assert!(reduced.len() + partial.len() < single.len());
            assert_eq!(
                cells.into_top_levels(&partial).unwrap(),
                top_levels_of_blocks(k, m, &single)
            );
        }
        let mut cells = CellStates::new(3, 3);
        for i in (0..512).rev() {
            cells.set_full(i);
        }
        assert_eq!(
            cells.blocks(),
            &[CellBlock {
                first: 0,
                depth: 0,
                state: NodeState::Full
            }]
        );
    }

    #[test]
    fn a_cell_given_twice_is_an_overlap() {
        let quadrant = CellBlock {
            first: 4,
            depth: 1,
            state: NodeState::Full,
        };
        let mut cells = CellStates::new(2, 2);
        cells.set_full(5);
        assert_eq!(cells.add_blocks([quadrant]), Err(Overlap));
        let mut cells = CellStates::new(2, 2);
        cells.add_blocks([quadrant]).unwrap();
        assert_eq!(cells.into_top_levels(&[6]), Err(Overlap));
        let cells = CellStates::new(2, 2);
        assert_eq!(cells.into_top_levels(&[6, 6]), Err(Overlap));
    }
}
