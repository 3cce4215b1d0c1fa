//! Output of the operations: nodes pushed level by level in depth-first order (children in child-code
//! order), which is level order for free, through the crate's one level writer (the one behind
//! [`crate::tree::TreeAssembler`]).
//!
//! Every operation here computes a node's children *before* pushing them, so a node whose children all come
//! out as the same leaf collapses into that leaf without anything to undo: the output is reduced by
//! construction, in one pass, with a buffer of at most `2^K` states per level of recursion.

pub(crate) use crate::tree::LevelWriter;
use crate::tree::NodeState;

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
