//! What the grid formats (binvox, OctoMap `.bt`, OpenVDB `.vdb`) share: their error type, the boxes a
//! reader collects, the placement of a grid's integer indices in a ktree universe and the bound on the
//! octree's nodes; the octree of the placed boxes is built by [`octree`].
//!
//! A grid file indexes voxels by integers that may be negative (OpenVDB, OctoMap) or need not start at a
//! power of two. ktree voxel `v` is grid index `i` with `v = i + offset`; the offset and the universe level
//! are chosen by [`GridPlacement::choose`] unless the caller fixes them.

mod octree;

use thiserror::Error;

pub(crate) use octree::place_boxes;

use crate::space::max_level;
use crate::tree::KTree;

/// What was wrong with a grid file (binvox, `.bt`, `.vdb`).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum GridFileErrorKind {
    /// The header is missing, malformed or names something this reader does not read.
    #[error("bad header: {0}")]
    Header(String),
    /// The file ends before the data it announces.
    #[error("the file ends early: {0}")]
    Truncated(String),
    /// The data contradicts itself or the header.
    #[error("bad data: {0}")]
    Data(String),
    /// A valid file of a kind this reader does not support.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The grid does not fit the universe asked for (or any universe), or its octree there would have more
    /// nodes than a file of its size may ask for.
    #[error("placement: {0}")]
    GridPlacement(String),
    /// The file could not be read.
    #[error("cannot read")]
    Io(crate::fs::IoCause),
}

/// An error reading or writing a grid file, with the file and the byte offset where it was found.
pub type GridFileError = crate::io::FileError<GridFileErrorKind>;

impl crate::io::ProblemKind for GridFileErrorKind {
    fn io_cause(&self) -> Option<&std::io::Error> {
        match self {
            Self::Io(cause) => Some(cause.error()),
            _ => None,
        }
    }
}

impl GridFileError {
    pub(crate) fn new(file: &str, offset: usize, kind: GridFileErrorKind) -> Self {
        Self::at_byte(file, offset as u64, kind)
    }
}

/// An axis-aligned box of grid indices: `origin` and the number of voxels along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct IndexBox {
    pub origin: [i64; 3],
    pub size: [u64; 3],
}

impl IndexBox {
    fn hi(&self) -> [i64; 3] {
        std::array::from_fn(|a| self.origin[a] + self.size[a] as i64)
    }
}

/// The largest number of boxes (runs, leaves) a grid reader collects (checked as they are made).
pub(crate) const MAX_GRID_RUNS: u64 = 1 << 27;

/// The object of a grid file as boxes of grid indices: `inside` must lie in the universe, `fill` (OctoMap's
/// unknown space read as full) is clipped to it; `known` is the region the file describes, whose bounding
/// box chooses the universe.
#[derive(Debug, Default)]
pub(crate) struct GridBoxes {
    pub inside: Vec<IndexBox>,
    pub fill: Vec<IndexBox>,
    pub known: Option<([i64; 3], [i64; 3])>,
}

impl GridBoxes {
    /// The side of the largest aligned cells among the boxes inside: the largest power of two that divides
    /// some box's origin on every axis and fits in its sizes (1 if there are no boxes). A default offset that
    /// is a multiple of it keeps every box as aligned in the universe as it is among the grid's indices, so
    /// a grid's tiles stay single nodes ([`GridPlacement::choose`]).
    pub fn alignment(&self) -> u64 {
        self.inside
            .iter()
            .map(|b| {
                (0..3)
                    .map(|a| {
                        let fits = 1u64 << (63 - b.size[a].max(1).leading_zeros());
                        let divides = match b.origin[a] {
                            0 => u64::MAX,
                            o => 1u64 << o.trailing_zeros(),
                        };
                        fits.min(divides)
                    })
                    .min()
                    .unwrap_or(1)
            })
            .max()
            .unwrap_or(1)
    }

    pub fn note_known(&mut self, b: IndexBox) {
        let hi = b.hi();
        self.known = Some(match self.known {
            None => (b.origin, hi),
            Some((lo0, hi0)) => (
                std::array::from_fn(|a| lo0[a].min(b.origin[a])),
                std::array::from_fn(|a| hi0[a].max(hi[a])),
            ),
        });
    }
}

/// Where a grid goes in a universe: ktree voxel = grid index + `offset`, in a universe of level `level`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridPlacement {
    /// Added to a grid index to give the ktree voxel.
    pub offset: [i64; 3],
    /// The universe level.
    pub level: u32,
}

