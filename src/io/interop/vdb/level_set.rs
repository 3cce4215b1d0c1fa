//! OpenVDB narrow-band level sets (`FloatGrid`, `Tree_float_5_4_3`, grid class `level set`) out of an
//! octree's signed distances ([`KTree::narrow_band`]), and the interior of a level set read back (see
//! [`super`] for what is read and how it compares with OpenVDB's `tools::sdfInteriorMask`).
//!
//! What is written, in OpenVDB's terms (see `openvdb/tools/LevelSetUtil.h` for how OpenVDB reads a level
//! set): the active voxels are the band, the voxels with `|sd| ≤ W` (`W` the half-width in voxels), their
//! values the signed distances in world units (`sd · S`, `S` the voxel size, negative inside); every
//! inactive value — a leaf's other voxels, the tiles of the internal nodes and of the root — is `−W · S`
//! inside the object and `+W · S` outside; the background is `W · S` (OpenVDB's `halfWidth · voxelSize`).
//! The transform is a uniform scale by `S` (`UniformScaleMap`: index `(i, j, k)` at world `S · (i, j, k)`),
//! and OpenVDB index = ktree voxel; the universe's level and offset 0 are grid metadata (`ktree_level`,
//! `ktree_offset`). The universe is the array: outside it is outside the object, and a full voxel on the
//! universe's border measures to the nearest empty voxel inside the universe (the surface is open there);
//! a tree filling its universe has no band, and its inside is carried by the inactive values of a leaf at
//! the origin (or by root tiles from 4096³ on). Values are stored uncompressed (compression flags 0), which
//! every OpenVDB reads.

use std::collections::{BTreeMap, HashSet};
use std::io::Write;

use super::read::{add_leaf, check_root_counts, push_box, root_origin};
use super::values::{ones, Reader, ValueCoding, ValueKind};
use super::write::{put_grid_head, put_str, put_u32};
use super::{
    corner_of, origin_of, slot, FILE_VERSION, FLOAT_TREE, LEAF_WORDS, LOWER_WORDS, MAGIC,
    UPPER_WORDS,
};
use crate::io::interop::grid::{GridBoxes, GridFileError};
use crate::tree::{KTree, NodeState};

/// Most root tiles (4096³ blocks wholly inside) written.
const MAX_ROOT_TILES: u64 = 1 << 20;

/// An 8³ leaf: active voxels and all 512 values.
struct Leaf {
    mask: [u64; LEAF_WORDS],
    values: Vec<f32>,
}

type Lower = BTreeMap<u32, Leaf>;
type Upper = BTreeMap<u32, Lower>;

