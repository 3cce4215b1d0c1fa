//! Sparse objects at the largest level of each K ([`ktree::max_level`]: 31, 31, 21, 16 for K = 1 … 4): a
//! few boxes placed anywhere, each small enough across that its surface — and so its tree — stays small
//! (up to 2^31 voxels long for K = 1, 2^10 for K = 2, 32 for K = 3, 8 for K = 4), so coordinates, Morton
//! keys, voxel counts and moments need the 64- and 128-bit paths while the trees stay small. A dense array
//! is impossible at these levels: the reference is computed on the boxes themselves — membership of a
//! point, exact voxel counts by inclusion–exclusion, bounding boxes and first moments.
//!
//! ```
//! use ktree_verify::sparse::{Boxes, Cuboid};
//! let b = Boxes::<2> { level: 31, boxes: vec![Cuboid { lo: [5, 0], hi: [7, 1 << 31] }] };
//! assert_eq!(b.voxel_count(), 1 << 32);
//! assert!(b.contains([6, (1 << 31) - 1]) && !b.contains([7, 0]));
//! ```

use std::fmt;

use ktree::{max_level, Ray, RaySet};
use proptest::prelude::*;

/// A half-open box `[lo, hi)` of voxels; empty when `hi[i] <= lo[i]` on some axis.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Cuboid<const K: usize> {
    /// Lowest voxel, inclusive.
    pub lo: [u64; K],
    /// Highest corner, exclusive.
    pub hi: [u64; K],
}

impl<const K: usize> fmt::Debug for Cuboid<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}..{:?}", self.lo, self.hi)
    }
}

impl<const K: usize> Cuboid<K> {
    /// Whether the box holds no voxel.
    pub fn is_empty(&self) -> bool {
        (0..K).any(|i| self.hi[i] <= self.lo[i])
    }

    /// The number of voxels in the box.
    pub fn volume(&self) -> u128 {
        if self.is_empty() {
            return 0;
        }
        (0..K)
            .map(|i| u128::from(self.hi[i] - self.lo[i]))
            .product()
    }

    /// The common part of two boxes (possibly empty).
    pub fn meet(&self, other: &Self) -> Self {
        Cuboid {
            lo: std::array::from_fn(|i| self.lo[i].max(other.lo[i])),
            hi: std::array::from_fn(|i| self.hi[i].min(other.hi[i])),
        }
    }

    /// Whether the voxel `p` is in the box.
    pub fn contains(&self, p: [u64; K]) -> bool {
        (0..K).all(|i| self.lo[i] <= p[i] && p[i] < self.hi[i])
    }

    /// Twice the first moment along `axis` of the box's voxels as unit cubes (`Σ (2x + 1)` over the box).
    pub fn doubled_first_moment(&self, axis: usize) -> i128 {
        if self.is_empty() {
            return 0;
        }
        let (lo, hi) = (i128::from(self.lo[axis]), i128::from(self.hi[axis]));
        let across: i128 = (0..K)
            .filter(|&i| i != axis)
            .map(|i| i128::from(self.hi[i] - self.lo[i]))
            .product();
        (hi * hi - lo * lo) * across
    }
}

/// A union of boxes in the universe of level `level`: the object under test and its own reference.
#[derive(Clone)]
pub struct Boxes<const K: usize> {
    /// The universe's level.
    pub level: u32,
    /// The boxes, possibly overlapping.
    pub boxes: Vec<Cuboid<K>>,
}

impl<const K: usize> fmt::Debug for Boxes<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "K={K} L={} boxes [lo,hi)={:?}", self.level, self.boxes)
    }
}

impl<const K: usize> Boxes<K> {
    /// The universe's side `2^level`.
    pub fn side(&self) -> u64 {
        1 << self.level
    }

    /// Whether the voxel `p` is in some box.
    pub fn contains(&self, p: [u64; K]) -> bool {
        self.boxes.iter().any(|b| b.contains(p))
    }

    /// The exact number of voxels of the union, by inclusion–exclusion over the boxes.
    pub fn voxel_count(&self) -> u128 {
        union_volume(&self.boxes)
    }

    /// Twice the first moment along `axis` of the union, by inclusion–exclusion.
    pub fn doubled_first_moment(&self, axis: usize) -> i128 {
        inclusion_exclusion(&self.boxes, |b| b.doubled_first_moment(axis))
    }

    /// The bounding box `[lo, hi)` of the union (the upper bound excluded, as the library's), or `None`
    /// if it is empty.
    pub fn bounding_box(&self) -> Option<([u64; K], [u64; K])> {
        let mut full = self.boxes.iter().filter(|b| !b.is_empty());
        let first = full.next()?;
        let (mut lo, mut hi) = (first.lo, first.hi);
        for b in full {
            for i in 0..K {
                lo[i] = lo[i].min(b.lo[i]);
                hi[i] = hi[i].max(b.hi[i]);
            }
        }
        Some((lo, hi))
    }

