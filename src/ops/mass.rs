//! Mass properties (Meagher §3, claim M10): volume, centroid and second moments (the inertia tensor in 3-D)
//! exactly from the full leaves, and the progressive form — at each level a lower and an upper bound,
//! stopping as soon as a requested tolerance is met.
//!
//! The object is the union of its full voxels as unit cubes (density 1, voxel units, origin at the
//! universe's corner). Sums are exact integers (`i128`): for a cell of side `s` at `o`, `∫x = s(2o+s)/2`,
//! `∫x² = (3o²s + 3os² + s³)/3` along one axis; they are scaled by 2, 3 and 4 to stay integral and turned
//! into `f64` only at the end. The second moments are summed about a corner of one of the object's own
//! voxels, so that a small object far from the origin keeps its central moments exact to `f64` precision
//! (summed about the origin, they would cancel).

use crate::space::Cell;
use crate::tree::{KTree, NodeState};

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

/// Exact integer moment sums of a set of cells, in coordinates relative to a reference point.
#[derive(Debug, Clone, Copy)]
struct Sums<const K: usize> {
    /// The point the moments are taken about.
    reference: [u32; K],
    volume: u128,
    /// `2 ∫ (x_a − r_a)`.
    first2: [i128; K],
    /// `3 ∫ (x_a − r_a)²` on the diagonal, `4 ∫ (x_a − r_a)(x_b − r_b)` off it.
    second: [[i128; K]; K],
}

impl<const K: usize> Sums<K> {
    fn new() -> Self {
        Self::about([0; K])
    }

    fn about(reference: [u32; K]) -> Self {
        Self {
            reference,
            volume: 0,
            first2: [0; K],
            second: [[0; K]; K],
        }
    }

    fn add(&mut self, cell: &Cell<K>) {
        let s = i128::from(cell.side());
        let v = cell.volume();
        self.volume += v;
        let face = v as i128 / s; // s^(K−1)
        let origin: [i128; K] =
            std::array::from_fn(|a| i128::from(cell.origin[a]) - i128::from(self.reference[a]));
        let lin: [i128; K] = origin.map(|o| s * (2 * o + s)); // 2 ∫ x over one axis
        for a in 0..K {
            self.first2[a] += face * lin[a];
            let o = origin[a];
            self.second[a][a] += face * (3 * o * o * s + 3 * o * s * s + s * s * s);
            for b in a + 1..K {
                let m = face / s * lin[a] * lin[b]; // s^(K−2) · (2∫x_a)(2∫x_b)
                self.second[a][b] += m;
                self.second[b][a] += m;
            }
        }
    }

    /// `∫ x_a` about the origin.
    fn first_moment(&self, a: usize) -> f64 {
        f64::from(self.reference[a]) * self.volume as f64 + self.first2[a] as f64 / 2.0
    }
}

/// Volume, centroid and central second moments, exactly from the full leaves (cost linear in the nodes).
///
/// ```
/// use ktree::{KTree, ops::mass_properties};
/// let a = KTree::<2>::from_dense(1, &[true, true, false, false]).unwrap(); // bottom row of a 2×2
/// let m = mass_properties(&a);
/// assert_eq!(m.volume, 2);
/// assert_eq!(m.centroid, [1.0, 0.5]);
/// ```
pub fn mass_properties<const K: usize>(tree: &KTree<K>) -> MassProperties<K> {
    // Moments about the corner of the first full voxel keep a small object far from the origin exact.
    let reference = tree
        .leaves()
        .find(|(_, state)| *state == NodeState::Full)
        .map_or([0; K], |(cell, _)| cell.origin);
    let mut sums = Sums::<K>::about(reference);
    tree.for_each_leaf(|cell, state| {
        if state == NodeState::Full {
            sums.add(&cell);
        }
    });
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
    MassProperties {
        volume: sums.volume,
        centroid,
        central_moments,
    }
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
/// use ktree::{stacking::stack, rays::ball_rays, ops::{mass_progressive, mass_properties}};
/// let tree = stack(&ball_rays::<3>(8, [256, 256, 256], 240).unwrap());
/// let p = mass_progressive(&tree, 0.05);
/// let exact = mass_properties(&tree).volume as f64;
/// assert!(p.met && (p.estimate - exact).abs() <= 0.05 * exact);
/// assert!(p.levels.last().unwrap().nodes_touched < p.total_nodes);
/// ```
pub fn mass_progressive<const K: usize>(tree: &KTree<K>, tolerance: f64) -> ProgressiveMass<K> {
    let mut full = Sums::<K>::new();
    let mut frontier = vec![(0usize, tree.universe().root())];
    let mut touched = 1u64;
    let mut levels = Vec::new();
    let mut depth = 0usize;
    // The root itself.
    match tree.root_state() {
        NodeState::Full => {
            full.add(&tree.universe().root());
            frontier.clear();
        }
        NodeState::Empty => frontier.clear(),
        NodeState::Partial => {}
    }
    loop {
        let mut partial = Sums::<K>::new();
        for (_, cell) in &frontier {
            partial.add(cell);
        }
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
            return ProgressiveMass {
                estimate,
                levels,
                met,
                total_nodes: tree.node_count(),
            };
        }
        let mut next = Vec::with_capacity(frontier.len() << K);
        for &(index, cell) in &frontier {
            let first = tree.first_child(depth, index);
            for c in 0..1usize << K {
                touched += 1;
                let child = cell.child(c);
                match tree.state(depth + 1, first + c) {
                    NodeState::Full => full.add(&child),
                    NodeState::Partial => next.push((first + c, child)),
                    NodeState::Empty => {}
                }
            }
        }
        frontier = next;
        depth += 1;
    }
}
