//! OctoMap's binary tree files (`.bt`): an occupancy octree of 16 levels, as written by
//! `OcTree::writeBinary`.
//!
//! ```text
//! # Octomap OcTree binary file      <- first line, exactly
//! # ...                             <- comment lines
//! id OcTree
//! size N                            <- the number of nodes, the root included
//! res R                             <- the edge of a voxel in metres
//! data
//! <nodes>                           <- depth first from the root
//! ```
//!
//! Each node that has children is two bytes, children 0–3 then 4–7, two bits per child: `(byte >> 2·(i mod 4))
//! & 3` is 1 for a free leaf, 2 for an occupied leaf, 3 for a child with children (its node follows, depth
//! first, after this node's two bytes and the subtrees of its earlier siblings), 0 for unknown. Child `i` is the
//! upper half along x if bit 0 of `i` is set, along y for bit 1, along z for bit 2 — ktree's child code. A
//! leaf at depth `d` covers `2^(16 − d)` voxels a side; OctoMap's key `k` (0…65535 on each axis) is grid
//! index `k − 32768`, at world coordinates `[k − 32768, k − 32767) · res`.
//!
//! Full ↔ occupied, empty ↔ free. Unknown space reads as empty unless asked to read as full; writing marks
//! the whole universe known (free or occupied) and everything outside it unknown.

use std::io::Write;

use super::grid::{
    max_grid_nodes, place_boxes, GridBoxes, GridFileError, GridFileErrorKind, GridMeta,
    GridPlacement, IndexBox, PlacedTree,
};
use crate::tree::{KTree, NodeRef, NodeState};

/// The first line of a `.bt` file.
pub const BT_HEADER: &str = "# Octomap OcTree binary file";
/// OctoMap's tree depth: keys have 16 bits.
pub const BT_DEPTH: u32 = 16;
const CENTRE: i64 = 1 << (BT_DEPTH - 1);

/// Reads a `.bt` file's bytes into an octree placed by `offset` and `level` (see [`GridPlacement::choose`];
/// the region chosen for is the known one, free and occupied). `unknown_full` reads unknown cells inside
/// the universe as full.
///
/// ```
/// use ktree::io::{read_bt, write_bt, GridMeta};
/// let tree = ktree::KTree::<3>::from_dense(1, &[true, false, false, false, false, false, false, true]).unwrap();
/// let mut bytes = Vec::new();
/// write_bt(&mut bytes, &tree, [0; 3], 0.1).unwrap();
/// let back = read_bt(&bytes, "mem", None, None, false).unwrap();
/// assert_eq!((back.tree, back.meta.voxel_size), (tree, 0.1));
/// ```
///
/// # Errors
/// [`GridFileError`] naming the byte offset: a bad header, a tree deeper than 16 levels, a node count that
/// differs from `size`, bytes missing or left over, or occupied cells outside the universe asked for.
pub fn read_bt(
    bytes: &[u8],
    file: &str,
    offset: Option<[i64; 3]>,
    level: Option<u32>,
    unknown_full: bool,
) -> Result<PlacedTree, GridFileError> {
    let fail = |at: usize, kind| GridFileError::new(file, at, kind);
    let (size, res, data_at) = read_header(bytes, file)?;
    let mut boxes = GridBoxes::default();
    let mut at = data_at;
    let mut nodes = 0u64;
    if size > 0 {
        nodes = 1;
        // Depth-first with an explicit stack of (key origin, depth) of nodes whose bytes come next.
        let mut stack = vec![([0i64; 3], 0u32)];
        while let Some((origin, depth)) = stack.pop() {
            let Some(pair) = bytes.get(at..at + 2) else {
                return Err(fail(
                    at,
                    GridFileErrorKind::Truncated(format!("{nodes} of {size} nodes read")),
                ));
            };
            let half = 1i64 << (BT_DEPTH - depth - 1);
            let mut inner = Vec::new();
            for i in 0..8usize {
                let code = (pair[i / 4] >> (2 * (i % 4))) & 3;
                let child = std::array::from_fn(|a| {
                    origin[a] + if i >> a & 1 == 1 { half } else { 0 } - CENTRE
                });
                let cube = IndexBox {
                    origin: child,
                    size: [half as u64; 3],
                };
                match code {
                    0 => {
                        if unknown_full {
                            boxes.fill.push(cube);
                        }
                        continue;
                    }
                    1 => boxes.note_known(cube),
                    2 => {
                        boxes.note_known(cube);
                        boxes.inside.push(cube);
                    }
                    _ => {
                        if depth + 1 >= BT_DEPTH {
                            return Err(fail(
                                at + i / 4,
                                GridFileErrorKind::Data(format!(
                                    "a node at depth {BT_DEPTH} (a voxel) is marked as having children"
                                )),
                            ));
                        }
                        inner.push((std::array::from_fn(|a| child[a] + CENTRE), depth + 1));
                    }
                }
                nodes += 1;
            }
            if nodes > size {
                return Err(fail(
                    at,
                    GridFileErrorKind::Data(format!("more nodes than the {size} of the header")),
                ));
            }
            stack.extend(inner.into_iter().rev());
            at += 2;
        }
    }
    if nodes != size {
        return Err(fail(
            at,
            GridFileErrorKind::Data(format!("{nodes} nodes read, the header says {size}")),
        ));
    }
    if at != bytes.len() {
        return Err(fail(
            at,
            GridFileErrorKind::Data(format!("{} bytes after the tree", bytes.len() - at)),
        ));
    }
    let placement = GridPlacement::choose(boxes.known, boxes.alignment(), offset, level)
        .map_err(|m| fail(0, GridFileErrorKind::GridPlacement(m)))?;
    let tree = place_boxes(&boxes, &placement, max_grid_nodes(bytes.len()))
        .map_err(|m| fail(0, GridFileErrorKind::GridPlacement(m)))?;
    Ok(PlacedTree {
        tree,
        placement,
        meta: GridMeta {
            voxel_size: res,
            origin: [0.0; 3],
        },
    })
}

