//! Building a level-order `KTree` from a depth-first (pre-order) stream of nodes or from full cells.
//!
//! In a depth-first traversal that visits children in child-code order, the nodes of each level appear in
//! the same order as in level order. So a pre-order stream is turned into level order by appending each node
//! to the array of its depth: no sorting, no pointers.

use super::cursor::subtree_ranges;
use super::ktree::KTree;
use super::states::{NodeState, PackedStates};
use super::words::LevelWords;
use super::TreeError;
use crate::space::{Cell, DimCheck, SpaceError, Universe};

/// Collects a tree from its nodes in depth-first order (children in child-code order). The caller
/// guarantees a complete traversal of a reduced tree.
#[derive(Debug, Clone)]
pub struct TreeAssembler<const K: usize> {
    universe: Universe<K>,
    levels: LevelWriter,
}

impl<const K: usize> TreeAssembler<K> {
    /// An assembler for a universe of level `level`.
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`] for a level beyond [`crate::max_level`].
    pub fn new(level: u32) -> Result<Self, SpaceError> {
        let () = DimCheck::<K>::OK;
        Ok(Self {
            universe: Universe::new(level)?,
            levels: LevelWriter::new(),
        })
    }

    /// Appends the next node of the depth-first traversal at `depth`.
    #[inline]
    pub fn push(&mut self, depth: usize, state: NodeState) {
        self.levels.push(depth, state);
    }

    /// The tree. The caller is responsible for having pushed a complete traversal; [`KTree::check`]
    /// verifies it.
    pub fn finish(mut self) -> KTree<K> {
        if self.levels.is_empty() {
            self.push(0, NodeState::Empty);
        }
        KTree::from_levels(self.universe, self.levels.finish())
    }
}

/// The one writer of tree levels: 2-bit states appended per level, in words, with whole blocks of
/// siblings and whole subtrees (contiguous ranges at every level) appended as bit-shifted word copies.
/// Writing the nodes of a depth-first traversal, each at its depth, yields level order.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelWriter {
    levels: Vec<LevelWords>,
}

impl LevelWriter {
    /// An empty writer.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// Whether nothing was written.
    pub(crate) fn is_empty(&self) -> bool {
        self.levels.iter().all(|l| l.len() == 0)
    }

    #[inline]
    fn level(&mut self, depth: usize) -> &mut LevelWords {
        if self.levels.len() <= depth {
            self.levels.resize_with(depth + 1, LevelWords::default);
        }
        &mut self.levels[depth]
    }

    /// Appends a node at `depth`.
    #[inline]
    pub(crate) fn push(&mut self, depth: usize, state: NodeState) {
        self.level(depth).push(state as u64, 1);
    }

    /// Appends `slots ≤ 32` states packed in the low bits of `chunk` (higher bits clear) at `depth`.
    #[inline]
    pub(crate) fn append_word(&mut self, depth: usize, chunk: u64, slots: usize) {
        self.level(depth).push(chunk, slots);
    }

    /// Appends the descendants of node `index` at `depth` of `tree` (not the node itself), the node's
    /// depth written as `to_depth`, leaves complemented if `invert`; returns the node's state
    /// (complemented if `invert` and a leaf), for the caller to write. One bit-shifted word copy per level.
    pub(crate) fn copy_subtree<const K: usize>(
        &mut self,
        tree: &KTree<K>,
        depth: usize,
        index: usize,
        to_depth: usize,
        invert: bool,
    ) -> NodeState {
        for (d, range) in subtree_ranges(tree, depth, index) {
            let src = tree.level_states(d);
            self.level(d - depth + to_depth).append_range(
                src.words(),
                range.start,
                range.len(),
                invert,
            );
        }
        match tree.state(depth, index) {
            NodeState::Full if invert => NodeState::Empty,
            NodeState::Empty if invert => NodeState::Full,
            s => s,
        }
    }

    /// The levels written, without trailing empty levels (at least one level).
    pub(crate) fn finish(mut self) -> Vec<PackedStates> {
        while self.levels.len() > 1 && self.levels.last().is_some_and(|l| l.len() == 0) {
            self.levels.pop();
        }
        if self.levels.is_empty() {
            self.levels.push(LevelWords::default());
        }
        self.levels
            .into_iter()
            .map(|l| {
                let (words, len) = l.into_words();
                PackedStates::from_words(words, len)
                    .expect("the writer only stores valid 2-bit codes")
            })
            .collect()
    }

    /// The tree with these levels below the root and `root` as its root state (level 0 is replaced):
    /// for writers that decide each node after its children.
    pub(crate) fn finish_with_root<const K: usize>(
        mut self,
        universe: Universe<K>,
        root: NodeState,
    ) -> KTree<K> {
        if root != NodeState::Partial {
            self.levels.clear();
        }
        let root_level = self.level(0);
        *root_level = LevelWords::default();
        root_level.push(root as u64, 1);
        KTree::from_levels(universe, self.finish())
    }
}

impl<const K: usize> KTree<K> {
    /// The tree whose full voxels are those of `cells` (in any order, disjoint, all of `universe`).
    /// Complete groups of `2^K` sibling cells are merged, so the tree is reduced.
    ///
    /// ```
    /// use ktree::{KTree, Universe};
    /// let u = Universe::<2>::new(2).unwrap();
    /// let voxels = [[2, 2], [3, 2], [2, 3], [3, 3], [0, 0]].map(|p| u.cell(p, 2).unwrap());
    /// let tree = KTree::from_cells(u, &voxels).unwrap();
    /// assert_eq!(tree.voxel_count(), 5);
    /// assert_eq!(tree.full_cells().count(), 2); // the four siblings are one cell
    /// assert!(KTree::from_cells(u, &[u.root(), voxels[0]]).is_err()); // overlapping
    /// ```
    ///
    /// Cost: `O(cells · log cells + nodes)`.
    ///
    /// # Errors
    /// [`TreeError::CellUniverse`] for a cell of another universe, [`TreeError::CellOrder`] for overlapping
    /// cells.
    pub fn from_cells(universe: Universe<K>, cells: &[Cell<K>]) -> Result<KTree<K>, TreeError> {
        let level = universe.level();
        if let Some(index) = cells.iter().position(|c| c.universe_level() != level) {
            return Err(TreeError::CellUniverse {
                index,
                expected: level,
                found: cells[index].universe_level(),
            });
        }
        let mut order: Vec<usize> = (0..cells.len()).collect();
        order.sort_unstable_by_key(|&i| (cells[i].morton(), cells[i].level));
        let k = K as u32;
        let mut merged: Vec<(u64, u32)> = Vec::with_capacity(cells.len());
        let mut end = 0u128;
        for &i in &order {
            let c = cells[i];
            let at = u128::from(c.morton());
            if at < end {
                return Err(TreeError::CellOrder { index: i });
            }
            end = at + c.volume();
            merged.push((c.morton(), c.level));
            // Merge complete sibling groups: the last 2^K cells at one level, of one parent, in order.
            while let Some(&(key, depth)) = merged.last() {
                let n = merged.len();
                if depth == 0 || n < Self::FANOUT {
                    break;
                }
                let step = 1u64 << (k * (level - depth));
                let Some(first) = key.checked_sub(step * (Self::FANOUT as u64 - 1)) else {
                    break;
                };
                let parent_aligned = u128::from(first) % (u128::from(step) << k) == 0;
                let group = &merged[n - Self::FANOUT..];
                let complete = parent_aligned
                    && group
                        .iter()
                        .enumerate()
                        .all(|(j, &(kj, dj))| dj == depth && kj == first + step * j as u64);
                if !complete {
                    break;
                }
                merged.truncate(n - Self::FANOUT);
                merged.push((first, depth - 1));
            }
        }
        let tree = Self::from_sorted_morton(universe, &merged);
        tree.check()?;
        Ok(tree)
    }

