//! Exact Euclidean distance transforms over windows of a tree: signed distances at points
//! ([`KTree::signed_distance_at`]), over a window ([`KTree::signed_distance_window`]) and in a narrow band
//! ([`KTree::narrow_band`]), and the ball morphology through the transform.
//!
//! # Conventions
//! scipy's: distances are Euclidean, in voxel units, between voxel centres. The signed distance of an
//! empty voxel is `+` its distance to the nearest full voxel; of a full voxel, `−` its distance to the
//! nearest empty voxel (`edt(~a) − edt(a)` in scipy, negative inside as OpenVDB's level sets). The universe
//! is the array: for a full voxel at the universe's border the nearest empty voxel is one inside the
//! universe (nothing outside counts). An empty tree's distances are `+∞`, a full universe's `−∞`.
//!
//! # Method
//! Squared distances are integers. A window's transform is a separable exact transform (the lower envelope
//! of parabolas of Felzenszwalb and Huttenlocher, in integer arithmetic, floor divisions only) over a dense
//! *source* box around the window, one axis after the other; each pass maps the source's extent on its axis
//! to the window's, so the arrays are never larger than `Π max(window, source)` along the axes. A value
//! found in a source box that reaches `m` voxels past the window is exact when it is at most `m` (the
//! nearest voxel then lies in the box) or when the box holds every voxel that could be nearest (the full
//! voxels' bounding box, grown by one for the empty ones); a window grows its margin until every value is
//! exact. The narrow band and the morphology work block by block (a block of about 2^15 voxels, its source
//! the block grown by the band's width or the radius): a value beyond the margin is beyond the band, so
//! clamping there is exact, and memory is proportional to a block, never to the universe. Blocks whose
//! grown box is all full or all empty ([`KTree::count`]) are skipped without a transform; the rest run on
//! all threads.
//!
//! ```
//! use ktree::KTree;
//! // A 3 × 3 square, voxels [2, 5)², in an 8 × 8 universe (dense order: axis 0 fastest).
//! let dense: Vec<bool> = (0..64).map(|i| (2..5).contains(&(i % 8)) && (2..5).contains(&(i / 8))).collect();
//! let tree = KTree::<2>::from_dense(3, &dense).unwrap();
//! let row = tree.signed_distance_window([0, 3], [8, 1]).unwrap(); // x = 0 … 7 at y = 3
//! assert_eq!(row, [2.0, 1.0, -1.0, -2.0, -1.0, 1.0, 2.0, 3.0]);
//! assert_eq!(tree.signed_distance_at(&[[3, 3], [7, 7]]).unwrap(), [-2.0, 18f64.sqrt()]);
//! let band = tree.narrow_band(1.5).unwrap();
//! assert!(band.values.iter().all(|v| v.abs() <= 1.5));
//! ```
//!
//! [`KTree::count`]: crate::KTree::count

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use super::input::{read_error, Complement};
use super::ShapeError;
use crate::query::{self, dense_window_into, DenseOrder};
use crate::rays::{ColumnKeys, RunGatherer};
use crate::tree::cursor::{try_walk, Visitor, Walk};
use crate::tree::storage::TreeStorage;
use crate::tree::{NodeRef, NodeState};
use crate::KTree;

/// No voxel of the sought kind in the source box.
const FAR: u64 = u64::MAX;

/// Most voxels of a block's source box in the ball morphology (2^25: 288 MiB of mask and squared distances).
const MAX_BLOCK_SOURCE: u128 = 1 << 25;

/// Most voxels of one dense array of a window's transform (2^31: 16 GiB of squared distances).
const MAX_WINDOW: u128 = 1 << 31;

/// A box of voxels with signed coordinates: `lo` and the extent along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Bx<const K: usize> {
    lo: [i64; K],
    dims: [i64; K],
}

impl<const K: usize> Bx<K> {
    fn from_lo_hi(lo: [i64; K], hi: [i64; K]) -> Self {
        Self {
            lo,
            dims: std::array::from_fn(|a| (hi[a] - lo[a]).max(0)),
        }
    }

    fn hi(&self) -> [i64; K] {
        std::array::from_fn(|a| self.lo[a] + self.dims[a])
    }

