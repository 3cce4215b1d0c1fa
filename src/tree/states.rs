//! Node states packed two bits a node (Meagher's encoding), with a rank index over the partial nodes.

use super::words::{
    children_mask, full_count, full_mask, partial_mask, unused_mask, EMPTY_CODE, FULL_CODE,
    NODES_PER_WORD, PARTIAL_CODE,
};
use super::TreeError;

/// The state of a k-tree node ("obel"): wholly outside the object, wholly inside, or mixed.
///
/// The discriminants are the 2-bit codes stored in trees and in `.ktree` files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum NodeState {
    /// No voxel of the node belongs to the object (code `00`).
    Empty = EMPTY_CODE,
    /// Every voxel of the node belongs to the object (code `01`).
    Full = FULL_CODE,
    /// Some voxels do, some do not: the node has `2^K` children (code `10`).
    Partial = PARTIAL_CODE,
}

impl NodeState {
    /// The state of a 2-bit code, `None` for the unused code `11`.
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            EMPTY_CODE => Some(Self::Empty),
            FULL_CODE => Some(Self::Full),
            PARTIAL_CODE => Some(Self::Partial),
            _ => None,
        }
    }

    /// The state of the low two bits of `bits`, reading the unused code `11` as partial (levels never
    /// hold it: they are checked when built).
    #[inline(always)]
    pub(crate) fn from_bits(bits: u32) -> Self {
        match bits & 3 {
            0 => Self::Empty,
            1 => Self::Full,
            _ => Self::Partial,
        }
    }

    /// Whether the node is a leaf (empty or full).
    pub fn is_leaf(self) -> bool {
        self != Self::Partial
    }
}

/// Words per rank block: 256 nodes share one 16-bit block rank.
const WORDS_PER_BLOCK: usize = 8;
/// Blocks per superblock: 65 536 nodes share one 64-bit superblock rank, so that a block rank (partial
/// nodes from the superblock's start to the block's) is below 2^16.
const BLOCKS_PER_SUPER: usize = 256;

/// One tree level: node states at 2 bits each in `u64` words, and a two-tier rank index over the partial
/// nodes so that the rank of a node (the partial nodes before it) is found in constant time.
///
/// The rank index holds a 64-bit count every 65 536 nodes and a 16-bit count (relative to that) every 256
/// nodes: 2 + 16/256 + 64/65 536 ≈ 2.064 bits a node in all. Measured with the per-level bookkeeping: 2.070
/// bits a node for an octree of 1.9 million nodes, 2.065 for 7.5 million (`results/performance/build.md`).
/// A rank reads two counts and at most four words besides the node's own, counting from the nearer end of its block.
///
/// Levels are built inside the crate; outside it, [`PackedStates::from_words`] checks raw words and
/// [`crate::KTree::from_level_states`] checks a whole tree.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct PackedStates {
    words: Vec<u64>,
    len: usize,
    /// `super_rank[s]` = partial nodes in words `0 .. 8·256·s`.
    super_rank: Vec<u64>,
    /// `block_rank[b]` = partial nodes in words `8·256·(b / 256) .. 8·b`; entries for blocks
    /// `0 ..= words.len() / 8`, so that every rank `i ≤ len` has its block.
    block_rank: Vec<u16>,
    /// The number of partial nodes.
    partial: usize,
}

/// Adds the slots of `word` that have children (partial, or mixed in a valued tree) into 4-bit fields of
/// `acc` (at most 2 a word per field): up to seven words can be summed before [`nibble_total`] reads the sum.
#[inline(always)]
fn nibble_add(acc: u64, word: u64) -> u64 {
    const NIBBLE_PAIRS: u64 = 0x3333_3333_3333_3333;
    let m = children_mask(word);
    acc + (m & NIBBLE_PAIRS) + ((m >> 2) & NIBBLE_PAIRS)
}

