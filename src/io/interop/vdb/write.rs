//! Writing an octree as an OpenVDB `BoolGrid`: the tree's boxes gathered into OpenVDB's nodes (root → 32³
//! → 16³ → 8³ leaves), written uncompressed.

use std::collections::BTreeMap;
use std::io::Write;

use super::*;
use crate::io::interop::grid::GridMeta;
use crate::tree::{KTree, NodeState};

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