fn put_f32s(out: &mut Vec<u8>, values: impl IntoIterator<Item = f32>) {
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

fn put_words(out: &mut Vec<u8>, words: &[u64]) {
    for w in words {
        out.extend_from_slice(&w.to_le_bytes());
    }
}

fn put_origin(out: &mut Vec<u8>, origin: [i64; 3]) {
    for c in origin {
        out.extend_from_slice(&(c as i32).to_le_bytes());
    }
}

/// Writes the narrow band of half-width `width` voxels of an octree as an OpenVDB level set (a
/// `FloatGrid` named `ktree`) with voxel size `voxel_size`.
///
/// What is written, in OpenVDB's terms: the active voxels are the band, the voxels with `|sd| ≤ W` (`W` =
/// `width`), their values the signed distances in world units (`sd · S`, `S` = `voxel_size`, negative
/// inside); every inactive value (a leaf's other voxels, the tiles of the internal nodes and of the root) is
/// `−W · S` inside the object and `+W · S` outside; the background is `W · S`. The transform is a uniform
/// scale by `S`, and OpenVDB index = ktree voxel; the universe's level is grid metadata. Values are stored
/// uncompressed. [`read_vdb`](crate::io::read_vdb) reads the interior back: the same tree.
///
/// ```
/// use ktree::io::{read_vdb, write_vdb_level_set};
/// use ktree::{rays::ball_rays, KTree};
/// let tree = KTree::from_rays(&ball_rays::<3>(5, [16, 16, 16], 12).unwrap());
/// let mut bytes = Vec::new();
/// write_vdb_level_set(&mut bytes, &tree, 3.0, 0.5).unwrap();
/// assert!(bytes.len() > 8 * 512);
/// assert_eq!(read_vdb(&bytes, "sdf.vdb", None, None).unwrap().tree, tree);
/// ```
///
/// # Errors
/// [`std::io::ErrorKind::InvalidInput`] for a width below 1 (a band that may miss the surface) or not
/// finite, a voxel size that is not a positive number, an index outside OpenVDB's 32-bit range (levels
/// over 31 cannot occur for an octree), or more than 2^20 root tiles; any I/O error.
pub fn write_vdb_level_set(
    mut w: impl Write,
    tree: &KTree<3>,
    width: f64,
    voxel_size: f64,
) -> std::io::Result<()> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    if !(width.is_finite() && width >= 1.0) {
        return Err(invalid(format!(
            "band half-width {width} is not a number >= 1"
        )));
    }
    if !(voxel_size.is_finite() && voxel_size > 0.0) {
        return Err(invalid(format!(
            "voxel size {voxel_size} is not a positive number"
        )));
    }
    let band = tree
        .narrow_band(width)
        .map_err(|e| invalid(e.to_string()))?;
    let background = (width * voxel_size) as f32;
    let side = tree.universe().side() as i64;
    // The nodes holding the band, leaves' values NaN until filled.
    let mut root: BTreeMap<[i64; 3], Upper> = BTreeMap::new();
    for (v, d) in band.iter() {
        let p = v.map(i64::from);
        let leaf = root
            .entry(origin_of(p, 12))
            .or_default()
            .entry(slot(p, 5, 7))
            .or_default()
            .entry(slot(p, 4, 3))
            .or_insert_with(|| Leaf {
                mask: [0; LEAF_WORDS],
                values: vec![f32::NAN; 512],
            });
        let n = slot(p, 3, 0) as usize;
        leaf.mask[n / 64] |= 1 << (n % 64);
        leaf.values[n] = (d * voxel_size) as f32;
    }
    // A tree filling its universe has no empty voxel to measure to, so no band: below 4096³ (root tiles),
    // a leaf at the origin carries the inside (its values, and those of the nodes above it, signed below).
    if band.is_empty() && side < 4096 && tree.voxel_count() > 0 {
        root.entry([0; 3])
            .or_default()
            .entry(0)
            .or_default()
            .entry(0)
            .or_insert_with(|| Leaf {
                mask: [0; LEAF_WORDS],
                values: vec![f32::NAN; 512],
            });
    }
    // Inactive values: ±background by inside/outside, asked of the tree in one batch.
    let in_universe = |p: [i64; 3]| p.iter().all(|&c| (0..side).contains(&c));
    let mut asked: Vec<[u32; 3]> = Vec::new();
    let visit_unset = |f: &mut dyn FnMut([i64; 3])| {
        for (&o, upper) in &root {
            for (&us, lower) in upper {
                let lo = corner_of(o, us as usize, 5, 7);
                for n in 0..4096usize {
                    if !lower.contains_key(&(n as u32)) {
                        f(corner_of(lo, n, 4, 3));
                    }
                }
                for (&ls, leaf) in lower {
                    let leaf_lo = corner_of(lo, ls as usize, 4, 3);
                    for n in 0..512usize {
                        if leaf.values[n].is_nan() {
                            f(corner_of(leaf_lo, n, 3, 0));
                        }
                    }
                }
            }
            for n in 0..UPPER_WORDS * 64 {
                if !upper.contains_key(&(n as u32)) {
                    f(corner_of(o, n, 5, 7));
                }
            }
        }
    };
    visit_unset(&mut |p| {
        if in_universe(p) {
            asked.push(p.map(|c| c as u32));
        }
    });
    let answers = tree.contains_many(&asked);
    let mut answers = answers.into_iter();
    let mut signs = Vec::new();
    visit_unset(&mut |p| {
        let inside = in_universe(p) && answers.next().expect("one answer a point");
        signs.push(if inside { -background } else { background });
    });
    // Root tiles: the 4096³ blocks wholly inside, which hold no band voxel.
    let mut tiles = Vec::new();
    let mut too_many = false;
    tree.for_each_leaf(|cell, state| {
        if state != NodeState::Full || cell.side() < 4096 || too_many {
            return;
        }
        let n = cell.side() / 4096;
        if tiles.len() as u64 + n * n * n > MAX_ROOT_TILES {
            too_many = true;
            return;
        }
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let o = cell.origin.map(i64::from);
                    tiles.push([
                        o[0] + 4096 * i as i64,
                        o[1] + 4096 * j as i64,
                        o[2] + 4096 * k as i64,
                    ]);
                }
            }
        }
    });
    if too_many {
        return Err(invalid(format!(
            "more than {MAX_ROOT_TILES} root tiles of 4096³ voxels wholly inside"
        )));
    }

    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC.to_le_bytes());
    put_u32(&mut out, FILE_VERSION);
    put_u32(&mut out, 10);
    put_u32(&mut out, 0);
    out.push(1); // the grid descriptors carry offsets
    let crc = crc32fast::hash(
        &band
            .values
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<u8>>(),
    );
    let uuid = format!(
        "{crc:08x}-0000-4000-8000-{:012x}",
        band.len() as u64 & 0xFFFF_FFFF_FFFF
    );
    out.extend_from_slice(uuid.as_bytes());
    let (positions_at, grid_at) =
        put_grid_head(&mut out, FLOAT_TREE, "level set", tree.level(), [0; 3]);
    put_str(&mut out, "UniformScaleMap");
    let s = voxel_size;
    for v in [
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
    // Topology: the root, then each internal node's masks and values, each leaf's value mask.
    put_u32(&mut out, 1); // buffer count
    put_f32s(&mut out, [background]);
    put_u32(&mut out, tiles.len() as u32);
    put_u32(&mut out, root.len() as u32);
    for t in &tiles {
        put_origin(&mut out, *t);
        put_f32s(&mut out, [-background]);
        out.push(0); // inactive
    }
    let mut sign = signs.into_iter();
    let mut filled = Vec::new();
    // Leaf values are taken from `sign` in the order `visit_unset` saw them: lower tiles, then leaves,
    // per lower node; then the upper node's tiles. Collect them per node first.
    for (&o, upper) in &root {
        let mut lower_parts = Vec::new();
        for lower in upper.values() {
            let tiles: Vec<f32> = (0..4096usize)
                .map(|n| {
                    if lower.contains_key(&(n as u32)) {
                        0.0
                    } else {
                        sign.next().expect("a sign a tile")
                    }
                })
                .collect();
            let leaves: Vec<Vec<f32>> = lower
                .values()
                .map(|leaf| {
                    leaf.values
                        .iter()
                        .map(|&v| {
                            if v.is_nan() {
                                sign.next().expect("a sign a voxel")
                            } else {
                                v
                            }
                        })
                        .collect()
                })
                .collect();
            lower_parts.push((tiles, leaves));
        }
        let upper_tiles: Vec<f32> = (0..UPPER_WORDS * 64)
            .map(|n| {
                if upper.contains_key(&(n as u32)) {
                    0.0
                } else {
                    sign.next().expect("a sign a tile")
                }
            })
            .collect();
        put_origin(&mut out, o);
        let mut children = [0u64; UPPER_WORDS];
        for &n in upper.keys() {
            children[n as usize / 64] |= 1 << (n % 64);
        }
        put_words(&mut out, &children);
        put_words(&mut out, &[0; UPPER_WORDS]); // no active tile
        out.push(6); // all values follow, uncompressed
        put_f32s(&mut out, upper_tiles);
        for (lower, (tiles, _)) in upper.values().zip(&lower_parts) {
            let mut children = [0u64; LOWER_WORDS];
            for &n in lower.keys() {
                children[n as usize / 64] |= 1 << (n % 64);
            }
            put_words(&mut out, &children);
            put_words(&mut out, &[0; LOWER_WORDS]);
            out.push(6);
            put_f32s(&mut out, tiles.iter().copied());
            for leaf in lower.values() {
                put_words(&mut out, &leaf.mask);
            }
        }
        // Keep the leaves' filled values for the buffers, in the same order.
        filled.push(lower_parts);
    }
    // Buffers: each leaf's value mask and its 512 values, in topology order.
    let block_at = out.len();
    for (upper, parts) in root.values().zip(filled) {
        for (lower, (_, leaves)) in upper.values().zip(parts) {
            for (leaf, values) in lower.values().zip(leaves) {
                put_words(&mut out, &leaf.mask);
                out.push(6);
                put_f32s(&mut out, values);
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

/// The bits of `a` that are not in `b`.
fn and_not(a: &[u64], b: &[u64]) -> Vec<u64> {
    a.iter().zip(b).map(|(x, y)| x & !y).collect()
}

/// The interior of a level set's tree (from its background on) as boxes of grid indices: every voxel of a
/// leaf, tile of an internal node and tile of the root whose value is below `min(0, background − ε)` (ε =
/// 10⁻⁸ for floats, 10⁻¹⁵ for doubles: `tools::sdfInteriorMask`'s threshold, 0 for a valid level set),
/// active or not.
pub(super) fn read_interior(
    r: &mut Reader,
    coding: &ValueCoding,
) -> Result<GridBoxes, GridFileError> {
    let kind = coding.kind;
    let background = r.scalar(kind, "background")?;
    let iso = match kind {
        ValueKind::F64 => (background - 1e-15).min(0.0),
        _ => f64::from((background as f32 - 1e-8).min(0.0)),
    };
    let tiles = r.u32("root tile count")? as usize;
    let children = r.u32("root child count")? as usize;
    check_root_counts(r, tiles, 12 + kind.size() + 1, children)?;
    let mut boxes = GridBoxes::default();
    let mut seen = HashSet::new();
    for _ in 0..tiles {
        let o = root_origin(r, &mut seen, "root tile origin")?;
        let value = r.scalar(kind, "tile value")?;
        r.take(1, "tile state")?;
        if value < iso {
            push_box(&mut boxes, r, o, [4096; 3])?;
        }
    }
    // The leaves' origins and value masks, in the order of their buffers.
    let mut leaves: Vec<([i64; 3], Vec<u64>)> = Vec::new();
    for _ in 0..children {
        let o = root_origin(r, &mut seen, "root child origin")?;
        let child_mask = r.mask(UPPER_WORDS)?;
        let value_mask = r.mask(UPPER_WORDS)?;
        let inside = r
            .values(
                coding,
                UPPER_WORDS * 64,
                &value_mask,
                [background, 0.0, 0.0],
            )?
            .below(&value_mask, iso);
        for n in ones(&and_not(&inside, &child_mask)) {
            push_box(&mut boxes, r, corner_of(o, n, 5, 7), [128; 3])?;
        }
        for n in ones(&child_mask) {
            let lo = corner_of(o, n, 5, 7);
            let lower_children = r.mask(LOWER_WORDS)?;
            let lower_values = r.mask(LOWER_WORDS)?;
            let inside = r
                .values(
                    coding,
                    LOWER_WORDS * 64,
                    &lower_values,
                    [background, 0.0, 0.0],
                )?
                .below(&lower_values, iso);
            for m in ones(&and_not(&inside, &lower_children)) {
                push_box(&mut boxes, r, corner_of(lo, m, 4, 3), [8; 3])?;
            }
            for m in ones(&lower_children) {
                leaves.push((corner_of(lo, m, 4, 3), r.mask(LEAF_WORDS)?));
            }
        }
    }
    for (lo, mask) in &leaves {
        // The buffer's copy of the value mask: OpenVDB reading a file seeks past it and keeps the
        // topology's.
        r.take(8 * LEAF_WORDS, "leaf value mask")?;
        let inside = r
            .values(coding, LEAF_WORDS * 64, mask, [background, 0.0, 0.0])?
            .below(mask, iso);
        add_leaf(&mut boxes, r, *lo, &inside)?;
    }
    Ok(boxes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read_vdb;
    use crate::rays::ball_rays;

    #[test]
    fn level_sets_read_back_as_their_trees_full_and_empty_ones_too() {
        let mut trees: Vec<KTree<3>> = (0..=4).map(|l| KTree::full(l).unwrap()).collect();
        trees.push(KTree::empty(3).unwrap());
        trees.push(KTree::from_rays(
            &ball_rays::<3>(6, [30, 20, 40], 36).unwrap(),
        ));
        for tree in trees {
            for width in [1.0, 2.5] {
                let mut bytes = Vec::new();
                write_vdb_level_set(&mut bytes, &tree, width, 0.1).unwrap();
                let back = read_vdb(&bytes, "sdf.vdb", None, None).unwrap();
                assert_eq!(back.tree, tree, "level {}", tree.level());
                assert_eq!(back.placement.offset, [0; 3]);
            }
        }
    }

    #[test]
    fn openvdb_files_of_every_compression_read_as_the_spheres_inside() {
        // The fuzz seeds written by OpenVDB 10 (pyopenvdb's createLevelSetSphere(radius=2.6,
        // center=(10.5, 10, 11), halfWidth=2), then rewritten by OpenVDB with other compressions): Blosc and
        // active mask, half floats, a DoubleGrid, active mask only, and sdfInteriorMask's BoolGrid in zlib.
        // The sphere's values are |p − c| − r: the inside is the voxels whose centre is nearer than r.
        let dir =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/vdb_level_set");
        let (c, r) = ([10.5f64, 10.0, 11.0], 2.6f64);
        let mut want = Vec::new();
        for x in 0..32u32 {
            for y in 0..32u32 {
                for z in 0..32u32 {
                    let d2: f64 = [x, y, z]
                        .iter()
                        .zip(c)
                        .map(|(&p, c)| (f64::from(p) - c).powi(2))
                        .sum();
                    if d2.sqrt() < r {
                        want.push(crate::Ray::new([x, y, z], z + 1));
                    }
                }
            }
        }
        let want = KTree::from_rays(&crate::RaySet::<3>::from_rays(5, want).unwrap());
        for name in ["blosc", "half", "double", "mask", "bool_zip"] {
            let path = dir.join(format!("openvdb_{name}.vdb"));
            let bytes = std::fs::read(&path).unwrap();
            let read = read_vdb(&bytes, name, Some([0; 3]), Some(5)).unwrap();
            assert_eq!(read.tree, want, "{name}");
        }
    }

    #[test]
    fn damaged_openvdb_files_give_an_error_at_a_byte_or_a_tree() {
        // OpenVDB's Blosc, half-float, double and zlib files with bytes changed and cut: never a panic, and
        // an error names a byte of the file.
        let dir =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/vdb_level_set");
        for name in ["blosc", "half", "double", "bool_zip"] {
            let bytes = std::fs::read(dir.join(format!("openvdb_{name}.vdb"))).unwrap();
            let check = |b: &[u8]| match read_vdb(b, name, Some([0; 3]), Some(5)) {
                Ok(p) => p.tree.assert_well_formed(),
                Err(e) => assert!(e.offset().is_some_and(|o| o <= bytes.len() as u64), "{e}"),
            };
            for at in (0..bytes.len()).step_by(31) {
                let mut bad = bytes.clone();
                bad[at] ^= 0xa5;
                check(&bad);
                assert!(
                    read_vdb(&bytes[..at], name, None, None).is_err(),
                    "{name} cut at {at}"
                );
            }
        }
    }

    #[test]
    fn a_fog_volume_reads_as_its_active_voxels_with_their_values() {
        let tree = KTree::from_rays(&ball_rays::<3>(4, [8, 8, 8], 10).unwrap());
        let mut bytes = Vec::new();
        write_vdb_level_set(&mut bytes, &tree, 2.0, 1.0).unwrap();
        let at = bytes.windows(9).position(|w| w == b"level set").unwrap();
        let fog = [
            &bytes[..at - 4],
            &10u32.to_le_bytes(),
            b"fog volume",
            &bytes[at + 9..],
        ]
        .concat();
        let band = tree.narrow_band(2.0).unwrap();
        let shape = read_vdb(&fog, "fog.vdb", None, None).unwrap().tree;
        assert_eq!(shape.voxel_count(), band.len() as u128);
        let values = crate::io::read_vdb_values(&fog, "fog.vdb", None, None).unwrap();
        let crate::AnyValuedTree::K3F32(values) = values.tree else {
            panic!("a FloatGrid reads as float32")
        };
        for (v, d) in band.iter() {
            assert!(shape.contains(v));
            assert_eq!(values.value_at(v), Some(d as f32));
        }
    }
}
