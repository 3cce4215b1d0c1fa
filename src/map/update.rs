//! One scan's update of a map: the voxels its points end in (hits) and the voxels its rays cross on the
//! way (misses), each once, hits winning — OctoMap's `computeUpdate` and `insertPointCloud` with
//! `discretize = false` — gathered on all threads: each ray's misses and each point's hit set as bits of
//! the blocks of voxels (repeats cost nothing; the blocks, not the voxels, are sorted), the hits taken
//! out of the misses, and the two lists merged into the map's tree in one depth-first pass.

use rayon::prelude::*;

use super::grid::MapGrid;
use super::model::SensorModel;
use super::ray_lanes::add_rays;
use super::traverse::{clipped_end, difference, norm};
use super::voxel_set::{Union, VoxelSet};
use crate::space::morton_encode;
use crate::tree::storage::infallible;
use crate::tree::top_down::{InputNode, Subtree};
use crate::tree::valued::{combine, ValueState, ValuedLevel};
use crate::KTree;

/// The points of a scan handed to one thread at a time.
const POINTS_A_TASK: usize = 2048;

/// The voxels one scan updates, as Morton keys of the map's universe in increasing order, each once: the
/// hits, and the misses (no hit among them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScanUpdate {
    /// The voxels holding a point of the scan.
    pub hits: Vec<u64>,
    /// The other voxels the scan's rays cross.
    pub misses: Vec<u64>,
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
        // Each task's misses and hits in sets of its own (repeats cost nothing).
        let parts: Vec<(VoxelSet, VoxelSet, usize)> = points
            .par_chunks(POINTS_A_TASK)
            .fold(
                || (VoxelSet::new(), VoxelSet::new(), 0usize),
                |(mut misses, mut hits, mut outside), chunk| {
                    // Each ray's end: the point, or where the maximum range cuts the ray.
                    let mut stops = Vec::with_capacity(chunk.len());
                    for &p in chunk {
                        let within = max_range.is_none_or(|m| norm(difference(origin, p)) <= m);
                        stops.push(match max_range {
                            Some(m) if !within => clipped_end(origin, p, m),
                            _ => p,
                        });
                        if within {
                            if let Some(k) = grid.keys(p) {
                                hits.insert(morton_encode(k));
                            }
                        }
                    }
                    outside += add_rays(&mut misses, grid, origin, &stops);
                    (misses, hits, outside)
                },
            )
            .collect();
        let rays_outside = parts.iter().map(|p| p.2).sum();
        let (miss_sets, hit_sets): (Vec<_>, Vec<_>) =
            parts.into_iter().map(|(m, h, _)| (m, h)).unzip();
        let (hits, misses) = rayon::join(
            || Union::of(hit_sets).into_keys_without(&[]),
            || Union::of(miss_sets),
        );
        Self {
            misses: misses.into_keys_without(&hits),
            hits,
            rays_outside,
        }
    }

    /// The number of voxels updated.
    pub fn len(&self) -> usize {
        self.hits.len() + self.misses.len()
    }

    /// Whether no voxel is updated.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The updated voxels in increasing order, each with whether it is a hit.
    ///
    /// ```
    /// use ktree::map::{MapGrid, ScanUpdate};
    /// let grid = MapGrid::new(1.0).unwrap();
    /// // A ray along x from the voxel of the origin to the third voxel after it.
    /// let update = ScanUpdate::compute(&grid, &[[3.5f32]], [0.5], None);
    /// let hits: Vec<bool> = update.voxels().map(|(_, hit)| hit).collect();
    /// assert_eq!(hits, [false, false, false, true]);
    /// ```
    pub fn voxels(&self) -> impl Iterator<Item = (u64, bool)> + '_ {
        Part::whole(self)
    }
}

/// The part of a scan's update inside a cell: its hits and its misses, each increasing.
#[derive(Debug, Clone, Copy, Default)]
struct Part<'a> {
    hits: &'a [u64],
    misses: &'a [u64],
}

impl<'a> Part<'a> {
    fn whole(update: &'a ScanUpdate) -> Self {
        Part {
            hits: &update.hits,
            misses: &update.misses,
        }
    }

    fn len(&self) -> usize {
        self.hits.len() + self.misses.len()
    }

    /// Whether every voxel is a hit (`Some(true)`) or every one a miss (`Some(false)`); `None` when
    /// there are both or none.
    fn all_alike(&self) -> Option<bool> {
        match (self.hits.is_empty(), self.misses.is_empty()) {
            (false, true) => Some(true),
            (true, false) => Some(false),
            _ => None,
        }
    }

    /// The part below key `end` and the rest.
    fn split_at_key(self, end: u64) -> (Self, Self) {
        let (h, m) = (
            self.hits.partition_point(|&k| k < end),
            self.misses.partition_point(|&k| k < end),
        );
        (
            Part {
                hits: &self.hits[..h],
                misses: &self.misses[..m],
            },
            Part {
                hits: &self.hits[h..],
                misses: &self.misses[m..],
            },
        )
    }
}

