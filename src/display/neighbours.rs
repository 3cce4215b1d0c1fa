//! Face neighbours in the compact tree, without pointers. Veenstra & Ahuja thread each black leaf to its
//! six neighbours with spare child pointers (V3); the level-order tree has no pointers, so a neighbour is
//! found by descending from the root to the equal-sized cell across a face — `O(L)` rank lookups — and the
//! part of it that touches the face (or an edge) is read by descending only into the children that touch
//! it.
//!
//! ```
//! use ktree::display::neighbours::is_surrounded;
//! use ktree::KTree;
//! // A full 4 × 4 × 4 universe: the voxel (1, 1, 1) is surrounded, the universe's corner voxel is not.
//! let full = KTree::<3>::full(2).unwrap();
//! let u = full.universe();
//! assert!(is_surrounded(&full, &u.cell([1, 1, 1], 2).unwrap()));
//! assert!(!is_surrounded(&full, &u.cell([0, 0, 0], 2).unwrap()));
//! ```

use crate::space::Cell;
use crate::tree::{KTree, NodeRef, NodeState};

/// The node whose cell contains the aligned cell `region` and is either a leaf or `region` itself.
/// `region` must lie inside the tree's universe.
pub fn locate<const K: usize>(tree: &KTree<K>, region: &Cell<K>) -> NodeRef<K> {
    let level = tree.level();
    let mut node = tree.root();
    while node.state == NodeState::Partial && node.cell.level < region.level {
        let depth = node.cell.level as usize;
        let bit = level - 1 - node.cell.level;
        let mut code = 0usize;
        for (axis, &c) in region.origin.iter().enumerate() {
            code |= ((c >> bit & 1) as usize) << axis;
        }
        let index = tree.first_child(depth, node.index) + code;
        node = NodeRef {
            index,
            cell: node.cell.child(code),
            state: tree.state(depth + 1, index),
        };
    }
    node
}

/// The cell of the same size as `cell` across its face on `axis` (`upper`: the face at `origin + side`),
/// `None` when that face is on the universe's boundary.
pub fn face_neighbour_cell<const K: usize>(
    cell: &Cell<K>,
    axis: usize,
    upper: bool,
    side_of_universe: u64,
) -> Option<Cell<K>> {
    shifted(cell, &[(axis, upper)], side_of_universe)
}

/// The cell of the same size as `cell` shifted by one side along each `(axis, upper)` given, `None`
/// outside the universe.
pub fn shifted<const K: usize>(
    cell: &Cell<K>,
    moves: &[(usize, bool)],
    side_of_universe: u64,
) -> Option<Cell<K>> {
    let s = cell.side();
    let mut out = *cell;
    for &(axis, upper) in moves {
        let o = u64::from(cell.origin[axis]);
        if upper {
            if o + s >= side_of_universe {
                return None;
            }
            out.origin[axis] = (o + s) as u32;
        } else {
            if o < s {
                return None;
            }
            out.origin[axis] = (o - s) as u32;
        }
    }
    Some(out)
}

/// Whether every voxel of `region` that touches its face on `axis` (`upper` side) is full: the face of the
/// region is wholly covered by the object.
pub fn face_all_full<const K: usize>(
    tree: &KTree<K>,
    region: &Cell<K>,
    axis: usize,
    upper: bool,
) -> bool {
    let node = locate(tree, region);
    match node.state {
        NodeState::Full => true,
        NodeState::Empty => false,
        NodeState::Partial => face_all_full_below(tree, &node, axis, upper),
    }
}

fn face_all_full_below<const K: usize>(
    tree: &KTree<K>,
    node: &NodeRef<K>,
    axis: usize,
    upper: bool,
) -> bool {
    tree.children(node)
        .filter(|c| {
            let code_bit = (c.cell.origin[axis] > node.cell.origin[axis]) as usize;
            code_bit == usize::from(upper)
        })
        .all(|c| match c.state {
            NodeState::Full => true,
            NodeState::Empty => false,
            NodeState::Partial => face_all_full_below(tree, &c, axis, upper),
        })
}

/// Whether a full leaf is surrounded: each of its `2K` faces touches only full voxels across it (V5).
/// Faces on the universe's boundary are open.
pub fn is_surrounded<const K: usize>(tree: &KTree<K>, cell: &Cell<K>) -> bool {
    let side = tree.universe().side();
    (0..K).all(|axis| {
        [false, true].iter().all(|&upper| {
            face_neighbour_cell(cell, axis, upper, side)
                .is_some_and(|n| face_all_full(tree, &n, axis, !upper))
        })
    })
}

/// The occupancy of a 3-D region's edge line: the region is an aligned cube; the edge runs along `axis`
/// at the region's `side_b` face on axis `b` and `side_c` face on axis `c` (`true` = upper). Returns
/// `(start, end, full)` runs covering `[0, region side)` as offsets from the region's origin along `axis`,
/// in order, adjacent runs of equal state merged. A missing region (outside the universe) is empty.
pub fn edge_occupancy(
    tree: &KTree<3>,
    region: Option<&Cell<3>>,
    side: u32,
    axis: usize,
    (b, side_b): (usize, bool),
    (c, side_c): (usize, bool),
) -> Vec<(u32, u32, bool)> {
    let mut out: Vec<(u32, u32, bool)> = Vec::new();
    let Some(region) = region else {
        return vec![(0, side, false)];
    };
    let node = locate(tree, region);
    let base = region.origin[axis];
    let mut push = |start: u32, end: u32, full: bool| match out.last_mut() {
        Some(last) if last.2 == full && last.1 == start => last.1 = end,
        _ => out.push((start, end, full)),
    };
    if node.state != NodeState::Partial {
        push(0, side, node.state == NodeState::Full);
        return out;
    }
    // Depth-first along the edge, lower half first.
    let mut stack = vec![node];
    while let Some(n) = stack.pop() {
        if n.state != NodeState::Partial {
            let start = n.cell.origin[axis] - base;
            push(
                start,
                start + n.cell.side() as u32,
                n.state == NodeState::Full,
            );
            continue;
        }
        let first = tree.first_child(n.cell.level as usize, n.index);
        for upper in [true, false] {
            let code = (usize::from(upper) << axis)
                | (usize::from(side_b) << b)
                | (usize::from(side_c) << c);
            stack.push(NodeRef {
                index: first + code,
                cell: n.cell.child(code),
                state: tree.state(n.cell.level as usize + 1, first + code),
            });
        }
    }
    out
}