/// Parses the header as OctoMap does (`readHeader`): returns `size`, `res` and the first data byte.
/// Reads a `.bt` file's header: its node count, resolution and where its data start, the count checked
/// against the bytes that follow.
pub(super) fn read_header(bytes: &[u8], file: &str) -> Result<(u64, f64, usize), GridFileError> {
    let (_, size, res, at) = read_octomap_header(bytes, file, BT_HEADER, &["OcTree", "1"])?;
    // Every node but the root is two bits of an inner node's two bytes: at most 8 per 2 bytes.
    let room = (bytes.len() - at) as u64 / 2 * 8 + 1;
    if size > room {
        return Err(GridFileError::new(
            file,
            bytes.len(),
            GridFileErrorKind::Truncated(format!(
                "{size} nodes cannot fit in {} data bytes",
                bytes.len() - at
            )),
        ));
    }
    Ok((size, res, at))
}

/// Reads the text header of an OctoMap file whose first line is `first` and whose tree type is one of
/// `ids`: the type, the node count (`size`), the resolution (`res`) and where the data start (after
/// `data`).
pub(super) fn read_octomap_header(
    bytes: &[u8],
    file: &str,
    first: &str,
    ids: &[&str],
) -> Result<(String, u64, f64, usize), GridFileError> {
    let fail = |at: usize, m: String| GridFileError::new(file, at, GridFileErrorKind::Header(m));
    if !bytes.starts_with(first.as_bytes()) {
        return Err(fail(0, format!("the first line is not {first:?}")));
    }
    let mut at = 0usize;
    let (mut id, mut size, mut res) = (None, None, None);
    loop {
        let rest = &bytes[at..];
        let Some(len) = rest.iter().take(1024).position(|&b| b == b'\n') else {
            return Err(fail(
                at,
                "expected a header line ending in a newline (before `data`)".into(),
            ));
        };
        let line_at = at;
        let line = String::from_utf8_lossy(&rest[..len]);
        at += len + 1;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] => {}
            [w, ..] if w.starts_with('#') => {}
            ["id", v] => id = Some(v.to_string()),
            ["size", v] => {
                size = Some(
                    v.parse::<u64>()
                        .map_err(|_| fail(line_at, format!("size {v:?} is not a whole number")))?,
                )
            }
            ["res", v] => match v.parse::<f64>() {
                Ok(r) if r > 0.0 && r.is_finite() => res = Some(r),
                _ => return Err(fail(line_at, format!("res {v:?} is not a positive number"))),
            },
            ["data"] => break,
            _ => return Err(fail(line_at, format!("unknown header line {line:?}"))),
        }
    }
    let id = match id {
        Some(id) if ids.contains(&id.as_str()) => id,
        Some(other) => {
            return Err(GridFileError::new(
                file,
                0,
                GridFileErrorKind::Unsupported(format!(
                    "tree type {other:?} (read here: {})",
                    ids.join(", ")
                )),
            ))
        }
        None => return Err(fail(0, "no `id` line".into())),
    };
    let size = size.ok_or_else(|| fail(0, "no `size` line".into()))?;
    let res = res.ok_or_else(|| fail(0, "no `res` line".into()))?;
    Ok((id, size, res, at))
}

