//! Occupancy maps in OctoMap's files, free and unknown space kept: `.ot` (`OcTree::write`: every node's
//! log-odds, `ColorOcTree`'s with a colour) and `.bt` (`OcTree::writeBinary`: the maximum-likelihood map,
//! each known leaf free or occupied). A map's keys are OctoMap's keys, so nothing is placed or moved.
//!
//! An `.ot` file, after a text header like a `.bt` file's (first line `# Octomap OcTree file`, `id OcTree`
//! or `id ColorOcTree`, `size`, `res`, `data`), holds its nodes depth first from the root, each its
//! log-odds (`f32`, little-endian; then three colour bytes in a `ColorOcTree`) and a byte whose bit `i` says
//! that child `i` exists (its node follows, after the subtrees of its earlier siblings). A node without
//! children is a leaf: all its voxels hold its log-odds; a missing child is unknown. An inner node holds
//! the largest log-odds of its children, as OctoMap keeps it.
//!
//! Reading a `.bt` file gives its occupied leaves the upper clamp's log-odds and its free leaves the
//! lower's (OctoMap's `readBinary`); writing one writes each known voxel as occupied or free by the map's
//! threshold, merged where eight siblings agree.

use std::io::Write;

use super::grid::{GridFileError, GridFileErrorKind};
use super::octomap::{read_header, read_octomap_header, BT_DEPTH, BT_HEADER};
use crate::map::{tree_from_leaves, Leaf, MapGrid, OccupancyMap, SensorModel, MAP_LEVEL};
use crate::space::morton_encode;
use crate::tree::top_down::InputNode;
use crate::tree::valued::ValueState;
use crate::KTree;

/// The first line of an `.ot` file.
pub const OT_HEADER: &str = "# Octomap OcTree file";

/// Reads an OctoMap `.ot` file's bytes (`OcTree` or `ColorOcTree`; colours are skipped) into a map with
/// the sensor model `model`.
///
/// # Errors
/// [`GridFileError`] naming the byte offset: a bad header, a node count that differs from `size`, bytes
/// missing or left over, children below depth 16, a log-odds value that is not a number.
pub fn read_ot_map(
    bytes: &[u8],
    file: &str,
    model: SensorModel,
) -> Result<OccupancyMap<3>, GridFileError> {
    let fail = |at: usize, kind| GridFileError::new(file, at, kind);
    let (id, size, res, data_at) =
        read_octomap_header(bytes, file, OT_HEADER, &["OcTree", "ColorOcTree"])?;
    let node_bytes = if id == "ColorOcTree" { 8 } else { 5 };
    let room = (bytes.len() - data_at) as u64 / node_bytes as u64;
    if size > room {
        return Err(fail(
            bytes.len(),
            GridFileErrorKind::Truncated(format!(
                "{size} nodes of {node_bytes} bytes cannot fit in {} data bytes",
                bytes.len() - data_at
            )),
        ));
    }
    let mut leaves: Vec<Leaf<f32>> = Vec::new();
    let mut at = data_at;
    let mut nodes = 0u64;
    if size > 0 {
        // Depth first with an explicit stack of (first key, depth) of the nodes whose bytes come next.
        let mut stack = vec![([0u32; 3], 0u32)];
        while let Some((origin, depth)) = stack.pop() {
            let Some(node) = bytes.get(at..at + node_bytes) else {
                return Err(fail(
                    at,
                    GridFileErrorKind::Truncated(format!("{nodes} of {size} nodes read")),
                ));
            };
            nodes += 1;
            if nodes > size {
                return Err(fail(
                    at,
                    GridFileErrorKind::Data(format!("more nodes than the {size} of the header")),
                ));
            }
            let value = f32::from_le_bytes([node[0], node[1], node[2], node[3]]);
            let children = node[node_bytes - 1];
            if children == 0 {
                if value.is_nan() {
                    return Err(fail(
                        at,
                        GridFileErrorKind::Data("a leaf's log-odds are not a number".into()),
                    ));
                }
                leaves.push((morton_encode(origin), BT_DEPTH - depth, value));
            } else {
                if depth >= BT_DEPTH {
                    return Err(fail(
                        at + node_bytes - 1,
                        GridFileErrorKind::Data(format!(
                            "a node at depth {BT_DEPTH} (a voxel) has children"
                        )),
                    ));
                }
                let half = 1u32 << (BT_DEPTH - depth - 1);
                for i in (0..8usize).rev() {
                    if children >> i & 1 == 1 {
                        let child = std::array::from_fn(|a| {
                            origin[a] + if i >> a & 1 == 1 { half } else { 0 }
                        });
                        stack.push((child, depth + 1));
                    }
                }
            }
            at += node_bytes;
        }
    }
    finish(file, (nodes, size, at, bytes.len()), res, model, leaves)
}