    fn len(&self) -> u128 {
        self.dims.iter().map(|&d| d as u128).product()
    }

    fn grown(&self, m: i64) -> Self {
        let hi = self.hi();
        Self::from_lo_hi(self.lo.map(|x| x - m), hi.map(|x| x + m))
    }

    fn meet(&self, other: &Self) -> Self {
        let (h1, h2) = (self.hi(), other.hi());
        Self::from_lo_hi(
            std::array::from_fn(|a| self.lo[a].max(other.lo[a])),
            std::array::from_fn(|a| h1[a].min(h2[a])),
        )
    }

    fn is_empty(&self) -> bool {
        self.dims.contains(&0)
    }

    /// The box as `u32` corners, for a box inside the universe.
    fn corners(&self) -> ([u32; K], [u32; K]) {
        (self.lo.map(|x| x as u32), self.hi().map(|x| x as u32))
    }
}

/// The universe as a box.
fn universe_box<const K: usize, T: TreeStorage<K>>(tree: &T) -> Bx<K> {
    Bx {
        lo: [0; K],
        dims: [tree.universe().side() as i64; K],
    }
}

/// Full voxels of `tree` in box `b` (clipped to the universe).
fn count_in<const K: usize, T: TreeStorage<K>>(tree: &T, b: &Bx<K>) -> Result<u128, ShapeError> {
    let m = b.meet(&universe_box(tree));
    if m.is_empty() {
        return Ok(0);
    }
    let (lo, hi) = m.corners();
    query::count(tree, lo, hi).map_err(read_error)
}

/// A dense mask of box `b` (row-major, last axis fastest): `true` on the full voxels when `full`, else on
/// the others (the empty voxels and those outside the universe): the one dense window of the crate.
fn mask<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    b: &Bx<K>,
    full: bool,
) -> Result<Vec<bool>, ShapeError> {
    let mut data = vec![false; b.len() as usize];
    dense_window_into(
        tree,
        b.lo,
        b.hi(),
        DenseOrder::LastAxisFastest,
        &mut data,
        full,
    )
    .map_err(read_error)?;
    Ok(data)
}

/// Row-major strides of a box's dims.
fn strides<const K: usize>(dims: &[i64; K]) -> [usize; K] {
    let mut s = [1usize; K];
    for a in (0..K - 1).rev() {
        s[a] = s[a + 1] * dims[a + 1] as usize;
    }
    s
}

/// Steps `at` over the first `axes` axes of `dims`, the last of them fastest; `false` when done.
fn odometer<const K: usize>(at: &mut [i64; K], dims: &[i64; K], axes: usize) -> bool {
    for a in (0..axes).rev() {
        at[a] += 1;
        if at[a] < dims[a] {
            return true;
        }
        at[a] = 0;
    }
    false
}

/// The 1-D transform of one line: for each query coordinate `first + j` (`j < out.len()`), the least
/// `(x − p)² + h` over the samples `(p, h)` (sorted by `p`, `h` finite), or [`FAR`] with no sample.
/// The lower envelope of the parabolas, boundaries by floor division: exact.
fn envelope(samples: &[(i64, u64)], first: i64, out: &mut [u64], hull: &mut Vec<(i64, u64, i128)>) {
    hull.clear();
    for &(p, h) in samples {
        let mut start = i128::MIN;
        while let Some(&(q, g, s)) = hull.last() {
            // The last x where the parabola at q is no higher than the new one.
            let num = i128::from(p) * i128::from(p) - i128::from(q) * i128::from(q) + i128::from(h)
                - i128::from(g);
            let sep = num.div_euclid(2 * i128::from(p - q));
            if sep < s {
                hull.pop();
            } else {
                start = sep + 1;
                break;
            }
        }
        hull.push((p, h, start));
    }
    if hull.is_empty() {
        out.fill(FAR);
        return;
    }
    let mut k = 0;
    for (j, o) in out.iter_mut().enumerate() {
        let x = first + j as i64;
        while k + 1 < hull.len() && hull[k + 1].2 <= i128::from(x) {
            k += 1;
        }
        let (p, h, _) = hull[k];
        let d = u128::from(x.abs_diff(p));
        *o = (d * d + u128::from(h)).min(u128::from(FAR - 1)) as u64;
    }
}

