//! Words of packed 2-bit node codes: the one place that knows the bit layout of a level.
//!
//! A level of a tree (in memory, in a `.ktree` version 2 file, in a spill file) is a sequence of 2-bit codes
//! (`00` empty, `01` full, `10` partial, `11` unused in a binary tree and mixed in a valued one: the
//! `*_CODE` constants) in `u64` words, node `i` at bits `2·(i mod 32)` of word `i / 32`. This module
//! holds the masks that pick out full and partial nodes from a word, the complement of a word's leaves,
//! reading codes at any node offset, and [`WordPacker`], the one shifted appender: codes appended at any
//! offset come out as whole words.

use super::states::NodeState;

/// Nodes in a word.
pub(crate) const NODES_PER_WORD: usize = 32;

/// The code of an empty node.
pub(crate) const EMPTY_CODE: u8 = 0b00;
/// The code of a full node (in a valued tree, every voxel holding the one value it keeps).
pub(crate) const FULL_CODE: u8 = 0b01;
/// The code of a node with children that has empty voxels.
pub(crate) const PARTIAL_CODE: u8 = 0b10;
/// The code of a valued tree's node with children whose voxels all hold a value, not all equal; unused
/// in a binary tree.
pub(crate) const MIXED_CODE: u8 = 0b11;

/// The low bit of every 2-bit slot.
pub(crate) const LOW_BITS: u64 = 0x5555_5555_5555_5555;

/// The low `2·nodes` bits set: the first `nodes` slots of a word (`nodes ≥ 32` gives the whole word).
#[inline(always)]
pub(crate) fn slots_mask(nodes: usize) -> u64 {
    if nodes >= NODES_PER_WORD {
        u64::MAX
    } else {
        (1u64 << (2 * nodes)) - 1
    }
}

/// The low bit of each slot set where the slot holds `Partial` (`10`).
#[inline(always)]
pub(crate) fn partial_mask(word: u64) -> u64 {
    (word >> 1) & !word & LOW_BITS
}

/// The low bit of each slot set where the node has children: `Partial` (`10`), or in a valued tree a
/// mixed node (`11`, every voxel holding a value, not all equal). In a binary tree, [`partial_mask`].
#[inline(always)]
pub(crate) fn children_mask(word: u64) -> u64 {
    (word >> 1) & LOW_BITS
}

/// The low bit of each slot set where the slot holds `Full` (`01`).
#[inline(always)]
pub(crate) fn full_mask(word: u64) -> u64 {
    word & !(word >> 1) & LOW_BITS
}

/// The low bit of each slot set where the slot holds the code `11`: unused in a binary tree, a mixed node
/// in a valued one.
#[inline(always)]
pub(crate) fn unused_mask(word: u64) -> u64 {
    (word >> 1) & word & LOW_BITS
}

/// The full nodes of a word.
#[inline(always)]
pub(crate) fn full_count(word: u64) -> u32 {
    full_mask(word).count_ones()
}

/// The first `nodes` slots of `word` with full and empty swapped (partial slots unchanged, slots from
/// `nodes` on untouched): the low bit of every non-partial slot is flipped.
#[inline(always)]
pub(crate) fn complement(word: u64, nodes: usize) -> u64 {
    word ^ (!(word >> 1) & LOW_BITS & slots_mask(nodes))
}

/// The codes of `states` packed from the low bits (at most 32 states).
#[inline]
pub(crate) fn pack(states: &[NodeState]) -> u64 {
    debug_assert!(states.len() <= NODES_PER_WORD);
    states
        .iter()
        .enumerate()
        .fold(0, |w, (i, &s)| w | (s as u64) << (2 * i))
}