impl GridPlacement {
    /// The placement of a grid whose known region is `known` (half-open bounds of grid indices):
    /// `offset` if given, else 0 on every axis where no index is negative and, where one is, the smallest
    /// multiple of `alignment` (a power of two: the side of the grid's largest aligned cells) that makes
    /// every index at least 0; `level` if given, else the smallest level whose universe holds the region (0 for an empty region).
    /// A grid's aligned cells (OpenVDB's tiles, OctoMap's pruned nodes) thus stay aligned cells: an offset
    /// that is not a multiple of a cell's side would cut it into nodes in proportion to its surface.
    ///
    /// ```
    /// use ktree::io::GridPlacement;
    /// let p = GridPlacement::choose(Some(([-3, 0, 5], [4, 9, 6])), 1, None, None).unwrap();
    /// assert_eq!(p, GridPlacement { offset: [3, 0, 0], level: 4 });
    /// // A grid of 8³ blocks at multiples of 8: the offset is one too.
    /// let p = GridPlacement::choose(Some(([-3, 0, 5], [4, 9, 6])), 8, None, None).unwrap();
    /// assert_eq!(p, GridPlacement { offset: [8, 0, 0], level: 4 });
    /// ```
    ///
    /// # Errors
    /// A sentence when the region does not fit (a level beyond [`max_level`]`(3)`).
    pub fn choose(
        known: Option<([i64; 3], [i64; 3])>,
        alignment: u64,
        offset: Option<[i64; 3]>,
        level: Option<u32>,
    ) -> Result<Self, String> {
        let step = i64::try_from(alignment.max(1)).unwrap_or(1 << 62);
        let offset = offset.unwrap_or_else(|| match known {
            Some((lo, _)) => std::array::from_fn(|a| {
                let shift = lo[a].saturating_neg().max(0);
                (shift / step + i64::from(shift % step != 0)).saturating_mul(step)
            }),
            None => [0; 3],
        });
        let level = match level {
            Some(l) => l,
            None => {
                let extent = known.map_or(1, |(_, hi)| {
                    (0..3)
                        .map(|a| hi[a].saturating_add(offset[a]))
                        .max()
                        .unwrap_or(1)
                        .max(1)
                });
                let mut l = 0u32;
                while (1i128 << l) < i128::from(extent) {
                    l += 1;
                }
                l
            }
        };
        if level > max_level(3) {
            return Err(format!(
                "the grid needs a level-{level} universe; octrees go to level {}",
                max_level(3)
            ));
        }
        Ok(Self { offset, level })
    }

    /// The ktree voxel range `[lo, hi)` of a box of grid indices, clipped to the universe; `None` if the
    /// box misses the universe. `clip = false` asks for the whole box to lie inside.
    fn voxels(&self, b: &IndexBox, clip: bool) -> Result<Option<VoxelBox>, String> {
        let side = 1i64 << self.level;
        let mut lo = [0u32; 3];
        let mut hi = [0u32; 3];
        for a in 0..3 {
            let l = b.origin[a].saturating_add(self.offset[a]);
            let h = l.saturating_add(b.size[a] as i64);
            if !clip && (l < 0 || h > side) {
                return Err(format!(
                    "grid voxels {:?}..{:?} fall outside the level-{} universe at offset {:?}: choose another \
                     offset or level",
                    b.origin,
                    b.hi(),
                    self.level,
                    self.offset
                ));
            }
            let (l, h) = (l.clamp(0, side), h.clamp(0, side));
            if l >= h {
                return Ok(None);
            }
            lo[a] = l as u32;
            hi[a] = h as u32;
        }
        Ok(Some((lo, hi)))
    }
}

/// The most nodes the octree of a grid file of `file_len` bytes may have: 2^20, plus 2^5 a byte. A box that the placement leaves unaligned (a large cell at an offset that is not a
/// multiple of its side) costs nodes in proportion to its surface, so a file of a few bytes could otherwise
/// ask for billions. Aligned, no format here makes more than about 20 nodes a byte (a `.vdb` checkerboard
/// of 8³ tiles: about 2; of voxels in leaves: about 10; a `.bt` inner node's 2 bytes: at most 8 children;
/// the real files of the tests: at most 2.3), so the bound only stops misplaced files. The readers count
/// the nodes before they make any, so a file refused costs the count alone. The allowance a byte is
/// what bounds a reader's work on any input: at 2^7 a byte, a 46 KB `.vdb` could still ask for 7 million
/// nodes (0.19 s in the fuzz build); at 2^5, for 2.5 million. A caller reading untrusted files may set a
/// smaller bound ([`read_vdb_within`](crate::io::read_vdb_within)).
///
/// ```
/// assert_eq!(ktree::io::max_grid_nodes(1000), (1 << 20) + 32 * 1000);
/// ```
pub fn max_grid_nodes(file_len: usize) -> u64 {
    BASE_NODES + (file_len as u64) * NODES_A_BYTE
}

/// The nodes any grid file may have, however short ([`max_grid_nodes`]).
const BASE_NODES: u64 = 1 << 20;
/// The nodes a grid file may have for each of its bytes ([`max_grid_nodes`]).
const NODES_A_BYTE: u64 = 1 << 5;

/// A box of voxels `[lo, hi)` in the universe.
pub(super) type VoxelBox = ([u32; 3], [u32; 3]);

/// Where a grid's voxels are in the world: grid index `i` covers `origin + voxel_size · [i, i + 1)` on each
/// axis (binvox `translate` and `scale / D`, OctoMap `res`, OpenVDB's linear transform). The crate's one
/// world frame, [`WorldFrame`](crate::space::WorldFrame).
pub type GridMeta = crate::space::WorldFrame;

/// An octree read from a grid file, with where it was placed and the grid's world metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedTree {
    /// The object.
    pub tree: KTree<3>,
    /// ktree voxel = grid index + `placement.offset`, in a universe of level `placement.level`.
    pub placement: GridPlacement,
    /// The grid's world metadata.
    pub meta: GridMeta,
}
