//! Akman & Franklin's *stacking*: rays → maximal rows → combine/split through the dimension-level lists
//! ι(D, l) → the minimal reduced k-tree.
//!
//! # The algorithm
//! An item of dimension `D` at level `l` is a slab of side `s = 2^(L−l)` along the last `D` axes and of
//! thickness one voxel along the others: a *row* for `D = 1`, a *square* for `D = 2`, a *cube* for `D = 3`.
//! The list ι(D, l) holds the items of dimension `D` and level `l` waiting to be combined along axis
//! `a = K − 1 − D` (rows combine along axis `K − 2`, squares along `K − 3`, …, the last along axis 0).
//!
//! 0. Each ray is cut into its maximal rows ([`crate::rays::maximal_rows`]); a row of length `2^s` goes to
//!    ι(1, L − s).
//! 1. For `D = 1 … K−1` and `l = 0 … L`: sort ι(D, l) so that items differing only in axis `a` are adjacent.
//!    `s` items at positions `a = m·s, m·s + 1, …, m·s + s − 1` with everything else equal *combine* into one
//!    item of dimension `D + 1` at the same level, appended to ι(D + 1, l). Every item of an incomplete
//!    group is *split* into `2^D` items of half the side, appended to ι(D, l + 1). At `l = L` the side is 1
//!    and every item combines.
//! 2. Items of dimension `K` are the tree's full leaves ("obels"); sorted by Morton key they are assembled
//!    into the level-order tree ([`KTree::from_sorted_morton`]).
//!
//! The `(K − 1)·(L + 1)` lists are the paper's ΔΛ-lists (claim AF4; [`StackingStats::lists_used`] counts the
//! ones that received items).
//!
//! # Streaming
//! Combining along axis `a` never mixes items whose coordinates on axes `0 … a−1` differ. Rays arrive sorted
//! by column (axis 0 most significant), so each stage works on one such *prefix group* at a time, sorts its
//! small lists in cache with a radix sort, and passes its output on in prefix order; only the last stage
//! (prefix empty) sees all its items at once. Memory is proportional to the rows of one slab plus the items
//! of the last stage plus the output: no dense array, no per-voxel work.
//!
//! # Performance
//! `O(n)` in the number of rows and items (radix sorts on keys of `(D+1)·L` bits) plus the Morton sort and
//! assembly of the output (`O(cells · L)`). Measured figures: `results/performance/build.md`.

use super::radix::radix_sort;
use crate::rays::{maximal_rows, RaySet};
use crate::space::{morton_encode, Universe};
use crate::tree::KTree;

/// What stacking did: the traffic through each dimension-level list and the peak number of items held.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct StackingStats {
    /// The dimension `K`.
    pub k: usize,
    /// The universe level `L`.
    pub level: u32,
    /// Runs in the input.
    pub rays: u64,
    /// Maximal rows cut from the runs.
    pub maximal_rows: u64,
    /// `entered[D−1][l]`: items that entered ι(D, l), for `D = 1 … K−1` (for `K = 1`, no list exists and
    /// the rows are the tree).
    pub entered: Vec<Vec<u64>>,
    /// `combined[D−1][l]`: groups of ι(D, l) combined into one item of dimension `D + 1`.
    pub combined: Vec<Vec<u64>>,
    /// `split[D−1][l]`: items of ι(D, l) that could not combine and were split into `2^D` halves.
    pub split: Vec<Vec<u64>>,
    /// Full leaves produced (items of dimension `K`).
    pub cells: u64,
    /// The largest number of items held in all lists at once (claim AF3: no intermediate swell).
    pub peak_items: u64,
}

impl StackingStats {
    /// The number of dimension-level lists that exist: `(K − 1)·(L + 1)` (claim AF4).
    pub fn lists_available(&self) -> usize {
        self.k.saturating_sub(1) * (self.level as usize + 1)
    }

    /// The number of lists that received at least one item.
    pub fn lists_used(&self) -> usize {
        self.entered.iter().flatten().filter(|&&n| n > 0).count()
    }
}

