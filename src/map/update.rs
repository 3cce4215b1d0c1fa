//! One scan's update of a map: the voxels its points end in (hits) and the voxels its rays cross on the
//! way (misses), each once, hits winning — OctoMap's `computeUpdate` and `insertPointCloud` with
//! `discretize = false` — gathered on all threads as Morton keys, deduplicated by sorting, and merged
//! into the map's tree in one depth-first pass.

use rayon::prelude::*;

use super::grid::MapGrid;
use super::model::SensorModel;
use super::traverse::{clipped_end, difference, norm, visit_key_ray};
use crate::radix::radix_sort;
use crate::space::morton_encode;
use crate::tree::storage::infallible;
use crate::tree::top_down::{pack, InputNode};
use crate::tree::valued::{combine, ValueState};
use crate::KTree;

/// The points of a scan handed to one thread at a time.
const POINTS_A_TASK: usize = 2048;

/// The voxels one scan updates, as Morton keys of the map's universe in increasing order, each once, with
/// whether it is a hit (`true`) or a miss.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScanUpdate {
    /// The updated voxels and whether each is a hit.
    pub voxels: Vec<(u64, bool)>,
    /// Rays whose origin or end fell outside the map (OctoMap skips them and warns).
    pub rays_outside: usize,
}

impl ScanUpdate {
    /// The update of the points `points` (world coordinates) seen from `origin`: a point within
    /// `max_range` of the origin (all points if `None`) is a hit and its ray's voxels before it misses; a
    /// point beyond gives only the misses of its ray cut at `max_range`.
    pub fn compute<const K: usize>(
        grid: &MapGrid,
        points: &[[f32; K]],
        origin: [f32; K],
        max_range: Option<f64>,
    ) -> Self {
        let bits = K as u32 * super::MAP_LEVEL;
        let parts: Vec<(Vec<u64>, Vec<u64>, usize)> = points
            .par_chunks(POINTS_A_TASK)
            .map(|chunk| {
                let (mut hits, mut misses, mut outside) = (Vec::new(), Vec::new(), 0usize);
                let mut seen = RepeatFilter::new();
                for &p in chunk {
                    let within = max_range.is_none_or(|m| norm(difference(origin, p)) <= m);
                    let end = match max_range {
                        Some(m) if !within => clipped_end(origin, p, m),
                        _ => p,
                    };
                    let inside = visit_key_ray(grid, origin, end, |k| {
                        let key = morton_encode(k);
                        if seen.is_new(key) {
                            misses.push(key);
                        }
                    });
                    outside += usize::from(!inside);
                    if within {
                        if let Some(k) = grid.keys(p) {
                            hits.push(morton_encode(k));
                        }
                    }
                }
                (hits, misses, outside)
            })
            .collect();
        let rays_outside = parts.iter().map(|p| p.2).sum();
        let (mut hits, mut misses) = (Vec::new(), Vec::new());
        for (h, m, _) in parts {
            hits.extend(h);
            misses.extend(m);
        }
        let ((), ()) = rayon::join(
            || sort_dedup(&mut hits, bits),
            || sort_dedup(&mut misses, bits),
        );
        Self {
            voxels: merge_sorted(&hits, &misses),
            rays_outside,
        }
    }
}

/// Sorts keys below `2^bits` and removes repeats.
fn sort_dedup(keys: &mut Vec<u64>, bits: u32) {
    radix_sort(keys, bits, &mut Vec::new());
    keys.dedup();
}

/// A direct-mapped table of recently seen keys: most voxels a ray crosses were crossed by the rays just
/// before it (they share the sensor), and a key found here is not gathered again. Lossy — a key pushed
/// out by another is gathered twice — so the sort still removes the remaining repeats.
struct RepeatFilter {
    slots: Vec<u64>,
}

impl RepeatFilter {
    const BITS: u32 = 14;

    fn new() -> Self {
        Self {
            slots: vec![u64::MAX; 1 << Self::BITS],
        }
    }

