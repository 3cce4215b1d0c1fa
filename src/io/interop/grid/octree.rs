//! The octree of a grid's boxes placed in a universe ([`place_boxes`]): counted before it is made, so a
//! placement past the node bound is refused at the cost of the count, then written level by level.

use std::collections::HashMap;

use super::{GridBoxes, GridPlacement, VoxelBox};
use crate::space::Universe;
use crate::tree::words::pack;
use crate::tree::LevelWriter;
use crate::tree::{KTree, NodeState};

/// The octree of a grid's boxes placed in a universe, of at most `max_nodes` nodes (else an error, found
/// before any node is made). The boxes are disjoint (every grid format here describes each voxel once), so
/// a cell is full exactly when the volumes of its overlaps with the boxes add up to its own.
///
/// The tree is walked top-down twice, first to count its nodes and then to write them; each cell keeps the
/// boxes that touch it. Below a cell that only one box touches, the subtree is that box's alone: counted
/// in closed form (see [`nodes_below`]) and written by a walk that compares intervals only. So a box that
/// the placement leaves unaligned (a large cell at an offset that is not a multiple of its side, which
/// costs nodes in proportion to its surface) is refused at the cost of a few arithmetic steps, and the
/// count's cost is that of the cells where boxes meet.
pub(crate) fn place_boxes(
    boxes: &GridBoxes,
    placement: &GridPlacement,
    max_nodes: u64,
) -> Result<KTree<3>, String> {
    let voxel_boxes = voxel_boxes(boxes, placement)?;
    let universe = Universe::<3>::new(placement.level).map_err(|e| e.to_string())?;
    let too_many = || {
        format!(
            "at offset {:?} in a level-{} universe the grid's octree has more than {max_nodes} nodes \
             (the bound of this read): choose an offset that is a multiple of the grid's cell sides",
            placement.offset, placement.level
        )
    };
    let root = Cell {
        lo: [0; 3],
        log_side: placement.level,
    };
    let (state, _) = count_nodes(&voxel_boxes, root, max_nodes).ok_or_else(too_many)?;
    let mut write = Placing::new(&voxel_boxes, max_nodes, Some(LevelWriter::new()));
    write.root(root).ok_or_else(too_many)?;
    let levels = write.out.take().expect("the writing walk has its writer");
    Ok(levels.finish_with_root(universe, state))
}

/// The root's state and the number of nodes of the octree of disjoint `boxes` below `root`, or `None` if
/// there are more than `max_nodes`.
fn count_nodes(boxes: &[VoxelBox], root: Cell, max_nodes: u64) -> Option<(NodeState, u64)> {
    let mut count = Placing::new(boxes, max_nodes, None);
    let state = count.root(root)?;
    Some((state, count.nodes))
}

/// The boxes of a grid in ktree voxels, clipped to the universe (those of `fill`) or checked to lie in it.
fn voxel_boxes(boxes: &GridBoxes, placement: &GridPlacement) -> Result<Vec<VoxelBox>, String> {
    let mut voxel_boxes = Vec::new();
    for (list, clip) in [(&boxes.inside, false), (&boxes.fill, true)] {
        for b in list {
            if let Some(v) = placement.voxels(b, clip)? {
                voxel_boxes.push(v);
            }
        }
    }
    Ok(voxel_boxes)
}

/// The work of counting a placed grid's octree: its nodes (`None` past `max_nodes`) and the cells the
/// count visited.
#[cfg(test)]
pub(crate) fn count_work(
    boxes: &GridBoxes,
    placement: &GridPlacement,
    max_nodes: u64,
) -> (Option<u64>, u64) {
    let voxel_boxes = voxel_boxes(boxes, placement).expect("the boxes fit the universe");
    let root = Cell {
        lo: [0; 3],
        log_side: placement.level,
    };
    let mut count = Placing::new(&voxel_boxes, max_nodes, None);
    let counted = count.root(root).map(|_| count.nodes);
    (counted, count.visited)
}