/// Builds the minimal reduced k-tree of a ray set by stacking.
///
/// ```
/// use ktree::{build::stack, Ray, RaySet, NodeState};
/// // A 2×2 square in a 4×4 quadtree universe, as two rays.
/// let rays = RaySet::<2>::from_rays(2, [Ray::new([0, 0], 2), Ray::new([1, 0], 2)]).unwrap();
/// let tree = stack(&rays);
/// assert_eq!(tree.node_count(), 5); // a partial root with one full and three empty quadrants
/// assert_eq!(tree.level_states(1).get(0), NodeState::Full);
/// ```
pub fn stack<const K: usize>(rays: &RaySet<K>) -> KTree<K> {
    stack_with_stats(rays).0
}

/// Like [`stack`], also returning what went through the dimension-level lists.
pub fn stack_with_stats<const K: usize>(rays: &RaySet<K>) -> (KTree<K>, StackingStats) {
    let universe = rays.universe();
    let level = universe.level();
    let lists = (level + 1) as usize;
    let mut stacker = Stacker::<K> {
        universe,
        stages: (1..K).map(|d| Stage::new(K, d, level)).collect(),
        cells: Vec::new(),
        stats: StackingStats {
            k: K,
            level,
            rays: rays.len() as u64,
            entered: vec![vec![0; lists]; K - 1],
            combined: vec![vec![0; lists]; K - 1],
            split: vec![vec![0; lists]; K - 1],
            ..Default::default()
        },
        held: 0,
        scratch: Vec::new(),
    };
    for (i, &(z1, z2)) in rays.runs().iter().enumerate() {
        let mut origin = rays.column_of_key(rays.column_keys()[i]);
        for row in maximal_rows(z1, z2) {
            stacker.stats.maximal_rows += 1;
            origin[K - 1] = row.z;
            stacker.feed(1, level - row.log_len, origin);
        }
    }
    for d in 1..K {
        stacker.flush(d);
    }
    let Stacker {
        mut cells,
        mut stats,
        mut scratch,
        ..
    } = stacker;
    stats.cells = cells.len() as u64;
    // Sort the obels by Morton key. A cell's key is unique (cells are disjoint), so sorting the keys alone
    // and re-attaching levels through a lookup is not needed: pack (key, level) when it fits in 64 bits.
    let tree = if (K as u32) * level + 5 <= 64 {
        let mut packed: Vec<u64> = cells
            .iter()
            .map(|&(key, l)| key << 5 | u64::from(l))
            .collect();
        radix_sort(&mut packed, K as u32 * level + 5, &mut scratch);
        let sorted: Vec<(u64, u32)> = packed.iter().map(|&p| (p >> 5, (p & 31) as u32)).collect();
        KTree::from_sorted_morton(universe, &sorted)
    } else {
        cells.sort_unstable();
        KTree::from_sorted_morton(universe, &cells)
    };
    (tree, stats)
}

/// The streaming pipeline of stages `D = 1 … K−1` and the collected output cells.
struct Stacker<const K: usize> {
    universe: Universe<K>,
    /// `stages[D − 1]`.
    stages: Vec<Stage>,
    /// Output cells as (Morton key, level).
    cells: Vec<(u64, u32)>,
    stats: StackingStats,
    /// Items currently held in lists.
    held: u64,
    scratch: Vec<u64>,
}

/// One dimension's lists ι(D, 0 … L) for the current prefix group.
struct Stage {
    /// The axis this stage combines along: `K − 1 − D`.
    axis: usize,
    /// Bits of a local key: the `D + 1` fields of axes `a+1 … K−1` and `a`, `L` bits each.
    local_bits: u32,
    /// The prefix (axes `0 … a−1`) of the group being collected, if any.
    prefix: Option<u64>,
    /// `lists[l]`: local keys of the items at level `l`.
    lists: Vec<Vec<u64>>,
}

impl Stage {
    fn new(k: usize, d: usize, level: u32) -> Self {
        Self {
            axis: k - 1 - d,
            local_bits: (d as u32 + 1) * level,
            prefix: None,
            lists: vec![Vec::new(); level as usize + 1],
        }
    }
}

