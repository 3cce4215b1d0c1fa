//! Reading an OpenVDB file's first grid of a type read: its header, metadata and transform, then its
//! tree's active voxels (or a level set's interior) as boxes placed into an octree.

use std::collections::HashSet;

use super::level_set::read_interior;
use super::values::{ones, Reader, Sample, ValueCoding, ValueKind};
use super::*;
use crate::io::interop::grid::{
    max_grid_nodes, place_boxes, GridBoxes, GridFileError, GridFileErrorKind, GridMeta,
    GridPlacement, IndexBox, PlacedTree, MAX_GRID_RUNS,
};

/// A grid type read, from a descriptor's type name (`_HalfFloat` marks a grid saved with half floats).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct GridType {
    pub kind: ValueKind,
    pub half: bool,
    /// A `MaskGrid` (bool topology, no values in its leaves).
    pub mask: bool,
}

impl GridType {
    fn of(name: &str) -> Option<Self> {
        let (base, half) = match name.strip_suffix(HALF_FLOAT_SUFFIX) {
            Some(base) => (base, true),
            None => (name, false),
        };
        let (kind, mask) = match base {
            BOOL_TREE => (ValueKind::Bool, false),
            MASK_TREE => (ValueKind::Bool, true),
            FLOAT_TREE => (ValueKind::F32, false),
            DOUBLE_TREE => (ValueKind::F64, false),
            INT32_TREE => (ValueKind::I32, false),
            INT64_TREE => (ValueKind::I64, false),
            VEC3S_TREE => (ValueKind::Vec3S, false),
            VEC3D_TREE => (ValueKind::Vec3D, false),
            _ => return None,
        };
        (!half || kind.is_float()).then_some(Self { kind, half, mask })
    }

    pub fn name(self) -> &'static str {
        match self.kind {
            ValueKind::Bool if self.mask => "MaskGrid",
            ValueKind::Bool => "BoolGrid",
            ValueKind::F32 => "FloatGrid",
            ValueKind::F64 => "DoubleGrid",
            ValueKind::I32 => "Int32Grid",
            ValueKind::I64 => "Int64Grid",
            ValueKind::Vec3S => "Vec3SGrid",
            ValueKind::Vec3D => "Vec3DGrid",
        }
    }

    /// Whether a grid of this type and class is a level set (read as its interior).
    pub fn is_level_set(self, class: Option<&str>) -> bool {
        matches!(self.kind, ValueKind::F32 | ValueKind::F64) && class == Some("level set")
    }

    /// How its node values are stored, under the file's compression flags.
    pub fn coding(self, compression: u32) -> ValueCoding {
        ValueCoding {
            compression,
            kind: self.kind,
            half: self.half,
        }
    }
}

/// What a grid's header (compression flags, metadata, transform) says.
pub(super) struct GridHeader {
    pub compression: u32,
    /// ktree's own metadata: the universe level and offset a file was written with.
    pub level: Option<u32>,
    pub offset: Option<[i64; 3]>,
    /// The grid class (`class` metadata), and where its value is.
    pub class: Option<(String, usize)>,
    pub meta: GridMeta,
}

