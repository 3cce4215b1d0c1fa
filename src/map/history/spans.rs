//! The cells of a history decided from the steps' states: a [`Span`] of time over a cell of space, and
//! a [`Window`] of steps whose cells are built together.

use super::MAP_LEVEL;
use crate::tree::storage::infallible;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::ValueState;
use crate::tree::TreeError;
use crate::KTree;

/// The label of a coarse cell whose states are not all one ([`coarse_states`]).
pub(super) const MIXED: u8 = 3;

/// A cell of the history being built: the first time of its span, its side, the node of the step before
/// the span that its 3-D part lies in (none before the first step: all unknown), and the same for each
/// step of the span that exists.
#[derive(Clone)]
pub(super) struct Span {
    pub(super) first: u64,
    pub(super) side: u64,
    pub(super) before: Option<InputNode<u8>>,
    pub(super) nodes: Vec<InputNode<u8>>,
}

/// The state all over a node's cell, if it has one: `Some(None)` unknown, `Some(Some(v))` the label
/// (not [`MIXED`]).
pub(super) fn uniform(node: Option<&InputNode<u8>>) -> Option<Option<u8>> {
    match node.map(|n| n.state) {
        None | Some(ValueState::Empty) => Some(None),
        Some(ValueState::Full(MIXED)) => None,
        Some(ValueState::Full(v)) => Some(Some(v)),
        Some(ValueState::Partial | ValueState::Mixed) => None,
    }
}

impl Span {
    /// How a span of the history is decided, given `count` steps in all: empty where nothing changes
    /// (after the last step nothing is recorded); a leaf of one label where every step of the span is
    /// recorded and has that label all over it; split otherwise.
    pub(super) fn decide(&self, count: u64) -> Decision<u8> {
        let before = uniform(self.before.as_ref());
        if self.nodes.is_empty()
            || before.is_some() && self.nodes.iter().all(|n| uniform(Some(n)) == before)
        {
            return Decision::Leaf(None);
        }
        let first = uniform(self.nodes.first());
        let whole = self.first + self.side <= count;
        match first {
            Some(Some(v)) if whole && self.nodes.iter().all(|n| uniform(Some(n)) == first) => {
                Decision::Leaf(Some(v))
            }
            _ => Decision::Split,
        }
    }

    /// The span of child `code` (its time half in bit 3), with `count` steps in all; `state(t)` is the
    /// tree of step `t`'s states the nodes are in.
    pub(super) fn child<'a>(
        &self,
        code: usize,
        count: u64,
        state: impl Fn(u64) -> &'a KTree<3, u8>,
    ) -> Span {
        let (half, space) = (self.side / 2, code & 7);
        let upper = code >> 3 & 1 == 1;
        let first = self.first + if upper { half } else { 0 };
        let at = |t: u64| -> InputNode<u8> {
            let node = &self.nodes[(t - self.first) as usize];
            infallible(node.child(state(t), space))
        };
        let before = if upper {
            (first - 1 < count).then(|| at(first - 1))
        } else {
            // A span after the first step has one before it.
            self.before
                .map(|b| infallible(b.child(state(first - 1), space)))
        };
        Span {
            first,
            side: half,
            before,
            nodes: (first..(first + half).min(count)).map(at).collect(),
        }
    }
}

/// Steps `first …` of a history (at most `side` of them, `side` a power of two dividing `first`) with
/// the states of the step before them: what decides the history's cells inside their span of time.
pub(super) struct Window<'a> {
    pub(super) first: u64,
    pub(super) before: Option<&'a KTree<3, u8>>,
    pub(super) steps: &'a [KTree<3, u8>],
    pub(super) side: u64,
}

impl Window<'_> {
    /// The states of step `t` (`first − 1 … first + steps`).
    fn state(&self, t: u64) -> &KTree<3, u8> {
        if t + 1 == self.first {
            self.before
                .expect("the step before a window's steps is kept")
        } else {
            &self.steps[(t - self.first) as usize]
        }
    }

    /// The 4-D tree whose cells inside the window's span of time are the history's (decided as
    /// [`Span::decide`]), empty outside it; a cell whose span holds the window's is split.
    pub(super) fn tree(&self) -> KTree<4, u8> {
        let count = self.first + self.steps.len() as u64;
        let root_of = |t: &KTree<3, u8>| infallible(InputNode::root(t));
        let root = Span {
            first: 0,
            side: 1 << MAP_LEVEL,
            before: self.before.map(root_of),
            nodes: self.steps.iter().map(root_of).collect(),
        };
        let inside = |span: &Span| span.side <= self.side;
        let built = build_top_down::<4, u8, Span, TreeError>(
            MAP_LEVEL,
            root,
            |_, span| {
                if inside(span) {
                    return Ok(span.decide(count));
                }
                // Above the window: empty where the window's steps change nothing in this part of
                // space (as the window's cells there are decided), split where they may.
                let before = uniform(span.before.as_ref());
                let unchanged =
                    before.is_some() && span.nodes.iter().all(|n| uniform(Some(n)) == before);
                Ok(if unchanged {
                    Decision::Leaf(None)
                } else {
                    Decision::Split
                })
            },
            |span, code| {
                if inside(span) {
                    return Ok(span.child(code, count, |t| self.state(t)));
                }
                // Above the window: the nodes stay those of the window's steps, carried down in
                // space, in the half of time that holds the window.
                let half = span.side / 2;
                let first = span.first + if code >> 3 & 1 == 1 { half } else { 0 };
                if self.first < first || self.first >= first + half {
                    return Ok(Span {
                        first,
                        side: half,
                        before: None,
                        nodes: Vec::new(),
                    });
                }
                let space = code & 7;
                Ok(Span {
                    first,
                    side: half,
                    before: span
                        .before
                        .map(|b| infallible(b.child(self.before.expect("kept"), space))),
                    nodes: span
                        .nodes
                        .iter()
                        .zip(self.steps)
                        .map(|(n, t)| infallible(n.child(t, space)))
                        .collect(),
                })
            },
        );
        built.unwrap_or_else(|e| unreachable!("a history of label trees is a valid tree: {e}"))
    }
}
