//! Trees with values as OpenVDB typed grids, and back: labels (`u8`, `u16`, `u32`, `i8`) as an `Int32Grid`
//! (`Tree_int32_5_4_3`), `f32` as a `FloatGrid` (`Tree_float_5_4_3`, class `unknown`), colours as a
//! `Vec3SGrid` (`Tree_vec3s_5_4_3`, each channel the float 0 … 255).
//!
//! Written as the `BoolGrid` is (see [`super::write`]): the voxels holding a value active with it, the empty
//! ones inactive with the background 0, and a full node of the tree that covers whole OpenVDB nodes written
//! as active tiles of its value — the grid OpenVDB's `prune()` makes.
//!
//! Read: the active voxels and tiles of the file's first grid with values — an `Int32Grid`, `Int64Grid`,
//! `FloatGrid` or `DoubleGrid` of any class but level set, `Vec3SGrid` or `Vec3DGrid` — hold their values,
//! every inactive voxel is empty. The value type is the grid's: integers read as the smallest of `u8`,
//! `u16`, `u32` holding them all when none is negative, else as `i8`; floats as `f32`; vectors as [`Rgb`](crate::value::Rgb),
//! each component rounded to an integer 0 … 255. A value beyond its type (or a NaN) is an error naming its
//! byte.

use std::io::Write;

use super::read::{find_grid, walk_active, ActiveVisitor, GridType};
use super::values::{Reader, Sample, ValueKind};
use super::write::{check_placement, write_grid, GridNodes};
use super::{FLOAT_TREE, INT32_TREE, VEC3S_TREE};
use crate::io::interop::grid::{
    max_grid_nodes, place_boxes, GridBoxes, GridFileError, GridFileErrorKind, GridMeta,
    GridPlacement, MAX_GRID_RUNS,
};
use crate::rays::{Ray, ValueRuns};
use crate::tree::valued::{ValueLeaves, ValueStorage};
use crate::value::{Dtype, Value};
use crate::{with_valued, AnyValuedTree, KTree};

/// The grid type a value type is written as, and its value's bytes as that grid stores it (`None`: a `u32`
/// label beyond `i32`).
fn vdb_value(dtype: Dtype, le: &[u8]) -> (&'static str, Option<Vec<u8>>) {
    let int = |v: i64| i32::try_from(v).ok().map(|v| v.to_le_bytes().to_vec());
    match dtype {
        Dtype::U8 => (INT32_TREE, int(i64::from(le[0]))),
        Dtype::I8 => (INT32_TREE, int(i64::from(le[0] as i8))),
        Dtype::U16 => (
            INT32_TREE,
            int(i64::from(u16::from_le_bytes([le[0], le[1]]))),
        ),
        Dtype::U32 => (
            INT32_TREE,
            int(i64::from(u32::from_le_bytes([le[0], le[1], le[2], le[3]]))),
        ),
        Dtype::F32 => (FLOAT_TREE, Some(le.to_vec())),
        Dtype::Rgb => (
            VEC3S_TREE,
            Some(
                le.iter()
                    .flat_map(|&c| f32::from(c).to_le_bytes())
                    .collect(),
            ),
        ),
    }
}