impl Reader<'_> {
    /// Reads a metadata map, keeping ktree's own entries (level, offset) and the grid class.
    fn metadata(&mut self) -> Result<GridHeader, GridFileError> {
        let count = self.u32("metadata count")?;
        let mut head = GridHeader {
            compression: 0,
            level: None,
            offset: None,
            class: None,
            meta: GridMeta::default(),
        };
        for _ in 0..count {
            let name = self.string("metadata name")?;
            let kind = self.string("metadata type")?;
            let value_at = self.at;
            let n = self.u32("metadata size")? as usize;
            let value = self.take(n, "metadata value")?;
            let int =
                |i: usize| i32::from_le_bytes(value[4 * i..4 * i + 4].try_into().expect("4 bytes"));
            match (name.as_str(), kind.as_str(), n) {
                (LEVEL_KEY, "int32", 4) => head.level = u32::try_from(int(0)).ok(),
                (OFFSET_KEY, "vec3i", 12) => {
                    head.offset = Some([0, 1, 2].map(|i| i64::from(int(i))));
                }
                ("class", "string", _) => {
                    head.class = Some((String::from_utf8_lossy(value).into_owned(), value_at));
                }
                _ => {}
            }
        }
        Ok(head)
    }

    /// A grid's compression flags, metadata and transform, from `at`.
    fn grid_header(&mut self, at: i64) -> Result<GridHeader, GridFileError> {
        self.at = usize::try_from(at)
            .ok()
            .filter(|&p| p <= self.bytes.len())
            .ok_or_else(|| {
                self.fail(GridFileErrorKind::Data(format!(
                    "grid position {at} is outside the file"
                )))
            })?;
        let compression = self.u32("compression flags")?;
        let mut head = self.metadata()?;
        head.compression = compression;
        let map_at = self.at;
        let map = self.string("transform type")?;
        head.meta = match map.as_str() {
            "UniformScaleTranslateMap" | "ScaleTranslateMap" => {
                let t = self.f64x3("translation")?;
                let s = self.f64x3("scale")?;
                self.take(4 * 24, "transform")?;
                GridMeta {
                    voxel_size: s[0],
                    origin: std::array::from_fn(|a| t[a] - s[0] / 2.0),
                }
            }
            "UniformScaleMap" | "ScaleMap" => {
                let s = self.f64x3("scale")?;
                self.take(4 * 24, "transform")?;
                GridMeta {
                    voxel_size: s[0],
                    origin: [-s[0] / 2.0; 3],
                }
            }
            "TranslationMap" => {
                let t = self.f64x3("translation")?;
                GridMeta {
                    voxel_size: 1.0,
                    origin: t.map(|x| x - 0.5),
                }
            }
            other => {
                self.at = map_at;
                return Err(self.fail(GridFileErrorKind::Unsupported(format!(
                    "transform {:?}",
                    shortened(other)
                ))));
            }
        };
        Ok(head)
    }
}

/// A name from the file for a message: its first 64 characters (a damaged file's name may be its whole
/// length).
fn shortened(name: &str) -> String {
    match name.char_indices().nth(64) {
        Some((end, _)) => format!("{}…", &name[..end]),
        None => name.to_string(),
    }
}

/// Adds a box of grid indices to the object (and to the region known), at most [`MAX_GRID_RUNS`] of them.
pub(super) fn push_box(
    boxes: &mut GridBoxes,
    r: &Reader,
    origin: [i64; 3],
    size: [u64; 3],
) -> Result<(), GridFileError> {
    let b = IndexBox { origin, size };
    boxes.note_known(b);
    boxes.inside.push(b);
    if boxes.inside.len() as u64 > MAX_GRID_RUNS {
        return Err(r.fail(GridFileErrorKind::Unsupported(format!(
            "more than {MAX_GRID_RUNS} boxes"
        ))));
    }
    Ok(())
}

/// Adds the voxels `n` of the 8³ leaf at `lo` whose bit is set in `mask` (8 words; `n = x·64 + y·8 + z`,
/// so a word is a slice of constant x and a byte a row along z) as boxes: each run of set bits in a row,
/// taken over the neighbouring rows (along y) and slices (along x) that are the same.
pub(super) fn add_leaf(
    boxes: &mut GridBoxes,
    r: &Reader,
    lo: [i64; 3],
    mask: &[u64],
) -> Result<(), GridFileError> {
    let mut x = 0;
    while x < 8 {
        let slice = mask[x];
        let x_end = x + mask[x..].iter().take_while(|&&w| w == slice).count();
        let rows = slice.to_le_bytes();
        let mut y = 0;
        while y < 8 {
            let row = rows[y];
            let y_end = y + rows[y..].iter().take_while(|&&b| b == row).count();
            let mut rest = row;
            while rest != 0 {
                let z0 = rest.trailing_zeros();
                let z1 = z0 + (rest >> z0).trailing_ones();
                let origin = [lo[0] + x as i64, lo[1] + y as i64, lo[2] + i64::from(z0)];
                let size = [x_end - x, y_end - y, (z1 - z0) as usize].map(|s| s as u64);
                push_box(boxes, r, origin, size)?;
                rest &= !(((1u16 << z1) - 1) as u8);
            }
            y = y_end;
        }
        x = x_end;
    }
    Ok(())
}

