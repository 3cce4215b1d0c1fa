//! Mass properties (Meagher §3, claim M10): volume, centroid and second moments (the inertia tensor in 3-D)
//! exactly from the full leaves, and the progressive form — at each level a lower and an upper bound,
//! stopping as soon as a requested tolerance is met.
//!
//! The object is the union of its full voxels as unit cubes (density 1, voxel units, origin at the
//! universe's corner). Sums are exact integers (`i128`): for a cell of side `s` at `o`, `∫x = s(2o+s)/2`,
//! `∫x² = (3o²s + 3os² + s³)/3` along one axis; they are scaled by 2, 3 and 4 to stay integral and turned
//! into `f64` only at the end. One pass over the leaves sums, per depth, the count of full leaves, their
//! origins and their origins' products (additions and 64-bit products only); the moments of each depth's
//! cells follow from those sums. The second moments are taken about the voxel holding the centroid, so
//! that a small object far from the origin keeps its central moments exact to `f64` precision (summed
//! about the origin, they would cancel).
//!
//! Both read any [`TreeStorage`]: a tree larger than memory is measured from its mapped file, leaf by leaf.

use crate::tree::cursor::TryLeaves;
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// Exact volume, centroid and second moments of an object.
#[derive(Debug, Clone, PartialEq)]
pub struct MassProperties<const K: usize> {
    /// Volume in voxels.
    pub volume: u128,
    /// Centre of mass (`NaN`s for an empty object).
    pub centroid: [f64; K],
    /// Second moments about the centroid, `C[a][b] = ∫ (x_a − c_a)(x_b − c_b) dV`.
    pub central_moments: [[f64; K]; K],
}

impl<const K: usize> MassProperties<K> {
    /// The inertia tensor about the centroid, `I = tr(C)·Id − C` (for `K = 3` the usual one; defined the
    /// same way in any `K`).
    pub fn inertia_tensor(&self) -> [[f64; K]; K] {
        let trace: f64 = (0..K).map(|i| self.central_moments[i][i]).sum();
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let id = if i == j { trace } else { 0.0 };
                id - self.central_moments[i][j]
            })
        })
    }
}

/// Sums over cells of one size, in the voxel coordinates of their origins: the count, `Σ o_a` and
/// `Σ o_a·o_b`. Exact: a coordinate is below 2^31, so a product fits a `u64`, and the sums over all cells of
/// one depth stay below 2^124 within the universe limits.
#[derive(Debug, Clone, Copy)]
struct SizeSums<const K: usize> {
    count: u64,
    origins: [u128; K],
    /// `products[a][b]` for `a ≤ b`.
    products: [[u128; K]; K],
}

impl<const K: usize> SizeSums<K> {
    fn new() -> Self {
        Self {
            count: 0,
            origins: [0; K],
            products: [[0; K]; K],
        }
    }

    #[inline]
    fn add(&mut self, origin: [u32; K]) {
        self.count += 1;
        for a in 0..K {
            let oa = u64::from(origin[a]);
            self.origins[a] += u128::from(oa);
            for (product, &ob) in self.products[a].iter_mut().zip(&origin).skip(a) {
                *product += u128::from(oa * u64::from(ob));
            }
        }
    }
}

/// Exact integer moment sums of a set of cells, in coordinates relative to a reference point.
///
/// The sums are computed in wrapping `i128` arithmetic: every final sum is an integral over the object that
/// fits an `i128` (at most `4·U^(K+2) ≤ 2^126`), so wrapping intermediate steps cancel out exactly.
#[derive(Debug, Clone, Copy)]
struct Sums<const K: usize> {
    /// The point the moments are taken about.
    reference: [i128; K],
    volume: u128,
    /// `2 ∫ (x_a − r_a)`.
    first2: [i128; K],
    /// `3 ∫ (x_a − r_a)²` on the diagonal, `4 ∫ (x_a − r_a)(x_b − r_b)` off it.
    second: [[i128; K]; K],
}

impl<const K: usize> Sums<K> {
    fn about(reference: [i128; K]) -> Self {
        Self {
            reference,
            volume: 0,
            first2: [0; K],
            second: [[0; K]; K],
        }
    }

