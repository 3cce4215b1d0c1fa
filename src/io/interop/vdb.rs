//! OpenVDB files (`.vdb`): octrees written as one `BoolGrid` (`Tree_bool_5_4_3`), the grid type OpenVDB's
//! Python module reads as a voxel set — active voxels are the object — and read from a `BoolGrid` or
//! `MaskGrid` (its active voxels) or a level set (a `FloatGrid` or `DoubleGrid` of class `level set`: its
//! interior, see [`super`]).
//!
//! The layout (file format version 224, OpenVDB 10): a header (magic `0x56444220` as `i64`, versions, a
//! UUID), file metadata, the grid count, and per grid its descriptor (name, type, positions), its compression
//! flags, metadata, transform, topology and leaf buffers. The tree is OpenVDB's root → 32³ internal nodes of
//! 128³ voxels → 16³ internal nodes of 8³ → 8³ leaves; masks are `u64` words, bit `n` of word `n / 64`,
//! with `n = x·D² + y·D + z` inside a node of side `D` (x slowest). All values little-endian.
//!
//! Written files are uncompressed (compression flags 0), which every OpenVDB reads. Reading takes what
//! OpenVDB writes (`vdb_values`): values raw or with active-mask compression, in zlib or Blosc
//! chunks (Blosc 1 frames with the LZ4 codec and byte shuffle, OpenVDB's default, decoded by
//! `blosc`); other Blosc codecs are reported as unsupported), and half floats. The first grid of a
//! type read is taken; a `FloatGrid` or `DoubleGrid` of another class (fog volume, unknown, staggered) is
//! passed over, and refused with its class when no other grid is read. OpenVDB index `(x, y, z)` is ktree
//! voxel `(x, y, z)` minus the offset written with, and the transform's voxel size and translation (the
//! world centre of index 0) become the [`GridMeta`].

use std::collections::{BTreeMap, HashSet};
use std::io::Write;

use super::grid::{
    max_grid_nodes, place_boxes, GridBoxes, GridFileError, GridFileErrorKind, GridMeta,
    GridPlacement, IndexBox, PlacedTree, MAX_GRID_RUNS,
};
use super::vdb_level_set::read_interior;
use super::vdb_values::{ones, Reader, ValueCoding, ValueKind};
use crate::tree::{KTree, NodeState};

pub(super) const MAGIC: i64 = 0x5644_4220;
pub(super) const FILE_VERSION: u32 = 224;
const BOOL_TREE: &str = "Tree_bool_5_4_3";
const MASK_TREE: &str = "Tree_mask_5_4_3";
pub(super) const FLOAT_TREE: &str = "Tree_float_5_4_3";
const DOUBLE_TREE: &str = "Tree_double_5_4_3";
/// Appended to a grid's type name when its values are saved as half floats.
const HALF_FLOAT_SUFFIX: &str = "_HalfFloat";
/// Grid metadata written by ktree: the universe level and the offset, read back as defaults.
pub(super) const LEVEL_KEY: &str = "ktree_level";
pub(super) const OFFSET_KEY: &str = "ktree_offset";
/// Words of a leaf mask (8³ bits), of a lower node mask (16³), of an upper node mask (32³).
pub(super) const LEAF_WORDS: usize = 8;
pub(super) const LOWER_WORDS: usize = 64;
pub(super) const UPPER_WORDS: usize = 512;

/// A 16³ internal node: 8³ tiles that are fully active, and leaves (8³ bit masks) by slot.
#[derive(Default)]
struct Lower {
    tiles: Vec<bool>,
    leaves: BTreeMap<u32, [u64; LEAF_WORDS]>,
}

/// A 32³ internal node: 128³ tiles that are fully active, and lower nodes by slot.
#[derive(Default)]
struct Upper {
    tiles: Vec<bool>,
    lowers: BTreeMap<u32, Lower>,
}

pub(super) fn slot(p: [i64; 3], log_dim: u32, child_log: u32) -> u32 {
    let m = (1i64 << (log_dim + child_log)) - 1;
    let c = |a: usize| ((p[a] & m) >> child_log) as u32;
    (c(0) << (2 * log_dim)) | (c(1) << log_dim) | c(2)
}