/// The squared distance from each voxel of `window` to the nearest `true` voxel of the source `src`
/// (its dense mask), row-major, [`FAR`] where the source has none.
fn edt<const K: usize>(src: &Bx<K>, mask: &[bool], window: &Bx<K>) -> Vec<u64> {
    if mask.is_empty() {
        // A source box of no voxel (a side of 0): nothing to measure to.
        return vec![FAR; window.dims.iter().map(|&d| d as usize).product()];
    }
    let mut cur: Vec<u64> = mask.iter().map(|&m| if m { 0 } else { FAR }).collect();
    let mut dims = src.dims;
    let (mut samples, mut line, mut hull) = (Vec::new(), Vec::new(), Vec::new());
    for a in 0..K {
        let mut nd = dims;
        nd[a] = window.dims[a];
        let (s_old, s_new) = (strides(&dims), strides(&nd));
        let count: usize = nd.iter().map(|&d| d as usize).product();
        let mut next = vec![FAR; count];
        line.resize(nd[a] as usize, 0);
        // Every line along axis a: the other coordinates by an odometer with axis a held at 0.
        let mut at = [0i64; K];
        let mut outer = nd;
        outer[a] = 1;
        loop {
            let base_old: usize = (0..K).map(|b| at[b] as usize * s_old[b]).sum();
            let base_new: usize = (0..K).map(|b| at[b] as usize * s_new[b]).sum();
            samples.clear();
            for i in 0..dims[a] as usize {
                let v = cur[base_old + i * s_old[a]];
                if v != FAR {
                    samples.push((src.lo[a] + i as i64, v));
                }
            }
            if !samples.is_empty() {
                envelope(&samples, window.lo[a], &mut line, &mut hull);
                for (j, &v) in line.iter().enumerate() {
                    next[base_new + j * s_new[a]] = v;
                }
            }
            if !odometer(&mut at, &outer, K) {
                break;
            }
        }
        cur = next;
        dims = nd;
    }
    cur
}

/// `d² ≤ r²` for integer `d²` ⟺ `d² ≤ ⌊r²⌋` (the f64 product, as [`super::Element::contains`] rounds it).
fn squared_limit(r: f64) -> u64 {
    (r * r).floor().min(FAR as f64 - 2.0) as u64
}

fn check_width(w: f64) -> Result<(), ShapeError> {
    if w.is_finite() && w >= 0.0 {
        Ok(())
    } else {
        Err(ShapeError::BadWidth(w))
    }
}

/// The signed distances of a narrow band: the voxels with `|sd| ≤ width` and their values, block by block
/// (within a block, row-major, last axis fastest).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NarrowBand<const K: usize> {
    /// The band's half-width asked for, in voxels.
    pub width: f64,
    /// The voxels of the band.
    pub voxels: Vec<[u32; K]>,
    /// Their signed distances (negative inside), in voxel units.
    pub values: Vec<f64>,
}

impl<const K: usize> NarrowBand<K> {
    /// The number of voxels in the band.
    pub fn len(&self) -> usize {
        self.voxels.len()
    }

    /// Whether the band holds no voxel (an empty tree or a full universe).
    pub fn is_empty(&self) -> bool {
        self.voxels.is_empty()
    }

    /// The voxels and their values.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = ([u32; K], f64)> + '_ {
        self.voxels.iter().copied().zip(self.values.iter().copied())
    }
}

/// The side of a block: a power of two of about 2^15 voxels, at least twice the margin, at most the
/// universe's side.
fn block_side<const K: usize, T: TreeStorage<K>>(tree: &T, margin: i64) -> i64 {
    let mut side = 1i64 << (15 / K);
    while side < 2 * margin {
        side *= 2;
    }
    side.min(tree.universe().side() as i64)
}