/// Writes a tree with values as an OpenVDB file with one typed grid named `ktree`: `u8`, `u16`, `u32` and
/// `i8` as an `Int32Grid`, `f32` as a `FloatGrid` (class `unknown`), [`Rgb`](crate::value::Rgb) as a `Vec3SGrid` (channels as
/// floats 0 … 255). OpenVDB index = ktree voxel − `offset`; the voxels holding a value are active with it,
/// the empty ones inactive (background 0), full nodes covering whole OpenVDB nodes are active tiles; `meta`
/// gives the transform. Uncompressed, as [`write_vdb`](super::write_vdb).
///
/// ```
/// use ktree::io::{read_vdb_values, write_vdb_values, GridMeta};
/// use ktree::{AnyValuedTree, KTree};
/// let tree = KTree::<3, u16>::from_dense_values(1, &[Some(7), None, Some(7), Some(900), None, None, None, None]).unwrap();
/// let mut bytes = Vec::new();
/// write_vdb_values(&mut bytes, &tree, [0; 3], &GridMeta::default()).unwrap();
/// let read = read_vdb_values(&bytes, "labels.vdb", None, None).unwrap();
/// assert_eq!(read.tree, AnyValuedTree::from(tree));
/// ```
///
/// # Errors
/// Any I/O error or the tree's read error; [`std::io::ErrorKind::InvalidInput`] as
/// [`write_vdb`](super::write_vdb), and for a `u32` label beyond `i32`.
pub fn write_vdb_values<T: ValueStorage<3>>(
    w: impl Write,
    tree: &T,
    offset: [i64; 3],
    meta: &GridMeta,
) -> std::io::Result<()> {
    let Some(dtype) = T::Value::DTYPE else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "a tree without values is written as a BoolGrid (write_vdb)",
        ));
    };
    check_placement(tree.level(), offset, meta)?;
    let (tree_type, zero) = vdb_value(dtype, &vec![0; dtype.bytes()]);
    let mut nodes = GridNodes::new(zero.map_or(4, |z| z.len()));
    let mut le = Vec::new();
    for leaf in ValueLeaves::new(tree) {
        let (cell, value) = leaf.map_err(std::io::Error::other)?;
        let Some(value) = value else { continue };
        le.clear();
        value.write_le(&mut le);
        let bytes = vdb_value(dtype, &le).1.ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "label {} does not fit an Int32Grid (at most {})",
                    value.text(),
                    i32::MAX
                ),
            )
        })?;
        let lo = std::array::from_fn(|a| i64::from(cell.origin[a]) - offset[a]);
        nodes.add_cube(lo, cell.side() as i64, &bytes);
    }
    write_grid(w, &nodes, tree_type, tree.level(), offset, meta)
}

/// [`write_vdb_values`] of a tree whose dimension and value type are known at run time.
///
/// # Errors
/// As [`write_vdb_values`]; [`std::io::ErrorKind::InvalidInput`] for a tree of another dimension than 3.
pub fn write_any_valued_vdb(
    w: impl Write,
    tree: &AnyValuedTree,
    offset: [i64; 3],
    meta: &GridMeta,
) -> std::io::Result<()> {
    match tree {
        AnyValuedTree::K3U8(t) => write_vdb_values(w, t, offset, meta),
        AnyValuedTree::K3U16(t) => write_vdb_values(w, t, offset, meta),
        AnyValuedTree::K3U32(t) => write_vdb_values(w, t, offset, meta),
        AnyValuedTree::K3I8(t) => write_vdb_values(w, t, offset, meta),
        AnyValuedTree::K3F32(t) => write_vdb_values(w, t, offset, meta),
        AnyValuedTree::K3Rgb(t) => write_vdb_values(w, t, offset, meta),
        other => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "OpenVDB grids hold octrees (K = 3); the tree has K = {}",
                other.k()
            ),
        )),
    }
}

/// A tree with values read from a `.vdb` file ([`read_vdb_values`]), with where it was placed and the
/// grid's world metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedValues {
    /// The voxels and their values (`K` = 3).
    pub tree: AnyValuedTree,
    /// ktree voxel = grid index + `placement.offset`, in a universe of level `placement.level`.
    pub placement: GridPlacement,
    /// The grid's world metadata.
    pub meta: GridMeta,
}

/// The active voxels and tiles of a grid with values: boxes of grid indices (a tile, a run of equal
/// values along z in a leaf's row), each with its value and the byte it is stored at.
#[derive(Default)]
struct ValueBoxes {
    boxes: GridBoxes,
    values: Vec<(Sample, usize)>,
    /// The columns of voxels the boxes make (the runs of the tree to build), at most `max_runs`.
    runs: u64,
    max_runs: u64,
}