/// A cell of the universe: its low corner and the log2 of its side.
#[derive(Debug, Clone, Copy)]
struct Cell {
    lo: [u32; 3],
    log_side: u32,
}

impl Cell {
    /// Child `code` (bit `a` set: the upper half along axis `a`).
    fn child(self, code: usize) -> Cell {
        let half = 1u32 << (self.log_side - 1);
        Cell {
            lo: std::array::from_fn(|a| self.lo[a] + if code >> a & 1 == 1 { half } else { 0 }),
            log_side: self.log_side - 1,
        }
    }

    fn volume(self) -> u128 {
        1 << (3 * self.log_side)
    }

    /// The part of the box `[lo, hi)` in the cell, if it is not empty.
    fn part(self, lo: &[u32; 3], hi: &[u32; 3]) -> Option<([u32; 3], [u32; 3])> {
        let mut part = ([0u32; 3], [0u32; 3]);
        for a in 0..3 {
            let end = u64::from(self.lo[a]) + (1 << self.log_side);
            let l = lo[a].max(self.lo[a]);
            let h = u64::from(hi[a]).min(end) as u32;
            if l >= h {
                return None;
            }
            part.0[a] = l;
            part.1[a] = h;
        }
        Some(part)
    }

    /// The child holding the non-empty box `[lo, hi)` (inside the cell), if one child does.
    fn child_holding(self, lo: [u32; 3], hi: [u32; 3]) -> Option<usize> {
        let mid = |a: usize| u64::from(self.lo[a]) + (1 << (self.log_side - 1));
        let mut code = 0;
        for a in 0..3 {
            if u64::from(lo[a]) >= mid(a) {
                code |= 1 << a;
            } else if u64::from(hi[a]) > mid(a) {
                return None;
            }
        }
        Some(code)
    }
}

/// The number of nodes strictly below a cell in the octree of one box, the cell partial for it: eight for
/// each partial cell at every level down to side 2. A cell of side `2^j` is partial for a box when it
/// meets the box without lying inside it, so per level that is the product over the axes of the aligned
/// intervals that meet the box's range, less the product of those inside it.
fn nodes_below(cell: Cell, (blo, bhi): &VoxelBox) -> u64 {
    let mut l = [0u64; 3];
    let mut h = [0u64; 3];
    for a in 0..3 {
        l[a] = u64::from(blo[a]).max(u64::from(cell.lo[a]));
        h[a] = u64::from(bhi[a]).min(u64::from(cell.lo[a]) + (1 << cell.log_side));
    }
    let mut nodes = 0u64;
    for j in 1..=cell.log_side {
        let round_up = |x: u64| (x + (1 << j) - 1) >> j;
        let meeting: u64 = (0..3).map(|a| round_up(h[a]) - (l[a] >> j)).product();
        let inside: u64 = (0..3)
            .map(|a| (h[a] >> j).saturating_sub(round_up(l[a])))
            .product();
        nodes = nodes.saturating_add((meeting - inside).saturating_mul(8));
    }
    nodes
}

/// One top-down walk of the octree of disjoint boxes: it counts the nodes (stopping past `max_nodes`) and,
/// given a writer, writes them level by level, in depth-first order.
struct Placing<'a> {
    boxes: &'a [VoxelBox],
    /// The candidate lists of the cells on the current path, one after the other…
    candidates: Vec<u32>,
    /// …and beside each candidate of a cell being split, the children it meets (bit `code`).
    meets: Vec<u8>,
    nodes: u64,
    max_nodes: u64,
    /// The cells whose subtrees were counted or written (the walk's work, beside the boxes' lists).
    visited: u64,
    out: Option<LevelWriter>,
    box_writer: BoxWriter,
}

/// The boxes that meet a cell: where their list is, the volume they cover in it, how many they are, the
/// last of them, and the bounding box of their parts in the cell.
#[derive(Debug, Clone)]
struct Meeting {
    candidates: std::ops::Range<usize>,
    covered: u64,
    touching: u32,
    last: u32,
    bounds: VoxelBox,
}

