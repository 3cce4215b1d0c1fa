//! The universe a k-tree lives in: its level `L` and side `U = 2^L`, voxel coordinates, aligned cells and
//! Morton keys, for any dimension `K` from 1 to [`MAX_K`].
//!
//! Coordinates are `u32` per axis. A Morton key interleaves the bits of all `K` coordinates into one `u64`,
//! so `K · L ≤ 64` bounds the level: [`max_level`] gives the largest `L` for each `K`. The universe's *size*
//! is never allocated: a level-21 octree universe has 2^63 voxels and is fine as long as the object is not
//! stored voxel by voxel.
//!
//! Child numbering (used by every tree in the crate): the child code of a cell's child is a `K`-bit number
//! whose bit `i` is set when the child is in the upper half of the parent along axis `i`. Axis `K − 1` (the
//! last, "z") is the ray axis.
//!
//! ```
//! use ktree::{max_level, Universe};
//! // The largest octree universe: 2^21 voxels a side, 2^63 voxels, none of them allocated.
//! let u = Universe::<3>::new(max_level(3)).unwrap();
//! assert_eq!(u.side(), 1 << 21);
//! assert_eq!(u.voxels(), 1u128 << 63);
//! // Child 1 of the root is its upper half along x (bit 0 of the child code).
//! let child = u.root().child(1);
//! assert_eq!(child.origin(), [1 << 20, 0, 0]);
//! assert!(child.contains([(1 << 21) - 1, 5, 5]) && !child.contains([0, 5, 5]));
//! assert!(Universe::<3>::new(22).is_err());
//! ```

use thiserror::Error;

/// The largest dimension supported: bintrees (1), quadtrees (2), octrees (3) and 4-D time-space trees (4).
pub const MAX_K: usize = 4;

/// The largest universe level `L` for dimension `k`: `K · L` must fit the 64 bits of a Morton key and a
/// coordinate (including the end `z2 = U` of a run) must fit a `u32`.
///
/// | K | largest L | side U |
/// |---|-----------|--------|
/// | 1 | 31 | 2^31 |
/// | 2 | 31 | 2^31 |
/// | 3 | 21 | 2^21 = 2 097 152 |
/// | 4 | 16 | 2^16 = 65 536 |
///
/// ```
/// assert_eq!(ktree::max_level(3), 21);
/// assert_eq!(ktree::max_level(4), 16);
/// ```
pub const fn max_level(k: usize) -> u32 {
    match k {
        1 | 2 => 31,
        3 => 21,
        4 => 16,
        _ => 0,
    }
}

/// Where voxels are in the world, the one frame of clouds, meshes, grid files and exports: the voxel (or
/// grid index) with coordinates `c` covers `origin + voxel_size · [c, c + 1)` on each axis, so coordinate 0's
/// lower corner is at `origin` (quadtrees use the first two coordinates). Known as
/// [`export::Frame`](crate::export::Frame) where a tree is placed for export and as
/// [`io::GridMeta`](crate::io::GridMeta) where a grid file states it (binvox `translate` and `scale / D`,
/// OctoMap `res`, OpenVDB's linear transform).
///
/// ```
/// let f = ktree::space::WorldFrame { voxel_size: 0.5, origin: [1.0, 0.0, -2.0] };
/// assert_eq!(f.corner_of([2, 0, 4]), [2.0, 0.0, 0.0]);
/// assert_eq!(ktree::space::WorldFrame::default().corner_of([3, 1, 2]), [3.0, 1.0, 2.0]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct WorldFrame {
    /// The edge of a voxel in world units.
    pub voxel_size: f64,
    /// The world position of the lower corner of coordinate 0.
    pub origin: [f64; 3],
}

impl Default for WorldFrame {
    /// Unit voxels, coordinate 0 at the world origin.
    fn default() -> Self {
        Self {
            voxel_size: 1.0,
            origin: [0.0; 3],
        }
    }
}

impl WorldFrame {
    /// The world position of the lower corner of the voxel at `c`.
    pub fn corner_of(&self, c: [i64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| self.origin[a] + c[a] as f64 * self.voxel_size)
    }