impl ValueBoxes {
    fn push(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        size: [u64; 3],
        value: Sample,
        at: usize,
    ) -> Result<(), GridFileError> {
        self.runs = self.runs.saturating_add(size[0] * size[1]);
        if self.runs > self.max_runs {
            return Err(r.fail_at(
                at,
                GridFileErrorKind::Unsupported(format!(
                    "more than {} runs of voxels along z (the bound on the tree's nodes)",
                    self.max_runs,
                )),
            ));
        }
        super::read::push_box(&mut self.boxes, r, origin, size)?;
        self.values.push((value, at));
        Ok(())
    }
}

impl ActiveVisitor for ValueBoxes {
    const VALUES: bool = true;

    fn tile(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        side: u64,
        value: Sample,
        at: usize,
    ) -> Result<(), GridFileError> {
        self.push(r, origin, [side; 3], value, at)
    }

    fn leaf(
        &mut self,
        r: &Reader,
        origin: [i64; 3],
        mask: &[u64],
        values: &[Sample],
        at: usize,
    ) -> Result<(), GridFileError> {
        // Each row along z (n = x·64 + y·8 + z): the runs of active voxels of one value.
        for row in 0..64usize {
            let mut z = 0usize;
            while z < 8 {
                let n = row * 8 + z;
                let on = |n: usize| mask[n / 64] >> (n % 64) & 1 == 1;
                if !on(n) {
                    z += 1;
                    continue;
                }
                let same =
                    |m: usize| on(m) && values[m].map(f64::to_bits) == values[n].map(f64::to_bits);
                let len = (z..8).take_while(|&e| same(row * 8 + e)).count();
                let p = [
                    origin[0] + (row / 8) as i64,
                    origin[1] + (row % 8) as i64,
                    origin[2] + z as i64,
                ];
                self.push(r, p, [1, 1, len as u64], values[n], at)?;
                z += len;
            }
        }
        Ok(())
    }
}

/// The value type of a grid's values ([`super::typed`]'s rules), or the error at the first value that
/// has none.
fn choose_dtype(
    r: &Reader,
    kind: ValueKind,
    values: &[(Sample, usize)],
) -> Result<Dtype, GridFileError> {
    let bad = |(v, at): (Sample, usize), why: &str| {
        let shown = match kind.components() {
            1 => format!("{}", v[0]),
            _ => format!("({}, {}, {})", v[0], v[1], v[2]),
        };
        r.fail_at(
            at,
            GridFileErrorKind::Data(format!("the value {shown} {why}")),
        )
    };
    if let Some(&nan) = values.iter().find(|(v, _)| v.iter().any(|c| c.is_nan())) {
        return Err(bad(nan, "is not a number, which no voxel may hold"));
    }
    match kind {
        ValueKind::F32 | ValueKind::F64 => {
            if let Some(&big) = values
                .iter()
                .find(|(v, _)| v[0].is_finite() && v[0].abs() > f64::from(f32::MAX))
            {
                return Err(bad(big, "is beyond float32"));
            }
            Ok(Dtype::F32)
        }
        ValueKind::Vec3S | ValueKind::Vec3D => {
            if let Some(&out) = values
                .iter()
                .find(|(v, _)| v.iter().any(|c| !(-0.5..255.5).contains(c)))
            {
                return Err(bad(out, "is not a colour (components 0 to 255)"));
            }
            Ok(Dtype::Rgb)
        }
        _ => {
            let lowest = values.iter().min_by(|a, b| a.0[0].total_cmp(&b.0[0]));
            let highest = values.iter().max_by(|a, b| a.0[0].total_cmp(&b.0[0]));
            let (lo, hi) = (
                lowest.map_or(0.0, |v| v.0[0]),
                highest.map_or(0.0, |v| v.0[0]),
            );
            if lo < 0.0 {
                if lo < -128.0 {
                    return Err(bad(
                        *lowest.expect("a lowest value"),
                        "is below int8's -128 (negative labels are read as int8)",
                    ));
                }
                if hi > 127.0 {
                    return Err(bad(
                        *highest.expect("a highest value"),
                        "is beyond int8's 127 (negative labels are read as int8)",
                    ));
                }
                return Ok(Dtype::I8);
            }
            Ok(match hi {
                h if h <= 255.0 => Dtype::U8,
                h if h <= 65535.0 => Dtype::U16,
                h if h <= f64::from(u32::MAX) => Dtype::U32,
                _ => return Err(bad(*highest.expect("a highest value"), "is beyond uint32")),
            })
        }
    }
}