    #[inline]
    fn is_new(&mut self, key: u64) -> bool {
        let slot = (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - Self::BITS)) as usize;
        let fresh = self.slots[slot] != key;
        self.slots[slot] = key;
        fresh
    }
}

/// The union of two increasing key lists, each key marked whether it is in `hits` (which win).
fn merge_sorted(hits: &[u64], misses: &[u64]) -> Vec<(u64, bool)> {
    let mut out = Vec::with_capacity(hits.len() + misses.len());
    let (mut i, mut j) = (0, 0);
    while i < hits.len() || j < misses.len() {
        match (hits.get(i), misses.get(j)) {
            (Some(&h), Some(&m)) if m < h => {
                out.push((m, false));
                j += 1;
            }
            (Some(&h), m) => {
                out.push((h, true));
                i += 1;
                if m == Some(&h) {
                    j += 1;
                }
            }
            (None, Some(&m)) => {
                out.push((m, false));
                j += 1;
            }
            (None, None) => unreachable!(),
        }
    }
    out
}

/// The map's log-odds after `update`: every updated voxel's log-odds (0 where it was unknown) moved by
/// one hit or miss of `model`, the others kept; minimal, as always. Depth first: each cell's children are
/// made before it, a block of alike children joined at once.
pub fn apply<const K: usize>(
    map: &KTree<K, f32>,
    update: &[(u64, bool)],
    model: &SensorModel,
) -> KTree<K, f32> {
    let level = map.level();
    let mut merge = Merge {
        map,
        model,
        levels: vec![Vec::new(); level as usize + 1],
    };
    let root = merge.node(infallible(InputNode::root(map)), update, 0, level, 0);
    merge.levels[0].push(root);
    pack(map.universe(), merge.levels)
}

/// The state of a depth-first merge: the settled states of each level so far.
struct Merge<'a, const K: usize> {
    map: &'a KTree<K, f32>,
    model: &'a SensorModel,
    levels: Vec<Vec<ValueState<f32>>>,
}

impl<const K: usize> Merge<'_, K> {
    /// The state of the cell of the map's `node` whose voxels' Morton keys start at `base` (a side of
    /// `2^log_side`, at `depth`) after the updates `update` inside it; its children, if any, pushed onto the
    /// level below.
    fn node(
        &mut self,
        node: InputNode<f32>,
        update: &[(u64, bool)],
        base: u64,
        log_side: u32,
        depth: usize,
    ) -> ValueState<f32> {
        let leaf = match node.state {
            ValueState::Empty => Some(None),
            ValueState::Full(v) => Some(Some(v)),
            _ => None,
        };
        if let (Some(v), Some(&(_, first))) = (leaf, update.first()) {
            let volume = 1u128 << (K as u32 * log_side);
            if update.len() as u128 == volume && update.iter().all(|&(_, h)| h == first) {
                return ValueState::Full(self.model.update(v.unwrap_or(0.0), first));
            }
        }
        if update.is_empty() {
            if let Some(v) = leaf {
                return v.map_or(ValueState::Empty, ValueState::Full);
            }
        }
        // Not a leaf of the result: its children, each from the map's child and its part of the update.
        let span = 1u64 << (K as u32 * (log_side - 1));
        let mut kids = [ValueState::Empty; 16];
        let mut rest = update;
        for (code, kid) in kids.iter_mut().enumerate().take(1 << K) {
            let start = base + code as u64 * span;
            let here = match start.checked_add(span) {
                Some(end) => rest.partition_point(|&(k, _)| k < end),
                // The last cell of a 4-D root ends at 2^64.
                None => rest.len(),
            };
            let child = infallible(node.child(self.map, code));
            *kid = self.node(child, &rest[..here], start, log_side - 1, depth + 1);
            rest = &rest[here..];
        }
        let kids = &kids[..1 << K];
        let state = combine(kids);
        if state.has_children() {
            self.levels[depth + 1].extend_from_slice(kids);
        }
        state
    }
}
