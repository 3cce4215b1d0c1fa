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

use crate::radix::radix_sort;
use crate::rays::{maximal_rows, RaySet};
use crate::space::{morton_encode, Universe};
use crate::tree::KTree;

/// What stacking did: the traffic through each dimension-level list and the peak number of items held.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
/// use ktree::{stacking::paper::stack, Ray, RaySet, NodeState};
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
    stack_impl(rays, RowPath::Auto)
}

/// How stage 1 (rows → squares) is run; both give the same tree (a unit test holds them equal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowPath {
    /// The merging row path when its packed keys fit 64 bits (`2L + 5 ≤ 64`), else the generic one.
    Auto,
    /// Always the generic path (every list radix-sorted); tests compare it with the merging path.
    #[cfg_attr(not(test), allow(dead_code))]
    Generic,
}

fn stack_impl<const K: usize>(rays: &RaySet<K>, path: RowPath) -> (KTree<K>, StackingStats) {
    let universe = rays.universe();
    let level = universe.level();
    let lists = (level + 1) as usize;
    let mut stacker = Stacker::<K> {
        universe,
        stages: (1..K).map(|d| Stage::new(K, d, level)).collect(),
        cells: Cells::new(level),
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
        combined_buf: Vec::new(),
    };
    if K >= 2 && path == RowPath::Auto && 2 * level + 5 <= 64 {
        stacker.rows_by_merging(rays);
    } else {
        for (i, &(z1, z2)) in rays.runs().iter().enumerate() {
            let mut origin = rays.column_of_key(rays.column_keys()[i]);
            for row in maximal_rows(z1, z2) {
                stacker.stats.maximal_rows += 1;
                origin[K - 1] = row.z;
                stacker.feed(1, level - row.log_len, origin);
            }
        }
    }
    for d in 1..K {
        stacker.flush(d);
    }
    // Destructured in full, so that the stages' lists are freed before the tree is assembled.
    let Stacker {
        cells,
        mut stats,
        scratch,
        stages,
        combined_buf,
        ..
    } = stacker;
    drop((stages, combined_buf));
    stats.cells = cells.len();
    (cells.into_tree(universe, scratch), stats)
}

/// The full leaves (items of dimension `K`, the "obels") collected by stacking, assembled into the tree.
pub(super) struct Cells<const K: usize> {
    /// Whether cells fit `Morton key << 5 | level` in 64 bits (`K·L + 5 ≤ 64`).
    packed: bool,
    /// The cells, packed.
    keys: Vec<u64>,
    /// The cells as (Morton key, level) when they do not fit packed.
    wide: Vec<(u64, u32)>,
    level: u32,
}

impl<const K: usize> Cells<K> {
    pub(super) fn new(level: u32) -> Self {
        Self {
            packed: K as u32 * level + 5 <= 64,
            keys: Vec::new(),
            wide: Vec::new(),
            level,
        }
    }

    /// Adds the cell of `level` at `origin`.
    #[inline]
    pub(super) fn push(&mut self, origin: [u32; K], level: u32) {
        let key = morton_encode(origin);
        if self.packed {
            self.keys.push(key << 5 | u64::from(level));
        } else {
            self.wide.push((key, level));
        }
    }

    pub(super) fn len(&self) -> u64 {
        (self.keys.len() + self.wide.len()) as u64
    }

    /// Sorts the cells by Morton key (unique: cells are disjoint) and assembles the level-order tree.
    pub(super) fn into_tree(self, universe: Universe<K>, mut scratch: Vec<u64>) -> KTree<K> {
        if self.packed {
            let mut keys = self.keys;
            radix_sort(&mut keys, K as u32 * self.level + 5, &mut scratch);
            drop(scratch);
            KTree::from_sorted_packed(universe, &keys)
        } else {
            let mut wide = self.wide;
            wide.sort_unstable();
            KTree::from_sorted_morton(universe, &wide)
        }
    }
}