/// The little-endian bytes of a value of `dtype` (checked by [`choose_dtype`] to hold it).
fn value_le(dtype: Dtype, v: Sample) -> Vec<u8> {
    match dtype {
        Dtype::U8 => vec![v[0] as u8],
        Dtype::I8 => vec![v[0] as i8 as u8],
        Dtype::U16 => (v[0] as u16).to_le_bytes().to_vec(),
        Dtype::U32 => (v[0] as u32).to_le_bytes().to_vec(),
        Dtype::F32 => (v[0] as f32).to_le_bytes().to_vec(),
        Dtype::Rgb => v.map(|c| c.round() as u8).to_vec(),
    }
}

/// The valued tree of placed boxes with their values.
fn build<V: Value>(
    boxes: &GridBoxes,
    values: &[(Sample, usize)],
    dtype: Dtype,
    placement: &GridPlacement,
) -> Result<AnyValuedTree, String> {
    let mut runs = Vec::new();
    for (b, (v, _)) in boxes.inside.iter().zip(values) {
        let value = V::read_le(&value_le(dtype, *v));
        let lo = std::array::from_fn::<u32, 3, _>(|a| (b.origin[a] + placement.offset[a]) as u32);
        for x in 0..b.size[0] as u32 {
            for y in 0..b.size[1] as u32 {
                runs.push((
                    Ray::new([lo[0] + x, lo[1] + y, lo[2]], lo[2] + b.size[2] as u32),
                    value,
                ));
            }
        }
    }
    let runs = ValueRuns::<3, V>::from_runs(placement.level, runs).map_err(|e| e.to_string())?;
    Ok(AnyValuedTree::from(KTree::from_value_runs(&runs)))
}

/// Reads the first grid with values of an OpenVDB file — an `Int32Grid`, `Int64Grid`, `FloatGrid` or
/// `DoubleGrid` not of class level set, a `Vec3SGrid` or `Vec3DGrid` — into a tree with values (`K` = 3):
/// its active voxels and tiles hold their values, inactive voxels are empty. Integers read as the smallest of
/// `u8`, `u16`, `u32` holding them all when none is negative, else as `i8`; floats as `f32`; vectors as
/// [`Rgb`](crate::value::Rgb) (components rounded). Placed by `offset` and `level` as [`read_vdb`](super::read_vdb) places a
/// grid (ktree's metadata used when none is given); values stored raw or compressed as OpenVDB writes them.
///
/// ```
/// use ktree::io::{read_vdb_values, vdb_holds_values, write_vdb_values, GridMeta};
/// use ktree::{value::Dtype, KTree};
/// let tree = KTree::<3, u32>::from_dense_values(1, &[Some(5), None, None, None, None, None, None, Some(9)]).unwrap();
/// let mut bytes = Vec::new();
/// write_vdb_values(&mut bytes, &tree, [-1, 0, 0], &GridMeta::default()).unwrap();
/// assert!(vdb_holds_values(&bytes, "labels.vdb").unwrap());
/// let read = read_vdb_values(&bytes, "labels.vdb", None, None).unwrap();
/// assert_eq!(read.tree.dtype(), Dtype::U8); // the smallest type holding 5 and 9
/// assert_eq!(read.placement.offset, [-1, 0, 0]);
/// ```
///
/// # Errors
/// [`GridFileError`] naming the byte offset: as [`read_vdb`](super::read_vdb); no grid with values (a
/// `BoolGrid`, `MaskGrid` or level set is named); a value its type cannot hold (an integer below −128 among
/// negative ones or beyond `u32`, a NaN, a float beyond `f32`, a vector component outside 0 … 255); more runs
/// of voxels along z than the node bound of a file of its size ([`max_grid_nodes`]).
pub fn read_vdb_values(
    bytes: &[u8],
    file: &str,
    offset: Option<[i64; 3]>,
    level: Option<u32>,
) -> Result<PlacedValues, GridFileError> {
    read_vdb_values_within(bytes, file, offset, level, max_grid_nodes(bytes.len()))
}

