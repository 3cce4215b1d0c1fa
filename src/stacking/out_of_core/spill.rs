//! Spilling the stacked cells: each partial cell's subtree goes to the [`PieceStore`], one piece per
//! level below its root, and its place to the index that stays in memory.

use super::pieces::PieceStore;
use crate::stacking::cells::CellStates;
use crate::stacking::partition::Piece;
use crate::tree::NodeState;

/// The stacked cells, in the order they were spilled: Morton index and node count per subtree level
/// `1 … t` (0 beyond the subtree's depth).
#[derive(Default)]
pub(super) struct SubtreeIndex {
    pub(super) mortons: Vec<u64>,
    pub(super) counts: Vec<u64>,
}

/// Sets `offsets[s]` to the word offset of cell `s`'s piece in level `j + 1` of the store (pieces are in
/// the order the cells were spilled); returns the level's length in words.
pub(super) fn level_offsets(index: &SubtreeIndex, t: usize, j: usize, offsets: &mut [u64]) -> u64 {
    let mut at = 0u64;
    for (s, offset) in offsets.iter_mut().enumerate() {
        *offset = at;
        at += index.counts[s * t + j].div_ceil(32);
    }
    at
}

/// Records a non-empty cell of depth `m`, spilling the levels `1 … t` below its root to `store` if it is
/// partial; returns the words spilled.
pub(super) fn spill_piece<const K: usize, P: PieceStore>(
    store: &mut P,
    t: usize,
    cells: &mut CellStates,
    index: &mut SubtreeIndex,
    morton: u64,
    piece: Piece<K>,
) -> Result<u64, P::Error> {
    let tree = match piece {
        Piece::Full => {
            cells.set_full(morton);
            return Ok(0);
        }
        Piece::Tree(tree) => tree,
    };
    match tree.root_state() {
        NodeState::Empty => return Ok(0),
        NodeState::Full => {
            cells.set_full(morton);
            return Ok(0);
        }
        NodeState::Partial => {}
    }
    index.mortons.push(morton);
    let mut spilled = 0;
    for j in 1..=t {
        let nodes = if j < tree.depth_count() {
            let states = tree.level_states(j);
            let nodes = states.len() as u64;
            let words = &states.words()[..states.len().div_ceil(32)];
            store.append(j, words, nodes)?;
            spilled += words.len() as u64;
            nodes
        } else {
            0
        };
        index.counts.push(nodes);
    }
    Ok(spilled)
}