/// The streaming pipeline of stages `D = 1 … K−1` and the collected output cells.
struct Stacker<const K: usize> {
    universe: Universe<K>,
    /// `stages[D − 1]`.
    stages: Vec<Stage>,
    /// Output cells.
    cells: Cells<K>,
    stats: StackingStats,
    /// Items currently held in lists.
    held: u64,
    scratch: Vec<u64>,
    /// Items combined during a flush — (stage key without prefix, level) — fed onward after the scan.
    combined_buf: Vec<(u64, u32)>,
}

/// One dimension's lists ι(D, 0 … L) for the current prefix group.
pub(super) struct Stage {
    /// The axis this stage combines along: `K − 1 − D`.
    pub(super) axis: usize,
    /// Bits of a local key: the `D + 1` fields of axes `a+1 … K−1` and `a`, `L` bits each.
    pub(super) local_bits: u32,
    /// The prefix (axes `0 … a−1`) of the group being collected, if any.
    pub(super) prefix: Option<u64>,
    /// `lists[l]`: local keys of the items at level `l`.
    pub(super) lists: Vec<Vec<u64>>,
    /// `half_offsets[l]`: the `2^D` key offsets that split an item of level `l` into its halves.
    half_offsets: Vec<Vec<u64>>,
}

/// For stage `D` of a `K`-tree in a level-`level` universe, `offsets[l]`: the `2^D` offsets that turn the
/// key of an item of level `l` into the keys of its halves (fields of axes `a+1 … K−1` at bit `(K − e)·L`,
/// in a local key as in a whole stage key).
pub(super) fn half_offsets(k: usize, d: usize, level: u32) -> Vec<Vec<u64>> {
    let axis = k - 1 - d;
    (0..=level)
        .map(|l| {
            let sh = level - l;
            if sh == 0 {
                return Vec::new();
            }
            let half = 1u64 << (sh - 1);
            (0..1usize << d)
                .map(|m| {
                    (0..d)
                        .filter(|j| m >> j & 1 == 1)
                        .map(|j| half << ((k - (axis + 1 + j)) as u32 * level))
                        .sum()
                })
                .collect()
        })
        .collect()
}

/// Packs an origin into the key of the stage combining along `axis`: fields (most significant first) axes
/// `0…a−1`, axes `a+1…K−1`, then axis `a`, `level` bits each.
#[inline]
pub(super) fn pack_key<const K: usize>(level: u32, axis: usize, origin: [u32; K]) -> u64 {
    let mut key = 0u64;
    for (i, &c) in origin.iter().enumerate() {
        if i != axis {
            key = key << level | u64::from(c);
        }
    }
    key << level | u64::from(origin[axis])
}