    /// The tree whose full leaves are exactly `cells`, which must be disjoint, inside `universe` and sorted
    /// by Morton key of their origins ([`Cell::morton`]). Every ancestor of a cell is partial; all other
    /// nodes are empty leaves. If the cells are maximal (no `2^K` sibling cells are all given), the tree is
    /// reduced; otherwise [`KTree::check`] reports it.
    ///
    /// Cost: `O(cells · L)`.
    pub(crate) fn from_sorted_cells(universe: Universe<K>, cells: &[Cell<K>]) -> KTree<K> {
        let keys: Vec<(u64, u32)> = cells.iter().map(|c| (c.morton(), c.level)).collect();
        Self::from_sorted_morton(universe, &keys)
    }

    /// Like [`KTree::from_sorted_cells`], with each cell given as `(Morton key of its origin, level)`.
    pub(crate) fn from_sorted_morton(universe: Universe<K>, cells: &[(u64, u32)]) -> KTree<K> {
        let mut out = TreeAssembler::<K> {
            universe,
            levels: LevelWriter::new(),
        };
        emit_leaves::<K, _>(&mut out, universe.level(), cells.iter().copied());
        out.finish()
    }

    /// Like [`KTree::from_sorted_morton`], with each cell packed as `Morton key << 5 | level` (needs
    /// `K·L + 5 ≤ 64`); sorting such packed values sorts the cells.
    pub(crate) fn from_sorted_packed(universe: Universe<K>, cells: &[u64]) -> KTree<K> {
        Self::from_sorted_packed_keys(universe, cells.iter().copied())
    }

    /// [`KTree::from_sorted_packed`] from the keys as they come (read from a sorted file, say).
    pub(crate) fn from_sorted_packed_keys(
        universe: Universe<K>,
        cells: impl IntoIterator<Item = u64>,
    ) -> KTree<K> {
        debug_assert!(K as u32 * universe.level() + 5 <= 64);
        let mut out = TreeAssembler::<K> {
            universe,
            levels: LevelWriter::new(),
        };
        emit_leaves::<K, _>(&mut out, universe.level(), cells);
        out.finish()
    }
}