impl<const K: usize> Stacker<K> {
    /// Packs an origin into stage `D`'s key: fields (most significant first) axes `0…a−1`, axes `a+1…K−1`,
    /// then axis `a`, `L` bits each.
    fn pack(&self, axis: usize, origin: [u32; K]) -> u64 {
        let level = self.universe.level();
        let mut key = 0u64;
        for (i, &c) in origin.iter().enumerate() {
            if i != axis {
                key = key << level | u64::from(c);
            }
        }
        key << level | u64::from(origin[axis])
    }

    fn unpack(&self, axis: usize, mut key: u64) -> [u32; K] {
        let level = self.universe.level();
        let mask = (1u64 << level) - 1;
        let mut origin = [0u32; K];
        origin[axis] = (key & mask) as u32;
        key >>= level;
        for i in (0..K).rev().filter(|&i| i != axis) {
            origin[i] = (key & mask) as u32;
            key >>= level;
        }
        origin
    }

    /// Puts an item of dimension `d` (1 ≤ d ≤ K) at `level` into its list (or, for `d = K`, the output).
    fn feed(&mut self, d: usize, level: u32, origin: [u32; K]) {
        if d == K {
            self.cells.push((morton_encode(origin), level));
            return;
        }
        let (axis, local_bits, current) = {
            let stage = &self.stages[d - 1];
            (stage.axis, stage.local_bits, stage.prefix)
        };
        let key = self.pack(axis, origin);
        // For a 64-bit local key the prefix is empty (K·L = 64 happens only for K = 4, L = 16).
        let prefix = key.checked_shr(local_bits).unwrap_or(0);
        if current.is_some_and(|p| p != prefix) {
            self.flush(d);
        }
        let local_mask = u64::MAX.checked_shr(64 - local_bits).unwrap_or(0);
        let stage = &mut self.stages[d - 1];
        stage.prefix = Some(prefix);
        stage.lists[level as usize].push(key & local_mask);
        self.stats.entered[d - 1][level as usize] += 1;
        self.held += 1;
        self.stats.peak_items = self.stats.peak_items.max(self.held);
    }