pub(super) fn origin_of(p: [i64; 3], log_side: u32) -> [i64; 3] {
    p.map(|c| c & !((1i64 << log_side) - 1))
}

/// The grid of a tree in OpenVDB's node structure, voxels at index = ktree voxel − `offset`.
fn build_nodes(tree: &KTree<3>, offset: [i64; 3]) -> BTreeMap<[i64; 3], Upper> {
    let mut root: BTreeMap<[i64; 3], Upper> = BTreeMap::new();
    tree.for_each_leaf(|cell, state| {
        if state != NodeState::Full {
            return;
        }
        let side = cell.side() as i64;
        let lo: [i64; 3] = std::array::from_fn(|a| i64::from(cell.origin[a]) - offset[a]);
        add_box(&mut root, lo, side);
    });
    root
}

/// Marks the cube `[lo, lo + side)³` active, as tiles where whole nodes are covered.
fn add_box(root: &mut BTreeMap<[i64; 3], Upper>, lo: [i64; 3], side: i64) {
    // Split the cube into the blocks of side `step` it covers: 128 (upper tiles), 8 (lower tiles), 1.
    let covers = |step: i64| lo.iter().all(|&c| c % step == 0) && side % step == 0;
    let step = [128, 8, 1].into_iter().find(|&s| covers(s)).unwrap_or(1);
    let n = side / step;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = [lo[0] + i * step, lo[1] + j * step, lo[2] + k * step];
                let upper = root.entry(origin_of(p, 12)).or_default();
                if upper.tiles.is_empty() {
                    upper.tiles = vec![false; UPPER_WORDS * 64];
                }
                let us = slot(p, 5, 7);
                if step == 128 {
                    upper.tiles[us as usize] = true;
                    continue;
                }
                let lower = upper.lowers.entry(us).or_default();
                if lower.tiles.is_empty() {
                    lower.tiles = vec![false; LOWER_WORDS * 64];
                }
                let ls = slot(p, 4, 3);
                if step == 8 {
                    lower.tiles[ls as usize] = true;
                    continue;
                }
                let leaf = lower.leaves.entry(ls).or_insert([0; LEAF_WORDS]);
                let n = slot(p, 3, 0) as usize;
                leaf[n / 64] |= 1 << (n % 64);
            }
        }
    }
}

pub(super) fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

pub(super) fn put_str(out: &mut Vec<u8>, s: &str) {
    put_u32(out, s.len() as u32);
    out.extend_from_slice(s.as_bytes());
}

/// Writes, after the file header, the one grid's descriptor (named "ktree", of tree type `tree_type`,
/// positions left as zeros) and its head: no compression, and the metadata `class`, `name` and the
/// universe (`LEVEL_KEY`, `OFFSET_KEY`), so that reading gives back the same tree. Returns where the
/// descriptor's positions are and where the grid starts, for the caller to fill in.
pub(super) fn put_grid_head(
    out: &mut Vec<u8>,
    tree_type: &str,
    class: &str,
    level: u32,
    offset: [i64; 3],
) -> (usize, usize) {
    put_u32(out, 0); // file metadata: none
    put_u32(out, 1); // one grid
    put_str(out, "ktree");
    put_str(out, tree_type);
    put_str(out, ""); // not an instance
    let positions_at = out.len();
    out.extend_from_slice(&[0; 24]); // grid, block and end positions, filled in by the caller
    let grid_at = out.len();
    put_u32(out, 0); // compression: none
    put_u32(out, 4); // grid metadata
    for (name, value) in [("class", class), ("name", "ktree")] {
        put_str(out, name);
        put_str(out, "string");
        put_str(out, value);
    }
    put_str(out, LEVEL_KEY);
    put_str(out, "int32");
    put_u32(out, 4);
    put_u32(out, level);
    put_str(out, OFFSET_KEY);
    put_str(out, "vec3i");
    put_u32(out, 12);
    for c in offset {
        out.extend_from_slice(&(c as i32).to_le_bytes());
    }
    (positions_at, grid_at)
}

