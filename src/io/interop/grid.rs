//! What the grid formats (binvox, OctoMap `.bt`, OpenVDB `.vdb`) share: their error type, the placement of
//! a grid's integer indices in a ktree universe, and the runs of a tree along z.
//!
//! A grid file indexes voxels by integers that may be negative (OpenVDB, OctoMap) or need not start at a
//! power of two. ktree voxel `v` is grid index `i` with `v = i + offset`; the offset and the universe level
//! are chosen by [`GridPlacement::choose`] unless the caller fixes them.

use thiserror::Error;

use crate::space::max_level;
use crate::tree::{KTree, NodeState, TreeAssembler};

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
    #[error("cannot read: {0}")]
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
    /// `offset` if given, else 0 on every axis where no index is negative and `−min` where one is; `level`
    /// if given, else the smallest level whose universe holds the region (0 for an empty region).
    ///
    /// ```
    /// use ktree::io::GridPlacement;
    /// let p = GridPlacement::choose(Some(([-3, 0, 5], [4, 9, 6])), None, None).unwrap();
    /// assert_eq!(p, GridPlacement { offset: [3, 0, 0], level: 4 });
    /// ```
    ///
    /// # Errors
    /// A sentence when the region does not fit (a level beyond [`max_level`]`(3)`).
    pub fn choose(
        known: Option<([i64; 3], [i64; 3])>,
        offset: Option<[i64; 3]>,
        level: Option<u32>,
    ) -> Result<Self, String> {
        let offset = offset.unwrap_or_else(|| match known {
            Some((lo, _)) => std::array::from_fn(|a| (-lo[a]).max(0)),
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

/// The most nodes the octree of a grid file of `file_len` bytes may have: 2^20, plus 2^7 a byte. A box
/// that the placement leaves unaligned (a large cell at an offset that is not a multiple of its side)
/// costs nodes in proportion to its surface, so a file of a few bytes could otherwise ask for billions.
/// Aligned, no format here makes more than about 20 nodes a byte (a `.vdb` checkerboard of 8³ tiles:
/// about 2; of voxels in leaves: about 10; a `.bt` inner node's 2 bytes: at most 8 children), so the
/// bound only stops misplaced files — and bounds the reader's time (about 45 ns a node) by the input's
/// size: 2^10 a byte let a 46 KB `.vdb` take 0.9 s.
pub(crate) fn max_grid_nodes(file_len: usize) -> u64 {
    (1 << 20) + ((file_len as u64) << 7)
}

/// The octree of a grid's boxes placed in a universe, of at most `max_nodes` nodes (else an error). The
/// boxes are disjoint (every grid format here describes each voxel once), so a cell is full exactly when
/// the volumes of its overlaps with the boxes add up to its own: the tree is built top-down, reduced as it
/// is made.
pub(crate) fn place_boxes(
    boxes: &GridBoxes,
    placement: &GridPlacement,
    max_nodes: u64,
) -> Result<KTree<3>, String> {
    let mut voxel_boxes = Vec::new();
    for (list, clip) in [(&boxes.inside, false), (&boxes.fill, true)] {
        for b in list {
            if let Some(v) = placement.voxels(b, clip)? {
                voxel_boxes.push(v);
            }
        }
    }
    let mut out = TreeAssembler::<3>::new(placement.level).map_err(|e| e.to_string())?;
    let all: Vec<u32> = (0..voxel_boxes.len() as u32).collect();
    let mut budget = max_nodes;
    if !build(
        &mut out,
        [0; 3],
        placement.level,
        0,
        &voxel_boxes,
        &all,
        &mut budget,
    ) {
        return Err(format!(
            "at offset {:?} in a level-{} universe the grid's octree has more than {max_nodes} nodes \
             (2^20 + 2^7 a byte of the file): choose an offset that is a multiple of the grid's cell sides",
            placement.offset, placement.level
        ));
    }
    Ok(out.finish())
}

type VoxelBox = ([u32; 3], [u32; 3]);

fn build(
    out: &mut TreeAssembler<3>,
    lo: [u32; 3],
    log_side: u32,
    depth: usize,
    boxes: &[VoxelBox],
    candidates: &[u32],
    budget: &mut u64,
) -> bool {
    if *budget == 0 {
        return false;
    }
    *budget -= 1;
    let side = 1u64 << log_side;
    let mut covered = 0u128;
    let mut touching = Vec::new();
    for &i in candidates {
        let (blo, bhi) = boxes[i as usize];
        let mut volume = 1u128;
        for a in 0..3 {
            let l = u64::from(blo[a]).max(u64::from(lo[a]));
            let h = u64::from(bhi[a]).min(u64::from(lo[a]) + side);
            volume *= u128::from(h.saturating_sub(l));
        }
        if volume > 0 {
            covered += volume;
            touching.push(i);
        }
    }
    let cell_volume = 1u128 << (3 * log_side);
    if covered == 0 {
        out.push(depth, NodeState::Empty);
    } else if covered >= cell_volume || log_side == 0 {
        out.push(depth, NodeState::Full);
    } else {
        out.push(depth, NodeState::Partial);
        let half = 1u32 << (log_side - 1);
        for code in 0..8 {
            let child = std::array::from_fn(|a| lo[a] + if code >> a & 1 == 1 { half } else { 0 });
            if !build(
                out,
                child,
                log_side - 1,
                depth + 1,
                boxes,
                &touching,
                budget,
            ) {
                return false;
            }
        }
    }
    true
}

/// Where a grid's voxels are in the world: grid index `i` covers `origin + voxel_size · [i, i + 1)` on each
/// axis (binvox `translate` and `scale / D`, OctoMap `res`, OpenVDB's linear transform).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridMeta {
    /// The edge length of a voxel in world units.
    pub voxel_size: f64,
    /// The world position of the corner of grid index (0, 0, 0).
    pub origin: [f64; 3],
}

impl Default for GridMeta {
    /// Unit voxels, grid index (0, 0, 0) at the world origin.
    fn default() -> Self {
        Self {
            voxel_size: 1.0,
            origin: [0.0; 3],
        }
    }
}

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