/// A part read as its voxels in increasing order, each with whether it is a hit.
impl Iterator for Part<'_> {
    type Item = (u64, bool);

    #[inline]
    fn next(&mut self) -> Option<(u64, bool)> {
        match (self.hits.split_first(), self.misses.split_first()) {
            (Some((&h, rest)), Some((&m, _))) if h < m => {
                self.hits = rest;
                Some((h, true))
            }
            (_, Some((&m, rest))) => {
                self.misses = rest;
                Some((m, false))
            }
            (Some((&h, rest)), None) => {
                self.hits = rest;
                Some((h, true))
            }
            (None, None) => None,
        }
    }
}

/// The map's log-odds after `update`: every updated voxel's log-odds (0 where it was unknown) moved by
/// one hit or miss of `model`, the others kept; minimal, as always. Depth first: each cell's children are
/// made before it, a block of alike children joined at once; on the threads of the current rayon pool,
/// a cell with many updates has its children made apart.
pub fn apply<const K: usize>(
    map: &KTree<K, f32>,
    update: &ScanUpdate,
    model: &SensorModel,
) -> KTree<K, f32> {
    let parallel = rayon::current_num_threads() > 1;
    let root = infallible(InputNode::root(map));
    let whole = subtree(
        map,
        model,
        root,
        Part::whole(update),
        0,
        map.level(),
        parallel,
    );
    whole.into_tree(map.universe())
}

/// Updates a cell must hold for its children to be made apart.
const UPDATES_APART: usize = 1 << 14;

/// The subtree of the cell of the map's `node` whose voxels' Morton keys start at `base` (a side of
/// `2^log_side`) after the updates `update` inside it: its children made apart on the rayon pool when
/// `parallel` and it holds many updates, else depth first on this thread.
fn subtree<const K: usize>(
    map: &KTree<K, f32>,
    model: &SensorModel,
    node: InputNode<f32>,
    update: Part,
    base: u64,
    log_side: u32,
    parallel: bool,
) -> Subtree<f32> {
    if !parallel || update.len() < UPDATES_APART || log_side < 2 {
        let mut merge = Merge {
            map,
            model,
            levels: vec![ValuedLevel::new(); log_side as usize + 1],
        };
        let root = merge.node(node, update, base, log_side, 0);
        let mut levels = merge.levels;
        levels.remove(0);
        return Subtree::new(root, levels);
    }
    let parts = children_updates::<K>(update, base, log_side);
    let kids = parts[..1 << K]
        .par_iter()
        .copied()
        .enumerate()
        .map(|(code, (start, part))| {
            let child = infallible(node.child(map, code));
            subtree(map, model, child, part, start, log_side - 1, parallel)
        })
        .collect();
    Subtree::join(kids)
}

/// The updates of each child of the cell whose voxels' Morton keys start at `base` (a side of
/// `2^log_side`, `log_side` ≥ 1), with the first key of the child, in code order (the first `2^K`).
fn children_updates<const K: usize>(update: Part, base: u64, log_side: u32) -> [(u64, Part); 16] {
    let span = 1u64 << (K as u32 * (log_side - 1));
    let mut rest = update;
    let mut parts = [(0, Part::default()); 16];
    for (code, part) in parts.iter_mut().enumerate().take(1 << K) {
        let start = base + code as u64 * span;
        let (mine, after) = match start.checked_add(span) {
            Some(end) => rest.split_at_key(end),
            // The last cell of a 4-D root ends at 2^64.
            None => (rest, Part::default()),
        };
        *part = (start, mine);
        rest = after;
    }
    parts
}

/// The state of a depth-first merge: the settled nodes of each level so far.
struct Merge<'a, const K: usize> {
    map: &'a KTree<K, f32>,
    model: &'a SensorModel,
    levels: Vec<ValuedLevel<f32>>,
}

