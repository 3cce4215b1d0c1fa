//! The level of detail of a view: which boxes to draw of a tree within a budget (see the [page's
//! notes](super)). Each refinement is a one-level [`cursor`](crate::tree::cursor) walk and each neighbour
//! question a walk towards one cell, so the selection works on any storage and reads only the nodes it
//! draws and their neighbours' paths.

use std::convert::Infallible;

use crate::space::Cell;
use crate::tree::cursor::{try_walk, try_walk_from, ChildOrder, TreeStorage, Visitor, Walk};
use crate::tree::{NodeRef, NodeState};

/// The boxes of a view: visible full leaves and the coarse partial cells left unrefined.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lod<const K: usize> {
    /// Full leaves with at least one face open on the drawn axes.
    pub full: Vec<Cell<K>>,
    /// Partial cells drawn whole because the budget ran out before they were refined.
    pub coarse: Vec<Cell<K>>,
    /// Whether every partial node was refined (`coarse` is then empty and `full` holds every visible leaf).
    pub complete: bool,
}

impl<const K: usize> Lod<K> {
    /// The number of boxes.
    pub fn len(&self) -> usize {
        self.full.len() + self.coarse.len()
    }

    /// Whether there is no box (an empty tree).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Whether every voxel of the aligned cell `region` that touches its face on `axis` (`upper`: the face at
/// `origin + side`) is full: a walk that takes one child at a time down to `region`, then only the
/// children on that face, stopping at the first empty node.
fn face_all_full<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    region: &Cell<K>,
    axis: usize,
    upper: bool,
) -> Result<bool, T::Error> {
    struct Face<const K: usize> {
        region: Cell<K>,
        face: ChildOrder,
        all_full: bool,
    }
    impl<const K: usize> Visitor<K> for Face<K> {
        const ORIGINS: bool = false;
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            if node.state() == NodeState::Empty {
                self.all_full = false;
                return Walk::Stop;
            }
            Walk::Descend
        }
        fn child_order(&self, node: &NodeRef<K>) -> ChildOrder {
            if node.cell().level() >= self.region.level() {
                return self.face;
            }
            let bit = node.cell().log_side() - 1;
            let code = (0..K).fold(0, |code, a| {
                code | ((self.region.origin()[a] >> bit & 1) as usize) << a
            });
            ChildOrder::one(code)
        }
    }
    let mut face = Face {
        region: *region,
        face: ChildOrder::half::<K>(axis, upper),
        all_full: true,
    };
    try_walk(tree, &mut face)?;
    Ok(face.all_full)
}

/// The children of a partial node, in code order: a walk of one level below it.
fn children<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    node: NodeRef<K>,
) -> Result<Vec<NodeRef<K>>, T::Error> {
    struct OneLevel<const K: usize> {
        top: u32,
        seen: Vec<NodeRef<K>>,
    }
    impl<const K: usize> Visitor<K> for OneLevel<K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            if node.cell().level() == self.top {
                return Walk::Descend;
            }
            self.seen.push(*node);
            Walk::Skip
        }
    }
    let mut one = OneLevel {
        top: node.cell().level(),
        seen: Vec::with_capacity(1 << K),
    };
    try_walk_from(tree, node, &mut one)?;
    Ok(one.seen)
}