    /// The world frame of a tree made from the voxels of two (a Boolean of them): the frame they both
    /// keep, or the one of the tree that keeps one; `Err` with both when they differ (the same voxel
    /// coordinates would be different places).
    ///
    /// ```
    /// use ktree::space::WorldFrame;
    /// let f = WorldFrame { voxel_size: 0.5, origin: [1.0, 0.0, -2.0] };
    /// assert_eq!(WorldFrame::shared(Some(f), None), Ok(Some(f)));
    /// assert_eq!(WorldFrame::shared(None, None), Ok(None));
    /// let g = WorldFrame { voxel_size: 0.25, ..f };
    /// assert_eq!(WorldFrame::shared(Some(f), Some(g)), Err([f, g]));
    /// ```
    ///
    /// # Errors
    /// Both frames, when both are given and differ.
    pub fn shared(a: Option<Self>, b: Option<Self>) -> Result<Option<Self>, [Self; 2]> {
        match (a, b) {
            (Some(a), Some(b)) if a != b => Err([a, b]),
            (a, b) => Ok(a.or(b)),
        }
    }

    /// The same placement with coordinates counted from `offset` (coordinate `c` here is `c − offset` in
    /// the frame returned): the world does not move.
    pub fn counted_from(&self, offset: [i64; 3]) -> Self {
        Self {
            voxel_size: self.voxel_size,
            origin: self.corner_of(offset),
        }
    }
}

/// Compile-time guard used by every `K`-generic type: `1 ≤ K ≤ MAX_K`.
pub(crate) struct DimCheck<const K: usize>;

impl<const K: usize> DimCheck<K> {
    pub(crate) const OK: () = assert!(K >= 1 && K <= MAX_K, "ktree supports 1 <= K <= 4");
}

/// Errors about levels, coordinates and cells.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum SpaceError {
    /// The level is larger than [`max_level`] allows for this dimension. Use a smaller level.
    #[error("level {level} is too large for K = {k}: the largest is {max}")]
    LevelTooLarge {
        /// The dimension.
        k: usize,
        /// The level asked for.
        level: u32,
        /// The largest level allowed for `k`.
        max: u32,
    },
    /// A coordinate lies outside `[0, U)`.
    #[error("coordinate {value} on axis {axis} is outside the universe [0, {side})")]
    OutOfUniverse {
        /// The axis (0-based).
        axis: usize,
        /// The offending value.
        value: u64,
        /// The universe's side `U`.
        side: u64,
    },
    /// A cell's origin is not a multiple of its side, or its level is deeper than the universe's.
    #[error("cell at level {level} with origin {origin:?} is not aligned in a level-{universe_level} universe")]
    Misaligned {
        /// The cell's origin.
        origin: Vec<u32>,
        /// The cell's level.
        level: u32,
        /// The universe level.
        universe_level: u32,
    },
    /// A dense array was asked for a universe too big to hold in memory.
    #[error("a dense array of {voxels} voxels is too large (limit {limit})")]
    TooLargeForDense {
        /// The number of voxels the array would need.
        voxels: u128,
        /// The limit.
        limit: u128,
    },
}

/// A `K`-dimensional universe of level `L`: the cube `[0, U)^K` with `U = 2^L`, divided into `U^K` voxels.
///
/// ```
/// use ktree::Universe;
/// let u = Universe::<3>::new(10).unwrap();
/// assert_eq!(u.side(), 1024);
/// assert!(Universe::<3>::new(22).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Universe<const K: usize> {
    level: u32,
}