/// The blocks (cells of side `side`, a power of two) that hold a full voxel, with their neighbours within
/// `reach` blocks when `reach > 0`, clipped to the universe: the only blocks where a margin of at most
/// `reach · side` voxels can see a full voxel.
fn blocks<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    side: i64,
    reach: i64,
) -> Result<Vec<Bx<K>>, ShapeError> {
    struct Occupied<const K: usize> {
        side: u64,
        out: Vec<[i64; K]>,
    }
    impl<const K: usize> Visitor<K> for Occupied<K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            let cell = node.cell();
            match node.state() {
                NodeState::Empty => Walk::Skip,
                NodeState::Partial if cell.side() > self.side => Walk::Descend,
                _ => {
                    let first = cell.origin.map(|x| (u64::from(x) / self.side) as i64);
                    let n = [(cell.side() / self.side).max(1) as i64; K];
                    let mut at = [0i64; K];
                    loop {
                        self.out.push(std::array::from_fn(|a| first[a] + at[a]));
                        if !odometer(&mut at, &n, K) {
                            return Walk::Skip;
                        }
                    }
                }
            }
        }
    }
    let mut v = Occupied {
        side: side as u64,
        out: Vec::new(),
    };
    try_walk(tree, &mut v).map_err(read_error)?;
    let count = tree.universe().side() as i64 / side;
    let mut all = if reach > 0 {
        let n = [2 * reach + 1; K];
        let mut out = Vec::new();
        for b in &v.out {
            let mut at = [0i64; K];
            loop {
                let c: [i64; K] = std::array::from_fn(|a| b[a] + at[a] - reach);
                if c.iter().all(|&x| (0..count).contains(&x)) {
                    out.push(c);
                }
                if !odometer(&mut at, &n, K) {
                    break;
                }
            }
        }
        out
    } else {
        v.out
    };
    all.par_sort_unstable();
    all.dedup();
    Ok(all
        .into_iter()
        .map(|b| Bx {
            lo: b.map(|x| x * side),
            dims: [side; K],
        })
        .collect())
}

/// The bounding box of the full voxels as a box.
fn object_box<const K: usize, T: TreeStorage<K>>(tree: &T) -> Result<Option<Bx<K>>, ShapeError> {
    Ok(query::bounding_box(tree)
        .map_err(read_error)?
        .map(|(lo, hi)| Bx::from_lo_hi(lo.map(i64::from), hi.map(i64::from))))
}

/// The voxel at row-major index `i` of box `b`.
fn voxel_of<const K: usize>(b: &Bx<K>, mut i: usize) -> [u32; K] {
    let mut p = [0u32; K];
    for a in (0..K).rev() {
        let d = b.dims[a] as usize;
        p[a] = (b.lo[a] + (i % d) as i64) as u32;
        i /= d;
    }
    p
}

/// Runs along the last axis of a row-major mask of box `b`, as `(column key, z1, z2)`.
fn runs_of<const K: usize>(keys: ColumnKeys<K>, b: &Bx<K>, keep: &[bool]) -> Vec<(u64, u32, u32)> {
    let n = b.dims[K - 1] as usize;
    let mut out = Vec::new();
    for (row, line) in keep.chunks(n).enumerate() {
        let key = keys.pack(voxel_of(b, row * n));
        let mut z = 0;
        while z < n {
            if !line[z] {
                z += 1;
                continue;
            }
            let start = z;
            while z < n && line[z] {
                z += 1;
            }
            let z0 = b.lo[K - 1] as u32;
            out.push((key, z0 + start as u32, z0 + z as u32));
        }
    }
    out
}

/// The tree of the runs that `runs_in` gives for each block (a block's runs `(column key, z1, z2)` in row
/// order), the blocks in [`blocks`]' order. The blocks are taken slab by slab along the first axis, each
/// slab's on all threads; a column's pieces then come in order along it (its blocks are consecutive, in
/// order along the last axis), as [`RunGatherer`] needs. Memory holds the result's runs and one slab's
/// pieces, never every block's at once.
fn tree_of_blocks<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    blocks: &[Bx<K>],
    side: i64,
    runs_in: impl Fn(&Bx<K>) -> Result<Vec<(u64, u32, u32)>, ShapeError> + Sync,
) -> Result<KTree<K>, ShapeError> {
    let mut out = RunGatherer::<K>::new(tree.level(), side as u64);
    let mut pieces = Vec::new();
    for slab in blocks.chunk_by(|a, b| a.lo[0] == b.lo[0]) {
        let parts: Vec<Vec<(u64, u32, u32)>> =
            slab.par_iter().map(&runs_in).collect::<Result<_, _>>()?;
        pieces.clear();
        parts.into_iter().for_each(|p| pieces.extend(p));
        out.append(slab[0].lo[0] as u64, &mut pieces);
    }
    Ok(KTree::from_rays(&out.finish(tree.universe())))
}