/// The `nodes ≤ 32` codes from node `start` of a packed level whose word `j` is `word(j)` (of `words`
/// words), in the low bits, the bits above them clear: two words joined by shifts where the run straddles
/// them.
#[inline(always)]
pub(crate) fn read_codes(
    word: impl Fn(usize) -> u64,
    words: usize,
    start: usize,
    nodes: usize,
) -> u64 {
    let (j, offset) = (start / NODES_PER_WORD, start % NODES_PER_WORD);
    let mut codes = word(j) >> (2 * offset);
    if offset > 0 && j + 1 < words {
        codes |= word(j + 1) << (64 - 2 * offset);
    }
    codes & slots_mask(nodes)
}

/// [`read_codes`] from a slice of words.
#[inline(always)]
pub(crate) fn codes_at(src: &[u64], start: usize, nodes: usize) -> u64 {
    read_codes(|j| src[j], src.len(), start, nodes)
}

/// Codes appended two bits each at any node offset, handed out as whole words: the one shifted appender of
/// levels in memory ([`LevelWords`]), of `.ktree` writers and of the streamed Booleans' output levels.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub(crate) struct WordPacker {
    /// Codes not yet forming a whole word, in the low bits (the bits above them clear).
    pending: u64,
    /// How many (below 32).
    pending_nodes: usize,
}

impl WordPacker {
    /// Appends the `nodes ≤ 32` codes in the low bits of `codes` (the bits above them must be clear);
    /// returns the word they complete, if any.
    #[inline(always)]
    pub(crate) fn push(&mut self, codes: u64, nodes: usize) -> Option<u64> {
        debug_assert!(nodes <= NODES_PER_WORD && codes & !slots_mask(nodes) == 0);
        let p = self.pending_nodes;
        let joined = self.pending | codes << (2 * p);
        let total = p + nodes;
        if total >= NODES_PER_WORD {
            // The codes that did not fit: `codes >> (64 − 2p)`, written as two shifts so that `p = 0`
            // (nothing pending, nothing left over) needs no branch.
            self.pending = (codes >> 1) >> (63 - 2 * p);
            self.pending_nodes = total - NODES_PER_WORD;
            Some(joined)
        } else {
            self.pending = joined;
            self.pending_nodes = total;
            None
        }
    }

    /// How many codes wait for their word to be completed (below 32).
    #[inline]
    pub(crate) fn pending_nodes(&self) -> usize {
        self.pending_nodes
    }

    /// The last, partly filled word (`None` if the codes so far fill whole words), leaving the packer
    /// empty.
    #[inline]
    pub(crate) fn flush(&mut self) -> Option<u64> {
        let last = (self.pending_nodes > 0).then_some(self.pending);
        *self = Self::default();
        last
    }
}

/// A level being written in memory: codes appended at any offset ([`WordPacker`]), single nodes, blocks,
/// runs of whole words and ranges of other levels (complemented or not) alike.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct LevelWords {
    /// The whole words so far.
    words: Vec<u64>,
    /// The codes after them.
    packer: WordPacker,
}