impl<const K: usize> Universe<K> {
    /// A universe of level `level`, checked against [`max_level`]`(K)`.
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`] when `level > max_level(K)`.
    pub fn new(level: u32) -> Result<Self, SpaceError> {
        let () = DimCheck::<K>::OK;
        let max = max_level(K);
        if level > max {
            return Err(SpaceError::LevelTooLarge { k: K, level, max });
        }
        Ok(Self { level })
    }

    /// The level `L`.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// The side `U = 2^L`.
    pub fn side(&self) -> u64 {
        1u64 << self.level
    }

    /// The number of voxels `U^K` (as `u128`: it can exceed `u64` only in principle, never within the limits).
    pub fn voxels(&self) -> u128 {
        1u128 << (self.level as usize * K)
    }

    /// Checks that every coordinate of `point` is inside `[0, U)`.
    ///
    /// # Errors
    /// [`SpaceError::OutOfUniverse`] naming the first axis outside.
    pub fn check_point(&self, point: [u32; K]) -> Result<(), SpaceError> {
        for (axis, &value) in point.iter().enumerate() {
            if u64::from(value) >= self.side() {
                return Err(SpaceError::OutOfUniverse {
                    axis,
                    value: value.into(),
                    side: self.side(),
                });
            }
        }
        Ok(())
    }

    /// The root cell: the whole universe.
    pub fn root(&self) -> Cell<K> {
        Cell {
            origin: [0; K],
            level: 0,
            log_side: self.level,
        }
    }

    /// The aligned cell at `level` with the given origin.
    ///
    /// # Errors
    /// [`SpaceError::Misaligned`] if `level > L` or an origin coordinate is not a multiple of the cell's side;
    /// [`SpaceError::OutOfUniverse`] if the origin is outside.
    pub fn cell(&self, origin: [u32; K], level: u32) -> Result<Cell<K>, SpaceError> {
        self.check_point(origin)?;
        if level > self.level {
            return Err(self.misaligned(origin, level));
        }
        let log_side = self.level - level;
        let mask = (1u64 << log_side) - 1;
        if origin.iter().any(|&c| u64::from(c) & mask != 0) {
            return Err(self.misaligned(origin, level));
        }
        Ok(Cell {
            origin,
            level,
            log_side,
        })
    }

    fn misaligned(&self, origin: [u32; K], level: u32) -> SpaceError {
        SpaceError::Misaligned {
            origin: origin.to_vec(),
            level,
            universe_level: self.level,
        }
    }

    /// The number of voxels if it fits a dense array of at most `limit` voxels.
    ///
    /// # Errors
    /// [`SpaceError::TooLargeForDense`] otherwise.
    pub fn dense_len(&self, limit: u128) -> Result<usize, SpaceError> {
        let voxels = self.voxels();
        if voxels > limit || voxels > usize::MAX as u128 {
            return Err(SpaceError::TooLargeForDense { voxels, limit });
        }
        Ok(voxels as usize)
    }

    /// Index of a voxel in a dense array of the universe, axis 0 fastest:
    /// `c_0 + U·(c_1 + U·(c_2 + …))`. Coordinates must be inside the universe.
    pub fn dense_index(&self, point: [u32; K]) -> usize {
        let mut index = 0usize;
        for &c in point.iter().rev() {
            index = (index << self.level) | c as usize;
        }
        index
    }

    /// The voxel of a dense-array index (the inverse of [`Universe::dense_index`]).
    pub fn dense_point(&self, mut index: usize) -> [u32; K] {
        let mask = (1usize << self.level) - 1;
        let mut point = [0u32; K];
        for c in point.iter_mut() {
            *c = (index & mask) as u32;
            index >>= self.level;
        }
        point
    }
}

/// The largest number of voxels the crate will put in a dense array (2^30, one gigabyte of `bool`).
pub const DENSE_LIMIT: u128 = 1 << 30;

/// An aligned cell of a universe: a cube of side `2^(L − level)` whose origin is a multiple of its side.
/// Level 0 is the whole universe, level `L` a voxel. Made by [`Universe::cell`] (checked) or by navigating a
/// tree, so a cell is always aligned and inside its universe.
///
/// ```
/// use ktree::Universe;
/// let u = Universe::<2>::new(3).unwrap();
/// let c = u.cell([4, 0], 1).unwrap();
/// assert_eq!((c.origin(), c.level(), c.side()), ([4, 0], 1, 4));
/// assert!(u.cell([2, 0], 1).is_err()); // not aligned
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Cell<const K: usize> {
    /// The corner with the smallest coordinates.
    pub(crate) origin: [u32; K],
    /// Depth in the tree (0 = root).
    pub(crate) level: u32,
    /// log2 of the side: `L − level`.
    pub(crate) log_side: u32,
}

impl<const K: usize> Cell<K> {
    /// The aligned cell at `level` with the given origin in `universe` (the same as [`Universe::cell`]).
    ///
    /// # Errors
    /// As [`Universe::cell`].
    pub fn new(universe: Universe<K>, origin: [u32; K], level: u32) -> Result<Self, SpaceError> {
        universe.cell(origin, level)
    }