/// The signed distance of each voxel of `points` (see [`crate::shape::distance`]'s conventions) in `tree`
/// (in memory or a file read in place), exact: one nearest-voxel search each, on all threads, in the
/// tree (empty voxels) or its complement (full voxels; read through the tree, not made).
///
/// ```
/// use ktree::{shape::signed_distance_at, KTree};
/// let tree = KTree::<1>::from_dense(3, &[false, true, true, true, false, false, false, false]).unwrap();
/// assert_eq!(signed_distance_at(&tree, &[[0], [2], [7]]).unwrap(), [1.0, -2.0, 4.0]);
/// ```
///
/// # Errors
/// [`ShapeError::PointOutside`] for a point outside the universe; [`ShapeError::Storage`] for a read
/// error.
pub fn signed_distance_at<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    points: &[[u32; K]],
) -> Result<Vec<f64>, ShapeError> {
    let side = tree.universe().side();
    if let Some(p) = points
        .iter()
        .find(|p| p.iter().any(|&x| u64::from(x) >= side))
    {
        return Err(ShapeError::PointOutside {
            point: p.to_vec(),
            side,
        });
    }
    let inside = query::contains_many(tree, points).map_err(read_error)?;
    let (mut full, mut empty) = (Vec::new(), Vec::new());
    for (p, &i) in points.iter().zip(&inside) {
        if i {
            full.push(*p);
        } else {
            empty.push(*p);
        }
    }
    let to_full = query::nearest_many(tree, &empty).map_err(read_error)?;
    let to_empty = query::nearest_many(&Complement(tree), &full).map_err(read_error)?;
    let (mut f, mut e) = (to_empty.into_iter(), to_full.into_iter());
    Ok(inside
        .iter()
        .map(|&i| {
            if i {
                -f.next().flatten().map_or(f64::INFINITY, |n| n.distance())
            } else {
                e.next().flatten().map_or(f64::INFINITY, |n| n.distance())
            }
        })
        .collect())
}

/// The signed distances of the window `[origin, origin + shape)` of `tree`, row-major with the last axis
/// fastest (numpy's C order of an array indexed `[x0, …, x(K−1)]`), exact as `f32` rounds them; the
/// window sees the whole tree, not only what lies inside it.
///
/// ```
/// use ktree::{shape::signed_distance_window, KTree};
/// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i == 5).collect::<Vec<_>>()).unwrap();
/// let f = signed_distance_window(&tree, [0, 0], [4, 4]).unwrap(); // dense voxel (1, 1)
/// assert_eq!(f[1 * 4 + 1], -1.0);
/// assert_eq!(f[3 * 4 + 3], 8f32.sqrt());
/// ```
///
/// # Performance
/// `O(K · voxels)` of the window grown by a margin that doubles until every value is exact (at most to
/// the full voxels' bounding box); memory the same.
///
/// # Errors
/// [`ShapeError::Window`] if the window leaves the universe or holds more than 2^31 voxels;
/// [`ShapeError::Storage`] for a read error.
pub fn signed_distance_window<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    origin: [u32; K],
    shape: [usize; K],
) -> Result<Vec<f32>, ShapeError> {
    let side = tree.universe().side();
    let voxels = shape.iter().map(|&s| s as u128).product::<u128>();
    if (0..K).any(|a| u64::from(origin[a]) + shape[a] as u64 > side) || voxels > MAX_WINDOW {
        return Err(ShapeError::Window {
            origin: origin.to_vec(),
            shape: shape.to_vec(),
            side,
        });
    }
    let w = Bx {
        lo: origin.map(i64::from),
        dims: shape.map(|s| s as i64),
    };
    if w.is_empty() {
        return Ok(Vec::new());
    }
    let Some(object) = object_box(tree)? else {
        return Ok(vec![f32::INFINITY; voxels as usize]);
    };
    let full = count_in(tree, &w)?;
    let outside = if full < voxels {
        Some(exact_window(tree, &w, &object, true)?)
    } else {
        None
    };
    let inside = if full > 0 {
        let grown = object.grown(1).meet(&universe_box(tree));
        Some(exact_window(tree, &w, &grown, false)?)
    } else {
        None
    };
    let sqrt = |d: u64| {
        if d == FAR {
            f32::INFINITY
        } else {
            (d as f64).sqrt() as f32
        }
    };
    Ok((0..voxels as usize)
        .map(|i| match (&outside, &inside) {
            (Some(o), Some(n)) if o[i] == 0 => -sqrt(n[i]),
            (Some(o), _) => sqrt(o[i]),
            (None, Some(n)) => -sqrt(n[i]),
            (None, None) => unreachable!("a window holds full or empty voxels"),
        })
        .collect())
}