impl LevelWords {
    /// The number of nodes appended.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.words.len() * NODES_PER_WORD + self.packer.pending_nodes()
    }

    /// Appends `nodes ≤ 32` codes packed in the low bits of `codes` (the bits above them clear).
    #[inline(always)]
    pub(crate) fn push(&mut self, codes: u64, nodes: usize) {
        if let Some(whole) = self.packer.push(codes, nodes) {
            self.words.push(whole);
        }
    }

    /// Appends `nodes` codes packed in `words` (the first in the low bits of `words[0]`; bits beyond
    /// `nodes` ignored): a bulk copy when the level ends on a word boundary, shifted words otherwise.
    pub(crate) fn append_words(&mut self, words: &[u64], nodes: usize) {
        let whole = nodes / NODES_PER_WORD;
        let rest = nodes % NODES_PER_WORD;
        if self.packer.pending_nodes() == 0 {
            self.words.extend_from_slice(&words[..whole]);
        } else {
            self.words.reserve(whole + 1);
            for &w in &words[..whole] {
                self.push(w, NODES_PER_WORD);
            }
        }
        if rest > 0 {
            self.push(words[whole] & slots_mask(rest), rest);
        }
    }

    /// Appends the codes of `other` (its whole words, then the codes after them).
    pub(crate) fn append(&mut self, other: &Self) {
        self.append_words(&other.words, other.words.len() * NODES_PER_WORD);
        let pending = other.packer.pending_nodes();
        if pending > 0 {
            self.push(other.packer.pending, pending);
        }
    }

    /// Room for `nodes` more codes without reallocating.
    pub(crate) fn reserve(&mut self, nodes: usize) {
        self.words.reserve(nodes / NODES_PER_WORD + 1);
    }

    /// Appends the codes `start .. start + nodes` of the packed level `src`, leaves complemented if
    /// `invert`.
    pub(crate) fn append_range(&mut self, src: &[u64], start: usize, nodes: usize, invert: bool) {
        self.words.reserve(nodes / NODES_PER_WORD + 1);
        let end = start + nodes;
        let mut at = start;
        while at < end {
            let n = (end - at).min(NODES_PER_WORD);
            let mut codes = codes_at(src, at, n);
            if invert {
                codes = complement(codes, n);
            }
            self.push(codes, n);
            at += n;
        }
    }

    /// The words (the last one padded with zeros) and the number of nodes.
    pub(crate) fn into_words(mut self) -> (Vec<u64>, usize) {
        let len = self.len();
        if let Some(last) = self.packer.flush() {
            self.words.push(last);
        }
        (self.words, len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Lcg;

    /// Each code read back by the masks, in every slot of a word.
    #[test]
    fn the_codes_are_what_the_masks_read() {
        let read = |code: u8, slot: usize| {
            let word = u64::from(code) << (2 * slot);
            let bit = |mask: u64| mask >> (2 * slot) & 1 == 1;
            (
                bit(full_mask(word)),
                bit(partial_mask(word)),
                bit(children_mask(word)),
                bit(unused_mask(word)),
            )
        };
        for slot in 0..NODES_PER_WORD {
            assert_eq!(read(EMPTY_CODE, slot), (false, false, false, false));
            assert_eq!(read(FULL_CODE, slot), (true, false, false, false));
            assert_eq!(read(PARTIAL_CODE, slot), (false, true, true, false));
            assert_eq!(read(MIXED_CODE, slot), (false, false, true, true));
        }
    }

    /// Random 2-bit codes 0…2 from a fixed seed.
    fn codes(n: usize, seed: u64) -> Vec<u64> {
        let mut lcg = Lcg(seed);
        (0..n).map(|_| lcg.below(3)).collect()
    }

    /// The naive packing: one code at a time.
    fn naive(codes: &[u64]) -> Vec<u64> {
        let mut words = vec![0u64; codes.len().div_ceil(32)];
        for (i, &c) in codes.iter().enumerate() {
            words[i / 32] |= c << (2 * (i % 32));
        }
        words
    }

    /// Decodes every slot of a word: `(full, partial, unused)` masks built one slot at a time.
    fn decoded(word: u64) -> (u64, u64, u64) {
        let (mut full, mut partial, mut unused) = (0, 0, 0);
        for slot in 0..32 {
            let bit = 1u64 << (2 * slot);
            match word >> (2 * slot) & 3 {
                1 => full |= bit,
                2 => partial |= bit,
                3 => unused |= bit,
                _ => {}
            }
        }
        (full, partial, unused)
    }

    #[test]
    fn masks_and_counts_agree_with_decoding_each_slot() {
        let mut lcg = Lcg(99);
        for _ in 0..2000 {
            let x = lcg.next_u64();
            for word in [
                x,
                x & 0x5555_5555_5555_5555,
                x & 0xAAAA_AAAA_AAAA_AAAA,
                0,
                u64::MAX,
            ] {
                let (full, partial, unused) = decoded(word);
                assert_eq!(full_mask(word), full);
                assert_eq!(partial_mask(word), partial);
                assert_eq!(unused_mask(word), unused);
                assert_eq!(full_count(word), full.count_ones());
                assert_eq!(partial_mask(word).count_ones(), partial.count_ones());
            }
        }
    }

    #[test]
    fn complement_swaps_leaves_of_the_first_slots_only() {
        let word = naive(&codes(32, 5))[0];
        for nodes in 0..=32 {
            let c = complement(word, nodes);
            for slot in 0..32 {
                let (before, after) = (word >> (2 * slot) & 3, c >> (2 * slot) & 3);
                let expected = match before {
                    0 if slot < nodes => 1,
                    1 if slot < nodes => 0,
                    code => code,
                };
                assert_eq!(after, expected, "slot {slot} of {nodes}");
            }
        }
        assert_eq!(slots_mask(0), 0);
        assert_eq!(slots_mask(1), 0b11);
        assert_eq!(slots_mask(32), u64::MAX);
    }

    #[test]
    fn pack_puts_the_first_state_in_the_low_bits() {
        let states = [NodeState::Partial, NodeState::Empty, NodeState::Full];
        assert_eq!(pack(&states), 0b01_00_10);
    }

    #[test]
    fn read_codes_agrees_with_reading_each_code() {
        let c = codes(200, 11);
        let words = naive(&c);
        for start in 0..c.len() {
            for n in [0, 1, 2, 7, 31, 32] {
                let n = n.min(c.len() - start);
                assert_eq!(
                    codes_at(&words, start, n),
                    naive(&c[start..start + n]).first().copied().unwrap_or(0)
                );
            }
        }
    }

    #[test]
    fn the_packer_appends_like_a_naive_push_at_every_bit_offset() {
        let c = codes(300, 3);
        for offset in 0..32 {
            for chunk in [1, 2, 5, 16, 31, 32] {
                let mut packer = WordPacker::default();
                let mut out = Vec::new();
                let mut at = 0;
                let mut next = offset;
                while at < c.len() {
                    let n = next.min(c.len() - at).min(32);
                    if let Some(w) =
                        packer.push(naive(&c[at..at + n]).first().copied().unwrap_or(0), n)
                    {
                        out.push(w);
                    }
                    at += n;
                    next = chunk;
                }
                out.extend(packer.flush());
                assert_eq!(out, naive(&c), "offset {offset}, chunk {chunk}");
                assert_eq!(packer, WordPacker::default());
            }
        }
    }

    #[test]
    fn level_words_append_words_and_ranges_like_naive_pushes_at_every_offset() {
        let c = codes(400, 8);
        let words = naive(&c);
        for offset in 0..32 {
            for (start, n) in [
                (0, 0),
                (0, 1),
                (3, 29),
                (0, 64),
                (5, 100),
                (31, 33),
                (1, 399),
            ] {
                let head = &c[..offset];
                let mut level = LevelWords::default();
                for &code in head {
                    level.push(code, 1);
                }
                let mut pieces = LevelWords::default();
                pieces.append_words(&naive(head), offset);
                let mut expected = head.to_vec();
                expected.extend_from_slice(&c[start..start + n]);
                let mut by_range = level.clone();
                by_range.append_range(&words, start, n, false);
                pieces.append_words(&naive(&c[start..start + n]), n);
                assert_eq!(by_range.len(), expected.len());
                assert_eq!(
                    by_range.clone().into_words(),
                    (naive(&expected), expected.len())
                );
                assert_eq!(pieces.into_words(), (naive(&expected), expected.len()));
                let mut inverted = level;
                inverted.append_range(&words, start, n, true);
                let mut flipped = head.to_vec();
                flipped.extend(
                    c[start..start + n]
                        .iter()
                        .map(|&x| if x == 2 { 2 } else { 1 - x }),
                );
                assert_eq!(inverted.into_words(), (naive(&flipped), flipped.len()));
            }
        }
    }
}