/// Reads a root entry's origin (a tile's or a child's): a multiple of 4096 on every axis, as OpenVDB keys
/// its root table, and not met before. An entry off those keys or at a place already taken describes no
/// tree OpenVDB writes, and its boxes could overlap others.
pub(super) fn root_origin(
    r: &mut Reader,
    seen: &mut HashSet<[i64; 3]>,
    what: &str,
) -> Result<[i64; 3], GridFileError> {
    let at = r.at;
    let o = [r.i32(what)?, r.i32(what)?, r.i32(what)?].map(i64::from);
    if o.iter().any(|c| c % 4096 != 0) {
        return Err(r.fail_at(
            at,
            GridFileErrorKind::Data(format!("{what} {o:?} is not a multiple of 4096")),
        ));
    }
    if !seen.insert(o) {
        return Err(r.fail_at(
            at,
            GridFileErrorKind::Data(format!("a second root entry at {o:?}")),
        ));
    }
    Ok(o)
}

/// Checks, before anything is allocated for them, that `tiles` root tiles of `tile_bytes` bytes and
/// `children` root children (each at least its origin, two masks and a value byte) fit in what is left.
pub(super) fn check_root_counts(
    r: &Reader,
    tiles: usize,
    tile_bytes: usize,
    children: usize,
) -> Result<(), GridFileError> {
    let left = r.bytes.len() - r.at.min(r.bytes.len());
    let child_bytes = 12 + 2 * 8 * UPPER_WORDS + 1;
    if tiles
        .saturating_mul(tile_bytes)
        .saturating_add(children.saturating_mul(child_bytes))
        > left
    {
        return Err(r.fail(GridFileErrorKind::Truncated(format!(
            "{tiles} root tiles and {children} children cannot fit in {left} bytes"
        ))));
    }
    Ok(())
}

/// What a walk over a grid's active voxels ([`walk_active`]) meets, in the file's order.
pub(super) trait ActiveVisitor {
    /// Whether the walk decodes the values (else only the topology is read, and the leaf buffers of a
    /// grid with values are left unread).
    const VALUES: bool;

    /// An active tile: the cube of side `side` at `origin`, its value (0 without [`Self::VALUES`]) stored
    /// at byte `at`.
    fn tile(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        side: u64,
        value: Sample,
        at: usize,
    ) -> Result<(), GridFileError>;

    /// The active voxels (`mask`) of the leaf at `origin`, and (with [`Self::VALUES`]) its 512 values,
    /// whose buffer starts at byte `at`.
    fn leaf(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        mask: &[u64],
        values: &[Sample],
        at: usize,
    ) -> Result<(), GridFileError>;
}