impl Meeting {
    fn empty() -> Self {
        Self {
            candidates: 0..0,
            covered: 0,
            touching: 0,
            last: 0,
            bounds: ([u32::MAX; 3], [0; 3]),
        }
    }

    /// Adds box `i`, whose part in the cell is `[lo, hi)`.
    fn add(&mut self, i: u32, lo: [u32; 3], hi: [u32; 3]) {
        let volume = (0..3).map(|a| u64::from(hi[a] - lo[a])).product::<u64>();
        self.covered = self.covered.saturating_add(volume);
        self.touching += 1;
        self.last = i;
        for a in 0..3 {
            self.bounds.0[a] = self.bounds.0[a].min(lo[a]);
            self.bounds.1[a] = self.bounds.1[a].max(hi[a]);
        }
    }

    fn state(&self, cell: Cell) -> NodeState {
        if self.touching == 0 {
            NodeState::Empty
        } else if u128::from(self.covered) >= cell.volume() || cell.log_side == 0 {
            NodeState::Full
        } else {
            NodeState::Partial
        }
    }
}

impl<'a> Placing<'a> {
    fn new(boxes: &'a [VoxelBox], max_nodes: u64, out: Option<LevelWriter>) -> Self {
        Self {
            boxes,
            candidates: Vec::new(),
            meets: Vec::new(),
            nodes: 1,
            max_nodes,
            visited: 0,
            out,
            box_writer: BoxWriter::default(),
        }
    }

    /// The root's state, its subtree counted or written; `None` past `max_nodes`.
    fn root(&mut self, root: Cell) -> Option<NodeState> {
        let mut meeting = Meeting::empty();
        for (i, (lo, hi)) in self.boxes.iter().enumerate() {
            if let Some((lo, hi)) = root.part(lo, hi) {
                self.candidates.push(i as u32);
                meeting.add(i as u32, lo, hi);
            }
        }
        meeting.candidates.end = self.candidates.len();
        self.meets.resize(self.candidates.len(), 0);
        let state = meeting.state(root);
        if state == NodeState::Partial {
            self.partial(root, 0, &meeting)?;
        }
        Some(state)
    }

    fn add(&mut self, nodes: u64) -> Option<()> {
        self.nodes = self.nodes.saturating_add(nodes);
        (self.nodes <= self.max_nodes).then_some(())
    }

    fn write(&mut self, depth: usize, states: [NodeState; 8]) {
        if let Some(out) = &mut self.out {
            out.append_word(depth, pack(&states), 8);
        }
    }

