//! Output of the operations: nodes pushed level by level in depth-first order (children in child-code
//! order), which is level order for free (see [`crate::tree::TreeAssembler`]).
//!
//! Every operation here computes a node's children *before* pushing them, so a node whose children all come
//! out as the same leaf collapses into that leaf without anything to undo: the output is reduced by
//! construction, in one pass, with a buffer of at most `2^K` states per level of recursion.

use crate::space::Universe;
use crate::tree::{KTree, NodeState, PackedStates};

/// Levels of an output tree under construction.
pub(crate) struct Levels {
    levels: Vec<PackedStates>,
}

impl Levels {
    /// Room for a tree of `depths` levels (the root is pushed last, by [`Levels::finish`]).
    pub(crate) fn new(depths: usize) -> Self {
        let mut levels = Vec::with_capacity(depths);
        levels.resize_with(depths.max(1), PackedStates::new);
        Self { levels }
    }

    /// Pushes the `2^K` children of a partial node, at `depth` (the children's depth).
    #[inline]
    pub(crate) fn push_block(&mut self, depth: usize, kids: &[NodeState]) {
        if self.levels.len() <= depth {
            self.levels.resize_with(depth + 1, PackedStates::new);
        }
        let level = &mut self.levels[depth];
        for &s in kids {
            level.push(s);
        }
    }

    /// The tree with `root` as its root state.
    pub(crate) fn finish<const K: usize>(
        mut self,
        universe: Universe<K>,
        root: NodeState,
    ) -> KTree<K> {
        self.levels[0] = PackedStates::with_capacity(1);
        self.levels[0].push(root);
        while self.levels.len() > 1 && self.levels.last().is_some_and(|l| l.is_empty()) {
            self.levels.pop();
        }
        if root != NodeState::Partial {
            self.levels.truncate(1);
        }
        for l in &mut self.levels {
            l.finish();
        }
        KTree::from_levels(universe, self.levels)
    }
}

/// The state of a node whose children are `kids`: a leaf if they are all the same leaf, else partial
/// (in which case the caller pushes them).
#[inline]
pub(crate) fn collapse(kids: &[NodeState]) -> Option<NodeState> {
    let first = kids[0];
    if first != NodeState::Partial && kids.iter().all(|&k| k == first) {
        Some(first)
    } else {
        None
    }
}

/// The leaf state of a boolean.
#[inline]
pub(crate) fn leaf(full: bool) -> NodeState {
    if full {
        NodeState::Full
    } else {
        NodeState::Empty
    }
}

/// Copies the subtree of `tree` at (`depth`, `index`) to `out`, complementing it if `invert`; returns the
/// subtree root's state (pushed by the caller). A reduced subtree stays reduced.
pub(crate) fn copy_subtree<const K: usize>(
    tree: &KTree<K>,
    out: &mut Levels,
    depth: usize,
    index: usize,
    invert: bool,
) -> NodeState {
    match tree.state(depth, index) {
        NodeState::Partial => {
            let first = tree.first_child(depth, index);
            let mut kids = [NodeState::Empty; 16];
            for (c, kid) in kids.iter_mut().enumerate().take(1 << K) {
                *kid = copy_subtree(tree, out, depth + 1, first + c, invert);
            }
            out.push_block(depth + 1, &kids[..1 << K]);
            NodeState::Partial
        }
        s if invert => leaf(s == NodeState::Empty),
        s => s,
    }
}