/// The sum of the 4-bit fields of `acc`, added bytewise by one multiply. Faster than a population count per
/// word on targets without a population count instruction.
#[inline(always)]
fn nibble_total(acc: u64) -> u64 {
    const NIBBLES: u64 = 0x0F0F_0F0F_0F0F_0F0F;
    let bytes = (acc & NIBBLES) + ((acc >> 4) & NIBBLES);
    bytes.wrapping_mul(0x0101_0101_0101_0101) >> 56
}

/// Nodes with children in `words` (partial, or mixed in a valued tree), two words per population count.
#[inline]
fn partials_in(words: &[u64]) -> u64 {
    let mut pairs = words.chunks_exact(2);
    let mut n = 0u64;
    for p in &mut pairs {
        n += u64::from((children_mask(p[0]) | children_mask(p[1]) << 1).count_ones());
    }
    if let [w] = pairs.remainder() {
        n += u64::from(children_mask(*w).count_ones());
    }
    n
}

#[cold]
#[inline(never)]
#[track_caller]
pub(crate) fn node_out_of_range(i: usize, len: usize) -> ! {
    panic!("node {i} of a level of {len} nodes")
}

impl PackedStates {
    /// An empty level.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// A level with room for `n` nodes.
    pub(crate) fn with_capacity(n: usize) -> Self {
        Self {
            words: Vec::with_capacity(n.div_ceil(NODES_PER_WORD)),
            ..Self::default()
        }
    }

    /// Appends a node. Call [`PackedStates::finish`] after the last push.
    #[inline]
    pub(crate) fn push(&mut self, state: NodeState) {
        let slot = self.len % NODES_PER_WORD;
        if slot == 0 {
            self.words.push(0);
        }
        let last = self.words.len() - 1;
        self.words[last] |= (state as u64) << (2 * slot);
        self.len += 1;
    }

    /// Builds the rank index; must be called once all nodes are pushed.
    pub(crate) fn finish(&mut self) {
        self.words.shrink_to_fit();
        let blocks = self.words.len() / WORDS_PER_BLOCK + 1;
        self.block_rank.clear();
        self.block_rank.reserve_exact(blocks);
        self.super_rank.clear();
        self.super_rank
            .reserve_exact(blocks.div_ceil(BLOCKS_PER_SUPER));
        let mut total = 0u64;
        let mut base = 0u64;
        for b in 0..blocks {
            if b % BLOCKS_PER_SUPER == 0 {
                self.super_rank.push(total);
                base = total;
            }
            self.block_rank.push((total - base) as u16);
            let from = b * WORDS_PER_BLOCK;
            let to = (from + WORDS_PER_BLOCK).min(self.words.len());
            total += partials_in(&self.words[from..to]);
        }
        self.partial = total as usize;
    }

    /// Builds a level from raw words (two bits a node, node `i` at bits `2(i mod 32)` of word `i / 32`).
    ///
    /// ```
    /// use ktree::tree::PackedStates;
    /// let level = PackedStates::from_words(vec![0b10_01_00], 3).unwrap(); // empty, full, partial
    /// assert_eq!(level.partial_count(), 1);
    /// assert!(PackedStates::from_words(vec![0b11], 1).is_err());
    /// ```
    ///
    /// # Errors
    /// [`TreeError::WordCount`], [`TreeError::UnusedCode`] or [`TreeError::StrayBits`] if the word count does not fit `len`, a slot holds the unused code `11`, or bits beyond
    /// `len` are set.
    pub fn from_words(words: Vec<u64>, len: usize) -> Result<Self, TreeError> {
        // The word count first (as the valued form checks it), then the code a binary tree never uses.
        if words.len() == len.div_ceil(NODES_PER_WORD) {
            if let Some(w) = words.iter().position(|&w| unused_mask(w) != 0) {
                let slot = unused_mask(words[w]).trailing_zeros() as usize / 2;
                return Err(TreeError::UnusedCode {
                    node: w * NODES_PER_WORD + slot,
                });
            }
        }
        Self::from_valued_words(words, len)
    }