/// The narrow band of half-width `width` (voxels) of `tree`: every voxel with `|sd| ≤ width` and its
/// signed distance, exact, computed block by block on all threads.
///
/// ```
/// use ktree::{shape::narrow_band, KTree};
/// let tree = KTree::<1>::from_dense(3, &[false, true, true, true, true, false, false, false]).unwrap();
/// let band = narrow_band(&tree, 1.0).unwrap();
/// assert_eq!(band.voxels, [[0], [1], [4], [5]]);
/// assert_eq!(band.values, [1.0, -1.0, -1.0, 1.0]);
/// ```
///
/// # Performance
/// `O(K · (b + 2w)^K)` per block of side `b` the surface passes through; memory one block per thread.
///
/// # Errors
/// [`ShapeError::BadWidth`] for a negative or non-finite width; [`ShapeError::Storage`] for a read error.
pub fn narrow_band<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    width: f64,
) -> Result<NarrowBand<K>, ShapeError> {
    check_width(width)?;
    let limit = squared_limit(width);
    let universe = universe_box(tree);
    let pad = (width.floor() as i64).min(universe.dims[0]);
    let side = block_side(tree, pad);
    let band_of = |b: &Bx<K>| -> Result<(Vec<[u32; K]>, Vec<f64>), ShapeError> {
        let src = b.grown(pad).meet(&universe);
        let n = count_in(tree, &src)?;
        if n == 0 || n == src.len() {
            return Ok((Vec::new(), Vec::new()));
        }
        let full = mask(tree, &src, true)?;
        let empty: Vec<bool> = full.iter().map(|&f| !f).collect();
        let out = edt(&src, &full, b);
        let inn = edt(&src, &empty, b);
        let (mut voxels, mut values) = (Vec::new(), Vec::new());
        for i in 0..out.len() {
            let (d, sign) = if out[i] == 0 {
                (inn[i], -1.0)
            } else {
                (out[i], 1.0)
            };
            if d <= limit {
                voxels.push(voxel_of(b, i));
                values.push(sign * (d as f64).sqrt());
            }
        }
        Ok((voxels, values))
    };
    let mut band = NarrowBand {
        width,
        ..NarrowBand::default()
    };
    // A few blocks a thread at a time, appended at once: memory is the band and those blocks' parts.
    let chunk = 16 * rayon::current_num_threads();
    for blocks in blocks(tree, side, 1)?.chunks(chunk) {
        let parts: Vec<(Vec<[u32; K]>, Vec<f64>)> =
            blocks.par_iter().map(band_of).collect::<Result<_, _>>()?;
        for (v, d) in parts {
            band.voxels.extend(v);
            band.values.extend(d);
        }
    }
    Ok(band)
}

