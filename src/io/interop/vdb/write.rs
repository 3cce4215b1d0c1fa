//! Writing an octree as an OpenVDB `BoolGrid`: the tree's boxes gathered into OpenVDB's nodes (root → 32³
//! → 16³ → 8³ leaves), written uncompressed.

use std::collections::BTreeMap;
use std::io::Write;

use super::*;
use crate::io::interop::grid::GridMeta;
use crate::tree::{KTree, NodeState};

/// A node of OpenVDB's tree: which of its `n` tiles (or voxels, in a leaf) are active, all `n` values of
/// `width` bytes each (0 where inactive), and its children by slot.
struct Node<C> {
    active: Vec<u64>,
    values: Vec<u8>,
    children: BTreeMap<u32, C>,
}

impl<C> Node<C> {
    fn new(words: usize, width: usize) -> Self {
        Self {
            active: vec![0; words],
            values: vec![0; words * 64 * width],
            children: BTreeMap::new(),
        }
    }

    fn set(&mut self, n: usize, value: &[u8]) {
        self.active[n / 64] |= 1 << (n % 64);
        self.values[n * value.len()..(n + 1) * value.len()].copy_from_slice(value);
    }
}

type Leaf = Node<()>;
type Lower = Node<Leaf>;
type Upper = Node<Lower>;

/// A grid in OpenVDB's node structure (root → 32³ → 16³ → 8³ leaves), built from cubes of one value each
/// (`width` bytes as the grid stores it): whole nodes covered become active tiles.
pub(super) struct GridNodes {
    width: usize,
    root: BTreeMap<[i64; 3], Upper>,
}

impl GridNodes {
    pub fn new(width: usize) -> Self {
        Self {
            width,
            root: BTreeMap::new(),
        }
    }

    /// Makes the cube `[lo, lo + side)³` active with `value`, as tiles where whole nodes are covered.
    pub fn add_cube(&mut self, lo: [i64; 3], side: i64, value: &[u8]) {
        // Split the cube into the blocks of side `step` it covers: 128 (upper tiles), 8 (lower tiles), 1.
        let covers = |step: i64| lo.iter().all(|&c| c % step == 0) && side % step == 0;
        let step = [128, 8, 1].into_iter().find(|&s| covers(s)).unwrap_or(1);
        let n = side / step;
        let width = self.width;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = [lo[0] + i * step, lo[1] + j * step, lo[2] + k * step];
                    let upper = self
                        .root
                        .entry(origin_of(p, 12))
                        .or_insert_with(|| Node::new(UPPER_WORDS, width));
                    let us = slot(p, 5, 7);
                    if step == 128 {
                        upper.set(us as usize, value);
                        continue;
                    }
                    let lower = upper
                        .children
                        .entry(us)
                        .or_insert_with(|| Node::new(LOWER_WORDS, width));
                    let ls = slot(p, 4, 3);
                    if step == 8 {
                        lower.set(ls as usize, value);
                        continue;
                    }
                    let leaf = lower
                        .children
                        .entry(ls)
                        .or_insert_with(|| Node::new(LEAF_WORDS, width));
                    leaf.set(slot(p, 3, 0) as usize, value);
                }
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

fn put_words(out: &mut Vec<u8>, words: &[u64]) {
    for w in words {
        out.extend_from_slice(&w.to_le_bytes());
    }
}

/// The mask of a node's children.
fn child_mask<C>(node: &Node<C>, words: usize) -> Vec<u64> {
    let mut mask = vec![0u64; words];
    for &n in node.children.keys() {
        mask[n as usize / 64] |= 1 << (n % 64);
    }
    mask
}

/// Checks that a universe of `level` at `offset` fits OpenVDB's 32-bit indices and the voxel size is a
/// positive number.
pub(super) fn check_placement(
    level: u32,
    offset: [i64; 3],
    meta: &GridMeta,
) -> std::io::Result<()> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    let side = 1i64 << level;
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
    Ok(())
}

