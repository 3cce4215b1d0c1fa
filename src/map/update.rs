//! One scan's update of a map: the voxels its points end in (hits) and the voxels its rays cross on the
//! way (misses), each once, hits winning — OctoMap's `computeUpdate` and `insertPointCloud` with
//! `discretize = false` — gathered on all threads as Morton keys, deduplicated by sorting, and merged
//! into the map's tree in one pass from the root down.

use rayon::prelude::*;

use super::grid::MapGrid;
use super::model::SensorModel;
use super::traverse::{clipped_end, difference, norm, visit_key_ray};
use crate::radix::radix_sort;
use crate::space::{morton_encode, Cell};
use crate::tree::storage::infallible;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::ValueState;
use crate::tree::TreeError;
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
/// one hit or miss of `model`, the others kept; minimal, as always.
pub fn apply<const K: usize>(
    map: &KTree<K, f32>,
    update: &[(u64, bool)],
    model: &SensorModel,
) -> KTree<K, f32> {
    let level = map.level();
    // The context of a cell: the map's node it lies in, the range of `update` inside it, and the Morton
    // keys the cell spans (its first and the log of its side).
    let root = (
        infallible(InputNode::root(map)),
        0..update.len(),
        0u64,
        level,
    );
    let out = build_top_down::<K, f32, _, TreeError>(
        level,
        root,
        |_: &Cell<K>, (node, range, _, log_side)| {
            let leaf = match node.state {
                ValueState::Empty => Some(None),
                ValueState::Full(v) => Some(Some(v)),
                _ => None,
            };
            let here = &update[range.clone()];
            let Some(&(_, first)) = here.first() else {
                // Nothing of the scan here: the map's node as it is (its subtree copied below).
                return Ok(match leaf {
                    Some(v) => Decision::Leaf(v),
                    None => Decision::Split,
                });
            };
            let volume = 1u128 << (K as u32 * log_side);
            let uniform = here.len() as u128 == volume && here.iter().all(|&(_, h)| h == first);
            Ok(match leaf {
                Some(v) if uniform => Decision::Leaf(Some(model.update(v.unwrap_or(0.0), first))),
                _ => Decision::Split,
            })
        },
        |(node, range, base, log_side), code| {
            let span = 1u64 << (K as u32 * (log_side - 1));
            let start = base + code as u64 * span;
            let here = &update[range.clone()];
            let lo = range.start + here.partition_point(|&(k, _)| k < start);
            // The last cell of a 4-D root ends at 2^64.
            let hi = match start.checked_add(span) {
                Some(end) => range.start + here.partition_point(|&(k, _)| k < end),
                None => range.end,
            };
            Ok((
                infallible(node.child(map, code)),
                lo..hi,
                start,
                log_side - 1,
            ))
        },
    );
    out.expect("log-odds stay finite and a voxel is never split")
}