/// [`dilate`](super::dilate) by a ball through the distance transform, block by block: the voxels within
/// `r` of a full voxel of `tree`. [`dilate`](super::dilate) takes this path where it is the faster one
/// (see [`crate::shape`]); the result is the same.
///
/// ```
/// use ktree::{rays::ball_rays, shape::{dilate, dilate_ball_by_distance, Element}, KTree};
/// let tree = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 6).unwrap());
/// assert_eq!(dilate_ball_by_distance(&tree, 4.5).unwrap(), dilate(&tree, 4.5, Element::Ball).unwrap());
/// ```
///
/// # Errors
/// [`ShapeError::BadRadius`] for a negative or non-finite `r`; [`ShapeError::Storage`] for a read error.
pub fn dilate_ball_by_distance<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    r: f64,
) -> Result<KTree<K>, ShapeError> {
    super::element::check_radius(r)?;
    let limit = squared_limit(r);
    let universe = universe_box(tree);
    let pad = (r.floor() as i64).min(universe.dims[0]);
    let side = block_side(tree, pad);
    let keys = ColumnKeys::new(tree.level());
    tree_of_blocks(tree, &blocks(tree, side, 1)?, side, |b| {
        let src = b.grown(pad).meet(&universe);
        if count_in(tree, &src)? == 0 {
            return Ok(Vec::new());
        }
        if count_in(tree, b)? == b.len() {
            return Ok(runs_of(keys, b, &vec![true; b.len() as usize]));
        }
        let d = edt(&src, &mask(tree, &src, true)?, b);
        let keep: Vec<bool> = d.iter().map(|&d| d <= limit).collect();
        Ok(runs_of(keys, b, &keep))
    })
}

/// [`erode`](super::erode) by a ball through the distance transform, the outside of the universe empty
/// (scipy's `border_value=0`): the full voxels of `tree` farther than `r` from every empty voxel.
///
/// ```
/// use ktree::{rays::ball_rays, shape::{erode, erode_ball_by_distance, Element}, KTree};
/// let tree = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 20).unwrap());
/// assert_eq!(erode_ball_by_distance(&tree, 4.5).unwrap(), erode(&tree, 4.5, Element::Ball).unwrap());
/// ```
///
/// # Errors
/// [`ShapeError::BadRadius`] for a negative or non-finite `r`; [`ShapeError::Storage`] for a read error.
pub fn erode_ball_by_distance<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    r: f64,
) -> Result<KTree<K>, ShapeError> {
    super::element::check_radius(r)?;
    let limit = squared_limit(r);
    let universe = universe_box(tree);
    let pad = (r.floor() as i64).min(universe.dims[0]);
    let side = block_side(tree, pad);
    let keys = ColumnKeys::new(tree.level());
    tree_of_blocks(tree, &blocks(tree, side, 0)?, side, |b| {
        let src = b.grown(pad);
        let inside = src.meet(&universe) == src;
        if count_in(tree, b)? == 0 {
            return Ok(Vec::new());
        }
        if inside && count_in(tree, &src)? == src.len() {
            return Ok(runs_of(keys, b, &vec![true; b.len() as usize]));
        }
        let d = edt(&src, &mask(tree, &src, false)?, b);
        let keep: Vec<bool> = d.iter().map(|&d| d > limit).collect();
        Ok(runs_of(keys, b, &keep))
    })
}

/// Whether a block of the ball morphology by distance of `tree`, grown by `r`, stays within
/// [`MAX_BLOCK_SOURCE`] voxels (else the run extension is taken, whatever its cost).
pub(crate) fn ball_by_distance_fits<const K: usize, T: TreeStorage<K>>(tree: &T, r: f64) -> bool {
    let pad = (r.floor().min(1e12) as i64).min(universe_box(tree).dims[0]);
    let side = block_side(tree, pad);
    ((side + 2 * pad) as u128).saturating_pow(K as u32) <= MAX_BLOCK_SOURCE
}

impl<const K: usize> KTree<K> {
    /// The signed distance of each voxel of `points` ([`signed_distance_at()`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(3, &[false, true, true, true, false, false, false, false]).unwrap();
    /// assert_eq!(tree.signed_distance_at(&[[0], [2], [7]]).unwrap(), [1.0, -2.0, 4.0]);
    /// ```
    ///
    /// # Errors
    /// As [`signed_distance_at()`].
    pub fn signed_distance_at(&self, points: &[[u32; K]]) -> Result<Vec<f64>, ShapeError> {
        signed_distance_at(self, points)
    }

    /// The signed distances of the window `[origin, origin + shape)`, C order ([`signed_distance_window()`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i == 5).collect::<Vec<_>>()).unwrap();
    /// assert_eq!(tree.signed_distance_window([1, 1], [1, 1]).unwrap(), [-1.0]);
    /// ```
    ///
    /// # Errors
    /// As [`signed_distance_window()`].
    pub fn signed_distance_window(
        &self,
        origin: [u32; K],
        shape: [usize; K],
    ) -> Result<Vec<f32>, ShapeError> {
        signed_distance_window(self, origin, shape)
    }