    /// A level of a valued tree from its words (code `11`, mixed, allowed).
    ///
    /// # Errors
    /// [`TreeError::WordCount`] or [`TreeError::StrayBits`] as [`PackedStates::from_words`].
    pub(crate) fn from_valued_words(words: Vec<u64>, len: usize) -> Result<Self, TreeError> {
        if words.len() != len.div_ceil(NODES_PER_WORD) {
            return Err(TreeError::WordCount {
                words: words.len(),
                len,
            });
        }
        let used = len % NODES_PER_WORD;
        if used != 0 && words[words.len() - 1] >> (2 * used) != 0 {
            return Err(TreeError::StrayBits { len });
        }
        let mut s = Self {
            words,
            len,
            ..Self::default()
        };
        s.finish();
        Ok(s)
    }

    /// A level with the same partial nodes as this one and other leaves (`words`, e.g. the leaves
    /// complemented): the rank index is copied, not rebuilt.
    pub(crate) fn with_same_partials(&self, words: Vec<u64>) -> Self {
        debug_assert!(
            words.len() == self.words.len()
                && words.iter().zip(&self.words).all(|(&new, &old)| {
                    partial_mask(new) == partial_mask(old) && unused_mask(new) == 0
                })
        );
        Self {
            words,
            len: self.len,
            super_rank: self.super_rank.clone(),
            block_rank: self.block_rank.clone(),
            partial: self.partial,
        }
    }

    /// The packed words.
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the level has no nodes.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The state of node `i`.
    ///
    /// ```
    /// use ktree::{tree::PackedStates, NodeState};
    /// let level = PackedStates::from_words(vec![0b10_01_00], 3).unwrap();
    /// assert_eq!(level.get(2), NodeState::Partial);
    /// ```
    ///
    /// # Panics
    /// If `i ≥ len`, in release builds as in debug ones (the slots past the end of the last word are
    /// padding, not nodes). Indexing, as of a slice: the trees' invariants keep the indices their navigation
    /// computes in range, so an index out of range is a caller's bug, not a state.
    #[inline]
    #[track_caller]
    pub fn get(&self, i: usize) -> NodeState {
        if i >= self.len {
            node_out_of_range(i, self.len);
        }
        NodeState::from_bits((self.words[i / NODES_PER_WORD] >> (2 * (i % NODES_PER_WORD))) as u32)
    }

    /// The 2-bit codes of the `2^k` nodes from `first` (a multiple of `2^k`, `k ≤ 4`), node `first + c` at
    /// bits `2c`: a block of children read with one load (it never straddles a word).
    #[inline(always)]
    pub(crate) fn block_codes(&self, first: usize, k: usize) -> u32 {
        debug_assert!(k <= 4 && first.is_multiple_of(1 << k) && first + (1 << k) <= self.len);
        let codes = self.words[first / NODES_PER_WORD] >> (2 * (first % NODES_PER_WORD));
        (codes & ((1u64 << (2 << k)) - 1)) as u32
    }

    /// The number of partial nodes before node `i` (`i ≤ len`).
    ///
    /// Counts from the nearer end of the node's block: four words masked and counted in parallel, without
    /// branches on the data.
    #[inline(always)]
    pub fn partial_rank(&self, i: usize) -> usize {
        let word = i / NODES_PER_WORD;
        let block = word / WORDS_PER_BLOCK;
        let from = block * WORDS_PER_BLOCK;
        let below = (1u64 << (2 * (i % NODES_PER_WORD))) - 1;
        let Some(words) = self.words.get(from..from + WORDS_PER_BLOCK) else {
            return self.rank_in_last_block(i);
        };
        // The lower half counts forwards from the block's start, the upper half backwards from its end.
        let upper = word - from >= WORDS_PER_BLOCK / 2;
        let half = if upper { WORDS_PER_BLOCK / 2 } else { 0 };
        let own = if upper { !below } else { below };
        let mut acc = 0;
        for (at, &w) in (from + half..).zip(&words[half..half + WORDS_PER_BLOCK / 2]) {
            let mask = if at == word {
                own
            } else if (at < word) != upper {
                u64::MAX
            } else {
                0
            };
            acc = nibble_add(acc, w & mask);
        }
        let count = nibble_total(acc);
        let rank = if upper {
            self.block_start(block + 1) - count
        } else {
            self.block_start(block) + count
        };
        rank as usize
    }