/// [`read_vdb_values`] with the octree, and the runs of voxels read, bounded to `max_nodes` (instead of
/// [`max_grid_nodes`] of the file's length), as [`read_vdb_within`](super::read_vdb_within) bounds a grid
/// without values.
///
/// # Errors
/// As [`read_vdb_values`].
pub fn read_vdb_values_within(
    bytes: &[u8],
    file: &str,
    offset: Option<[i64; 3]>,
    level: Option<u32>,
    max_nodes: u64,
) -> Result<PlacedValues, GridFileError> {
    let (mut r, grid, head) = find_grid(
        bytes,
        file,
        |g: GridType, class| g.kind != ValueKind::Bool && !g.is_level_set(class),
        "holds no values (read its voxels with read_vdb); Int32Grid, Int64Grid, FloatGrid, DoubleGrid, \
         Vec3SGrid and Vec3DGrid are read with their values",
    )?;
    let coding = grid.coding(head.compression);
    let mut read = ValueBoxes {
        max_runs: max_nodes.min(MAX_GRID_RUNS),
        ..ValueBoxes::default()
    };
    walk_active(&mut r, grid, &coding, &mut read)?;
    let dtype = choose_dtype(&r, grid.kind, &read.values)?;
    let placement = GridPlacement::choose(
        read.boxes.known,
        read.boxes.alignment(),
        offset.or(head.offset),
        level.or(head.level),
    )
    .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::GridPlacement(m)))?;
    // The shape first: it checks that the voxels fit the universe and bounds the tree's nodes.
    place_boxes(&read.boxes, &placement, max_nodes)
        .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::GridPlacement(m)))?;
    let tree =
        with_valued!(3, dtype, K, V => build::<V>(&read.boxes, &read.values, dtype, &placement),
        else unreachable!("K = 3"))
        .map_err(|m| GridFileError::new(file, 0, GridFileErrorKind::Data(m)))?;
    Ok(PlacedValues {
        tree,
        placement,
        meta: head.meta,
    })
}