/// Writes an octree as an OctoMap `.bt` file with voxels of edge `res`: ktree voxel `v` is grid index
/// `v − offset`, i.e. OctoMap key `v − offset + 32768`.
///
/// # Errors
/// Any I/O error; [`std::io::ErrorKind::InvalidInput`] if the universe is deeper than 16 levels or its
/// corner is not a multiple of its side in OctoMap's key space (the offset must be a multiple of `2^L`
/// and keep the universe within keys 0…65535).
pub fn write_bt(
    mut w: impl Write,
    tree: &KTree<3>,
    offset: [i64; 3],
    res: f64,
) -> std::io::Result<()> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    let level = tree.level();
    if level > BT_DEPTH {
        return Err(invalid(format!(
            "a level-{level} universe is deeper than OctoMap's {BT_DEPTH} levels"
        )));
    }
    if !(res > 0.0 && res.is_finite()) {
        return Err(invalid(format!(
            "resolution {res} is not a positive number"
        )));
    }
    let side = 1i64 << level;
    let corner: [i64; 3] = std::array::from_fn(|a| CENTRE - offset[a]);
    if corner
        .iter()
        .any(|&c| c < 0 || c + side > 2 * CENTRE || c % side != 0)
    {
        return Err(invalid(format!(
            "offset {offset:?} puts the level-{level} universe at OctoMap keys {corner:?}: they must be \
             multiples of {side} within 0…{}",
            2 * CENTRE - side
        )));
    }
    let code = |s: NodeState| match s {
        NodeState::Empty => 1u8,
        NodeState::Full => 2,
        NodeState::Partial => 3,
    };
    let mut data = Vec::new();
    let mut size = 1u64; // the root
    let root = tree.root();
    let chain = BT_DEPTH - level;
    // The nodes above the universe: one known child each, the others unknown.
    for depth in 0..chain {
        let bit = BT_DEPTH - 1 - depth;
        let i = (0..3).fold(0usize, |i, a| i | ((corner[a] >> bit & 1) as usize) << a);
        let state = if depth + 1 == chain {
            root.state
        } else {
            NodeState::Partial
        };
        let mut pair = [0u8; 2];
        pair[i / 4] |= code(state) << (2 * (i % 4));
        data.extend_from_slice(&pair);
        size += 1;
    }
    if chain == 0 && root.state != NodeState::Partial {
        // OctoMap's root always has children: eight leaves of the root's state.
        let c = code(root.state);
        let byte = c | c << 2 | c << 4 | c << 6;
        data.extend_from_slice(&[byte, byte]);
        size += 8;
    } else if root.state == NodeState::Partial {
        write_node(tree, &root, &mut data, &mut size, &code);
    }
    write!(
        w,
        "{BT_HEADER}\n# written by ktree\nid OcTree\nsize {size}\nres {res}\ndata\n"
    )?;
    w.write_all(&data)?;
    w.flush()
}