    /// Adds cells of side `2^log_side` summed in `cells`. For one cell of side `s` at `o` (relative to the
    /// reference), along one axis `2∫x = s(2o + s)` and `3∫x² = 3o²s + 3os² + s³`, times `s^(K−1)`.
    fn add(&mut self, log_side: u32, cells: &SizeSums<K>) {
        if cells.count == 0 {
            return;
        }
        let n = i128::from(cells.count);
        let s = 1i128 << log_side;
        let volume = 1i128 << (log_side as usize * K); // s^K
        self.volume += (volume as u128) * cells.count as u128;
        let r = self.reference;
        // Σ (o_a − r_a), and Σ (o_a − r_a)(o_b − r_b).
        let sum: [i128; K] =
            std::array::from_fn(|a| (cells.origins[a] as i128).wrapping_sub(n.wrapping_mul(r[a])));
        let product = |a: usize, b: usize| -> i128 {
            let (lo, hi) = (a.min(b), a.max(b));
            (cells.products[lo][hi] as i128)
                .wrapping_sub(r[b].wrapping_mul(cells.origins[a] as i128))
                .wrapping_sub(r[a].wrapping_mul(cells.origins[b] as i128))
                .wrapping_add(n.wrapping_mul(r[a]).wrapping_mul(r[b]))
        };
        let ns2 = n.wrapping_mul(s * s);
        for a in 0..K {
            let first = sum[a].wrapping_mul(2).wrapping_add(n.wrapping_mul(s));
            self.first2[a] = self.first2[a].wrapping_add(volume.wrapping_mul(first));
            let diagonal = product(a, a)
                .wrapping_mul(3)
                .wrapping_add(sum[a].wrapping_mul(3 * s))
                .wrapping_add(ns2);
            self.second[a][a] = self.second[a][a].wrapping_add(volume.wrapping_mul(diagonal));
            for b in a + 1..K {
                let off = product(a, b)
                    .wrapping_mul(4)
                    .wrapping_add(sum[a].wrapping_mul(2 * s))
                    .wrapping_add(sum[b].wrapping_mul(2 * s))
                    .wrapping_add(ns2);
                let m = volume.wrapping_mul(off);
                self.second[a][b] = self.second[a][b].wrapping_add(m);
                self.second[b][a] = self.second[b][a].wrapping_add(m);
            }
        }
    }

    /// `∫ x_a` about the origin.
    fn first_moment(&self, a: usize) -> f64 {
        self.reference[a] as f64 * self.volume as f64 + self.first2[a] as f64 / 2.0
    }
}