    /// Runs combine/split over all levels of stage `d`'s current prefix group.
    fn flush(&mut self, d: usize) {
        let Some(prefix) = self.stages[d - 1].prefix.take() else {
            return;
        };
        let top = self.universe.level();
        let axis = self.stages[d - 1].axis;
        let local_bits = self.stages[d - 1].local_bits;
        let prefix_bits = prefix.checked_shl(local_bits).unwrap_or(0);
        for l in 0..=top {
            let mut list = std::mem::take(&mut self.stages[d - 1].lists[l as usize]);
            if list.is_empty() {
                continue;
            }
            self.held -= list.len() as u64;
            radix_sort(&mut list, local_bits, &mut self.scratch);
            let sh = top - l;
            let side = 1usize << sh;
            // Offsets that split an item into its 2^D halves along axes a+1 … K−1. In a local key the
            // field of axis e sits at bit (K − e)·L.
            let half_offsets: Vec<u64> = if sh > 0 {
                let half = 1u64 << (sh - 1);
                (0..1usize << d)
                    .map(|m| {
                        (0..d)
                            .filter(|j| m >> j & 1 == 1)
                            .map(|j| half << ((K - (axis + 1 + j)) as u32 * top))
                            .sum()
                    })
                    .collect()
            } else {
                Vec::new()
            };
            let mut split_items = Vec::new();
            let mut i = 0;
            while i < list.len() {
                let group = list[i] >> sh;
                let mut j = i + 1;
                while j < list.len() && list[j] >> sh == group {
                    j += 1;
                }
                if j - i == side {
                    self.stats.combined[d - 1][l as usize] += 1;
                    let origin = self.unpack(axis, prefix_bits | group << sh);
                    self.feed(d + 1, l, origin);
                } else {
                    self.stats.split[d - 1][l as usize] += (j - i) as u64;
                    for &key in &list[i..j] {
                        split_items.extend(half_offsets.iter().map(|&o| key + o));
                    }
                }
                i = j;
            }
            if !split_items.is_empty() {
                let n = split_items.len() as u64;
                self.stats.entered[d - 1][l as usize + 1] += n;
                self.held += n;
                self.stats.peak_items = self.stats.peak_items.max(self.held);
                self.stages[d - 1].lists[l as usize + 1].extend_from_slice(&split_items);
            }
            // Give the buffer back for reuse.
            list.clear();
            let slot = &mut self.stages[d - 1].lists[l as usize];
            if slot.capacity() < list.capacity() {
                *slot = list;
            }
        }
        // The prefix group is done; a combined item may have started the next stage's group, so flushing
        // that stage is left to the caller's order (prefixes of stage d+1 are coarser).
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::Ray;

    fn rays3(level: u32, rays: &[([u32; 3], u32)]) -> RaySet<3> {
        RaySet::from_rays(level, rays.iter().map(|&(s, z2)| Ray::new(s, z2))).unwrap()
    }

    #[test]
    fn fig4_aligned_rows_combine_into_a_square() {
        // AF2: rows (0,0,0) … (0,3,0) of length four combine (level 1 in an 8-universe).
        let set = rays3(
            3,
            &[
                ([0, 0, 0], 4),
                ([0, 1, 0], 4),
                ([0, 2, 0], 4),
                ([0, 3, 0], 4),
            ],
        );
        let (tree, stats) = stack_with_stats(&set);
        tree.assert_well_formed();
        assert_eq!(stats.entered[0][1], 4);
        assert_eq!(stats.combined[0][1], 1, "one square from four rows");
        assert_eq!(stats.split[0][1], 0);
        assert_eq!(tree.voxel_count(), 16);
    }

    #[test]
    fn fig4_misaligned_rows_do_not_combine_but_their_halves_do() {
        // AF2: rows (0,1,0) … (0,4,0) cannot combine; split, the halves at y = 2, 3 combine (Fig. 6).
        let set = rays3(
            3,
            &[
                ([0, 1, 0], 4),
                ([0, 2, 0], 4),
                ([0, 3, 0], 4),
                ([0, 4, 0], 4),
            ],
        );
        let (tree, stats) = stack_with_stats(&set);
        tree.assert_well_formed();
        assert_eq!(stats.combined[0][1], 0);
        assert_eq!(stats.split[0][1], 4);
        assert_eq!(stats.entered[0][2], 8, "four rows split into eight halves");
        assert_eq!(
            stats.combined[0][2], 2,
            "two squares of side two: y = 2..3, z = 0..1 and 2..3"
        );
        assert_eq!(tree.voxel_count(), 16);
    }

    #[test]
    fn fig5_aligned_squares_combine_into_a_cube() {
        // AF2: squares (0,0,0) … (3,0,0) of side four combine into a cube.
        let mut rays = Vec::new();
        for x in 0..4 {
            for y in 0..4 {
                rays.push(([x, y, 0], 4));
            }
        }
        let (tree, stats) = stack_with_stats(&rays3(3, &rays));
        assert_eq!(stats.combined[1][1], 1);
        assert_eq!(stats.cells, 1);
        assert_eq!(tree.full_cells()[0].side(), 4);
        // Shifted by one along x: the squares cannot combine and are split.
        let shifted: Vec<_> = rays
            .iter()
            .map(|&(s, z)| ([s[0] + 1, s[1], s[2]], z))
            .collect();
        let (_, stats) = stack_with_stats(&rays3(3, &shifted));
        assert_eq!(stats.combined[1][1], 0);
        assert_eq!(stats.split[1][1], 4);
    }

    #[test]
    fn list_count_is_k_minus_one_times_l_plus_one() {
        let set = rays3(4, &[([3, 5, 1], 9)]);
        let (_, stats) = stack_with_stats(&set);
        assert_eq!(stats.lists_available(), 2 * 5);
        assert!(stats.lists_used() <= stats.lists_available());
    }
}