/// Writes a file of one grid named `ktree` of tree type `tree_type` holding `nodes`, uncompressed, with
/// ktree's metadata (`level`, `offset`) and the transform of `meta`; background 0. A `BoolGrid`'s leaves
/// store their values as bits, the others' as `6` (all values follow) and the 512 values.
pub(super) fn write_grid(
    mut w: impl Write,
    nodes: &GridNodes,
    tree_type: &str,
    level: u32,
    offset: [i64; 3],
    meta: &GridMeta,
) -> std::io::Result<()> {
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC.to_le_bytes());
    put_u32(&mut out, FILE_VERSION);
    put_u32(&mut out, 10);
    put_u32(&mut out, 0);
    out.push(1); // the grid descriptors carry offsets
    let uuid_at = out.len();
    out.extend_from_slice(&[b'0'; 36]); // filled in below from the grid's bytes
    let (positions_at, grid_at) = put_grid_head(&mut out, tree_type, "unknown", level, offset);
    put_str(&mut out, "UniformScaleTranslateMap");
    let s = meta.voxel_size;
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
    // Topology: the root, then each internal node's masks and values, each leaf's value mask.
    put_u32(&mut out, 1); // buffer count
    out.extend(std::iter::repeat_n(0u8, nodes.width)); // background: 0
    put_u32(&mut out, 0); // root tiles
    put_u32(&mut out, nodes.root.len() as u32);
    for (origin, upper) in &nodes.root {
        for c in origin {
            out.extend_from_slice(&(*c as i32).to_le_bytes());
        }
        put_words(&mut out, &child_mask(upper, UPPER_WORDS));
        put_words(&mut out, &upper.active);
        out.push(6); // all values follow, uncompressed
        out.extend_from_slice(&upper.values);
        for lower in upper.children.values() {
            put_words(&mut out, &child_mask(lower, LOWER_WORDS));
            put_words(&mut out, &lower.active);
            out.push(6);
            out.extend_from_slice(&lower.values);
            for leaf in lower.children.values() {
                put_words(&mut out, &leaf.active);
            }
        }
    }
    // Buffers: each leaf's value mask, then its origin and values as bits (bool) or its values.
    let block_at = out.len();
    for (origin, upper) in &nodes.root {
        for (&us, lower) in &upper.children {
            for (&ls, leaf) in &lower.children {
                put_words(&mut out, &leaf.active);
                if tree_type == BOOL_TREE {
                    let leaf_origin =
                        corner_of(corner_of(*origin, us as usize, 5, 7), ls as usize, 4, 3);
                    for c in leaf_origin {
                        out.extend_from_slice(&(c as i32).to_le_bytes());
                    }
                    put_words(&mut out, &leaf.active);
                } else {
                    out.push(6);
                    out.extend_from_slice(&leaf.values);
                }
            }
        }
    }
    let end_at = out.len();
    for (i, p) in [grid_at, block_at, end_at].into_iter().enumerate() {
        out[positions_at + 8 * i..positions_at + 8 * i + 8]
            .copy_from_slice(&(p as i64).to_le_bytes());
    }
    let crc = crc32fast::hash(&out[grid_at..]);
    let uuid = format!(
        "{crc:08x}-0000-4000-8000-{:012x}",
        (end_at - grid_at) as u64 & 0xFFFF_FFFF_FFFF
    );
    out[uuid_at..uuid_at + 36].copy_from_slice(uuid.as_bytes());
    w.write_all(&out)?;
    w.flush()
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
    w: impl Write,
    tree: &KTree<3>,
    offset: [i64; 3],
    meta: &GridMeta,
) -> std::io::Result<()> {
    check_placement(tree.level(), offset, meta)?;
    let mut nodes = GridNodes::new(1);
    tree.for_each_leaf(|cell, state| {
        if state == NodeState::Full {
            let lo = std::array::from_fn(|a| i64::from(cell.origin[a]) - offset[a]);
            nodes.add_cube(lo, cell.side() as i64, &[1]);
        }
    });
    write_grid(w, &nodes, BOOL_TREE, tree.level(), offset, meta)
}
