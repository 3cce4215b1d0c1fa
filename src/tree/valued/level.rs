//! A level of a valued tree as it is written: its nodes' 2-bit codes, packed as they come, and its full
//! nodes' values — appended node by node, a block of siblings at a time, or a whole level after another.

use super::ValueState;
use crate::tree::states::PackedStates;
use crate::tree::words::{
    LevelWords, EMPTY_CODE, FULL_CODE, MIXED_CODE, NODES_PER_WORD, PARTIAL_CODE,
};
use crate::value::Value;

/// A level of a valued tree being written: 2 bits a node and the values of its full nodes, nothing more.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ValuedLevel<V> {
    codes: LevelWords,
    values: Vec<V>,
}

impl<V> Default for ValuedLevel<V> {
    fn default() -> Self {
        Self {
            codes: LevelWords::default(),
            values: Vec::new(),
        }
    }
}

impl<V: Value> ValuedLevel<V> {
    /// An empty level.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// The level of `states`, in order.
    pub(crate) fn from_states(states: &[ValueState<V>]) -> Self {
        let mut level = Self::new();
        level.extend_from_slice(states);
        level
    }

    /// The number of nodes.
    pub(crate) fn len(&self) -> usize {
        self.codes.len()
    }

    /// Whether the level has no node.
    pub(crate) fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of the full nodes so far, in order.
    pub(crate) fn values(&self) -> &[V] {
        &self.values
    }

    /// The code of `state`, its value (if it is full) kept.
    #[inline(always)]
    fn code(&mut self, state: ValueState<V>) -> u64 {
        let code = match state {
            ValueState::Empty => EMPTY_CODE,
            ValueState::Full(v) => {
                if V::STORED {
                    self.values.push(v);
                }
                FULL_CODE
            }
            ValueState::Partial => PARTIAL_CODE,
            ValueState::Mixed => MIXED_CODE,
        };
        u64::from(code)
    }

    /// Appends a node.
    #[inline]
    pub(crate) fn push(&mut self, state: ValueState<V>) {
        let code = self.code(state);
        self.codes.push(code, 1);
    }

    /// Appends nodes, up to a word of codes at a time.
    #[inline]
    pub(crate) fn extend_from_slice(&mut self, states: &[ValueState<V>]) {
        for chunk in states.chunks(NODES_PER_WORD) {
            let mut codes = 0;
            for (slot, &state) in chunk.iter().enumerate() {
                codes |= self.code(state) << (2 * slot);
            }
            self.codes.push(codes, chunk.len());
        }
    }

    /// Appends `nodes` codes packed in `words` (see [`LevelWords::append_words`]) and the values of
    /// their full nodes.
    pub(crate) fn append_words(&mut self, words: &[u64], nodes: usize, values: &[V]) {
        self.codes.append_words(words, nodes);
        self.values.extend_from_slice(values);
    }

    /// Appends the nodes of `other` after these (its codes shifted into place, or moved when this level
    /// is empty).
    pub(crate) fn append(&mut self, other: Self) {
        if self.is_empty() {
            *self = other;
            return;
        }
        self.codes.append(&other.codes);
        self.values.extend(other.values);
    }

    /// Room for `nodes` more nodes and `values` more values without reallocating.
    pub(crate) fn reserve(&mut self, nodes: usize, values: usize) {
        self.codes.reserve(nodes);
        self.values.reserve(values);
    }

    /// The level packed for a tree: its codes with their rank index, and its full nodes' values.
    pub(crate) fn into_packed(self) -> (PackedStates, Vec<V>) {
        let (words, len) = self.codes.into_words();
        let level = PackedStates::from_valued_words(words, len)
            .expect("one word for every NODES_PER_WORD codes, none past the last");
        (level, self.values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// States of every kind, values 0…4, from a fixed seed.
    fn states(n: usize, seed: u64) -> Vec<ValueState<u8>> {
        let mut lcg = crate::testing::Lcg(seed);
        (0..n)
            .map(|_| {
                let x = lcg.next_u64();
                match (x >> 33) % 4 {
                    0 => ValueState::Empty,
                    1 => ValueState::Full((x >> 40) as u8 % 5),
                    2 => ValueState::Partial,
                    _ => ValueState::Mixed,
                }
            })
            .collect()
    }

    /// The naive reading of a packed level: each node's code and each full node's value in turn.
    fn read(level: ValuedLevel<u8>) -> Vec<ValueState<u8>> {
        let (packed, values) = level.into_packed();
        let mut values = values.into_iter();
        let words = packed.words().to_vec();
        (0..packed.len())
            .map(
                |i| match (words[i / NODES_PER_WORD] >> (2 * (i % NODES_PER_WORD))) & 3 {
                    0 => ValueState::Empty,
                    1 => ValueState::Full(values.next().unwrap()),
                    2 => ValueState::Partial,
                    _ => ValueState::Mixed,
                },
            )
            .collect()
    }

    #[test]
    fn pushed_appended_and_sliced_levels_read_back_in_order() {
        for (n, cut) in [
            (0, 0),
            (1, 0),
            (31, 7),
            (32, 32),
            (33, 1),
            (100, 37),
            (200, 64),
        ] {
            let all = states(n, n as u64 + 1);
            let mut one_by_one = ValuedLevel::new();
            for &s in &all {
                one_by_one.push(s);
            }
            assert_eq!(read(one_by_one), all);
            assert_eq!(read(ValuedLevel::from_states(&all)), all);
            let mut joined = ValuedLevel::from_states(&all[..cut]);
            joined.append(ValuedLevel::from_states(&all[cut..]));
            assert_eq!(read(joined), all, "{n} cut at {cut}");
        }
    }

    #[test]
    fn the_packed_level_ranks_its_partial_and_mixed_nodes_as_nodes_with_children() {
        let all = states(300, 9);
        let (packed, _) = ValuedLevel::from_states(&all).into_packed();
        let with_children = all.iter().filter(|s| s.has_children()).count();
        assert_eq!(packed.partial_count(), with_children);
    }
}
