//! A set of a map's voxels held as bitmaps of blocks: a block is the 2^15 voxels whose Morton keys share
//! all but their last 15 bits (for K = 3 an aligned cube of 32 voxels a side), kept as 32 768 bits found
//! through a small open-addressed table. A ray's voxels mostly follow one another inside a block, so adding
//! one is a bit set, and the table is asked only when the ray enters another block; repeats cost nothing
//! and the set is read back in Morton order without sorting its voxels (only its blocks). (Blocks of 2^12
//! and 2^18 voxels were measured slower, for OctoMap's scan and for LiDAR scans alike.)

/// The bits of a Morton key that place a voxel inside its block.
pub(crate) const BLOCK_BITS: u32 = 15;
/// The 64-bit words of a block's bitmap.
pub(crate) const WORDS: usize = 1 << (BLOCK_BITS - 6);
/// A table slot no block holds (block codes are below 2^49).
const NO_BLOCK: u64 = u64::MAX;

/// A block's bitmap: bit `i` of word `w` is the voxel at `64 · w + i` in the block's Morton order.
type Bitmap = [u64; WORDS];

/// A set of Morton keys of a map's universe.
#[derive(Debug, Clone)]
pub(crate) struct VoxelSet {
    /// Open addressing, linear probing: each slot a block code (or [`NO_BLOCK`]) and its bitmap's index.
    slots: Vec<(u64, u32)>,
    /// The block code of each bitmap.
    codes: Vec<u64>,
    bitmaps: Vec<Bitmap>,
    /// The block of the last key added and its bitmap's index.
    last: (u64, usize),
}

impl VoxelSet {
    pub(crate) fn new() -> Self {
        Self {
            slots: vec![(NO_BLOCK, 0); 1 << 10],
            codes: Vec::new(),
            bitmaps: Vec::new(),
            last: (NO_BLOCK, 0),
        }
    }

    /// Adds the voxel of Morton key `key`.
    #[inline]
    pub(crate) fn insert(&mut self, key: u64) {
        let block = key >> BLOCK_BITS;
        if block != self.last.0 {
            self.last = (block, self.bitmap_of(block));
        }
        let local = (key & ((1 << BLOCK_BITS) - 1)) as usize;
        self.bitmaps[self.last.1][local >> 6] |= 1 << (local & 63);
    }

    /// The words of the set's bitmaps, one after another: the bitmap of index `i` (see
    /// [`bitmap_of`](Self::bitmap_of)) is `WORDS` words from `i · WORDS`.
    #[inline]
    pub(crate) fn words_mut(&mut self) -> &mut [u64] {
        self.bitmaps.as_flattened_mut()
    }

    /// The index of `block`'s bitmap, made empty if the set has none yet. (Kept out of its callers'
    /// loops: inlined, it slowed the stepping of rays by a tenth.)
    #[inline(never)]
    pub(crate) fn bitmap_of(&mut self, block: u64) -> usize {
        let mask = self.slots.len() - 1;
        let mut slot = Self::hash(block, mask);
        loop {
            match self.slots[slot] {
                (code, index) if code == block => return index as usize,
                (NO_BLOCK, _) => break,
                _ => slot = (slot + 1) & mask,
            }
        }
        let index = self.bitmaps.len();
        self.codes.push(block);
        self.bitmaps.push([0; WORDS]);
        self.slots[slot] = (block, index as u32);
        if 2 * self.codes.len() > self.slots.len() {
            self.grow();
        }
        index
    }

    #[inline]
    fn hash(block: u64, mask: usize) -> usize {
        (block.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) as usize & mask
    }

    /// Doubles the table, placing every block again.
    fn grow(&mut self) {
        self.slots = vec![(NO_BLOCK, 0); 2 * self.slots.len()];
        let mask = self.slots.len() - 1;
        for (index, &block) in self.codes.iter().enumerate() {
            let mut slot = Self::hash(block, mask);
            while self.slots[slot].0 != NO_BLOCK {
                slot = (slot + 1) & mask;
            }
            self.slots[slot] = (block, index as u32);
        }
    }
}

/// The union of several sets, its blocks in increasing order.
#[derive(Debug, Clone, Default)]
pub(crate) struct SortedVoxels {
    codes: Vec<u64>,
    bitmaps: Vec<Bitmap>,
}

impl SortedVoxels {
    /// The union of `sets`.
    pub(crate) fn union(sets: Vec<VoxelSet>) -> Self {
        let mut order: Vec<(u64, u32, u32)> = sets
            .iter()
            .enumerate()
            .flat_map(|(s, set)| {
                set.codes
                    .iter()
                    .enumerate()
                    .map(move |(b, &code)| (code, s as u32, b as u32))
            })
            .collect();
        order.sort_unstable();
        let mut out = Self::default();
        for (code, s, b) in order {
            let bitmap = &sets[s as usize].bitmaps[b as usize];
            if out.codes.last() == Some(&code) {
                let last = out.bitmaps.last_mut().expect("a bitmap for each code");
                for (word, &add) in last.iter_mut().zip(bitmap) {
                    *word |= add;
                }
            } else {
                out.codes.push(code);
                out.bitmaps.push(*bitmap);
            }
        }
        out
    }

    /// Hands the set's keys to `visit` in increasing order.
    #[inline]
    pub(crate) fn for_each(&self, mut visit: impl FnMut(u64)) {
        for (&code, bitmap) in self.codes.iter().zip(&self.bitmaps) {
            for (w, &word) in bitmap.iter().enumerate() {
                let base = (code << BLOCK_BITS) | (w as u64) << 6;
                let mut bits = word;
                while bits != 0 {
                    visit(base | u64::from(bits.trailing_zeros()));
                    bits &= bits - 1;
                }
            }
        }
    }

    /// The number of keys in the set.
    pub(crate) fn len(&self) -> usize {
        self.bitmaps
            .iter()
            .flatten()
            .map(|w| w.count_ones() as usize)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The union of sets is the sorted, deduplicated list of every key added to any of them.
        #[test]
        fn union_is_sorted_distinct_keys(parts in prop::collection::vec(prop::collection::vec(prop_oneof![0u64..20_000, any::<u64>(), (0u64..40).prop_map(|b| b << 12)], 0..300), 0..4)) {
            let mut expected: Vec<u64> = parts.iter().flatten().copied().collect();
            expected.sort_unstable();
            expected.dedup();
            let sets = parts
                .iter()
                .map(|keys| {
                    let mut set = VoxelSet::new();
                    keys.iter().for_each(|&k| set.insert(k));
                    set
                })
                .collect();
            let union = SortedVoxels::union(sets);
            let mut keys = Vec::new();
            union.for_each(|k| keys.push(k));
            prop_assert_eq!(keys, expected.clone());
            prop_assert_eq!(union.len(), expected.len());
        }
    }

    #[test]
    fn the_table_grows_past_its_first_size() {
        let mut set = VoxelSet::new();
        let blocks = 5000u64;
        for b in 0..blocks {
            set.insert(((b * 7919) << BLOCK_BITS) | (b % 4096));
        }
        assert!(set.slots.len() >= 2 * blocks as usize);
        let union = SortedVoxels::union(vec![set]);
        assert_eq!(union.len(), blocks as usize);
    }
}