/// Whether the full child `code` of a partial node (its siblings `kids`, in code order) has a face on one
/// of `axes` that touches a voxel that is not full (the universe's boundary is open).
fn visible<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    kids: &[NodeRef<K>],
    code: usize,
    axes: &[usize],
) -> Result<bool, T::Error> {
    if axes.is_empty() {
        return Ok(true);
    }
    let cell = kids[code].cell();
    let side = cell.side();
    let universe = tree.universe().side();
    // Faces inside the parent first: their neighbours are siblings; a full or empty one is answered
    // without a walk.
    for &a in axes {
        let sibling = kids[code ^ (1 << a)];
        let open = match sibling.state() {
            NodeState::Full => false,
            NodeState::Empty => true,
            NodeState::Partial => !face_all_full(tree, &sibling.cell(), a, code >> a & 1 == 1)?,
        };
        if open {
            return Ok(true);
        }
    }
    for &a in axes {
        let upper = code >> a & 1 == 1;
        let o = u64::from(cell.origin()[a]);
        let across = if upper {
            o + side
        } else {
            o.wrapping_sub(side)
        };
        if across >= universe {
            return Ok(true);
        }
        let mut origin = cell.origin();
        origin[a] = across as u32;
        let neighbour = Cell {
            origin,
            level: cell.level(),
            log_side: cell.log_side(),
        };
        if !face_all_full(tree, &neighbour, a, !upper)? {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The boxes to draw of `tree` within `budget`: breadth-first refinement from the root while the number
/// of boxes (visible full leaves plus the partial cells not yet refined) stays within the budget. A full
/// leaf is kept when one of its faces on `axes` touches a voxel that is not full or the universe's
/// boundary (`axes` empty: every full leaf is kept).
///
/// # Errors
/// The storage's read error.
///
/// # Performance
/// `O(B · K · L)` node reads for `B` boxes, plus for a buried leaf the nodes along its faces: each face
/// question is a walk of `L` steps to the cell across, then down that cell's face until an empty node.
pub fn select_boxes<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    budget: usize,
    axes: &[usize],
) -> Result<Lod<K>, T::Error> {
    let root = tree.root()?;
    let mut full = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    match root.state() {
        NodeState::Full if budget > 0 => full.push(root.cell()),
        NodeState::Partial if budget > 0 => queue.push_back(root),
        _ => {}
    }
    let mut complete = root.state() != NodeState::Partial;
    let mut boxes = full.len() + queue.len();
    while let Some(node) = queue.pop_front() {
        let kids = children(tree, node)?;
        let mut keep = Vec::new();
        let mut partial = 0;
        for (code, kid) in kids.iter().enumerate() {
            match kid.state() {
                NodeState::Partial => partial += 1,
                NodeState::Full if visible(tree, &kids, code, axes)? => keep.push(kid.cell()),
                _ => {}
            }
        }
        if boxes - 1 + keep.len() + partial > budget {
            queue.push_front(node);
            break;
        }
        boxes = boxes - 1 + keep.len() + partial;
        full.extend(keep);
        queue.extend(kids.into_iter().filter(|k| k.state() == NodeState::Partial));
        complete = queue.is_empty();
    }
    let coarse = queue.into_iter().map(|n| n.cell()).collect();
    Ok(Lod {
        full,
        coarse,
        complete,
    })
}

/// [`select_boxes`] over a tree whose reads cannot fail.
pub fn select_boxes_of<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    budget: usize,
    axes: &[usize],
) -> Lod<K> {
    match select_boxes(tree, budget, axes) {
        Ok(lod) => lod,
        Err(never) => match never {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::DensePyramid;
    use crate::KTree;
    use proptest::prelude::*;

    /// The brute-force reference: every full leaf with a voxel whose neighbour across a face on `axes`
    /// is outside the universe or not full (from the dense array), in no particular order.
    fn visible_leaves<const K: usize>(tree: &KTree<K>, axes: &[usize]) -> Vec<Cell<K>> {
        let u = tree.universe();
        let side = u.side() as i64;
        let dense = tree.to_dense().unwrap();
        let n = dense.len();
        let full = |p: [i64; K]| {
            p.iter().all(|&c| (0..side).contains(&c)) && dense[u.dense_index(p.map(|c| c as u32))]
        };
        let mut out = Vec::new();
        for (cell, state) in tree.leaves() {
            if state != NodeState::Full {
                continue;
            }
            let s = cell.side() as i64;
            let o = cell.origin().map(i64::from);
            let open = axes.is_empty()
                || (0..n).any(|i| {
                    let p = u.dense_point(i).map(i64::from);
                    if !(0..K).all(|a| (o[a]..o[a] + s).contains(&p[a])) {
                        return false;
                    }
                    axes.iter().any(|&a| {
                        [-1, 1].iter().any(|&d| {
                            let mut q = p;
                            q[a] += d;
                            !(o[a]..o[a] + s).contains(&q[a]) && !full(q)
                        })
                    })
                });
            if open {
                out.push(cell);
            }
        }
        out
    }

    fn check<const K: usize>(dense: &[bool], level: u32, budget: usize, axes: &[usize]) {
        let tree = KTree::<K>::from_dense(level, dense).unwrap();
        let lod = select_boxes_of(&tree, budget, axes);
        let reference = visible_leaves(&tree, axes);
        let key = |c: &Cell<K>| (c.level(), c.morton());
        assert!(
            lod.len() <= budget,
            "{} boxes for a budget of {budget}",
            lod.len()
        );
        // Every box holds part of the object; the full ones are visible leaves of the tree.
        let mut leaves: Vec<_> = reference.iter().map(key).collect();
        leaves.sort_unstable();
        for c in &lod.full {
            assert!(
                leaves.binary_search(&key(c)).is_ok(),
                "{c:?} is not a visible full leaf"
            );
        }
        let pyramid = DensePyramid::<K>::from_dense(level, dense).unwrap();
        for c in &lod.coarse {
            let unit = c.origin().map(|o| o >> c.log_side());
            assert_eq!(pyramid.state(c.level(), unit), NodeState::Partial, "{c:?}");
        }
        // Every visible leaf is drawn: itself, or inside a coarse box.
        for c in &reference {
            let drawn = lod.full.iter().any(|f| key(f) == key(c))
                || lod
                    .coarse
                    .iter()
                    .any(|p| p.level() < c.level() && p.contains(c.origin()));
            assert!(drawn, "visible leaf {c:?} is not drawn");
        }
        if lod.complete {
            assert!(lod.coarse.is_empty());
            assert_eq!(lod.full.len(), reference.len());
        }
        // A budget as large as the reference's count is always enough to finish.
        let enough = reference.len()
            + tree
                .counts_per_level()
                .iter()
                .map(|c| c.partial as usize)
                .sum::<usize>();
        let all = select_boxes_of(&tree, enough.max(1), axes);
        assert!(all.complete);
        assert_eq!(all.full.len(), reference.len());
    }

    fn dense_strategy(k: usize, level: u32) -> impl Strategy<Value = Vec<bool>> {
        let n = 1usize << (k as u32 * level);
        (
            prop::collection::vec(any::<bool>(), n),
            0.0f64..1.0,
            any::<u64>(),
        )
            .prop_map(move |(bits, p, seed)| {
                // Blobs: a random field thresholded after smoothing by its neighbours in code order.
                let mut out = bits.clone();
                let mut s = seed | 1;
                for (i, b) in out.iter_mut().enumerate() {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    let keep = (s % 1000) as f64 / 1000.0 < p;
                    *b = if keep { bits[i] } else { bits[i / 8 * 8] };
                }
                out
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn lod_k1(dense in dense_strategy(1, 5), budget in 1usize..40) {
            check::<1>(&dense, 5, budget, &[0]);
        }
        #[test]
        fn lod_k2(dense in dense_strategy(2, 3), budget in 1usize..60, cull in any::<bool>()) {
            check::<2>(&dense, 3, budget, if cull { &[0, 1] } else { &[] });
        }
        #[test]
        fn lod_k3(dense in dense_strategy(3, 3), budget in 1usize..200) {
            check::<3>(&dense, 3, budget, &[0, 1, 2]);
        }
        #[test]
        fn lod_k4(dense in dense_strategy(4, 2), budget in 1usize..200, time in 0usize..4) {
            let axes: Vec<usize> = (0..4).filter(|&a| a != time).collect();
            check::<4>(&dense, 2, budget, &axes);
        }
    }

    #[test]
    fn full_and_empty_universes() {
        let full = KTree::<3>::full(3).unwrap();
        let lod = select_boxes_of(&full, 1, &[0, 1, 2]);
        assert_eq!(
            (lod.full.len(), lod.coarse.len(), lod.complete),
            (1, 0, true)
        );
        let empty = KTree::<3>::empty(3).unwrap();
        assert!(select_boxes_of(&empty, 5, &[0, 1, 2]).is_empty());
    }
}
