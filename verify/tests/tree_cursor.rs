//! The cursor against brute force on the dense array, K = 1 … 4: one-tree and two-tree walks visit exactly
//! the nodes (cells and states) a recursive enumeration of the dense array finds, in the same order, with
//! skipping and early exit; point location (from the root, or from a [`PointCursor`]'s last path) and
//! subtree ranges agree with the dense array.

use ktree::tree::cursor::{
    subtree_ranges, walk, walk_pair, ChildOrder, PairNode, PairVisitor, Visitor, Walk,
};
use ktree::tree::locate::{locate, PointCursor};
use ktree::tree::NodeRef;
use ktree::{Cell, KTree, NodeState, Universe};
use ktree_verify::objects::{object, pair, Obj};
use proptest::prelude::*;

/// The state of `cell` in the dense array: full, empty or mixed (its voxels read one by one).
fn dense_state<const K: usize>(u: &Universe<K>, dense: &[bool], cell: &Cell<K>) -> NodeState {
    let side = cell.side() as u32;
    let (mut any, mut all) = (false, true);
    let mut offset = [0u32; K];
    'voxels: loop {
        let p: [u32; K] = std::array::from_fn(|i| cell.origin()[i] + offset[i]);
        let v = dense[u.dense_index(p)];
        any |= v;
        all &= v;
        for o in offset.iter_mut() {
            *o += 1;
            if *o < side {
                continue 'voxels;
            }
            *o = 0;
        }
        break;
    }
    match (any, all) {
        (false, _) => NodeState::Empty,
        (true, true) => NodeState::Full,
        _ => NodeState::Partial,
    }
}

/// Whether the brute-force walk skips a cell (and its subtree): an arbitrary rule the visitor shares.
fn skips<const K: usize>(cell: &Cell<K>, rule: u32) -> bool {
    rule != 0 && cell.level() > 0 && (cell.origin()[0] >> cell.log_side()) % rule == rule - 1
}

/// Brute force: the pre-order list of (cell, state) of the tree of `dense`, children in `order`'s codes,
/// skipping as [`skips`] says; `true` once `limit` cells are listed.
fn brute<const K: usize>(
    u: &Universe<K>,
    dense: &[bool],
    cell: Cell<K>,
    order: &ChildOrder,
    rule: u32,
    limit: usize,
    out: &mut Vec<(Cell<K>, NodeState)>,
) -> bool {
    let state = dense_state(u, dense, &cell);
    out.push((cell, state));
    if out.len() >= limit {
        return true;
    }
    if skips(&cell, rule) || state != NodeState::Partial {
        return false;
    }
    for code in order.codes() {
        if brute(u, dense, cell.child(code), order, rule, limit, out) {
            return true;
        }
    }
    false
}

struct Record<const K: usize> {
    order: ChildOrder,
    rule: u32,
    limit: usize,
    seen: Vec<(Cell<K>, NodeState)>,
    left: usize,
}

impl<const K: usize> Visitor<K> for Record<K> {
    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        self.seen.push((node.cell(), node.state()));
        if self.seen.len() >= self.limit {
            Walk::Stop
        } else if skips(&node.cell(), self.rule) {
            Walk::Skip
        } else {
            Walk::Descend
        }
    }

    fn leave(&mut self, _node: &NodeRef<K>) {
        self.left += 1;
    }

    fn child_order(&self, _node: &NodeRef<K>) -> ChildOrder {
        self.order
    }
}

fn check_one<const K: usize>(
    obj: &Obj<K>,
    mask: usize,
    rule: u32,
    limit: usize,
) -> Result<(), TestCaseError> {
    let (u, dense, tree) = (obj.universe(), obj.dense(), obj.tree());
    let order = ChildOrder::xor::<K>(mask % (1 << K));
    let mut expect = Vec::new();
    let stopped = brute(&u, &dense, u.root(), &order, rule, limit, &mut expect);
    let mut v = Record {
        order,
        rule,
        limit,
        seen: Vec::new(),
        left: 0,
    };
    prop_assert_eq!(walk(&tree, &mut v), stopped);
    prop_assert_eq!(&v.seen, &expect);
    if rule == 0 && !stopped {
        // Every partial node is left once.
        prop_assert_eq!(
            v.left as u64,
            tree.counts().partial,
            "leave calls = partial nodes"
        );
    }
    // Point location: the located leaf holds the voxel's dense value.
    for (i, &full) in dense.iter().enumerate().step_by(7) {
        let voxel = u.cell(u.dense_point(i), u.level()).unwrap();
        let node = locate(&tree, tree.root(), &voxel).unwrap();
        prop_assert!(node.cell().contains(voxel.origin()));
        prop_assert_eq!(
            node.state(),
            if full {
                NodeState::Full
            } else {
                NodeState::Empty
            }
        );
        prop_assert_eq!(tree.contains(voxel.origin()), full);
    }
    // Subtree ranges: the nodes below the root, level by level, are the whole levels.
    let ranges: Vec<_> = subtree_ranges(&tree, 0, 0).collect();
    prop_assert_eq!(ranges.len(), tree.depth_count() - 1);
    for (d, r) in ranges {
        prop_assert_eq!(r, 0..tree.level_states(d).len());
    }
    Ok(())
}

struct RecordPair<const K: usize> {
    rule: u32,
    limit: usize,
    seen: Vec<(Cell<K>, NodeState, NodeState)>,
}

impl<const K: usize> PairVisitor<K> for RecordPair<K> {
    fn visit(&mut self, p: &PairNode<K>) -> Walk {
        self.seen.push((p.cell, p.a.state, p.b.state));
        if self.seen.len() >= self.limit {
            Walk::Stop
        } else if skips(&p.cell, self.rule) {
            Walk::Skip
        } else {
            Walk::Descend
        }
    }
}