/// The active voxels and tiles of a grid's tree (from its background on), shown to `visitor`. Values are
/// decoded (and so checked) node by node as the file stores them.
pub(super) fn walk_active<V: ActiveVisitor>(
    r: &mut Reader,
    grid: GridType,
    coding: &ValueCoding,
    visitor: &mut V,
) -> Result<(), GridFileError> {
    let kind = coding.kind;
    let background = r.value(kind, "background")?;
    let tiles = r.u32("root tile count")? as usize;
    let children = r.u32("root child count")? as usize;
    check_root_counts(r, tiles, 12 + kind.size() + 1, children)?;
    let mut seen = HashSet::new();
    for _ in 0..tiles {
        let o = root_origin(r, &mut seen, "root tile origin")?;
        let at = r.at;
        let value = r.value(kind, "tile value")?;
        if r.take(1, "tile state")?[0] != 0 {
            visitor.tile(r, o, 4096, value, at)?;
        }
    }
    // An internal node's active tiles: the values that are active and not children.
    let tiles_of = |r: &mut Reader,
                    visitor: &mut V,
                    count: usize,
                    children: &[u64],
                    lo: [i64; 3],
                    (log_dim, child_log): (u32, u32)|
     -> Result<(), GridFileError> {
        let active = r.mask(count / 64)?;
        let at = r.at;
        let node = r.values(coding, count, &active, background)?;
        let mut values = Vec::new();
        if V::VALUES {
            node.each(&active, |_, v| values.push(v));
        }
        for n in ones(&active) {
            if children[n / 64] >> (n % 64) & 1 == 0 {
                let value = values.get(n).copied().unwrap_or_default();
                visitor.tile(
                    r,
                    corner_of(lo, n, log_dim, child_log),
                    1 << child_log,
                    value,
                    at,
                )?;
            }
        }
        Ok(())
    };
    let mut leaves: Vec<([i64; 3], Vec<u64>)> = Vec::new();
    for _ in 0..children {
        let o = root_origin(r, &mut seen, "root child origin")?;
        let child_mask = r.mask(UPPER_WORDS)?;
        tiles_of(r, visitor, UPPER_WORDS * 64, &child_mask, o, (5, 7))?;
        for n in ones(&child_mask) {
            let lo = corner_of(o, n, 5, 7);
            let lower_children = r.mask(LOWER_WORDS)?;
            tiles_of(r, visitor, LOWER_WORDS * 64, &lower_children, lo, (4, 3))?;
            for m in ones(&lower_children) {
                leaves.push((corner_of(lo, m, 4, 3), r.mask(LEAF_WORDS)?));
            }
        }
    }
    for (lo, mask) in &leaves {
        let at = r.at;
        let mut values = Vec::new();
        if kind == ValueKind::Bool && !grid.mask {
            // A bool leaf's buffer: its value mask, origin and values again.
            r.take(2 * 8 * LEAF_WORDS + 12, "leaf buffer")?;
        } else if V::VALUES {
            // The buffer's copy of the value mask: OpenVDB reading a file seeks past it and keeps the
            // topology's.
            r.take(8 * LEAF_WORDS, "leaf value mask")?;
            let node = r.values(coding, LEAF_WORDS * 64, mask, background)?;
            node.each(mask, |_, v| values.push(v));
        }
        visitor.leaf(r, *lo, mask, &values, at)?;
    }
    Ok(())
}

/// The active voxels of a grid, as boxes.
#[derive(Default)]
struct ActiveBoxes(GridBoxes);

impl ActiveVisitor for ActiveBoxes {
    const VALUES: bool = false;

    fn tile(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        side: u64,
        _: Sample,
        _: usize,
    ) -> Result<(), GridFileError> {
        push_box(&mut self.0, r, origin, [side; 3])
    }

    fn leaf(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        mask: &[u64],
        _: &[Sample],
        _: usize,
    ) -> Result<(), GridFileError> {
        add_leaf(&mut self.0, r, origin, mask)
    }
}