/// Whether an OpenVDB file's first grid read is one with values ([`read_vdb_values`] reads it; otherwise
/// [`read_vdb`](super::read_vdb) reads its voxels).
///
/// # Errors
/// As [`read_vdb`](super::read_vdb) for the file's header and grid descriptors.
pub fn vdb_holds_values(bytes: &[u8], file: &str) -> Result<bool, GridFileError> {
    let (_, grid, head) = find_grid(bytes, file, |_, _| true, "")?;
    let class = head.class.as_ref().map(|(c, _)| c.as_str());
    Ok(grid.kind != ValueKind::Bool && !grid.is_level_set(class))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::Ray;
    use crate::value::Rgb;
    use proptest::prelude::*;

    /// The voxels' values of a tree as text (empty: `None`), whatever its type: a `u16` tree and the `u8`
    /// tree read back from its small labels compare equal.
    fn dense_text(tree: &AnyValuedTree) -> Vec<Option<String>> {
        with_valued!(tree, t => t.to_dense_values().unwrap().iter().map(|v| v.map(Value::text)).collect())
    }

    /// A level-`level` tree of blocks (aligned cubes of side `2^s`) and voxels, each of a value of
    /// `palette`, later ones over earlier ones.
    fn blocks<V: Value>(level: u32, palette: &[V], picks: &[Pick]) -> KTree<3, V> {
        let side = 1usize << level;
        let mut dense = vec![None; side * side * side];
        for &(s, p, v) in picks {
            let s = s.min(level);
            let lo = p.map(|c| (c % side as u32) >> s << s);
            for x in 0..1u32 << s {
                for y in 0..1u32 << s {
                    for z in 0..1u32 << s {
                        let [i, j, k] = [lo[0] + x, lo[1] + y, lo[2] + z].map(|c| c as usize);
                        dense[i + side * (j + side * k)] = Some(palette[v % palette.len()]);
                    }
                }
            }
        }
        KTree::from_dense_values(level, &dense).unwrap()
    }

    /// Writes `tree` at `offset`, reads it back, and checks it voxel for voxel (and exactly when the
    /// value type read is the tree's).
    fn round_trip<V: Value>(tree: &KTree<3, V>, offset: [i64; 3]) -> Vec<u8> {
        let mut bytes = Vec::new();
        write_vdb_values(&mut bytes, tree, offset, &GridMeta::default()).unwrap();
        let read = read_vdb_values(&bytes, "t.vdb", None, None).unwrap();
        assert_eq!(
            read.placement,
            GridPlacement {
                offset,
                level: tree.level()
            }
        );
        let want = AnyValuedTree::from(tree.clone());
        if tree.level() <= 5 {
            assert_eq!(dense_text(&read.tree), dense_text(&want));
        }
        if read.tree.dtype() == want.dtype() || tree.level() > 5 {
            assert_eq!(read.tree, want);
        }
        assert!(vdb_holds_values(&bytes, "t.vdb").unwrap());
        bytes
    }

    /// A block or voxel of [`blocks`]: the log of its side, a corner, which value of the palette.
    type Pick = (u32, [u32; 3], usize);

    /// A level, blocks, and the offset to write at.
    fn picks() -> impl Strategy<Value = (u32, Vec<Pick>, [i64; 3])> {
        (
            0u32..=5,
            prop::collection::vec((0u32..=5, any::<[u32; 3]>(), 0usize..8), 0..12),
            prop::array::uniform3(-20i64..20),
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn every_value_type_comes_back_voxel_for_voxel((level, p, offset) in picks()) {
            round_trip(&blocks::<u8>(level, &[0, 1, 7, 255], &p), offset);
            round_trip(&blocks::<u16>(level, &[0, 300, 65535, 2], &p), offset);
            round_trip(&blocks::<u32>(level, &[0, 70_000, i32::MAX as u32, 9], &p), offset);
            round_trip(&blocks::<i8>(level, &[-128, -1, 0, 127], &p), offset);
            round_trip(&blocks::<f32>(level, &[0.0, -0.0, 1.5, -2.25e30, f32::INFINITY, 1e-40], &p), offset);
            round_trip(&blocks::<Rgb>(level, &[[0; 3], [255, 128, 1], [10, 20, 30]], &p), offset);
        }
    }

    #[test]
    fn whole_nodes_of_one_value_are_tiles() {
        // A 128³ block of 7 and an 8³ block of 9 in a level-8 universe: one upper node with a tile, one
        // lower node with a tile, no leaf.
        let mut runs = Vec::new();
        for x in 0..128 {
            for y in 0..128 {
                runs.push((Ray::new([x, y, 128], 256), 7u8));
            }
        }
        for x in 0..8 {
            for y in 0..8 {
                runs.push((Ray::new([x, y, 0], 8), 9u8));
            }
        }
        let tree = KTree::from_value_runs(&ValueRuns::from_runs(8, runs).unwrap());
        let bytes = round_trip(&tree, [0; 3]);
        // Without tiles the 128³ block alone would be 4096 leaves of 2 KB.
        assert!(bytes.len() < 200_000, "{} bytes", bytes.len());
        // Shifted by 1 the blocks cover no whole node: leaves.
        let shifted = round_trip(&tree, [1, 0, 0]);
        assert!(shifted.len() > 4096 * 2048, "{} bytes", shifted.len());
    }

    #[test]
    fn cut_and_damaged_files_give_errors_never_panics() {
        let p = vec![(0, [1, 2, 3], 1), (3, [0, 0, 0], 2), (0, [9, 9, 9], 3)];
        let files = [
            round_trip(&blocks::<u16>(4, &[1, 300, 5, 6], &p), [0; 3]),
            round_trip(&blocks::<f32>(4, &[0.5, -1.0, 3.0, 2.0], &p), [2, 0, -3]),
            round_trip(&blocks::<Rgb>(4, &[[1, 2, 3], [4, 5, 6]], &p), [0; 3]),
        ];
        // Every offset of the descriptors, headers and first node, then every 53rd (a file holds at least
        // one 32³ node of 2^15 values, which each read decodes again).
        for bytes in files {
            for at in (0..bytes.len()).filter(|&at| at < 1500 || at % 53 == 0) {
                assert!(
                    read_vdb_values(&bytes[..at], "cut.vdb", None, None).is_err(),
                    "cut at {at}"
                );
                let mut bad = bytes.clone();
                bad[at] ^= 0x5a;
                if let Ok(read) = read_vdb_values(&bad, "bad.vdb", None, None) {
                    with_valued!(&read.tree, t => t.shape().assert_well_formed());
                }
            }
        }
    }

    /// The bytes of `bytes` with the first `from` (after byte 100) replaced by `to`.
    fn patched(bytes: &[u8], from: &[u8], to: &[u8]) -> (Vec<u8>, usize) {
        let at = 100
            + bytes[100..]
                .windows(from.len())
                .position(|w| w == from)
                .unwrap();
        let mut b = bytes.to_vec();
        b[at..at + to.len()].copy_from_slice(to);
        (b, at)
    }

    #[test]
    fn values_no_type_holds_are_errors_at_their_bytes() {
        let p = vec![(0, [1, 2, 3], 0), (0, [5, 5, 5], 1)];
        let mut bytes = Vec::new();
        write_vdb_values(
            &mut bytes,
            &blocks::<u16>(4, &[300, 12345], &p),
            [0; 3],
            &GridMeta::default(),
        )
        .unwrap();
        // −2 among labels up to 300: int8 cannot hold them.
        let (bad, at) = patched(&bytes, &12345i32.to_le_bytes(), &(-2i32).to_le_bytes());
        let e = read_vdb_values(&bad, "neg.vdb", None, None).unwrap_err();
        assert!(
            e.to_string().contains("300") && e.to_string().contains("neg.vdb"),
            "{e}"
        );
        assert!(e.offset().is_some_and(|o| o <= at as u64 && o > 100), "{e}");
        // A NaN in a float grid.
        let mut bytes = Vec::new();
        write_vdb_values(
            &mut bytes,
            &blocks::<f32>(4, &[0.5, 2.5], &p),
            [0; 3],
            &GridMeta::default(),
        )
        .unwrap();
        let (bad, _) = patched(&bytes, &2.5f32.to_le_bytes(), &f32::NAN.to_le_bytes());
        let e = read_vdb_values(&bad, "nan.vdb", None, None).unwrap_err();
        assert!(e.to_string().contains("NaN"), "{e}");
        // A u32 label beyond i32 is not written.
        let e = write_vdb_values(
            Vec::new(),
            &blocks::<u32>(1, &[u32::MAX], &[(0, [0; 3], 0)]),
            [0; 3],
            &GridMeta::default(),
        )
        .unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
    }

    #[test]
    fn a_bool_grid_is_not_read_with_values_and_a_typed_grid_reads_as_its_shape() {
        let tree = blocks::<u8>(4, &[3, 4], &[(2, [4, 4, 4], 0), (0, [0; 3], 1)]);
        let mut bool_grid = Vec::new();
        super::super::write_vdb(&mut bool_grid, &tree.shape(), [0; 3], &GridMeta::default())
            .unwrap();
        assert!(!vdb_holds_values(&bool_grid, "b.vdb").unwrap());
        let e = read_vdb_values(&bool_grid, "b.vdb", None, None).unwrap_err();
        assert!(e.to_string().contains("BoolGrid"), "{e}");
        let mut typed = Vec::new();
        write_vdb_values(&mut typed, &tree, [0; 3], &GridMeta::default()).unwrap();
        assert_eq!(
            super::super::read_vdb(&typed, "t.vdb", None, None)
                .unwrap()
                .tree,
            tree.shape()
        );
    }
}
