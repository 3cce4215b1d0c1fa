//! A set of a map's voxels held as bitmaps of blocks: a block is the 2^15 voxels whose Morton keys share
//! all but their last 15 bits (for K = 3 an aligned cube of 32 voxels a side), kept as 32 768 bits found
//! through a small open-addressed table. A ray's voxels mostly follow one another inside a block, so adding
//! one is a bit set, and the table is asked only when the ray enters another block; repeats cost nothing
//! and the set is read back in Morton order without sorting its voxels (only its blocks). (Blocks of 2^12
//! and 2^18 voxels were measured slower, for OctoMap's scan and for LiDAR scans alike.)

use rayon::prelude::*;

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

/// Blocks of the union made by one task: about the voxels of a few ray chunks' worth.
const BLOCKS_A_PIECE: usize = 64;

/// The union of several sets: its blocks in increasing order, in pieces of consecutive blocks each made
/// apart on the rayon pool (only the blocks are sorted, never the voxels).
#[derive(Debug, Clone, Default)]
pub(crate) struct Union {
    pieces: Vec<SortedVoxels>,
}

impl Union {
    /// The union of `sets`.
    pub(crate) fn of(sets: Vec<VoxelSet>) -> Self {
        Self {
            pieces: SortedVoxels::union(&sets),
        }
    }

    /// The union's keys that are not among the increasing keys `excluded`, in increasing order.
    pub(crate) fn into_keys_without(mut self, excluded: &[u64]) -> Vec<u64> {
        let counts: Vec<usize> = self
            .pieces
            .par_iter_mut()
            .map(|piece| {
                piece.remove(excluded);
                piece.len()
            })
            .collect();
        let mut keys = vec![0; counts.iter().sum()];
        let mut slices = Vec::with_capacity(counts.len());
        let mut rest = keys.as_mut_slice();
        for &count in &counts {
            let (mine, after) = rest.split_at_mut(count);
            slices.push(mine);
            rest = after;
        }
        self.pieces
            .par_iter()
            .zip(slices)
            .for_each(|(piece, out)| piece.write_keys(out));
        keys
    }
}

/// Blocks of a set in increasing order of their codes.
#[derive(Debug, Clone, Default)]
struct SortedVoxels {
    codes: Vec<u64>,
    bitmaps: Vec<Bitmap>,
}

impl SortedVoxels {
    /// The union of `sets` as pieces of at most [`BLOCKS_A_PIECE`] blocks, in increasing order, each
    /// made apart on the rayon pool.
    fn union(sets: &[VoxelSet]) -> Vec<Self> {
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
        // Where each block's bitmaps start in `order`, and the end.
        let mut starts: Vec<usize> = (0..order.len())
            .filter(|&i| i == 0 || order[i - 1].0 != order[i].0)
            .collect();
        starts.push(order.len());
        starts
            .windows(2)
            .collect::<Vec<_>>()
            .par_chunks(BLOCKS_A_PIECE)
            .map(|blocks| {
                let mut piece = Self::default();
                for block in blocks {
                    let members = &order[block[0]..block[1]];
                    let (code, s, b) = members[0];
                    let mut bitmap = sets[s as usize].bitmaps[b as usize];
                    for &(_, s, b) in &members[1..] {
                        for (word, &add) in
                            bitmap.iter_mut().zip(&sets[s as usize].bitmaps[b as usize])
                        {
                            *word |= add;
                        }
                    }
                    piece.codes.push(code);
                    piece.bitmaps.push(bitmap);
                }
                piece
            })
            .collect()
    }

    /// Takes out the keys of the increasing list `keys` (those outside the set's blocks ignored).
    fn remove(&mut self, keys: &[u64]) {
        let (Some(&first), Some(&last)) = (self.codes.first(), self.codes.last()) else {
            return;
        };
        let from = keys.partition_point(|&k| k >> BLOCK_BITS < first);
        let to = keys.partition_point(|&k| k >> BLOCK_BITS <= last);
        let mut block = 0;
        for &key in &keys[from..to] {
            let code = key >> BLOCK_BITS;
            while self.codes[block] < code {
                block += 1;
            }
            if self.codes[block] == code {
                let local = (key & ((1 << BLOCK_BITS) - 1)) as usize;
                self.bitmaps[block][local >> 6] &= !(1 << (local & 63));
            }
        }
    }

    /// Writes the set's keys in increasing order into `out`, which holds exactly [`len`](Self::len).
    fn write_keys(&self, out: &mut [u64]) {
        let mut slots = out.iter_mut();
        self.for_each(|key| *slots.next().expect("a slot for every key") = key);
    }

    /// Hands the set's keys to `visit` in increasing order.
    #[inline]
    fn for_each(&self, mut visit: impl FnMut(u64)) {
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
    fn len(&self) -> usize {
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
        /// The union of sets without some keys is the sorted, deduplicated list of every key added to
        /// any of them and not among those keys.
        #[test]
        fn union_without_keys_is_sorted_distinct_keys(parts in prop::collection::vec(prop::collection::vec(key(), 0..300), 0..4), excluded in prop::collection::vec(key(), 0..200)) {
            let mut excluded = excluded;
            excluded.sort_unstable();
            excluded.dedup();
            let mut expected: Vec<u64> = parts.iter().flatten().copied().filter(|k| excluded.binary_search(k).is_err()).collect();
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
            prop_assert_eq!(Union::of(sets).into_keys_without(&excluded), expected);
        }
    }

    /// Keys in a few blocks, at their ends, in many blocks (more than a piece of the union) and anywhere.
    fn key() -> impl Strategy<Value = u64> {
        prop_oneof![
            0u64..20_000,
            any::<u64>(),
            (0u64..40).prop_map(|b| b << BLOCK_BITS),
            (0u64..40).prop_map(|b| ((b + 1) << BLOCK_BITS) - 1),
            (0u64..1000).prop_map(|b| (b << BLOCK_BITS) | (b * 37 % (1 << BLOCK_BITS))),
        ]
    }

    #[test]
    fn the_table_grows_past_its_first_size() {
        let mut set = VoxelSet::new();
        let blocks = 5000u64;
        for b in 0..blocks {
            set.insert(((b * 7919) << BLOCK_BITS) | (b % 4096));
        }
        assert!(set.slots.len() >= 2 * blocks as usize);
        assert_eq!(
            Union::of(vec![set]).into_keys_without(&[]).len(),
            blocks as usize
        );
    }
}