/// The header of a file and the first grid of a type that `wanted` takes (given the type and its class),
/// the reader left at the grid's tree (its buffer count). A grid passed over is named in the error when no
/// grid is taken, with `why` (a sentence on what is read).
pub(super) fn find_grid<'a>(
    bytes: &'a [u8],
    file: &'a str,
    wanted: impl Fn(GridType, Option<&str>) -> bool,
    why: &str,
) -> Result<(Reader<'a>, GridType, GridHeader), GridFileError> {
    let mut r = Reader { bytes, at: 0, file };
    if r.i64("magic")? != MAGIC {
        r.at = 0;
        return Err(r.fail(GridFileErrorKind::Header(
            "not an OpenVDB file (bad magic)".into(),
        )));
    }
    let version = r.u32("file version")?;
    if version < 222 {
        r.at -= 4;
        return Err(r.fail(GridFileErrorKind::Unsupported(format!(
            "file format version {version} (222 and later are read)"
        ))));
    }
    r.take(8, "library version")?;
    let has_offsets = r.take(1, "grid offsets flag")?[0] != 0;
    r.take(36, "UUID")?;
    r.metadata()?;
    let grids = r.i32("grid count")?;
    let mut found = None;
    let mut refused = None;
    let mut header_bytes = 0usize;
    for _ in 0..grids.max(0) {
        let _name = r.string("grid name")?;
        let kind = r.string("grid type")?;
        let parent = r.string("instance parent")?;
        let grid_at = r.i64("grid position")?;
        r.i64("block position")?;
        let end_at = r.i64("end position")?;
        if let Some(grid) = GridType::of(&kind).filter(|_| parent.is_empty()) {
            if has_offsets && usize::try_from(end_at).map_or(true, |e| e > bytes.len()) {
                return Err(r.fail(GridFileErrorKind::Truncated(format!(
                    "the grid ends at byte {end_at}, the file has {}",
                    bytes.len()
                ))));
            }
            let after_descriptor = r.at;
            let header_at = if has_offsets {
                grid_at
            } else {
                after_descriptor as i64
            };
            let head = r.grid_header(header_at)?;
            // The headers of grids passed over are read at most about twice the file's length in all:
            // descriptors pointing at one long header again and again would otherwise take quadratic time.
            header_bytes += r.at.saturating_sub(usize::try_from(header_at).unwrap_or(0));
            let class = head.class.as_ref().map(|(c, _)| c.as_str());
            if !wanted(grid, class) {
                refused.get_or_insert_with(|| {
                    let at = head.class.as_ref().map_or(after_descriptor, |(_, at)| *at);
                    r.fail_at(
                        at,
                        GridFileErrorKind::Unsupported(format!(
                            "a {} of class {:?}: {why}",
                            grid.name(),
                            shortened(class.unwrap_or("unknown"))
                        )),
                    )
                });
                r.at = after_descriptor;
                if header_bytes > 2 * bytes.len() {
                    break;
                }
            } else {
                found = Some((grid, head));
                break;
            }
        }
        if !has_offsets {
            break;
        }
        // The next descriptor starts where this grid ends, which must lie past this descriptor: otherwise
        // a small file with a large grid count would read the same bytes again and again.
        if usize::try_from(end_at).map_or(true, |e| e <= r.at) {
            r.at -= 8;
            return Err(r.fail(GridFileErrorKind::Data(format!(
                "the grid ends at byte {end_at}, not past its descriptor"
            ))));
        }
        r.at = usize::try_from(end_at)
            .unwrap_or(usize::MAX)
            .min(bytes.len());
    }
    let Some((grid, head)) = found else {
        return Err(refused.unwrap_or_else(|| {
            r.fail(GridFileErrorKind::Unsupported(format!(
                "no grid of a type read in the file: {why}"
            )))
        }));
    };
    if r.i32("buffer count")? != 1 {
        r.at -= 4;
        return Err(r.fail(GridFileErrorKind::Unsupported(
            "more than one buffer".into(),
        )));
    }
    Ok((r, grid, head))
}