    /// The narrow band of half-width `width` ([`narrow_band()`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(3, &[false, true, true, true, true, false, false, false]).unwrap();
    /// assert_eq!(tree.narrow_band(1.0).unwrap().len(), 4);
    /// ```
    ///
    /// # Errors
    /// As [`narrow_band()`].
    pub fn narrow_band(&self, width: f64) -> Result<NarrowBand<K>, ShapeError> {
        narrow_band(self, width)
    }

    /// [`KTree::dilate`] by a ball through the distance transform ([`dilate_ball_by_distance()`]).
    ///
    /// # Errors
    /// As [`dilate_ball_by_distance()`].
    pub fn dilate_ball_by_distance(&self, r: f64) -> Result<KTree<K>, ShapeError> {
        dilate_ball_by_distance(self, r)
    }

    /// [`KTree::erode`] by a ball through the distance transform ([`erode_ball_by_distance()`]).
    ///
    /// # Errors
    /// As [`erode_ball_by_distance()`].
    pub fn erode_ball_by_distance(&self, r: f64) -> Result<KTree<K>, ShapeError> {
        erode_ball_by_distance(self, r)
    }
}

/// Most voxels of a window's source box, as a multiple of the window's (and at least 2^20): past it the
/// values still unsure are found by nearest-voxel searches.
const SOURCE_GROWTH: u128 = 8;

/// The exact squared distances from each voxel of `w` to the nearest full (`full`) or empty voxel of the
/// tree, which all lie in `feature` (the full voxels' bounding box, or it grown by one for the empty
/// ones): the source box grows until every value is exact, or until it would outgrow
/// [`SOURCE_GROWTH`] windows, when the values still unsure come from nearest-voxel searches (in the
/// tree or its complement).
fn exact_window<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    w: &Bx<K>,
    feature: &Bx<K>,
    full: bool,
) -> Result<Vec<u64>, ShapeError> {
    let widest = w.dims.iter().copied().max().unwrap_or(1);
    let cap = (w.len() * SOURCE_GROWTH).max(1 << 20);
    let mut m = (widest / 2).max(8);
    loop {
        let src = w.grown(m).meet(feature);
        let mut d = edt(&src, &mask(tree, &src, full)?, w);
        let bound = (m as u128 * m as u128).min(u128::from(FAR - 1)) as u64;
        if src == *feature || d.iter().all(|&v| v <= bound) {
            return Ok(d);
        }
        let next = m.saturating_mul(4);
        if w.grown(next).meet(feature).len() > cap {
            let unsure: Vec<usize> = (0..d.len()).filter(|&i| d[i] > bound).collect();
            let points: Vec<[u32; K]> = unsure.iter().map(|&i| voxel_of(w, i)).collect();
            let found = if full {
                query::nearest_many(tree, &points)
            } else {
                query::nearest_many(&Complement(tree), &points)
            }
            .map_err(read_error)?;
            for (i, n) in unsure.into_iter().zip(found) {
                d[i] = n.map_or(FAR, |n| n.squared.min(u128::from(FAR - 1)) as u64);
            }
            return Ok(d);
        }
        m = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The envelope against the minimum over all samples, with random-ish samples and query ranges.
    #[test]
    fn envelope_is_the_lower_envelope() {
        let mut lcg = crate::testing::Lcg(7);
        let mut next = |n: u64| lcg.below(n);
        let mut hull = Vec::new();
        for _ in 0..500 {
            let mut samples: Vec<(i64, u64)> = (0..next(12))
                .map(|_| (next(40) as i64 - 20, next(200)))
                .collect();
            samples.sort();
            samples.dedup_by_key(|s| s.0);
            let first = next(60) as i64 - 30;
            let mut out = vec![0; next(30) as usize];
            envelope(&samples, first, &mut out, &mut hull);
            for (j, &v) in out.iter().enumerate() {
                let x = first + j as i64;
                let want = samples
                    .iter()
                    .map(|&(p, h)| (x - p).pow(2) as u64 + h)
                    .min()
                    .unwrap_or(FAR);
                assert_eq!(v, want, "{samples:?} at {x}");
            }
        }
    }
}