/// Volume, centroid and central second moments, exactly from the full leaves (cost linear in the nodes).
///
/// The full leaves are summed per depth in one pass; the second moments are then taken about the voxel
/// holding the centroid, so that a small object far from the origin keeps its central moments exact to
/// `f64` precision (summed about the origin, they would cancel).
///
/// ```
/// use ktree::{KTree, ops::mass_properties};
/// let a = KTree::<2>::from_dense(1, &[true, true, false, false]).unwrap(); // bottom row of a 2×2
/// let m = mass_properties(&a).unwrap();
/// assert_eq!(m.volume, 2);
/// assert_eq!(m.centroid, [1.0, 0.5]);
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`](crate::KTree)).
pub fn mass_properties<const K: usize, T: TreeStorage<K>>(
    tree: &T,
) -> Result<MassProperties<K>, T::Error> {
    let level = tree.level();
    let mut per_depth = vec![SizeSums::<K>::new(); level as usize + 1];
    for leaf in TryLeaves::new(tree) {
        let (cell, state) = leaf?;
        if state == NodeState::Full {
            per_depth[cell.level as usize].add(cell.origin);
        }
    }
    let sum_about = |reference: [i128; K]| {
        let mut sums = Sums::<K>::about(reference);
        for (depth, cells) in per_depth.iter().enumerate() {
            sums.add(level - depth as u32, cells);
        }
        sums
    };
    // First about the origin, for the centroid; then about the voxel holding the centroid.
    let rough = sum_about([0; K]);
    let reference: [i128; K] = std::array::from_fn(|a| {
        if rough.volume == 0 {
            0
        } else {
            (rough.first2[a] as u128 / (2 * rough.volume)) as i128
        }
    });
    let sums = sum_about(reference);
    let v = sums.volume as f64;
    let centroid: [f64; K] = std::array::from_fn(|a| sums.first_moment(a) / v);
    // The centroid relative to the reference point.
    let relative: [f64; K] = std::array::from_fn(|a| sums.first2[a] as f64 / (2.0 * v));
    let central_moments = std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let raw = if a == b {
                sums.second[a][a] as f64 / 3.0
            } else {
                sums.second[a][b] as f64 / 4.0
            };
            raw - v * relative[a] * relative[b]
        })
    });
    Ok(MassProperties {
        volume: sums.volume,
        centroid,
        central_moments,
    })
}

/// Bounds after one level of the progressive computation.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LevelBounds<const K: usize> {
    /// The depth reached (0 = root).
    pub level: u32,
    /// Volume of the full nodes down to this depth: a lower bound.
    pub lower: u128,
    /// Plus the volume of the partial nodes at this depth: an upper bound.
    pub upper: u128,
    /// Nodes visited so far.
    pub nodes_touched: u64,
    /// Per axis, an interval holding the centroid (`[−∞, ∞]` while the lower bound is 0).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub centroid_bounds: [(f64, f64); K],
}

/// The progressive mass computation's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgressiveMass<const K: usize> {
    /// The estimate `(lower + upper) / 2` at the level where it stopped.
    pub estimate: f64,
    /// The bounds level by level, down to where it stopped.
    pub levels: Vec<LevelBounds<K>>,
    /// Whether the tolerance was met (false only if it was not even met at the deepest level, which
    /// happens only for a tolerance below 0).
    pub met: bool,
    /// The tree's total node count, to compare with the nodes touched.
    pub total_nodes: u64,
}

/// Meagher's progressive mass (M10): working down from the root, at each level the volume of the full
/// nodes found so far is a lower bound and adding the partial nodes' volume gives an upper bound; stops
/// at the first level where `upper − lower ≤ tolerance · (upper + lower) / 2` (a relative tolerance on the
/// estimate), reporting how many nodes were touched. With tolerance 0 it visits every node and is exact.
///
/// ```
/// use ktree::{stacking::paper::stack, rays::ball_rays, ops::{mass_progressive, mass_properties}};
/// let tree = stack(&ball_rays::<3>(8, [256, 256, 256], 240).unwrap());
/// let p = mass_progressive(&tree, 0.05).unwrap();
/// let exact = mass_properties(&tree).unwrap().volume as f64;
/// assert!(p.met && (p.estimate - exact).abs() <= 0.05 * exact);
/// assert!(p.levels.last().unwrap().nodes_touched < p.total_nodes);
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`](crate::KTree)).
pub fn mass_progressive<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    tolerance: f64,
) -> Result<ProgressiveMass<K>, T::Error> {
    let level = tree.level();
    let mut full = Sums::<K>::about([0; K]);
    // The partial nodes of the current depth, in index order: the `j`-th one's children are `j·2^K ..`.
    let mut frontier = vec![tree.universe().root()];
    let mut touched = 1u64;
    let mut levels = Vec::new();
    let mut depth = 0usize;
    // The root itself.
    match tree.root_state()? {
        NodeState::Full => {
            let mut root = SizeSums::new();
            root.add([0; K]);
            full.add(level, &root);
            frontier.clear();
        }
        NodeState::Empty => frontier.clear(),
        NodeState::Partial => {}
    }
    loop {
        let mut frontier_cells = SizeSums::new();
        for cell in &frontier {
            frontier_cells.add(cell.origin);
        }
        let mut partial = Sums::<K>::about([0; K]);
        partial.add(level - depth as u32, &frontier_cells);
        let (lower, upper) = (full.volume, full.volume + partial.volume);
        let centroid_bounds = std::array::from_fn(|a| {
            if lower == 0 {
                (f64::NEG_INFINITY, f64::INFINITY)
            } else {
                (
                    full.first_moment(a) / upper as f64,
                    (full.first_moment(a) + partial.first_moment(a)) / lower as f64,
                )
            }
        });
        levels.push(LevelBounds {
            level: depth as u32,
            lower,
            upper,
            nodes_touched: touched,
            centroid_bounds,
        });
        let estimate = (lower + upper) as f64 / 2.0;
        let met = (upper - lower) as f64 <= tolerance * estimate;
        if met || frontier.is_empty() {
            return Ok(ProgressiveMass {
                estimate,
                levels,
                met,
                total_nodes: tree.node_count(),
            });
        }
        let mut next = Vec::with_capacity(frontier.len() << K);
        let mut full_children = SizeSums::new();
        for (j, cell) in frontier.iter().enumerate() {
            let codes = tree.block_codes(depth + 1, j << K)?;
            for c in 0..1usize << K {
                touched += 1;
                let child = cell.child(c);
                match NodeState::from_bits(codes >> (2 * c)) {
                    NodeState::Full => full_children.add(child.origin),
                    NodeState::Partial => next.push(child),
                    NodeState::Empty => {}
                }
            }
        }
        full.add(level - depth as u32 - 1, &full_children);
        frontier = next;
        depth += 1;
    }
}