    /// [`PackedStates::partial_rank`] in the level's last, incomplete block: counted forwards.
    #[inline(never)]
    fn rank_in_last_block(&self, i: usize) -> usize {
        let word = i / NODES_PER_WORD;
        let block = word / WORDS_PER_BLOCK;
        let mut acc = 0;
        for &w in &self.words[block * WORDS_PER_BLOCK..word] {
            acc = nibble_add(acc, w);
        }
        let below = (1u64 << (2 * (i % NODES_PER_WORD))) - 1;
        if below != 0 {
            acc = nibble_add(acc, self.words[word] & below);
        }
        (self.block_start(block) + nibble_total(acc)) as usize
    }

    /// The partial nodes in the words before block `block`.
    #[inline(always)]
    fn block_start(&self, block: usize) -> u64 {
        self.super_rank[block / BLOCKS_PER_SUPER] + u64::from(self.block_rank[block])
    }

    /// The number of partial nodes in the level.
    pub fn partial_count(&self) -> usize {
        self.partial
    }

    /// The number of full nodes in the level.
    pub fn full_count(&self) -> usize {
        self.words.iter().map(|&w| full_count(w) as usize).sum()
    }

    /// The bytes a level of `len` nodes holds once built ([`PackedStates::heap_bytes`]), without building it.
    pub fn heap_bytes_for(len: usize) -> usize {
        let words = len.div_ceil(NODES_PER_WORD);
        let blocks = words / WORDS_PER_BLOCK + 1;
        words * 8 + blocks.div_ceil(BLOCKS_PER_SUPER) * 8 + blocks * 2
    }

    /// Bytes of memory held (words and rank index).
    pub fn heap_bytes(&self) -> usize {
        self.words.capacity() * 8 + self.super_rank.capacity() * 8 + self.block_rank.capacity() * 2
    }
}

/// A rank index over the full nodes (`01`) of a level, for a valued tree: the number of full nodes before a
/// node is the position of its value in the level's value column. Built only for trees that carry values:
/// a 64-bit count every 65 536 nodes and a 16-bit count every 256 nodes, as [`PackedStates`]' own index
/// (about 0.064 bits a node).
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub(crate) struct FullRank {
    /// `super_rank[s]` = full nodes in words `0 .. 8·256·s`.
    super_rank: Vec<u64>,
    /// `block_rank[b]` = full nodes from the start of block `b`'s superblock to the block's.
    block_rank: Vec<u16>,
}

impl FullRank {
    /// The index of the full nodes of `level`.
    pub(crate) fn new(level: &PackedStates) -> Self {
        let words = level.words();
        let blocks = words.len() / WORDS_PER_BLOCK + 1;
        let mut super_rank = Vec::with_capacity(blocks.div_ceil(BLOCKS_PER_SUPER));
        let mut block_rank = Vec::with_capacity(blocks);
        let (mut total, mut base) = (0u64, 0u64);
        for b in 0..blocks {
            if b % BLOCKS_PER_SUPER == 0 {
                super_rank.push(total);
                base = total;
            }
            block_rank.push((total - base) as u16);
            let from = b * WORDS_PER_BLOCK;
            let to = (from + WORDS_PER_BLOCK).min(words.len());
            total += words[from..to]
                .iter()
                .map(|&w| u64::from(full_count(w)))
                .sum::<u64>();
        }
        Self {
            super_rank,
            block_rank,
        }
    }

    /// The number of full nodes of `level` (the level this index was built for) before node `i ≤ len`.
    #[inline]
    pub(crate) fn rank(&self, level: &PackedStates, i: usize) -> usize {
        let words = level.words();
        let word = i / NODES_PER_WORD;
        let block = word / WORDS_PER_BLOCK;
        let mut rank =
            self.super_rank[block / BLOCKS_PER_SUPER] + u64::from(self.block_rank[block]);
        for &w in &words[block * WORDS_PER_BLOCK..word] {
            rank += u64::from(full_count(w));
        }
        let below = (1u64 << (2 * (i % NODES_PER_WORD))) - 1;
        if below != 0 {
            rank += u64::from((full_mask(words[word]) & below).count_ones());
        }
        rank as usize
    }