/// Reads an OpenVDB file's first `BoolGrid` or `MaskGrid` — its active voxels — or level set (a
/// `FloatGrid` or `DoubleGrid` of class `level set`) — its interior, every voxel and tile whose value is
/// below zero, active or not (see [`crate::io::interop`]'s notes on level sets) — into an octree, placed by
/// `offset` and `level` (see [`GridPlacement::choose`]; the region chosen for is the one read). A file
/// written by ktree carries its level and offset as grid metadata (`ktree_level`, `ktree_offset`), used
/// when the caller gives none. Values may be stored raw or compressed as OpenVDB writes them: active-mask
/// compression, zlib, Blosc (LZ4), half floats.
///
/// ```
/// use ktree::io::{read_vdb, write_vdb_level_set};
/// use ktree::{rays::ball_rays, KTree};
/// let ball = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 24).unwrap());
/// let mut sdf = Vec::new();
/// write_vdb_level_set(&mut sdf, &ball, 3.0, 0.5).unwrap();
/// assert_eq!(read_vdb(&sdf, "sdf.vdb", None, None).unwrap().tree, ball);
/// ```
///
/// # Errors
/// [`GridFileError`] naming the byte offset: not a `.vdb` file, a format version before 222, no grid of a
/// type read, a `FloatGrid` or `DoubleGrid` of another class than level set (a fog volume, say; when no
/// other grid is read), a transform other than a scale and translation, sizes beyond the file, compressed
/// data that does not decode to its size, a Blosc codec other than LZ4, or voxels outside the universe
/// asked for.
pub fn read_vdb(
    bytes: &[u8],
    file: &str,
    offset: Option<[i64; 3]>,
    level: Option<u32>,
) -> Result<PlacedTree, GridFileError> {
    read_vdb_within(bytes, file, offset, level, max_grid_nodes(bytes.len()))
}

/// [`read_vdb`] with the octree bounded to `max_nodes` nodes (instead of [`max_grid_nodes`] of the file's
/// length): a placement that would make more is refused with a [`GridFileErrorKind::GridPlacement`] error
/// before any node is made. For a caller that reads untrusted files in bounded time and memory.
///
/// ```
/// use ktree::io::{read_vdb_within, write_vdb, GridFileErrorKind, GridMeta};
/// use ktree::{rays::ball_rays, KTree};
/// let ball = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 12).unwrap());
/// let mut bytes = Vec::new();
/// write_vdb(&mut bytes, &ball, [0; 3], &GridMeta::default()).unwrap();
/// assert_eq!(read_vdb_within(&bytes, "ball.vdb", None, None, 10_000).unwrap().tree, ball);
/// let e = read_vdb_within(&bytes, "ball.vdb", None, None, 100).unwrap_err();
/// assert!(matches!(e.kind, GridFileErrorKind::GridPlacement(_)));
/// ```
///
/// # Errors
/// As [`read_vdb`].
pub fn read_vdb_within(
    bytes: &[u8],
    file: &str,
    offset: Option<[i64; 3]>,
    level: Option<u32>,
    max_nodes: u64,
) -> Result<PlacedTree, GridFileError> {
    let (mut r, grid, head) = find_grid(
        bytes,
        file,
        |_, _| true,
        "BoolGrid, MaskGrid, Int32Grid, Int64Grid, FloatGrid, DoubleGrid, Vec3SGrid and Vec3DGrid are read",
    )?;
    let level = level.or(head.level);
    let offset = offset.or(head.offset);
    let coding = grid.coding(head.compression);
    let class = head.class.as_ref().map(|(c, _)| c.as_str());
    let boxes = if grid.is_level_set(class) {
        read_interior(&mut r, &coding)?
    } else {
        let mut active = ActiveBoxes::default();
        walk_active(&mut r, grid, &coding, &mut active)?;
        active.0
    };
    let placement = GridPlacement::choose(boxes.known, boxes.alignment(), offset, level)
        .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::GridPlacement(m)))?;
    let tree = place_boxes(&boxes, &placement, max_nodes)
        .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::GridPlacement(m)))?;
    Ok(PlacedTree {
        tree,
        placement,
        meta: head.meta,
    })
}