fn put_mask(out: &mut Vec<u8>, bits: impl Iterator<Item = bool>, words: usize) {
    let mut w = vec![0u64; words];
    for (n, on) in bits.enumerate() {
        if on {
            w[n / 64] |= 1 << (n % 64);
        }
    }
    for x in w {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

/// Writes an octree as an OpenVDB file with one `BoolGrid` named `ktree`: OpenVDB index = ktree voxel −
/// `offset`, active and `true` where the tree is full; `meta` gives the transform (voxel size, and the
/// corner of index 0 in the world).
///
/// ```
/// use ktree::io::{read_vdb, write_vdb, GridMeta};
/// let tree = ktree::stacking::paper::stack(&ktree::rays::ball_rays::<3>(5, [16, 16, 16], 12).unwrap());
/// let mut bytes = Vec::new();
/// write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
/// assert_eq!(read_vdb(&bytes, "mem", Some([0; 3]), Some(5)).unwrap().tree, tree);
/// ```
///
/// # Errors
/// Any I/O error; [`std::io::ErrorKind::InvalidInput`] if an index falls outside OpenVDB's 32-bit range or
/// the voxel size is not positive.
pub fn write_vdb(
    mut w: impl Write,
    tree: &KTree<3>,
    offset: [i64; 3],
    meta: &GridMeta,
) -> std::io::Result<()> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    let side = 1i64 << tree.level();
    for a in 0..3 {
        if i32::try_from(offset[a]).is_err() || side - offset[a] > i64::from(i32::MAX) {
            return Err(invalid(format!(
                "offset {offset:?} puts indices outside OpenVDB's 32-bit range"
            )));
        }
    }
    let s = meta.voxel_size;
    if !(s > 0.0 && s.is_finite()) {
        return Err(invalid(format!("voxel size {s} is not a positive number")));
    }
    let root = build_nodes(tree, offset);
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC.to_le_bytes());
    put_u32(&mut out, FILE_VERSION);
    put_u32(&mut out, 10);
    put_u32(&mut out, 0);
    out.push(1); // the grid descriptors carry offsets
    let crc = crc32fast::hash(
        &tree
            .level_states(tree.depth_count() - 1)
            .words()
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect::<Vec<u8>>(),
    );
    let uuid = format!("{crc:08x}-0000-4000-8000-{:012x}", tree.node_count());
    out.extend_from_slice(uuid.as_bytes());
    let (positions_at, grid_at) =
        put_grid_head(&mut out, BOOL_TREE, "unknown", tree.level(), offset);
    put_str(&mut out, "UniformScaleTranslateMap");
    let centre = meta.origin.map(|o| o + s / 2.0);
    for v in [
        centre,
        [s; 3],
        [s; 3],
        [1.0 / s; 3],
        [1.0 / (s * s); 3],
        [0.5 / s; 3],
    ] {
        for x in v {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    // Topology.
    put_u32(&mut out, 1); // buffer count
    out.push(0); // background: false
    put_u32(&mut out, 0); // root tiles
    put_u32(&mut out, root.len() as u32);
    for (origin, upper) in &root {
        for c in origin {
            out.extend_from_slice(&(*c as i32).to_le_bytes());
        }
        put_mask(
            &mut out,
            (0..UPPER_WORDS * 64).map(|n| upper.lowers.contains_key(&(n as u32))),
            UPPER_WORDS,
        );
        put_mask(&mut out, upper.tiles.iter().copied(), UPPER_WORDS);
        out.push(6); // all values follow, uncompressed
        out.extend(upper.tiles.iter().map(|&t| u8::from(t)));
        for lower in upper.lowers.values() {
            put_mask(
                &mut out,
                (0..LOWER_WORDS * 64).map(|n| lower.leaves.contains_key(&(n as u32))),
                LOWER_WORDS,
            );
            put_mask(&mut out, lower.tiles.iter().copied(), LOWER_WORDS);
            out.push(6);
            out.extend(lower.tiles.iter().map(|&t| u8::from(t)));
            for leaf in lower.leaves.values() {
                for x in leaf {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
        }
    }
    let block_at = out.len();
    for (origin, upper) in &root {
        for (&us, lower) in &upper.lowers {
            for (&ls, leaf) in &lower.leaves {
                for x in leaf {
                    out.extend_from_slice(&x.to_le_bytes());
                }
                let leaf_origin =
                    corner_of(corner_of(*origin, us as usize, 5, 7), ls as usize, 4, 3);
                for c in leaf_origin {
                    out.extend_from_slice(&(c as i32).to_le_bytes());
                }
                for x in leaf {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
        }
    }
    let end_at = out.len();
    for (i, p) in [grid_at, block_at, end_at].into_iter().enumerate() {
        out[positions_at + 8 * i..positions_at + 8 * i + 8]
            .copy_from_slice(&(p as i64).to_le_bytes());
    }
    w.write_all(&out)?;
    w.flush()
}

/// The grid types read, from a descriptor's type name (`_HalfFloat` marks a grid saved with half floats).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GridType {
    /// `BoolGrid`: its active voxels.
    Bool,
    /// `MaskGrid`: its active voxels.
    Mask,
    /// `FloatGrid` or `DoubleGrid` of class level set: its interior.
    Real { kind: ValueKind, half: bool },
}

impl GridType {
    fn of(name: &str) -> Option<Self> {
        let (base, half) = match name.strip_suffix(HALF_FLOAT_SUFFIX) {
            Some(base) => (base, true),
            None => (name, false),
        };
        Some(match base {
            BOOL_TREE => Self::Bool,
            MASK_TREE => Self::Mask,
            FLOAT_TREE => Self::Real {
                kind: ValueKind::F32,
                half,
            },
            DOUBLE_TREE => Self::Real {
                kind: ValueKind::F64,
                half,
            },
            _ => return None,
        })
    }

    fn name(self) -> &'static str {
        match self {
            Self::Bool => "BoolGrid",
            Self::Mask => "MaskGrid",
            Self::Real {
                kind: ValueKind::F64,
                ..
            } => "DoubleGrid",
            Self::Real { .. } => "FloatGrid",
        }
    }

    /// How its node values are stored, under the file's compression flags.
    fn coding(self, compression: u32) -> ValueCoding {
        let (kind, half) = match self {
            Self::Bool | Self::Mask => (ValueKind::Bool, false),
            Self::Real { kind, half } => (kind, half),
        };
        ValueCoding {
            compression,
            kind,
            half,
        }
    }
}

/// What a grid's header (compression flags, metadata, transform) says.
struct GridHeader {
    compression: u32,
    /// ktree's own metadata: the universe level and offset a file was written with.
    level: Option<u32>,
    offset: Option<[i64; 3]>,
    /// The grid class (`class` metadata), and where its value is.
    class: Option<(String, usize)>,
    meta: GridMeta,
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

/// The active voxels of a `BoolGrid` or `MaskGrid`'s tree (from its background on), as boxes. The node
/// values are decoded (and so checked) but play no part.
fn read_active(
    r: &mut Reader,
    coding: &ValueCoding,
    is_bool: bool,
) -> Result<GridBoxes, GridFileError> {
    r.take(1, "background")?;
    let tiles = r.u32("root tile count")? as usize;
    let children = r.u32("root child count")? as usize;
    check_root_counts(r, tiles, 14, children)?;
    let mut boxes = GridBoxes::default();
    let mut seen = HashSet::new();
    for _ in 0..tiles {
        let o = root_origin(r, &mut seen, "root tile origin")?;
        r.take(1, "tile value")?;
        if r.take(1, "tile state")?[0] != 0 {
            push_box(&mut boxes, r, o, [4096; 3])?;
        }
    }
    let mut leaves = 0usize;
    for _ in 0..children {
        let o = root_origin(r, &mut seen, "root child origin")?;
        let child_mask = r.mask(UPPER_WORDS)?;
        let value_mask = r.mask(UPPER_WORDS)?;
        r.values(coding, UPPER_WORDS * 64, &value_mask, 0.0)?;
        for n in ones(&value_mask) {
            if child_mask[n / 64] >> (n % 64) & 1 == 0 {
                push_box(&mut boxes, r, corner_of(o, n, 5, 7), [128; 3])?;
            }
        }
        for n in ones(&child_mask) {
            let lo = corner_of(o, n, 5, 7);
            let lower_children = r.mask(LOWER_WORDS)?;
            let lower_values = r.mask(LOWER_WORDS)?;
            r.values(coding, LOWER_WORDS * 64, &lower_values, 0.0)?;
            for m in ones(&lower_values) {
                if lower_children[m / 64] >> (m % 64) & 1 == 0 {
                    push_box(&mut boxes, r, corner_of(lo, m, 4, 3), [8; 3])?;
                }
            }
            for m in ones(&lower_children) {
                leaves += 1;
                let leaf = r.mask(LEAF_WORDS)?;
                add_leaf(&mut boxes, r, corner_of(lo, m, 4, 3), &leaf)?;
            }
        }
    }
    if is_bool {
        // Each bool leaf's buffer: its value mask, origin and values again.
        for _ in 0..leaves {
            r.take(2 * 8 * LEAF_WORDS + 12, "leaf buffer")?;
        }
    }
    Ok(boxes)
}

pub(super) fn corner_of(origin: [i64; 3], n: usize, log_dim: u32, child_log: u32) -> [i64; 3] {
    let m = (1usize << log_dim) - 1;
    let c = [n >> (2 * log_dim), n >> log_dim & m, n & m];
    std::array::from_fn(|a| origin[a] + ((c[a] as i64) << child_log))
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
            if matches!(grid, GridType::Real { .. }) && class != Some("level set") {
                refused.get_or_insert_with(|| {
                    let at = head.class.as_ref().map_or(after_descriptor, |(_, at)| *at);
                    r.fail_at(
                        at,
                        GridFileErrorKind::Unsupported(format!(
                            "a {} of class {:?}: of a FloatGrid or DoubleGrid only a level set's \
                             interior (values below 0) is read",
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
            r.fail(GridFileErrorKind::Unsupported(
                "no BoolGrid, MaskGrid or level set (FloatGrid, DoubleGrid) in the file".into(),
            ))
        }));
    };
    let level = level.or(head.level);
    let offset = offset.or(head.offset);
    if r.i32("buffer count")? != 1 {
        r.at -= 4;
        return Err(r.fail(GridFileErrorKind::Unsupported(
            "more than one buffer".into(),
        )));
    }
    let coding = grid.coding(head.compression);
    let boxes = match grid {
        GridType::Bool | GridType::Mask => read_active(&mut r, &coding, grid == GridType::Bool)?,
        GridType::Real { .. } => read_interior(&mut r, &coding)?,
    };
    let placement = GridPlacement::choose(boxes.known, offset, level)
        .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::GridPlacement(m)))?;
    let tree = place_boxes(&boxes, &placement, max_grid_nodes(bytes.len()))
        .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::GridPlacement(m)))?;
    Ok(PlacedTree {
        tree,
        placement,
        meta: head.meta,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;

    #[test]
    fn round_trip_keeps_the_universe_and_tiles_cover_whole_nodes() {
        for (tree, offset) in [
            (
                stack(&ball_rays::<3>(6, [30, 25, 26], 20).unwrap()),
                [5, -300, 0],
            ),
            (
                stack(&ball_rays::<3>(9, [300, 250, 260], 200).unwrap()),
                [0, -512, 128],
            ),
            (KTree::<3>::empty(2).unwrap(), [0; 3]),
        ] {
            let mut bytes = Vec::new();
            write_vdb(&mut bytes, &tree, offset, &GridMeta::default()).unwrap();
            let p = read_vdb(&bytes, "v", None, None).unwrap();
            assert_eq!(p.tree, tree);
            assert_eq!(p.placement.offset, offset);
        }
        // A full level-13 universe at offset 0 is 8 root children of tiles: no leaf at all.
        let mut bytes = Vec::new();
        write_vdb(
            &mut bytes,
            &KTree::<3>::full(13).unwrap(),
            [0; 3],
            &GridMeta::default(),
        )
        .unwrap();
        assert!(bytes.len() < 8 * 50_000, "{} bytes", bytes.len());
    }

    /// A file's header up to its grid count: magic, versions, no file metadata.
    fn file_head() -> Vec<u8> {
        let mut b = MAGIC.to_le_bytes().to_vec();
        b.extend_from_slice(&FILE_VERSION.to_le_bytes());
        b.extend_from_slice(&[0; 8]);
        b.push(1);
        b.extend_from_slice(&[b'0'; 36]);
        b.extend_from_slice(&0u32.to_le_bytes());
        b
    }

    #[test]
    fn a_grid_end_before_its_descriptor_is_refused_at_the_first_descriptor() {
        // A header, a grid count of 100 000, and one descriptor of another grid type whose end position
        // points back at the descriptor itself: the scan must stop there, not read it 100 000 times.
        let mut b = file_head();
        b.extend_from_slice(&100_000i32.to_le_bytes());
        let descriptor_at = b.len() as i64;
        for s in ["g", "Tree_vec3s_5_4_3", ""] {
            put_str(&mut b, s);
        }
        let end_field_at = b.len() + 16;
        for p in [0, 0, descriptor_at] {
            b.extend_from_slice(&p.to_le_bytes());
        }
        let e = read_vdb(&b, "loop", None, None).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Data(_)), "{e}");
        assert_eq!(e.offset(), Some(end_field_at as u64), "{e}");
    }

    #[test]
    fn fog_volumes_are_passed_over_and_refused_by_their_class() {
        // A header, then 3000 descriptors of FloatGrids, each followed by a byte and pointing at one header
        // of 2000 metadata entries and class "fog volume": the scan stops reading that header again once
        // twice the file's length has been read, and says why the file is refused.
        let mut b = file_head();
        let count = 3000;
        b.extend_from_slice(&(count as i32).to_le_bytes());
        let descriptor = |grid_at: i64, end_at: i64| {
            let mut d = Vec::new();
            for s in ["g", FLOAT_TREE, ""] {
                put_str(&mut d, s);
            }
            for p in [grid_at, 0, end_at] {
                d.extend_from_slice(&p.to_le_bytes());
            }
            d.push(0);
            d
        };
        let each = descriptor(0, 0).len() as i64;
        let header_at = b.len() as i64 + each * count;
        for i in 0..count {
            let end_at = b.len() as i64 + each;
            assert_eq!(b.len() as i64, header_at - each * (count - i));
            b.extend_from_slice(&descriptor(header_at, end_at));
        }
        b.extend_from_slice(&0u32.to_le_bytes()); // compression
        put_u32(&mut b, 2001);
        for _ in 0..2000 {
            for s in ["a", "b"] {
                put_str(&mut b, s);
            }
            put_u32(&mut b, 0);
        }
        let class_at = b.len() + 4 + 5 + 4 + 6;
        for s in ["class", "string", "fog volume"] {
            put_str(&mut b, s);
        }
        put_str(&mut b, "TranslationMap");
        b.extend_from_slice(&[0; 24]);
        let e = read_vdb(&b, "fog", None, None).unwrap_err();
        assert!(
            matches!(&e.kind, GridFileErrorKind::Unsupported(m) if m.contains("\"fog volume\"")),
            "{e}"
        );
        assert_eq!(e.offset(), Some(class_at as u64), "{e}");
    }

    #[test]
    fn a_small_file_claiming_huge_counts_is_refused_before_allocating() {
        let tree = stack(&ball_rays::<3>(4, [8, 8, 8], 5).unwrap());
        let mut bytes = Vec::new();
        write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
        // The root child count sits right after the tile count, just before the first node origin.
        let topo = bytes
            .windows(9)
            .position(|w| w == [1, 0, 0, 0, 0, 0, 0, 0, 0])
            .unwrap();
        let mut huge = bytes[..topo + 13].to_vec();
        huge[topo + 9..topo + 13].copy_from_slice(&u32::MAX.to_le_bytes());
        huge.truncate(100.max(huge.len()));
        let e = read_vdb(&huge, "huge", None, None).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
        assert!(e.to_string().starts_with("huge: byte "), "{e}");
        let e = read_vdb(b"not a vdb file at all", "x", None, None).unwrap_err();
        assert_eq!(
            (e.offset(), e.to_string().contains("bad magic")),
            (Some(0), true)
        );
    }

    /// The position of the root child count in a file `write_vdb` wrote: after the buffer count (1), the
    /// background (false) and the tile count (0); the first child's origin follows it.
    fn root_counts_at(bytes: &[u8]) -> usize {
        bytes
            .windows(9)
            .position(|w| w == [1, 0, 0, 0, 0, 0, 0, 0, 0])
            .unwrap()
            + 9
    }

    #[test]
    fn root_entries_off_the_root_keys_or_met_twice_are_refused() {
        let tree = stack(&ball_rays::<3>(4, [8, 8, 8], 5).unwrap());
        let mut bytes = Vec::new();
        write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
        let origin_at = root_counts_at(&bytes) + 4;
        // The child's origin moved one voxel along y: OpenVDB keys its root table by multiples of 4096.
        let mut off = bytes.clone();
        off[origin_at + 4] = 1;
        let e = read_vdb(&off, "off", None, None).unwrap_err();
        assert!(
            matches!(&e.kind, GridFileErrorKind::Data(m) if m.contains("[0, 1, 0] is not a multiple of 4096")),
            "{e}"
        );
        assert_eq!(e.offset(), Some(origin_at as u64), "{e}");
        // An active tile at the child's origin, before it: the child meets a place already taken.
        let tiles_at = origin_at - 8;
        let mut twice = bytes[..tiles_at].to_vec();
        twice.extend_from_slice(&1u32.to_le_bytes());
        twice.extend_from_slice(&bytes[tiles_at + 4..origin_at]);
        twice.extend_from_slice(&[0; 12]);
        twice.extend_from_slice(&[1, 1]);
        twice.extend_from_slice(&bytes[origin_at..]);
        let e = read_vdb(&twice, "twice", None, None).unwrap_err();
        assert!(
            matches!(&e.kind, GridFileErrorKind::Data(m) if m.contains("a second root entry at [0, 0, 0]")),
            "{e}"
        );
        assert_eq!(e.offset(), Some(origin_at as u64 + 14), "{e}");
    }

    #[test]
    fn leaf_masks_become_boxes_of_exactly_their_voxels() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut random = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut masks = vec![[0u64; 8], [u64::MAX; 8], [0x5555_5555_5555_5555; 8]];
        masks.push(std::array::from_fn(
            |x| if x % 3 == 0 { u64::MAX } else { 0 },
        ));
        for _ in 0..200 {
            let sparse = random() % 4;
            masks.push(std::array::from_fn(|_| {
                let w = random();
                (0..sparse).fold(w, |w, _| w & random())
            }));
        }
        let r = Reader {
            bytes: &[],
            at: 0,
            file: "t",
        };
        for mask in &masks {
            let mut boxes = GridBoxes::default();
            add_leaf(&mut boxes, &r, [8, -16, 24], mask).unwrap();
            let mut seen = [false; 512];
            for b in &boxes.inside {
                for x in 0..b.size[0] as i64 {
                    for y in 0..b.size[1] as i64 {
                        for z in 0..b.size[2] as i64 {
                            let p = [
                                b.origin[0] + x - 8,
                                b.origin[1] + y + 16,
                                b.origin[2] + z - 24,
                            ];
                            assert!(p.iter().all(|c| (0..8).contains(c)), "{b:?}");
                            let n = (p[0] * 64 + p[1] * 8 + p[2]) as usize;
                            assert!(!seen[n], "voxel {n} twice");
                            seen[n] = true;
                        }
                    }
                }
            }
            for (n, &s) in seen.iter().enumerate() {
                assert_eq!(
                    s,
                    mask[n / 64] >> (n % 64) & 1 == 1,
                    "voxel {n} of {mask:x?}"
                );
            }
        }
        // Equal rows and slices are one box: a full leaf is one.
        let mut boxes = GridBoxes::default();
        add_leaf(&mut boxes, &r, [0; 3], &[u64::MAX; 8]).unwrap();
        assert_eq!(boxes.inside.len(), 1);
    }

    #[test]
    fn a_long_transform_name_is_shortened_in_its_message() {
        let tree = stack(&ball_rays::<3>(4, [8, 8, 8], 5).unwrap());
        let mut bytes = Vec::new();
        write_vdb(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
        let name = b"UniformScaleTranslateMap";
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap();
        let long = "M".repeat(10_000);
        let mut bad = bytes[..at - 4].to_vec();
        put_str(&mut bad, &long);
        bad.extend_from_slice(&bytes[at + name.len()..]);
        let e = read_vdb(&bad, "long", None, None).unwrap_err();
        assert!(
            matches!(&e.kind, GridFileErrorKind::Unsupported(m) if m.contains(&format!("{}…", &long[..64]))),
            "{e}"
        );
        assert!(e.to_string().len() < 200, "{e}");
        assert_eq!(e.offset(), Some(at as u64 - 4));
    }
}