    /// The corner with the smallest coordinates.
    pub fn origin(&self) -> [u32; K] {
        self.origin
    }

    /// The depth in the tree (0 = the root, the whole universe).
    pub fn level(&self) -> u32 {
        self.level
    }

    /// log2 of the side: `L − level`.
    pub fn log_side(&self) -> u32 {
        self.log_side
    }

    /// The level `L` of the universe the cell belongs to.
    pub fn universe_level(&self) -> u32 {
        self.level + self.log_side
    }

    /// The side length in voxels.
    pub fn side(&self) -> u64 {
        1u64 << self.log_side
    }

    /// The number of voxels in the cell.
    pub fn volume(&self) -> u128 {
        1u128 << (self.log_side as usize * K)
    }

    /// Whether the voxel `point` lies in the cell.
    pub fn contains(&self, point: [u32; K]) -> bool {
        let side = self.side();
        point
            .iter()
            .zip(self.origin.iter())
            .all(|(&p, &o)| p >= o && u64::from(p - o) < side)
    }

    /// The child with the given child code (bit `i` set = upper half along axis `i`).
    /// The cell must not be a voxel.
    pub fn child(&self, code: usize) -> Cell<K> {
        debug_assert!(self.log_side > 0 && code < (1 << K));
        let half = 1u32 << (self.log_side - 1);
        let mut origin = self.origin;
        for (axis, o) in origin.iter_mut().enumerate() {
            if code >> axis & 1 == 1 {
                *o += half;
            }
        }
        Cell {
            origin,
            level: self.level + 1,
            log_side: self.log_side - 1,
        }
    }