    /// The rays of the union: one run per column of every box (runs of one column are merged by
    /// [`RaySet::from_rays`]).
    pub fn rays(&self) -> RaySet<K> {
        let mut rays = Vec::new();
        for b in self.boxes.iter().filter(|b| !b.is_empty()) {
            let lo = b.lo.map(|v| v as u32);
            let hi = b.hi.map(|v| v as u32);
            crate::cases::for_each_column(lo, hi, |mut start| {
                start[K - 1] = lo[K - 1];
                rays.push(Ray::new(start, hi[K - 1]));
            });
        }
        RaySet::from_rays(self.level, rays).expect("boxes lie inside the universe")
    }

    /// Points worth testing membership at: every corner of every box, and the voxels just outside each
    /// box's faces (where they are inside the universe).
    pub fn probe_points(&self) -> Vec<[u64; K]> {
        let side = self.side();
        let mut points = Vec::new();
        for b in self.boxes.iter().filter(|b| !b.is_empty()) {
            for corner in 0..1usize << K {
                points.push(std::array::from_fn(|i| {
                    if corner >> i & 1 == 1 {
                        b.hi[i] - 1
                    } else {
                        b.lo[i]
                    }
                }));
            }
            let mid: [u64; K] = std::array::from_fn(|i| b.lo[i] + (b.hi[i] - b.lo[i]) / 2);
            points.push(mid);
            for i in 0..K {
                if b.lo[i] > 0 {
                    let mut p = mid;
                    p[i] = b.lo[i] - 1;
                    points.push(p);
                }
                if b.hi[i] < side {
                    let mut p = mid;
                    p[i] = b.hi[i];
                    points.push(p);
                }
            }
        }
        points
    }
}

/// The number of voxels in the union of `boxes`, by inclusion–exclusion.
pub fn union_volume<const K: usize>(boxes: &[Cuboid<K>]) -> u128 {
    u128::try_from(inclusion_exclusion(boxes, |b| b.volume() as i128))
        .expect("a count is not negative")
}

/// `Σ_S (−1)^{|S|+1} f(∩S)` over the non-empty subsets `S` of `boxes`: the additive measure `f` of their
/// union.
pub fn inclusion_exclusion<const K: usize>(
    boxes: &[Cuboid<K>],
    f: impl Fn(&Cuboid<K>) -> i128,
) -> i128 {
    assert!(
        boxes.len() <= 16,
        "inclusion–exclusion over at most 16 boxes"
    );
    let mut total = 0i128;
    for subset in 1u32..1 << boxes.len() {
        let mut members = (0..boxes.len()).filter(|&i| subset >> i & 1 == 1);
        let first = boxes[members.next().expect("non-empty subset")];
        let common = members.fold(first, |acc, i| acc.meet(&boxes[i]));
        if common.is_empty() {
            continue;
        }
        let sign = if subset.count_ones() % 2 == 1 { 1 } else { -1 };
        total += sign * f(&common);
    }
    total
}

/// The largest box side along each axis for dimension `K`, as a power of two: a k-tree of a box has about
/// as many nodes as the box has voxels on its surface, so the side shrinks as `K` grows.
pub const fn max_log_side(k: usize) -> u32 {
    match k {
        1 => 31,
        2 => 10,
        3 => 5,
        _ => 3,
    }
}

/// One box at level `level`: anywhere, of any side up to `2^max_log_side(K)` along each axis (sides spread
/// evenly over their binary magnitudes).
fn cuboid<const K: usize>(level: u32) -> impl Strategy<Value = Cuboid<K>> {
    let side = 1u64 << level;
    let log_side = max_log_side(K).min(level);
    let axis = (0..side, 0..=log_side, 0..side);
    prop::array::uniform::<_, K>(axis).prop_map(move |axes| {
        let lo: [u64; K] = axes.map(|(lo, _, _)| lo);
        let hi: [u64; K] = std::array::from_fn(|i| {
            let (lo, magnitude, jitter) = axes[i];
            let width = (1u64 << magnitude) + jitter % (1u64 << magnitude);
            (lo + width.min(1 << log_side)).min(side)
        });
        Cuboid { lo, hi }
    })
}

/// One to three boxes at the largest level of `K`.
pub fn boxes<const K: usize>() -> impl Strategy<Value = Boxes<K>> {
    let level = max_level(K);
    prop::collection::vec(cuboid::<K>(level), 1..=3).prop_map(move |boxes| Boxes { level, boxes })
}

/// A voxel anywhere in the universe of the largest level of `K`.
pub fn point<const K: usize>() -> impl Strategy<Value = [u64; K]> {
    prop::array::uniform::<_, K>(0..1u64 << max_level(K))
}
