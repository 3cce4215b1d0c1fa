//! Node states packed two bits a node (Meagher's encoding), with a rank index over the partial nodes.

/// The state of a k-tree node ("obel"): wholly outside the object, wholly inside, or mixed.
///
/// The discriminants are the 2-bit codes stored in trees and in `.ktree` files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum NodeState {
    /// No voxel of the node belongs to the object (code `00`).
    Empty = 0,
    /// Every voxel of the node belongs to the object (code `01`).
    Full = 1,
    /// Some voxels do, some do not: the node has `2^K` children (code `10`).
    Partial = 2,
}

impl NodeState {
    /// The state of a 2-bit code, `None` for the unused code `11`.
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Empty),
            1 => Some(Self::Full),
            2 => Some(Self::Partial),
            _ => None,
        }
    }

    /// Whether the node is a leaf (empty or full).
    pub fn is_leaf(self) -> bool {
        self != Self::Partial
    }
}

const NODES_PER_WORD: usize = 32;
const WORDS_PER_BLOCK: usize = 4;
const LOW_BITS: u64 = 0x5555_5555_5555_5555;

/// One tree level: node states at 2 bits each in `u64` words, and the number of partial nodes before each
/// block of 4 words (128 nodes) so that the rank of a partial node is found in constant time.
///
/// Memory: 2 bits a node plus 32 bits every 128 nodes = 2.25 bits a node.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct PackedStates {
    words: Vec<u64>,
    len: usize,
    /// `block_rank[b]` = partial nodes in words `0 .. 4·b`; one extra entry holds the total.
    block_rank: Vec<u64>,
}

/// Mask with the low bit of each 2-bit slot set where the slot holds `Partial` (`10`).
#[inline]
fn partial_mask(word: u64) -> u64 {
    (word >> 1) & !word & LOW_BITS
}

/// Mask with the low bit of each 2-bit slot set where the slot holds `Full` (`01`).
#[inline]
fn full_mask(word: u64) -> u64 {
    word & !(word >> 1) & LOW_BITS
}

impl PackedStates {
    /// An empty level.
    pub fn new() -> Self {
        Self::default()
    }

    /// A level with room for `n` nodes.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            words: Vec::with_capacity(n.div_ceil(NODES_PER_WORD)),
            len: 0,
            block_rank: Vec::new(),
        }
    }

    /// Appends a node. Call [`PackedStates::finish`] after the last push.
    #[inline]
    pub fn push(&mut self, state: NodeState) {
        let slot = self.len % NODES_PER_WORD;
        if slot == 0 {
            self.words.push(0);
        }
        let last = self.words.len() - 1;
        self.words[last] |= (state as u64) << (2 * slot);
        self.len += 1;
    }

    /// Appends `n` copies of a state.
    pub fn push_many(&mut self, state: NodeState, n: usize) {
        for _ in 0..n {
            self.push(state);
        }
    }

    /// Builds the rank index; must be called once all nodes are pushed.
    pub fn finish(&mut self) {
        self.words.shrink_to_fit();
        self.block_rank.clear();
        self.block_rank
            .reserve_exact(self.words.len().div_ceil(WORDS_PER_BLOCK) + 1);
        let mut total = 0u64;
        for block in self.words.chunks(WORDS_PER_BLOCK) {
            self.block_rank.push(total);
            total += block
                .iter()
                .map(|&w| u64::from(partial_mask(w).count_ones()))
                .sum::<u64>();
        }
        self.block_rank.push(total);
    }

    /// Builds a level from raw words (two bits a node, node `i` at bits `2(i mod 32)` of word `i / 32`).
    /// Returns `None` if a slot holds the unused code `11` or bits beyond `len` are set.
    pub fn from_words(words: Vec<u64>, len: usize) -> Option<Self> {
        if words.len() != len.div_ceil(NODES_PER_WORD) {
            return None;
        }
        if words.iter().any(|&w| (w >> 1) & w & LOW_BITS != 0) {
            return None;
        }
        let used = len % NODES_PER_WORD;
        if used != 0 && words[words.len() - 1] >> (2 * used) != 0 {
            return None;
        }
        let mut s = Self {
            words,
            len,
            block_rank: Vec::new(),
        };
        s.finish();
        Some(s)
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
    #[inline]
    pub fn get(&self, i: usize) -> NodeState {
        debug_assert!(i < self.len);
        let code = (self.words[i / NODES_PER_WORD] >> (2 * (i % NODES_PER_WORD))) & 3;
        match code {
            0 => NodeState::Empty,
            1 => NodeState::Full,
            _ => NodeState::Partial,
        }
    }

    /// The number of partial nodes before node `i` (`i ≤ len`).
    #[inline]
    pub fn partial_rank(&self, i: usize) -> usize {
        let word = i / NODES_PER_WORD;
        let block = word / WORDS_PER_BLOCK;
        let mut rank = self.block_rank[block];
        for &w in &self.words[block * WORDS_PER_BLOCK..word] {
            rank += u64::from(partial_mask(w).count_ones());
        }
        let slot = i % NODES_PER_WORD;
        if slot > 0 {
            let below = (1u64 << (2 * slot)) - 1;
            rank += u64::from((partial_mask(self.words[word]) & below).count_ones());
        }
        rank as usize
    }

    /// The number of partial nodes in the level.
    pub fn partial_count(&self) -> usize {
        self.block_rank.last().copied().unwrap_or(0) as usize
    }

    /// The number of full nodes in the level.
    pub fn full_count(&self) -> usize {
        self.words
            .iter()
            .map(|&w| full_mask(w).count_ones() as usize)
            .sum()
    }

    /// Bytes of memory held (words and rank index).
    pub fn heap_bytes(&self) -> usize {
        self.words.capacity() * 8 + self.block_rank.capacity() * 8
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
        for _ in 0..1000 {
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
    fn from_words_rejects_code_three_and_stray_bits() {
        assert!(PackedStates::from_words(vec![0b11], 1).is_none());
        assert!(PackedStates::from_words(vec![0b0100], 1).is_none());
        assert!(PackedStates::from_words(vec![0b0110], 2).is_some());
        assert!(PackedStates::from_words(vec![], 1).is_none());
    }
}