/// Reads an OctoMap `.bt` file's bytes into a map with the sensor model `model`: occupied leaves at its
/// upper clamp, free leaves at its lower one, the rest unknown.
///
/// # Errors
/// As [`crate::io::read_bt`].
pub fn read_bt_map(
    bytes: &[u8],
    file: &str,
    model: SensorModel,
) -> Result<OccupancyMap<3>, GridFileError> {
    let fail = |at: usize, kind| GridFileError::new(file, at, kind);
    let (size, res, data_at) = read_header(bytes, file)?;
    let mut leaves: Vec<Leaf<f32>> = Vec::new();
    let mut at = data_at;
    let mut nodes = 0u64;
    if size > 0 {
        nodes = 1;
        let mut stack = vec![([0u32; 3], 0u32)];
        while let Some((origin, depth)) = stack.pop() {
            let Some(pair) = bytes.get(at..at + 2) else {
                return Err(fail(
                    at,
                    GridFileErrorKind::Truncated(format!("{nodes} of {size} nodes read")),
                ));
            };
            let half = 1u32 << (BT_DEPTH - depth - 1);
            let mut inner = Vec::new();
            for i in 0..8usize {
                let code = (pair[i / 4] >> (2 * (i % 4))) & 3;
                if code == 0 {
                    continue;
                }
                nodes += 1;
                let child: [u32; 3] =
                    std::array::from_fn(|a| origin[a] + if i >> a & 1 == 1 { half } else { 0 });
                match code {
                    1 => leaves.push((morton_encode(child), BT_DEPTH - depth - 1, model.clamp_min)),
                    2 => leaves.push((morton_encode(child), BT_DEPTH - depth - 1, model.clamp_max)),
                    _ if depth + 1 >= BT_DEPTH => {
                        return Err(fail(
                            at + i / 4,
                            GridFileErrorKind::Data(format!(
                                "a node at depth {BT_DEPTH} (a voxel) is marked as having children"
                            )),
                        ))
                    }
                    _ => inner.push((child, depth + 1)),
                }
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
    finish(file, (nodes, size, at, bytes.len()), res, model, leaves)
}

/// Checks the counts and the end of the data, and makes the map of the leaves read (any order).
fn finish(
    file: &str,
    (nodes, size, at, len): (u64, u64, usize, usize),
    res: f64,
    model: SensorModel,
    mut leaves: Vec<Leaf<f32>>,
) -> Result<OccupancyMap<3>, GridFileError> {
    let fail = |at: usize, kind| GridFileError::new(file, at, kind);
    if nodes != size {
        return Err(fail(
            at,
            GridFileErrorKind::Data(format!("{nodes} nodes read, the header says {size}")),
        ));
    }
    if at != len {
        return Err(fail(
            at,
            GridFileErrorKind::Data(format!("{} bytes after the last node", len - at)),
        ));
    }
    // A `.bt` node lists its leaf children before the subtrees of its inner ones: into Morton order.
    leaves.sort_unstable_by_key(|l| l.0);
    let tree = tree_from_leaves::<3, f32>(MAP_LEVEL, &leaves)
        .map_err(|e| fail(at, GridFileErrorKind::Data(e.to_string())))?;
    let grid = MapGrid::new(res).map_err(|e| fail(0, GridFileErrorKind::Header(e)))?;
    OccupancyMap::from_log_odds(grid, model, tree).map_err(|e| fail(0, GridFileErrorKind::Data(e)))
}

/// Writes a map as an OctoMap `.ot` file (`OcTree`): every node's log-odds, inner nodes the largest of
/// their children's.
///
/// ```
/// use ktree::io::{read_ot_map, write_ot_map};
/// use ktree::map::OccupancyMap;
/// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
/// map.insert(&[[1.0, 0.5, 0.2]], [0.0; 3], None).unwrap();
/// let mut bytes = Vec::new();
/// write_ot_map(&mut bytes, &map).unwrap();
/// assert_eq!(read_ot_map(&bytes, "mem", *map.model()).unwrap(), map);
/// ```
///
/// # Errors
/// Any I/O error of `w`.
pub fn write_ot_map(mut w: impl Write, map: &OccupancyMap<3>) -> std::io::Result<()> {
    let tree = map.log_odds();
    let mut data = Vec::new();
    let mut size = 0u64;
    let root = InputNode::root(tree).unwrap_or_else(|e| match e {});
    if root.state != ValueState::Empty {
        write_ot_node(tree, root, &mut data, &mut size);
    }
    write!(
        w,
        "{OT_HEADER}\n# written by ktree\nid OcTree\nsize {size}\nres {}\ndata\n",
        map.grid().resolution()
    )?;
    w.write_all(&data)?;
    w.flush()
}

/// Writes `node` (not empty) and its subtree; returns its log-odds (an inner node's: its children's
/// largest).
fn write_ot_node(
    tree: &KTree<3, f32>,
    node: InputNode<f32>,
    data: &mut Vec<u8>,
    size: &mut u64,
) -> f32 {
    *size += 1;
    let at = data.len();
    data.extend_from_slice(&[0; 5]);
    let value = match node.state {
        ValueState::Full(v) => v,
        _ => {
            let mut children = 0u8;
            let mut largest = f32::NEG_INFINITY;
            for code in 0..8 {
                let child = node.child(tree, code).unwrap_or_else(|e| match e {});
                if child.state != ValueState::Empty {
                    children |= 1 << code;
                    largest = largest.max(write_ot_node(tree, child, data, size));
                }
            }
            data[at + 4] = children;
            largest
        }
    };
    data[at..at + 4].copy_from_slice(&value.to_le_bytes());
    value
}

/// Writes a map as an OctoMap `.bt` file: every known voxel occupied or free by the map's threshold.
///
/// ```
/// use ktree::io::{read_bt_map, write_bt_map};
/// use ktree::map::OccupancyMap;
/// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
/// map.insert(&[[1.0, 0.5, 0.2]], [0.0; 3], None).unwrap();
/// let mut bytes = Vec::new();
/// write_bt_map(&mut bytes, &map).unwrap();
/// let back = read_bt_map(&bytes, "mem", *map.model()).unwrap();
/// assert_eq!(back.occupied(), map.occupied());
/// assert_eq!(back.free(), map.free());
/// ```
///
/// # Errors
/// Any I/O error of `w`.
pub fn write_bt_map(mut w: impl Write, map: &OccupancyMap<3>) -> std::io::Result<()> {
    let model = *map.model();
    // 1 free, 2 occupied: the `.bt` codes of the leaves.
    let states = map
        .log_odds()
        .map_values(|l| Some(if model.is_occupied(l) { 2u8 } else { 1u8 }))
        .expect("codes are values");
    let mut data = Vec::new();
    let mut size = 0u64;
    let root = InputNode::root(&states).unwrap_or_else(|e| match e {});
    match root.state {
        ValueState::Empty => {}
        // OctoMap's root always has children: eight leaves of the root's state.
        ValueState::Full(c) => {
            let byte = c | c << 2 | c << 4 | c << 6;
            data.extend_from_slice(&[byte, byte]);
            size = 9;
        }
        _ => {
            size = 1;
            write_bt_node(&states, root, &mut data, &mut size);
        }
    }
    write!(
        w,
        "{BT_HEADER}\n# written by ktree\nid OcTree\nsize {size}\nres {}\ndata\n",
        map.grid().resolution()
    )?;
    w.write_all(&data)?;
    w.flush()
}

fn write_bt_node(tree: &KTree<3, u8>, node: InputNode<u8>, data: &mut Vec<u8>, size: &mut u64) {
    let children: Vec<InputNode<u8>> = (0..8)
        .map(|code| node.child(tree, code).unwrap_or_else(|e| match e {}))
        .collect();
    let mut pair = [0u8; 2];
    for (i, c) in children.iter().enumerate() {
        let code = match c.state {
            ValueState::Empty => 0,
            ValueState::Full(code) => code,
            _ => 3,
        };
        if code != 0 {
            *size += 1;
        }
        pair[i / 4] |= code << (2 * (i % 4));
    }
    data.extend_from_slice(&pair);
    for c in children {
        if c.state.has_children() {
            write_bt_node(tree, c, data, size);
        }
    }
}