    /// The subtree below a partial cell at `depth` that the boxes of `meeting` meet.
    fn partial(&mut self, cell: Cell, depth: usize, meeting: &Meeting) -> Option<()> {
        self.visited += 1;
        if meeting.touching == 1 {
            let b = self.boxes[meeting.last as usize];
            self.add(nodes_below(cell, &b))?;
            if let Some(out) = &mut self.out {
                self.box_writer.write(out, cell, depth, &b);
            }
            return Some(());
        }
        self.add(8)?;
        // All the boxes' parts in one child (data in a corner of a large universe): that child has the
        // same boxes, the others none.
        let (lo, hi) = meeting.bounds;
        if let Some(code) = cell.child_holding(lo, hi) {
            let child = cell.child(code);
            let mut states = [NodeState::Empty; 8];
            states[code] = meeting.state(child);
            self.write(depth + 1, states);
            if states[code] == NodeState::Partial {
                self.partial(child, depth + 1, meeting)?;
            }
            return Some(());
        }
        // Each box's children: those it meets along every axis; noted beside it for the children's lists.
        let mut children: [Meeting; 8] = std::array::from_fn(|_| Meeting::empty());
        for k in meeting.candidates.clone() {
            let i = self.candidates[k];
            let (lo, hi) = &self.boxes[i as usize];
            let mut meets = 0xFFu8;
            for a in 0..3 {
                let mid = cell.lo[a] + (1 << (cell.log_side - 1));
                let lower = if lo[a] < mid { HALF_ALONG[a][0] } else { 0 };
                let upper = if hi[a] > mid { HALF_ALONG[a][1] } else { 0 };
                meets &= lower | upper;
            }
            self.meets[k] = meets;
            let mut rest = meets;
            while rest != 0 {
                let code = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                if let Some((lo, hi)) = cell.child(code).part(lo, hi) {
                    children[code].add(i, lo, hi);
                }
            }
        }
        let states: [NodeState; 8] =
            std::array::from_fn(|code| children[code].state(cell.child(code)));
        self.write(depth + 1, states);
        // The lists of the partial children that more than one box meets, one after the other.
        let start = self.candidates.len();
        let mut at = start;
        let mut next = [0usize; 8];
        for (code, child) in children.iter_mut().enumerate() {
            let listed = if states[code] == NodeState::Partial && child.touching > 1 {
                child.touching as usize
            } else {
                0
            };
            child.candidates = at..at + listed;
            next[code] = at;
            at += listed;
        }
        self.candidates.resize(at, 0);
        self.meets.resize(at, 0);
        for k in meeting.candidates.clone() {
            let mut rest = self.meets[k];
            while rest != 0 {
                let code = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                if next[code] < children[code].candidates.end {
                    self.candidates[next[code]] = self.candidates[k];
                    next[code] += 1;
                }
            }
        }
        let mut done = Some(());
        for (code, child) in children.iter().enumerate() {
            if states[code] == NodeState::Partial {
                done = self.partial(cell.child(code), depth + 1, child);
                self.candidates.truncate(at);
                self.meets.truncate(at);
                if done.is_none() {
                    break;
                }
            }
        }
        self.candidates.truncate(start);
        self.meets.truncate(start);
        done
    }
}

/// The children codes (bit `a` set: the upper half along axis `a`) whose half along axis `a` is `half`.
const HALF_ALONG: [[u8; 2]; 3] = [
    [0b0101_0101, 0b1010_1010],
    [0b0011_0011, 0b1100_1100],
    [0b0000_1111, 0b1111_0000],
];

/// The 2-bit codes of eight children from the masks of the full ones and of the partial ones.
fn child_codes(full: u8, partial: u8) -> u64 {
    (0..8).fold(0, |w, c| {
        w | u64::from(full >> c & 1) << (2 * c) | u64::from(partial >> c & 1) << (2 * c + 1)
    })
}

/// The smallest cell side (log2) whose single-box subtrees are kept for copying.
const TEMPLATE_MIN_LOG_SIDE: u32 = 4;

/// Writes the subtrees that one box makes below the cells it leaves partial. Along each axis, each half of
/// a cell lies outside the box's range, inside it, or across its end; a child is empty if it is outside
/// along some axis, full if inside along all three. A box's face or edge crosses many cells of a level at
/// the same place, which then have the same subtree: those subtrees (of cells of side 16 and more inside
/// the box along some axis) are made once, kept as trees keyed by the cell's level and the box's part
/// relative to the cell, and copied a level at a time, 32 nodes a word.
#[derive(Default)]
struct BoxWriter {
    templates: HashMap<(u32, [u32; 6]), KTree<3>>,
}

impl BoxWriter {
    fn write(&mut self, out: &mut LevelWriter, cell: Cell, depth: usize, (blo, bhi): &VoxelBox) {
        let side = 1u32 << cell.log_side;
        let (lo, hi) = cell.part(blo, bhi).expect("a partial cell meets its box");
        let relative: [u32; 6] = std::array::from_fn(|i| {
            if i < 3 {
                lo[i] - cell.lo[i]
            } else {
                hi[i - 3] - cell.lo[i - 3]
            }
        });
        let inside_along_some_axis = (0..3).any(|a| relative[a] == 0 && relative[a + 3] == side);
        if cell.log_side < TEMPLATE_MIN_LOG_SIDE || !inside_along_some_axis {
            self.write_children(out, cell, depth, &(lo, hi));
            return;
        }
        let key = (cell.log_side, relative);
        if !self.templates.contains_key(&key) {
            let mut template = LevelWriter::new();
            let local = Cell {
                lo: [0; 3],
                log_side: cell.log_side,
            };
            let part = (
                [relative[0], relative[1], relative[2]],
                [relative[3], relative[4], relative[5]],
            );
            self.write_children(&mut template, local, 0, &part);
            let universe = Universe::<3>::new(cell.log_side).expect("a cell's level is valid");
            let tree = template.finish_with_root(universe, NodeState::Partial);
            self.templates.insert(key, tree);
        }
        out.copy_subtree(&self.templates[&key], 0, 0, depth, false);
    }