/// The origin of a key packed by [`pack_key`].
#[inline]
pub(super) fn unpack_key<const K: usize>(level: u32, axis: usize, mut key: u64) -> [u32; K] {
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

impl Stage {
    pub(super) fn new(k: usize, d: usize, level: u32) -> Self {
        Self {
            axis: k - 1 - d,
            local_bits: (d as u32 + 1) * level,
            prefix: None,
            lists: vec![Vec::new(); level as usize + 1],
            half_offsets: half_offsets(k, d, level),
        }
    }

    /// Sorts `list`, the items of level `l` (of a universe of level `top`), and combines or splits them:
    /// each combined group's first key goes to `on_combined`, the halves of every split item to
    /// `self.lists[l + 1]`. Returns the number of items split.
    pub(super) fn combine_level(
        &mut self,
        l: usize,
        list: &mut Vec<u64>,
        top: u32,
        scratch: &mut Vec<u64>,
        on_combined: impl FnMut(u64),
    ) -> u64 {
        let sh = top - l as u32;
        // At the voxel level every item combines on its own: no need to sort.
        if sh > 0 {
            radix_sort(list, self.local_bits, scratch);
        }
        let offsets = &self.half_offsets[l];
        let mut next = self.lists.get_mut(l + 1);
        combine_or_split(list, sh, on_combined, |key| {
            let next = next
                .as_deref_mut()
                .expect("items split only above the voxel level");
            next.extend(offsets.iter().map(|&o| key + o));
        })
    }
}

impl<const K: usize> Stacker<K> {
    /// Packs an origin into stage `D`'s key: fields (most significant first) axes `0…a−1`, axes `a+1…K−1`,
    /// then axis `a`, `L` bits each.
    fn pack(&self, axis: usize, origin: [u32; K]) -> u64 {
        pack_key(self.universe.level(), axis, origin)
    }

    fn unpack(&self, axis: usize, key: u64) -> [u32; K] {
        unpack_key(self.universe.level(), axis, key)
    }

    fn hold(&mut self, n: u64) {
        self.held += n;
        self.stats.peak_items = self.stats.peak_items.max(self.held);
    }

    /// Puts an item of dimension `d` (1 ≤ d ≤ K) at `level` into its list (or, for `d = K`, the output).
    fn feed(&mut self, d: usize, level: u32, origin: [u32; K]) {
        if d == K {
            self.cells.push(origin, level);
            return;
        }
        let stage = &self.stages[d - 1];
        let local_bits = stage.local_bits;
        let key = self.pack(stage.axis, origin);
        // For a 64-bit local key the prefix is empty (K·L = 64 happens only for K = 4, L = 16).
        let prefix = key.checked_shr(local_bits).unwrap_or(0);
        let local_mask = u64::MAX.checked_shr(64 - local_bits).unwrap_or(0);
        self.feed_local(d, level, prefix, key & local_mask);
    }

    /// Puts an item of dimension `d < K`, given as its stage's prefix and local key, into its list.
    fn feed_local(&mut self, d: usize, level: u32, prefix: u64, local: u64) {
        if self.stages[d - 1].prefix.is_some_and(|p| p != prefix) {
            self.flush(d);
        }
        let stage = &mut self.stages[d - 1];
        stage.prefix = Some(prefix);
        stage.lists[level as usize].push(local);
        self.stats.entered[d - 1][level as usize] += 1;
        self.hold(1);
    }

    /// Runs combine/split over all levels of stage `d`'s current prefix group.
    fn flush(&mut self, d: usize) {
        let Some(prefix) = self.stages[d - 1].prefix.take() else {
            return;
        };
        let top = self.universe.level();
        let mut list = Vec::new();
        for l in 0..=top as usize {
            std::mem::swap(&mut list, &mut self.stages[d - 1].lists[l]);
            if list.is_empty() {
                continue;
            }
            self.held -= list.len() as u64;
            let mut combined = std::mem::take(&mut self.combined_buf);
            let split =
                self.stages[d - 1].combine_level(l, &mut list, top, &mut self.scratch, |key| {
                    combined.push((key, l as u32))
                });
            list.clear();
            self.stats.split[d - 1][l] += split;
            self.stats.combined[d - 1][l] += combined.len() as u64;
            if split > 0 {
                let n = split << d;
                self.stats.entered[d - 1][l + 1] += n;
                self.hold(n);
            }
            self.pass_on(d, prefix, &mut combined);
            self.combined_buf = combined;
        }
    }

    /// Feeds the items combined by stage `d` (local keys of its current `prefix`) to stage `d + 1`.
    fn pass_on(&mut self, d: usize, prefix: u64, combined: &mut Vec<(u64, u32)>) {
        let axis = self.stages[d - 1].axis;
        let prefix_bits = prefix
            .checked_shl(self.stages[d - 1].local_bits)
            .unwrap_or(0);
        for (key, l) in combined.drain(..) {
            let origin = self.unpack(axis, prefix_bits | key);
            self.feed(d + 1, l, origin);
        }
    }

    /// Stage 1 without sorting every list: the rows of one slice (a fixed prefix) are sorted once by
    /// (level, z, y); at each level the list is the merge of that level's fresh rows with the two halves of
    /// the rows split at the level above — each of the three is already sorted, since adding the same offset
    /// to sorted keys keeps them sorted. Same lists, same combine/split, linear work per level.
    fn rows_by_merging(&mut self, rays: &RaySet<K>) {
        let top = self.universe.level();
        let y_mask = (1u64 << top) - 1;
        let level_shift = 2 * top;
        let local_mask = (1u64 << level_shift) - 1;
        let keys = rays.column_keys();
        let runs = rays.runs();
        let mut fresh = Vec::new();
        let mut list = Vec::new();
        let (mut cur_low, mut cur_high) = (Vec::new(), Vec::new());
        let (mut next_low, mut next_high) = (Vec::new(), Vec::new());
        let mut combined = Vec::new();
        let mut start = 0;
        while start < runs.len() {
            let prefix = keys[start] >> top;
            let mut end = start;
            fresh.clear();
            while end < runs.len() && keys[end] >> top == prefix {
                let y = keys[end] & y_mask;
                let (z1, z2) = runs[end];
                for row in maximal_rows(z1, z2) {
                    let l = u64::from(top - row.log_len);
                    fresh.push(l << level_shift | u64::from(row.z) << top | y);
                }
                end += 1;
            }
            self.stats.maximal_rows += fresh.len() as u64;
            self.hold(fresh.len() as u64);
            radix_sort(&mut fresh, level_shift + 5, &mut self.scratch);
            let mut at = 0;
            cur_low.clear();
            cur_high.clear();
            for l in 0..=top as usize {
                let from = at;
                while at < fresh.len() && (fresh[at] >> level_shift) as usize == l {
                    at += 1;
                }
                // cur_low and cur_high hold the halves split from level l − 1, each sorted; merge them
                // with this level's fresh rows.
                list.clear();
                if l == top as usize {
                    // Voxel level: everything combines on its own, order does not matter.
                    list.extend(fresh[from..at].iter().map(|&v| v & local_mask));
                    list.extend_from_slice(&cur_low);
                    list.extend_from_slice(&cur_high);
                } else {
                    merge3(&fresh[from..at], local_mask, &cur_low, &cur_high, &mut list);
                }
                if list.is_empty() {
                    continue;
                }
                self.held -= list.len() as u64;
                self.stats.entered[0][l] += list.len() as u64;
                let sh = top - l as u32;
                next_low.clear();
                next_high.clear();
                let half = if sh > 0 {
                    [0, (1u64 << (sh - 1)) << top]
                } else {
                    [0, 0]
                };
                let split = combine_or_split(
                    &list,
                    sh,
                    |key| combined.push((key, l as u32)),
                    |key| {
                        next_low.push(key + half[0]);
                        next_high.push(key + half[1]);
                    },
                );
                self.stats.split[0][l] += split;
                self.stats.combined[0][l] += combined.len() as u64;
                self.hold(2 * split);
                std::mem::swap(&mut cur_low, &mut next_low);
                std::mem::swap(&mut cur_high, &mut next_high);
                self.pass_on_rows(prefix, &mut combined);
            }
            start = end;
        }
    }

    /// Feeds squares combined by the row stage (local keys `z << L | y` of slice `prefix`) to stage 2.
    fn pass_on_rows(&mut self, prefix: u64, combined: &mut Vec<(u64, u32)>) {
        let top = self.universe.level();
        if K == 2 {
            // Squares are the output cells.
            for (key, l) in combined.drain(..) {
                let origin = self.unpack(0, key);
                self.feed(2, l, origin);
            }
            return;
        }
        // Stage 2 combines along axis K − 3, the last coordinate of the slice prefix; its local key is
        // (c_{K−2}, c_{K−1}, c_{K−3}) and its prefix the slice prefix without c_{K−3}.
        let mask = (1u64 << top) - 1;
        let (stage_prefix, c) = (prefix >> top, prefix & mask);
        for (key, l) in combined.drain(..) {
            let (z, y) = (key >> top, key & mask);
            let local = y << (2 * top) | z << top | c;
            self.feed_local(2, l, stage_prefix, local);
        }
    }
}

/// Scans a sorted list of local keys at shift `sh` (side `2^sh`): each run of keys equal above bit `sh`
/// with exactly `2^sh` members combines (`on_combined` gets the run's first key with the low `sh` bits
/// cleared); every member of any other run is split (`on_split` gets its key). Returns the number of items
/// split.
pub(super) fn combine_or_split(
    list: &[u64],
    sh: u32,
    mut on_combined: impl FnMut(u64),
    mut on_split: impl FnMut(u64),
) -> u64 {
    let side = 1usize << sh;
    let mut split = 0;
    let mut i = 0;
    while i < list.len() {
        let group = list[i] >> sh;
        let mut j = i + 1;
        while j < list.len() && list[j] >> sh == group {
            j += 1;
        }
        if j - i == side {
            on_combined(group << sh);
        } else {
            list[i..j].iter().for_each(|&key| on_split(key));
            split += (j - i) as u64;
        }
        i = j;
    }
    split
}

/// Merges three sorted sequences into `out`: `fresh` (keys masked by `mask`) and the two halves `lows`,
/// `highs`. Keys are below 2^62, so `u64::MAX` marks an exhausted sequence.
fn merge3(fresh: &[u64], mask: u64, lows: &[u64], highs: &[u64], out: &mut Vec<u64>) {
    let (mut i, mut j, mut k) = (0, 0, 0);
    let total = fresh.len() + lows.len() + highs.len();
    out.reserve(total);
    for _ in 0..total {
        let f = fresh.get(i).map_or(u64::MAX, |&v| v & mask);
        let a = lows.get(j).copied().unwrap_or(u64::MAX);
        let b = highs.get(k).copied().unwrap_or(u64::MAX);
        if f <= a && f <= b {
            out.push(f);
            i += 1;
        } else if a <= b {
            out.push(a);
            j += 1;
        } else {
            out.push(b);
            k += 1;
        }
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
        assert_eq!(tree.full_cells().next().unwrap().side(), 4);
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
    fn merging_row_path_equals_generic_path() {
        let mut x = 0x2545F4914F6CDD1Du64;
        for level in 0..=6u32 {
            let side = 1u32 << level;
            for _ in 0..20 {
                let rays: Vec<Ray<3>> = (0..30)
                    .map(|_| {
                        x ^= x << 13;
                        x ^= x >> 7;
                        x ^= x << 17;
                        let c = (x % u64::from(side)) as u32;
                        let y = ((x >> 10) % u64::from(side)) as u32;
                        let z1 = ((x >> 20) % u64::from(side)) as u32;
                        let z2 = z1 + 1 + ((x >> 30) % u64::from(side - z1)) as u32;
                        Ray::new([c / 2, y, z1], z2)
                    })
                    .collect();
                let set = RaySet::from_rays(level, rays).unwrap();
                let (a, sa) = stack_impl(&set, RowPath::Auto);
                let (b, sb) = stack_impl(&set, RowPath::Generic);
                assert_eq!(a, b);
                assert_eq!(
                    (sa.entered, sa.combined, sa.split),
                    (sb.entered, sb.combined, sb.split)
                );
            }
        }
    }

    #[test]
    fn list_count_is_k_minus_one_times_l_plus_one() {
        let set = rays3(4, &[([3, 5, 1], 9)]);
        let (_, stats) = stack_with_stats(&set);
        assert_eq!(stats.lists_available(), 2 * 5);
        assert!(stats.lists_used() <= stats.lists_available());
    }
}