impl<const K: usize> Merge<'_, K> {
    /// The state of the cell of the map's `node` whose voxels' Morton keys start at `base` (a side of
    /// `2^log_side`, at `depth`) after the updates `update` inside it; its children, if any, pushed onto the
    /// level below.
    fn node(
        &mut self,
        node: InputNode<f32>,
        update: Part,
        base: u64,
        log_side: u32,
        depth: usize,
    ) -> ValueState<f32> {
        let leaf = match node.state {
            ValueState::Empty => Some(None),
            ValueState::Full(v) => Some(Some(v)),
            _ => None,
        };
        if let (Some(v), Some(hit)) = (leaf, update.all_alike()) {
            let volume = 1u128 << (K as u32 * log_side);
            if update.len() as u128 == volume {
                return ValueState::Full(self.model.update(v.unwrap_or(0.0), hit));
            }
        }
        if let Some(v) = leaf {
            let background = v.map_or(ValueState::Empty, ValueState::Full);
            if update.len() == 0 {
                return background;
            }
            return self.leaf(background, v.unwrap_or(0.0), update, base, log_side, depth);
        }
        // Not a leaf of the result: its children, each from the map's child and its part of the update.
        let parts = children_updates::<K>(update, base, log_side);
        let mut kids = [ValueState::Empty; 16];
        for (code, (kid, (start, part))) in kids.iter_mut().zip(parts).enumerate().take(1 << K) {
            let child = infallible(node.child(self.map, code));
            *kid = self.node(child, part, start, log_side - 1, depth + 1);
        }
        let kids = &kids[..1 << K];
        let state = combine(kids);
        if state.has_children() {
            self.levels[depth + 1].extend_from_slice(kids);
        }
        state
    }

    /// [`node`](Self::node) for a leaf of the map (every voxel `background`, of log-odds `before`), in one
    /// pass over its updates: the updated voxels sharing a cell of side 2 are settled together, and the
    /// cells on the way from one such cell to the next are opened and closed as they come (their Morton
    /// keys are in order), each cell's children settled once, with no search. `log_side` ≥ 1.
    fn leaf(
        &mut self,
        background: ValueState<f32>,
        before: f32,
        update: Part,
        base: u64,
        log_side: u32,
        depth: usize,
    ) -> ValueState<f32> {
        let k = K as u32;
        let fanout = 1usize << K;
        let voxel_digit = fanout as u64 - 1;
        let hit = ValueState::Full(self.model.update(before, true));
        let miss = ValueState::Full(self.model.update(before, false));
        let top = log_side as usize;
        // The open cell at each height r ≥ 2 (a side of 2^r; r = top is this leaf's cell): its children
        // and how many of them are settled.
        let mut kids = vec![[background; 16]; top + 1];
        let mut settled = vec![0usize; top + 1];
        let digit = |key: u64, r: usize| (key >> (k * (r as u32 - 1))) as usize & (fanout - 1);
        // Settles the rest of the open cell at height r with the background; its state.
        let close = |levels: &mut [ValuedLevel<f32>],
                     kids: &mut [ValueState<f32>; 16],
                     from: usize,
                     r: usize| {
            kids[from..fanout].fill(background);
            let state = combine(&kids[..fanout]);
            if state.has_children() {
                levels[depth + top - r + 1].extend_from_slice(&kids[..fanout]);
            }
            state
        };
        // Closes the open cells from height 2 to below `height` on the way to key `key`, each handed to
        // the cell above it.
        let close_below = |levels: &mut [ValuedLevel<f32>],
                           kids: &mut [[ValueState<f32>; 16]],
                           settled: &mut [usize],
                           key: u64,
                           height: usize| {
            for r in 2..height {
                let state = close(levels, &mut kids[r], settled[r], r);
                let d = digit(key, r + 1);
                kids[r + 1][d] = state;
                settled[r + 1] = d + 1;
            }
        };
        let mut voxels = update.peekable();
        let mut previous: Option<u64> = None;
        while let Some((first, is_hit)) = voxels.next() {
            // The cell of side 2 holding this voxel, with every updated voxel in it.
            let first = first - base;
            let cell_key = first & !voxel_digit;
            let mut cell = [background; 16];
            cell[(first & voxel_digit) as usize] = if is_hit { hit } else { miss };
            while let Some((key, is_hit)) =
                voxels.next_if(|&(key, _)| (key - base) & !voxel_digit == cell_key)
            {
                cell[((key - base) & voxel_digit) as usize] = if is_hit { hit } else { miss };
            }
            let state = combine(&cell[..fanout]);
            if state.has_children() {
                self.levels[depth + top].extend_from_slice(&cell[..fanout]);
            }
            if top == 1 {
                return state;
            }
            // The lowest height whose cell holds both this cell and the one before: the cells below it
            // on the previous cell's way are finished.
            let shared = match previous {
                None => top,
                Some(p) => {
                    let shared = ((64 - (p ^ cell_key).leading_zeros()).div_ceil(k)) as usize;
                    close_below(&mut self.levels, &mut kids, &mut settled, p, shared);
                    shared
                }
            };
            for r in (2..=shared).rev() {
                let from = if r == shared { settled[r] } else { 0 };
                let d = digit(cell_key, r);
                kids[r][from..d].fill(background);
                settled[r] = d;
            }
            let d = digit(cell_key, 2);
            kids[2][d] = state;
            settled[2] = d + 1;
            previous = Some(cell_key);
        }
        let last = previous.expect("a leaf's update is not empty");
        close_below(&mut self.levels, &mut kids, &mut settled, last, top);
        close(&mut self.levels, &mut kids[top], settled[top], top)
    }
}