/// A cell as the assembler sees it: a Morton key and a level.
trait CellKey: Copy {
    fn key(self) -> u64;
    fn level(self) -> u32;
}

impl CellKey for (u64, u32) {
    #[inline]
    fn key(self) -> u64 {
        self.0
    }
    #[inline]
    fn level(self) -> u32 {
        self.1
    }
}

impl CellKey for u64 {
    #[inline]
    fn key(self) -> u64 {
        self >> 5
    }
    #[inline]
    fn level(self) -> u32 {
        (self & 31) as u32
    }
}

/// Emits the pre-order traversal of the tree whose full leaves are `cells` (sorted, disjoint), in one pass.
///
/// The leaves of a k-tree tile the Morton order of its voxels with aligned blocks of `2^(K·j)` voxels. Walking
/// the cells in order, each gap before a cell is filled with the largest aligned empty blocks that fit (like
/// the maximal rows of a run, in Morton space), and before each leaf the partial nodes it is the first
/// descendant of are opened: those at the depths where the leaf's position is aligned to the node's size.
/// Cost: `O(nodes)`.
fn emit_leaves<const K: usize, C: CellKey>(
    out: &mut TreeAssembler<K>,
    level: u32,
    cells: impl IntoIterator<Item = C>,
) {
    let k = K as u32;
    let end = 1u128 << (k * level);
    let mut pos = 0u128;
    let leaf = |out: &mut TreeAssembler<K>, at: u128, depth: u32, state: NodeState| {
        // Open the partial ancestors whose first leaf this is: depths where `at` is aligned.
        let shallowest = if at == 0 {
            0
        } else {
            level - (at.trailing_zeros() / k).min(level)
        };
        for d in shallowest..depth {
            out.push(d as usize, NodeState::Partial);
        }
        out.push(depth as usize, state);
    };
    let fill = |out: &mut TreeAssembler<K>, from: u128, to: u128| {
        let mut at = from;
        while at < to {
            let by_alignment = if at == 0 {
                level
            } else {
                (at.trailing_zeros() / k).min(level)
            };
            let by_room = (127 - (to - at).leading_zeros()) / k;
            let j = by_alignment.min(by_room);
            leaf(out, at, level - j, NodeState::Empty);
            at += 1u128 << (k * j);
        }
    };
    for c in cells {
        let at = u128::from(c.key());
        fill(out, pos, at);
        leaf(out, at, c.level(), NodeState::Full);
        pos = at + (1u128 << (k * (level - c.level())));
    }
    fill(out, pos, end);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_depth_first_stream_assembles_into_levels() {
        let mut a = TreeAssembler::<1>::new(1).unwrap();
        a.push(0, NodeState::Partial);
        a.push(1, NodeState::Full);
        a.push(1, NodeState::Empty);
        let tree = a.finish();
        tree.assert_well_formed();
        assert!(tree.contains([0]) && !tree.contains([1]));
    }

    #[test]
    fn cells_assemble_into_the_expected_quadtree() {
        let u = Universe::<2>::new(2).unwrap();
        let mut cells = vec![u.cell([0, 0], 1).unwrap(), u.cell([3, 3], 2).unwrap()];
        cells.sort_by_key(|c| c.morton());
        let t = KTree::from_sorted_cells(u, &cells);
        t.assert_well_formed();
        assert_eq!(t.node_count(), 1 + 4 + 4);
        assert_eq!(t.voxel_count(), 5);
        assert_eq!(t.full_cells().collect::<Vec<_>>(), cells);
    }

    #[test]
    fn from_cells_merges_siblings_and_rejects_overlaps() {
        let u = Universe::<1>::new(3).unwrap();
        let c = |x, l| u.cell([x], l).unwrap();
        let t = KTree::from_cells(u, &[c(1, 3), c(0, 3), c(2, 2), c(6, 3)]).unwrap();
        assert_eq!(t.full_cells().collect::<Vec<_>>(), [c(0, 1), c(6, 3)]);
        assert_eq!(
            KTree::from_cells(u, &[c(0, 1), c(2, 3)]),
            Err(TreeError::CellOrder { index: 1 })
        );
        let other = Universe::<1>::new(2).unwrap().cell([0], 1).unwrap();
        assert!(matches!(
            KTree::from_cells(u, &[other]),
            Err(TreeError::CellUniverse { index: 0, .. })
        ));
        assert_eq!(KTree::from_cells(u, &[]).unwrap(), KTree::empty(3).unwrap());
        let all: Vec<_> = (0..8).map(|x| c(x, 3)).collect();
        assert_eq!(KTree::from_cells(u, &all).unwrap(), KTree::full(3).unwrap());
    }

    #[test]
    fn non_maximal_cells_are_caught_by_check() {
        let u = Universe::<1>::new(1).unwrap();
        let cells = [u.cell([0], 1).unwrap(), u.cell([1], 1).unwrap()];
        let t = KTree::from_sorted_cells(u, &cells);
        assert!(t.check().is_err());
    }
}