/// Brute force for two trees: pre-order over the cells where either dense array is mixed.
#[allow(clippy::too_many_arguments)]
fn brute_pair<const K: usize>(
    u: &Universe<K>,
    da: &[bool],
    db: &[bool],
    cell: Cell<K>,
    rule: u32,
    limit: usize,
    out: &mut Vec<(Cell<K>, NodeState, NodeState)>,
) -> bool {
    let (sa, sb) = (dense_state(u, da, &cell), dense_state(u, db, &cell));
    out.push((cell, sa, sb));
    if out.len() >= limit {
        return true;
    }
    if skips(&cell, rule) || (sa != NodeState::Partial && sb != NodeState::Partial) {
        return false;
    }
    for code in 0..1 << K {
        if brute_pair(u, da, db, cell.child(code), rule, limit, out) {
            return true;
        }
    }
    false
}

fn check_pair<const K: usize>(
    a: &Obj<K>,
    b: &Obj<K>,
    rule: u32,
    limit: usize,
) -> Result<(), TestCaseError> {
    let u = a.universe();
    let mut expect = Vec::new();
    let stopped = brute_pair(
        &u,
        &a.dense(),
        &b.dense(),
        u.root(),
        rule,
        limit,
        &mut expect,
    );
    let mut v = RecordPair {
        rule,
        limit,
        seen: Vec::new(),
    };
    prop_assert_eq!(walk_pair(&a.tree(), &b.tree(), &mut v), stopped);
    prop_assert_eq!(v.seen, expect);
    Ok(())
}

fn limits() -> impl Strategy<Value = usize> {
    prop_oneof![Just(usize::MAX), 1..40usize]
}

proptest! {
    #[test]
    fn one_tree_walks_match_brute_force_k1(o in object::<1>(), m in 0..16usize, r in 0..4u32, n in limits()) {
        check_one(&o, m, r, n)?;
    }
    #[test]
    fn one_tree_walks_match_brute_force_k2(o in object::<2>(), m in 0..16usize, r in 0..4u32, n in limits()) {
        check_one(&o, m, r, n)?;
    }
    #[test]
    fn one_tree_walks_match_brute_force_k3(o in object::<3>(), m in 0..16usize, r in 0..4u32, n in limits()) {
        check_one(&o, m, r, n)?;
    }
    #[test]
    fn one_tree_walks_match_brute_force_k4(o in object::<4>(), m in 0..16usize, r in 0..4u32, n in limits()) {
        check_one(&o, m, r, n)?;
    }
    #[test]
    fn two_tree_walks_match_brute_force_k1((a, b) in pair::<1>(), r in 0..4u32, n in limits()) {
        check_pair(&a, &b, r, n)?;
    }
    #[test]
    fn two_tree_walks_match_brute_force_k2((a, b) in pair::<2>(), r in 0..4u32, n in limits()) {
        check_pair(&a, &b, r, n)?;
    }
    #[test]
    fn two_tree_walks_match_brute_force_k3((a, b) in pair::<3>(), r in 0..4u32, n in limits()) {
        check_pair(&a, &b, r, n)?;
    }
    #[test]
    fn two_tree_walks_match_brute_force_k4((a, b) in pair::<4>(), r in 0..4u32, n in limits()) {
        check_pair(&a, &b, r, n)?;
    }
}

#[test]
fn a_single_leaf_tree_is_one_visit() {
    let tree = KTree::<3>::full(4).unwrap();
    let mut v = Record {
        order: ChildOrder::morton::<3>(),
        rule: 0,
        limit: usize::MAX,
        seen: Vec::new(),
        left: 0,
    };
    assert!(!walk(&tree, &mut v));
    assert_eq!(v.seen, [(tree.universe().root(), NodeState::Full)]);
}

/// A cursor that keeps its path finds, for any sequence of cells, the node the dense array says holds
/// each: a leaf of the cell's dense state containing it, or the cell itself when it is mixed.
fn check_locator<const K: usize>(o: &Obj<K>, picks: &[(u64, u32)]) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let u = tree.universe();
    let dense = tree.to_dense().unwrap();
    let mut locator = PointCursor::new(&tree).unwrap();
    for &(seed, level) in picks {
        let level = level % (u.level() + 1);
        let side = 1u64 << level;
        let origin = std::array::from_fn(|a| {
            let x = (seed >> (16 * a)) % side;
            (x << (u.level() - level)) as u32
        });
        let target = u.cell(origin, level).unwrap();
        let node = locator.locate(&target).unwrap();
        prop_assert!(
            node.cell().contains(target.origin()) && node.depth() <= target.level() as usize
        );
        let expect = dense_state(&u, &dense, &node.cell());
        prop_assert_eq!(node.state(), expect);
        if expect == NodeState::Partial {
            prop_assert_eq!(node.cell(), target);
        }
        prop_assert_eq!(node, locate(&tree, tree.root(), &target).unwrap());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn locator_matches_locate_k1(o in object::<1>(), p in prop::collection::vec((any::<u64>(), 0..32u32), 1..40)) { check_locator(&o, &p)?; }
    #[test]
    fn locator_matches_locate_k2(o in object::<2>(), p in prop::collection::vec((any::<u64>(), 0..32u32), 1..40)) { check_locator(&o, &p)?; }
    #[test]
    fn locator_matches_locate_k3(o in object::<3>(), p in prop::collection::vec((any::<u64>(), 0..32u32), 1..40)) { check_locator(&o, &p)?; }
    #[test]
    fn locator_matches_locate_k4(o in object::<4>(), p in prop::collection::vec((any::<u64>(), 0..32u32), 1..40)) { check_locator(&o, &p)?; }
}