fn write_node(
    tree: &KTree<3>,
    node: &NodeRef<3>,
    data: &mut Vec<u8>,
    size: &mut u64,
    code: &impl Fn(NodeState) -> u8,
) {
    let children: Vec<NodeRef<3>> = tree.children(node).collect();
    let mut pair = [0u8; 2];
    for (i, c) in children.iter().enumerate() {
        pair[i / 4] |= code(c.state) << (2 * (i % 4));
    }
    data.extend_from_slice(&pair);
    *size += 8;
    for c in &children {
        if c.state == NodeState::Partial {
            write_node(tree, c, data, size, code);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;

    fn sample() -> (KTree<3>, Vec<u8>) {
        let tree = stack(&ball_rays::<3>(4, [7, 8, 9], 6).unwrap());
        let mut bytes = Vec::new();
        write_bt(&mut bytes, &tree, [0; 3], 0.05).unwrap();
        (tree, bytes)
    }

    #[test]
    fn round_trips_at_every_placement_octomap_allows() {
        let (tree, bytes) = sample();
        assert_eq!(read_bt(&bytes, "s", None, None, false).unwrap().tree, tree);
        for offset in [[16, 0, -32], [32768, 32768, 32768], [-32752, 0, 0]] {
            let mut b = Vec::new();
            write_bt(&mut b, &tree, offset, 1.0).unwrap();
            let p = read_bt(&b, "s", Some(offset), Some(4), false).unwrap();
            assert_eq!(p.tree, tree, "offset {offset:?}");
        }
        assert!(write_bt(Vec::new(), &tree, [3, 0, 0], 1.0).is_err());
        assert!(write_bt(Vec::new(), &tree, [-32768, 0, 0], 1.0).is_err());
        // Level 16 at the whole key space, and leaf roots.
        for t in [
            KTree::<3>::full(16).unwrap(),
            KTree::<3>::empty(3).unwrap(),
            KTree::<3>::full(3).unwrap(),
        ] {
            let offset = if t.level() == 16 { [32768; 3] } else { [0; 3] };
            let mut b = Vec::new();
            write_bt(&mut b, &t, offset, 1.0).unwrap();
            let p = read_bt(&b, "s", Some(offset), Some(t.level()), false).unwrap();
            assert_eq!(p.tree, t);
        }
    }

    #[test]
    fn unknown_space_reads_as_empty_or_as_full() {
        // Root with one child: child 7 (the +x+y+z octant) inner, whose child 0 is an occupied leaf of side
        // 2^14; every other cell unknown.
        let mut b = format!("{BT_HEADER}\nid OcTree\nsize 3\nres 1\ndata\n").into_bytes();
        b.extend_from_slice(&[0, 0b11 << 6, 0b10, 0]);
        let p = read_bt(&b, "u", None, None, false).unwrap();
        assert_eq!((p.placement.offset, p.placement.level), ([0; 3], 14));
        assert_eq!(p.tree, KTree::<3>::full(14).unwrap());
        let p = read_bt(&b, "u", None, Some(15), true).unwrap();
        assert_eq!(p.tree, KTree::<3>::full(15).unwrap());
        let p = read_bt(&b, "u", None, Some(15), false).unwrap();
        assert_eq!(p.tree.voxel_count(), 1 << 42);
    }

    #[test]
    fn bad_files_name_the_byte() {
        let (_, bytes) = sample();
        let data_at = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        let e = read_bt(&bytes[..bytes.len() - 1], "s", None, None, false).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
        let mut padded = bytes.clone();
        padded.push(0);
        assert!(read_bt(&padded, "s", None, None, false).is_err());
        let mut bad = bytes.clone();
        bad[data_at + 4] ^= 0b01; // a leaf's code changes: either the tree or the count breaks
        let flipped = read_bt(&bad, "s", None, None, false);
        assert!(flipped.is_err() || flipped.unwrap().tree != sample().0);
        // A 100-byte file claiming billions of nodes is refused from its header.
        let mut huge =
            format!("{BT_HEADER}\nid OcTree\nsize 4000000000\nres 1\ndata\n").into_bytes();
        huge.resize(100, 0xff);
        let e = read_bt(&huge, "huge", None, None, false).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
        // Children below depth 16.
        let mut deep = format!("{BT_HEADER}\nid OcTree\nsize 129\nres 1\ndata\n").into_bytes();
        for _ in 0..16 {
            deep.extend_from_slice(&[0b11, 0]);
        }
        let e = read_bt(&deep, "deep", None, None, false).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Data(_)), "{e}");
        for text in [
            "# Octomap OcTree\n",
            "# Octomap OcTree binary file\nid ColorOcTree\nsize 0\nres 1\ndata\n",
        ] {
            assert!(
                read_bt(text.as_bytes(), "h", None, None, false).is_err(),
                "{text}"
            );
        }
    }
}