    /// Bytes of memory held.
    pub(crate) fn heap_bytes(&self) -> usize {
        self.super_rank.capacity() * 8 + self.block_rank.capacity() * 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_get_and_rank_agree_with_a_plain_vector() {
        let mut plain = Vec::new();
        let mut packed = PackedStates::new();
        let mut x = 12345u32;
        // Enough nodes for several superblocks.
        for _ in 0..200_000 {
            x = x.wrapping_mul(1103515245).wrapping_add(12345);
            let s = NodeState::from_code(((x >> 16) % 3) as u8).unwrap();
            plain.push(s);
            packed.push(s);
        }
        packed.finish();
        let mut rank = 0;
        for (i, &s) in plain.iter().enumerate() {
            assert_eq!(packed.get(i), s);
            assert_eq!(packed.partial_rank(i), rank);
            rank += usize::from(s == NodeState::Partial);
        }
        assert_eq!(packed.partial_rank(plain.len()), rank);
        assert_eq!(packed.partial_count(), rank);
        let full = plain.iter().filter(|&&s| s == NodeState::Full).count();
        assert_eq!(packed.full_count(), full);
    }

    #[test]
    fn ranks_of_nodes_with_children_and_of_full_nodes_count_a_valued_level_as_a_plain_vector_does()
    {
        // Codes 00, 01, 10 and 11 (a mixed node of a valued tree: it has children, it is not full).
        let mut words = Vec::new();
        let mut codes = Vec::new();
        let mut lcg = crate::testing::Lcg(99);
        let n = 2 * 65_536 + 4_321;
        for i in 0..n {
            let code = (lcg.next_u64() >> 61) & 3;
            if i % 32 == 0 {
                words.push(0u64);
            }
            *words.last_mut().unwrap() |= code << (2 * (i % 32));
            codes.push(code);
        }
        let mut level = PackedStates {
            words,
            len: n,
            ..PackedStates::default()
        };
        level.finish();
        let full = FullRank::new(&level);
        let (mut with_children, mut fulls) = (0, 0);
        for (i, &code) in codes.iter().enumerate() {
            assert_eq!(level.partial_rank(i), with_children, "node {i}");
            assert_eq!(full.rank(&level, i), fulls, "node {i}");
            with_children += usize::from(code >= 2);
            fulls += usize::from(code == 1);
        }
        assert_eq!(level.partial_rank(n), with_children);
        assert_eq!(full.rank(&level, n), fulls);
        assert_eq!(level.partial_count(), with_children);
    }

    #[test]
    fn ranks_hold_in_a_level_of_partial_nodes_only() {
        let n = 3 * 65_536 + 77;
        let mut packed = PackedStates::new();
        for _ in 0..n {
            packed.push(NodeState::Partial);
        }
        packed.finish();
        for i in (0..=n).step_by(97).chain([65_535, 65_536, 65_537, n]) {
            assert_eq!(packed.partial_rank(i), i);
        }
        assert_eq!(packed.partial_count(), n);
    }

    #[test]
    #[should_panic(expected = "node 5 of a level of 3 nodes")]
    fn get_past_the_end_panics_rather_than_reading_padding() {
        let level = PackedStates::from_words(vec![0b10_01_00], 3).unwrap();
        let _ = level.get(5);
    }

    #[test]
    fn from_words_rejects_code_three_and_stray_bits() {
        assert_eq!(
            PackedStates::from_words(vec![0b1100], 2),
            Err(TreeError::UnusedCode { node: 1 })
        );
        assert!(PackedStates::from_words(vec![0b0100], 1).is_err());
        assert!(PackedStates::from_words(vec![0b0110], 2).is_ok());
        assert!(PackedStates::from_words(vec![], 1).is_err());
    }
}