    /// Writes the cell's children and the subtrees of the partial ones.
    fn write_children(&mut self, out: &mut LevelWriter, cell: Cell, depth: usize, b: &VoxelBox) {
        let (blo, bhi) = b;
        let half = 1u64 << (cell.log_side - 1);
        let (mut outside, mut inside) = (0u8, 0xFFu8);
        for a in 0..3 {
            let (bl, bh) = (u64::from(blo[a]), u64::from(bhi[a]));
            let mut inside_along = 0u8;
            for h in 0..2 {
                let lo = u64::from(cell.lo[a]) + h * half;
                if bh <= lo || bl >= lo + half {
                    outside |= HALF_ALONG[a][h as usize];
                } else if bl <= lo && bh >= lo + half {
                    inside_along |= HALF_ALONG[a][h as usize];
                }
            }
            inside &= inside_along;
        }
        let full = inside & !outside;
        let partial = !(inside | outside);
        out.append_word(depth + 1, child_codes(full, partial), 8);
        let mut rest = partial;
        while rest != 0 {
            let code = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            self.write(out, cell.child(code), depth + 1, b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{max_grid_nodes, IndexBox};
    use super::*;
    use proptest::prelude::*;

    /// Disjoint boxes of grid indices for a universe of `level` at `offset`: candidates of any size and
    /// place (cubes of a power-of-two side at multiples of it among them, like a grid file's tiles), each
    /// kept if it lies in the universe and meets no box kept before; some read as `fill` (clipped to the
    /// universe, sticking out of it). Returns the boxes and the dense array of their voxels.
    fn disjoint_boxes(
        level: u32,
        offset: [i64; 3],
        candidates: &[([i64; 3], [u64; 3], bool, bool)],
    ) -> (GridBoxes, Vec<bool>) {
        let side = 1i64 << level;
        let universe = Universe::<3>::new(level).unwrap();
        let mut dense = vec![false; 1 << (3 * level)];
        let mut boxes = GridBoxes::default();
        for &(origin, size, cube, fill) in candidates {
            let (origin, size) = if cube {
                let s = 1u64 << size[0].min(6).trailing_zeros().min(level);
                (origin.map(|c| c.div_euclid(s as i64) * s as i64), [s; 3])
            } else {
                (origin, size)
            };
            let lo: [i64; 3] = std::array::from_fn(|a| origin[a] + offset[a]);
            let hi: [i64; 3] = std::array::from_fn(|a| lo[a] + size[a] as i64);
            let inside = (0..3).all(|a| lo[a] >= 0 && hi[a] <= side);
            if !fill && !inside {
                continue;
            }
            let (l, h) = (lo.map(|c| c.clamp(0, side)), hi.map(|c| c.clamp(0, side)));
            let voxels = || {
                (l[0]..h[0]).flat_map(move |x| {
                    (l[1]..h[1]).flat_map(move |y| (l[2]..h[2]).map(move |z| [x, y, z]))
                })
            };
            let index = |p: [i64; 3]| universe.dense_index(p.map(|c| c as u32));
            if voxels().any(|p| dense[index(p)]) {
                continue;
            }
            for p in voxels() {
                dense[index(p)] = true;
            }
            let b = IndexBox { origin, size };
            if fill {
                boxes.fill.push(b);
            } else {
                boxes.inside.push(b);
            }
        }
        (boxes, dense)
    }

    proptest! {
        #[test]
        fn placed_boxes_are_the_tree_of_their_voxels_and_counted_exactly(
            level in 0u32..=6,
            offset in prop::array::uniform3(-40i64..40),
            candidates in prop::collection::vec(
                (
                    prop::array::uniform3(-48i64..80),
                    prop::array::uniform3(1u64..40),
                    any::<bool>(),
                    prop::bool::weighted(0.1),
                ),
                0..24,
            ),
        ) {
            let (boxes, dense) = disjoint_boxes(level, offset, &candidates);
            let placement = GridPlacement { offset, level };
            let want = KTree::<3>::from_dense(level, &dense).unwrap();
            let got = place_boxes(&boxes, &placement, u64::MAX).unwrap();
            prop_assert_eq!(&got, &want);
            got.assert_well_formed();
            let nodes = want.node_count();
            prop_assert_eq!(count_work(&boxes, &placement, u64::MAX).0, Some(nodes));
            // The bound is the tree's size: refused one node below it.
            prop_assert!(place_boxes(&boxes, &placement, nodes).is_ok());
            if nodes > 1 {
                let e = place_boxes(&boxes, &placement, nodes - 1).unwrap_err();
                prop_assert!(e.contains(&format!("more than {} nodes", nodes - 1)), "{}", e);
            }
        }
    }

    #[test]
    fn an_unaligned_tile_is_refused_from_its_count_alone() {
        // One 4096³ tile (as an OpenVDB root tile) three voxels off its alignment: its octree has about 10^9
        // nodes. The count sees one box at the root and counts its subtree in closed form.
        let mut boxes = GridBoxes::default();
        boxes.inside.push(IndexBox {
            origin: [0; 3],
            size: [4096; 3],
        });
        let placement = GridPlacement {
            offset: [3, 0, 0],
            level: 13,
        };
        let max = max_grid_nodes(46_742);
        assert_eq!(count_work(&boxes, &placement, max), (None, 1));
        let (counted, visited) = count_work(&boxes, &placement, u64::MAX);
        assert_eq!(visited, 1);
        // Its two faces across x (at x = 3 and 4099) cross 2 · (4096 / 2^j)² cells of each side 2^j ≤ 2048:
        // about 2 · 4096² / 3 partial cells in all, eight nodes each.
        let nodes = counted.unwrap();
        let faces = 2 * 4096u64 * 4096 / 3 * 8;
        assert!(nodes > faces && nodes < faces + faces / 64, "{nodes}");
        // Aligned, the tile is one full cell at depth 1: the root and its eight children.
        let aligned = GridPlacement {
            offset: [0; 3],
            level: 13,
        };
        assert_eq!(count_work(&boxes, &aligned, max), (Some(9), 1));
        assert_eq!(place_boxes(&boxes, &aligned, max).unwrap().node_count(), 9);
    }

    #[test]
    fn single_box_counts_in_closed_form_match_the_dense_tree() {
        // Every box [lo, hi) of a 16³ universe whose corners are on a coarse lattice (and one voxel off it).
        let coords = [0u32, 1, 3, 4, 7, 8, 9, 15, 16];
        for &l in &coords {
            for &h in &coords {
                if l >= h {
                    continue;
                }
                let b: VoxelBox = ([l, 0, 3], [h, 16, 9]);
                let mut dense = vec![false; 1 << 12];
                for x in l..h {
                    for y in 0..16 {
                        for z in 3..9 {
                            dense[(z << 8 | y << 4 | x) as usize] = true;
                        }
                    }
                }
                let tree = KTree::<3>::from_dense(4, &dense).unwrap();
                let root = Cell {
                    lo: [0; 3],
                    log_side: 4,
                };
                if tree.root_state() == NodeState::Partial {
                    assert_eq!(nodes_below(root, &b) + 1, tree.node_count() as u64, "{b:?}");
                }
            }
        }
    }
}