    /// The Morton key of the cell's origin (see [`morton_encode`]); cells of one tree sort by it in the
    /// order of a depth-first traversal.
    pub fn morton(&self) -> u64 {
        morton_encode(self.origin)
    }
}

/// Spreads the low bits of `v` so that bit `b` lands at bit `b · K` (`K` = 1…4).
#[inline]
pub fn spread_bits<const K: usize>(v: u32) -> u64 {
    let mut x = u64::from(v);
    match K {
        1 => x,
        2 => {
            x = (x | x << 16) & 0x0000_FFFF_0000_FFFF;
            x = (x | x << 8) & 0x00FF_00FF_00FF_00FF;
            x = (x | x << 4) & 0x0F0F_0F0F_0F0F_0F0F;
            x = (x | x << 2) & 0x3333_3333_3333_3333;
            (x | x << 1) & 0x5555_5555_5555_5555
        }
        3 => {
            x &= 0x1F_FFFF;
            x = (x | x << 32) & 0x001F_0000_0000_FFFF;
            x = (x | x << 16) & 0x001F_0000_FF00_00FF;
            x = (x | x << 8) & 0x100F_00F0_0F00_F00F;
            x = (x | x << 4) & 0x10C3_0C30_C30C_30C3;
            (x | x << 2) & 0x1249_2492_4924_9249
        }
        4 => {
            x &= 0xFFFF;
            x = (x | x << 24) & 0x0000_00FF_0000_00FF;
            x = (x | x << 12) & 0x000F_000F_000F_000F;
            x = (x | x << 6) & 0x0303_0303_0303_0303;
            (x | x << 3) & 0x1111_1111_1111_1111
        }
        _ => unreachable!("K is checked to be 1..=4"),
    }
}

/// The inverse of [`spread_bits`]: gathers every `K`-th bit of `x` starting at bit 0.
#[inline]
pub fn compact_bits<const K: usize>(mut x: u64) -> u32 {
    match K {
        1 => x as u32,
        2 => {
            x &= 0x5555_5555_5555_5555;
            x = (x | x >> 1) & 0x3333_3333_3333_3333;
            x = (x | x >> 2) & 0x0F0F_0F0F_0F0F_0F0F;
            x = (x | x >> 4) & 0x00FF_00FF_00FF_00FF;
            x = (x | x >> 8) & 0x0000_FFFF_0000_FFFF;
            ((x | x >> 16) & 0xFFFF_FFFF) as u32
        }
        3 => {
            x &= 0x1249_2492_4924_9249;
            x = (x | x >> 2) & 0x10C3_0C30_C30C_30C3;
            x = (x | x >> 4) & 0x100F_00F0_0F00_F00F;
            x = (x | x >> 8) & 0x001F_0000_FF00_00FF;
            x = (x | x >> 16) & 0x001F_0000_0000_FFFF;
            ((x | x >> 32) & 0x1F_FFFF) as u32
        }
        4 => {
            x &= 0x1111_1111_1111_1111;
            x = (x | x >> 3) & 0x0303_0303_0303_0303;
            x = (x | x >> 6) & 0x000F_000F_000F_000F;
            x = (x | x >> 12) & 0x0000_00FF_0000_00FF;
            ((x | x >> 24) & 0xFFFF) as u32
        }
        _ => unreachable!("K is checked to be 1..=4"),
    }
}

/// The Morton (Z-order) key of a point: bit `b` of coordinate `i` goes to bit `b · K + i`.
/// Sorting cells by the Morton key of their origins gives depth-first (Morton) order.
///
/// ```
/// use ktree::space::{morton_encode, morton_decode};
/// assert_eq!(morton_encode([1u32, 0, 0]), 0b001);
/// assert_eq!(morton_encode([0u32, 0, 1]), 0b100);
/// assert_eq!(morton_decode::<3>(morton_encode([5u32, 9, 1000])), [5, 9, 1000]);
/// ```
#[inline]
pub fn morton_encode<const K: usize>(point: [u32; K]) -> u64 {
    let mut key = 0u64;
    for (axis, &c) in point.iter().enumerate() {
        key |= spread_bits::<K>(c) << axis;
    }
    key
}

/// The point of a Morton key (the inverse of [`morton_encode`]).
#[inline]
pub fn morton_decode<const K: usize>(key: u64) -> [u32; K] {
    let mut point = [0u32; K];
    for (axis, c) in point.iter_mut().enumerate() {
        *c = compact_bits::<K>(key >> axis);
    }
    point
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive_morton<const K: usize>(p: [u32; K], bits: u32) -> u64 {
        let mut key = 0u64;
        for b in 0..bits {
            for (i, &c) in p.iter().enumerate() {
                key |= u64::from(c >> b & 1) << (b as usize * K + i);
            }
        }
        key
    }

    fn check_morton<const K: usize>() {
        let bits = max_level(K);
        let mut lcg = crate::testing::Lcg(0x9E37_79B9_7F4A_7C15);
        for _ in 0..2000 {
            let mut p = [0u32; K];
            for c in p.iter_mut() {
                *c = ((lcg.next_u64() >> 33) as u32) & ((1u64 << bits) - 1) as u32;
            }
            let key = morton_encode(p);
            assert_eq!(key, naive_morton(p, bits), "K={K} p={p:?}");
            assert_eq!(morton_decode::<K>(key), p);
        }
    }

    #[test]
    fn morton_matches_bit_by_bit_interleaving_for_every_k() {
        check_morton::<1>();
        check_morton::<2>();
        check_morton::<3>();
        check_morton::<4>();
    }

    #[test]
    fn levels_are_checked() {
        assert!(Universe::<1>::new(31).is_ok());
        assert!(Universe::<2>::new(32).is_err());
        assert!(Universe::<3>::new(21).is_ok());
        assert!(Universe::<3>::new(22).is_err());
        assert!(Universe::<4>::new(16).is_ok());
        assert!(Universe::<4>::new(17).is_err());
    }

    #[test]
    fn cells_check_alignment() {
        let u = Universe::<2>::new(3).unwrap();
        assert!(u.cell([4, 0], 1).is_ok());
        assert!(u.cell([2, 0], 1).is_err());
        assert!(u.cell([0, 0], 4).is_err());
        assert!(u.cell([8, 0], 3).is_err());
        let c = u.cell([4, 4], 1).unwrap();
        assert_eq!(c.child(0b10).origin, [4, 6]);
        assert!(c.contains([7, 7]) && !c.contains([3, 7]));
    }

    #[test]
    fn dense_index_round_trips() {
        let u = Universe::<3>::new(2).unwrap();
        for i in 0..64 {
            assert_eq!(u.dense_index(u.dense_point(i)), i);
        }
        assert_eq!(u.dense_index([1, 2, 3]), 1 + 4 * (2 + 4 * 3));
    }
}
