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
//! A `ColorOcTree`'s colours are read and written beside the map as a colour tree at the same keys
//! ([`read_color_ot_map`], [`write_color_ot_map`]): a voxel's colour is its leaf's. OctoMap's white is its
//! "no colour", and the colours of its inner nodes are averages of their children's that ktree computes
//! when writing and does not read.
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
use crate::value::Rgb;
use crate::KTree;

/// The first line of an `.ot` file.
pub const OT_HEADER: &str = "# Octomap OcTree file";

/// Reads an OctoMap `.ot` file's bytes (`OcTree` or `ColorOcTree`; colours are skipped, see
/// [`read_color_ot_map`] to keep them) into a map with the sensor model `model`.
///
/// # Errors
/// [`GridFileError`] naming the byte offset: a bad header, a node count that differs from `size`, bytes
/// missing or left over, children below depth 16, a log-odds value that is not a number.
pub fn read_ot_map(
    bytes: &[u8],
    file: &str,
    model: SensorModel,
) -> Result<OccupancyMap<3>, GridFileError> {
    let nodes = read_ot_nodes(bytes, file, &["OcTree", "ColorOcTree"], false)?;
    finish(file, nodes.counts, nodes.res, model, nodes.leaves)
}

/// Reads an OctoMap `ColorOcTree` `.ot` file's bytes into a map with the sensor model `model` and the
/// colours of its leaves, at the map's keys.
///
/// A leaf's colour is its voxels' colour. OctoMap's white (255, 255, 255) is its "no colour"
/// (`isColorSet`), so a white leaf has none: its voxels are empty in the colour tree. Inner nodes' colours
/// (OctoMap's averages of their children's) are not read: a colour tree's value is a voxel's.
///
/// # Errors
/// As [`read_ot_map`]; [`GridFileErrorKind::Unsupported`] for a file of another tree type (`OcTree`).
pub fn read_color_ot_map(
    bytes: &[u8],
    file: &str,
    model: SensorModel,
) -> Result<(OccupancyMap<3>, KTree<3, Rgb>), GridFileError> {
    let nodes = read_ot_nodes(bytes, file, &["ColorOcTree"], true)?;
    let (map, colours) = finish_with_colours(file, nodes, model)?;
    Ok((map, colours.expect("a ColorOcTree read with its colours")))
}

/// Reads an OctoMap `.ot` file's bytes of either tree type into a map with the sensor model `model`, and
/// the colours of its leaves if it is a `ColorOcTree` (as [`read_color_ot_map`]; `None` for an `OcTree`).
///
/// # Errors
/// As [`read_ot_map`].
pub fn read_ot_map_with_colours(
    bytes: &[u8],
    file: &str,
    model: SensorModel,
) -> Result<(OccupancyMap<3>, Option<KTree<3, Rgb>>), GridFileError> {
    let nodes = read_ot_nodes(bytes, file, &["OcTree", "ColorOcTree"], true)?;
    finish_with_colours(file, nodes, model)
}

/// The map of nodes read and, if they were read with colours, the colour tree.
fn finish_with_colours(
    file: &str,
    nodes: OtNodes,
    model: SensorModel,
) -> Result<(OccupancyMap<3>, Option<KTree<3, Rgb>>), GridFileError> {
    let map = finish(file, nodes.counts, nodes.res, model, nodes.leaves)?;
    let Some(mut colours) = nodes.colours else {
        return Ok((map, None));
    };
    colours.sort_unstable_by_key(|l| l.0);
    let colours = tree_from_leaves::<3, Rgb>(MAP_LEVEL, &colours).map_err(|e| {
        GridFileError::new(file, nodes.counts.2, GridFileErrorKind::Data(e.to_string()))
    })?;
    Ok((map, Some(colours)))
}

/// OctoMap's colour of a node with no colour set (`ColorOcTreeNode::isColorSet`): white.
const NO_COLOUR: Rgb = [255; 3];

/// The nodes of an `.ot` file as read: the resolution, the leaves' log-odds and (if asked, for a
/// `ColorOcTree`) their colours, and the counts [`finish`] checks.
struct OtNodes {
    res: f64,
    /// Nodes read, nodes the header says, the byte after the last node read, the file's length.
    counts: (u64, u64, usize, usize),
    leaves: Vec<Leaf<f32>>,
    /// The leaves' colours, for a `ColorOcTree` read with them.
    colours: Option<Vec<Leaf<Rgb>>>,
}

/// Reads the header and the nodes of an `.ot` file whose tree type is one of `ids`: the one reader of
/// `OcTree` and `ColorOcTree` files.
fn read_ot_nodes(
    bytes: &[u8],
    file: &str,
    ids: &[&str],
    keep_colours: bool,
) -> Result<OtNodes, GridFileError> {
    let fail = |at: usize, kind| GridFileError::new(file, at, kind);
    let (id, size, res, data_at) = read_octomap_header(bytes, file, OT_HEADER, ids)?;
    let coloured = id == "ColorOcTree";
    let node_bytes = if coloured { 8 } else { 5 };
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
    let mut colours: Vec<Leaf<Rgb>> = Vec::new();
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
                if keep_colours && coloured {
                    let colour = [node[4], node[5], node[6]];
                    if colour != NO_COLOUR {
                        colours.push((morton_encode(origin), BT_DEPTH - depth, colour));
                    }
                }
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
    Ok(OtNodes {
        res,
        counts: (nodes, size, at, bytes.len()),
        leaves,
        colours: (keep_colours && coloured).then_some(colours),
    })
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
pub fn write_ot_map(w: impl Write, map: &OccupancyMap<3>) -> std::io::Result<()> {
    write_ot(w, map, None)
}

/// Writes a map and its voxels' colours (a colour tree at the map's keys) as an OctoMap `ColorOcTree`
/// `.ot` file: every node's log-odds and colour.
///
/// A leaf of the file is a leaf of the map split where its voxels' colours differ (the split nodes keep
/// its log-odds); a voxel without a colour is written white, OctoMap's "no colour" — so a voxel coloured
/// pure white reads back without one. An inner node holds what OctoMap's `updateInnerOccupancy` gives
/// it: the largest log-odds of its children and the average of their colours that are set (each channel
/// rounded down, white if none is).
///
/// ```
/// use ktree::io::{read_color_ot_map, write_color_ot_map};
/// use ktree::map::OccupancyMap;
/// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
/// map.insert(&[[1.05, 0.55, 0.25]], [0.0; 3], None).unwrap();
/// // The occupied voxel red.
/// let colours = map.log_odds().mask(&map.occupied()).map_values(|_| Some([200u8, 0, 0])).unwrap();
/// let mut bytes = Vec::new();
/// write_color_ot_map(&mut bytes, &map, &colours).unwrap();
/// let (back, back_colours) = read_color_ot_map(&bytes, "mem", *map.model()).unwrap();
/// assert_eq!((back, back_colours.value_at([32778, 32773, 32770])), (map, Some([200, 0, 0])));
/// assert_eq!(back_colours, colours);
/// ```
///
/// # Errors
/// Any I/O error of `w`; [`std::io::ErrorKind::InvalidInput`] if the colour tree is not of the map's level
/// ([`MAP_LEVEL`]) or colours a voxel the map does not know (a `ColorOcTree` colours its nodes only).
pub fn write_color_ot_map(
    w: impl Write,
    map: &OccupancyMap<3>,
    colours: &KTree<3, Rgb>,
) -> std::io::Result<()> {
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    if colours.level() != MAP_LEVEL {
        return Err(invalid(format!(
            "a map's colours are a tree of level {MAP_LEVEL}, not {}",
            colours.level()
        )));
    }
    let unknown = (&colours.shape() - &map.log_odds().shape())
        .map_err(|e| invalid(e.to_string()))?
        .voxel_count();
    if unknown > 0 {
        return Err(invalid(format!(
            "{unknown} coloured voxels are unknown in the map: a ColorOcTree colours only the voxels it \
             knows"
        )));
    }
    write_ot(w, map, Some(colours))
}

/// Writes a map as an `.ot` file: an `OcTree`, or a `ColorOcTree` with `colours`.
fn write_ot(
    mut w: impl Write,
    map: &OccupancyMap<3>,
    colours: Option<&KTree<3, Rgb>>,
) -> std::io::Result<()> {
    let tree = map.log_odds();
    let mut writer = OtWriter {
        tree,
        colours,
        data: Vec::new(),
        size: 0,
    };
    let root = InputNode::root(tree).unwrap_or_else(|e| match e {});
    if root.state != ValueState::Empty {
        let colour = colours.map(|c| InputNode::root(c).unwrap_or_else(|e| match e {}));
        writer.node(root, colour);
    }
    let id = if colours.is_some() {
        "ColorOcTree"
    } else {
        "OcTree"
    };
    write!(
        w,
        "{OT_HEADER}\n# written by ktree\nid {id}\nsize {}\nres {}\ndata\n",
        writer.size,
        map.grid().resolution()
    )?;
    w.write_all(&writer.data)?;
    w.flush()
}

/// The nodes of an `.ot` file being written, depth first.
struct OtWriter<'a> {
    tree: &'a KTree<3, f32>,
    /// The colours of a `ColorOcTree`; `None` for an `OcTree`.
    colours: Option<&'a KTree<3, Rgb>>,
    data: Vec<u8>,
    size: u64,
}

impl OtWriter<'_> {
    /// Writes `node` (not empty), whose cell's colours are `colour` (`None` for an `OcTree`), and its
    /// subtree; returns its log-odds and colour.
    fn node(&mut self, node: InputNode<f32>, colour: Option<InputNode<Rgb>>) -> (f32, Rgb) {
        self.size += 1;
        let at = self.data.len();
        let node_bytes = if self.colours.is_some() { 8 } else { 5 };
        self.data.resize(at + node_bytes, 0);
        let colour_split = colour.is_some_and(|c| c.state.has_children());
        let (value, rgb) = match node.state {
            ValueState::Full(v) if !colour_split => match colour.map(|c| c.state) {
                Some(ValueState::Full(c)) => (v, c),
                _ => (v, NO_COLOUR),
            },
            _ => {
                let mut children = 0u8;
                let mut largest = f32::NEG_INFINITY;
                let (mut sum, mut set) = ([0u32; 3], 0u32);
                for code in 0..8 {
                    let child = node.child(self.tree, code).unwrap_or_else(|e| match e {});
                    if child.state == ValueState::Empty {
                        continue;
                    }
                    let child_colour = match (self.colours, colour) {
                        (Some(tree), Some(c)) => {
                            Some(c.child(tree, code).unwrap_or_else(|e| match e {}))
                        }
                        _ => None,
                    };
                    children |= 1 << code;
                    let (l, c) = self.node(child, child_colour);
                    largest = largest.max(l);
                    if c != NO_COLOUR {
                        set += 1;
                        for (s, c) in sum.iter_mut().zip(c) {
                            *s += u32::from(c);
                        }
                    }
                }
                self.data[at + node_bytes - 1] = children;
                let average = if set == 0 {
                    NO_COLOUR
                } else {
                    sum.map(|s| (s / set) as u8)
                };
                (largest, average)
            }
        };
        self.data[at..at + 4].copy_from_slice(&value.to_le_bytes());
        if self.colours.is_some() {
            self.data[at + 4..at + 7].copy_from_slice(&rgb);
        }
        (value, rgb)
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A map of a few scans and colours on its voxels: the occupied ones coloured by their keys, the free
    /// ones alternating along x (so that a free leaf of several voxels splits).
    fn coloured_map() -> (OccupancyMap<3>, KTree<3, Rgb>) {
        let mut map = OccupancyMap::<3>::new(0.25).unwrap();
        let points: Vec<[f32; 3]> = (0..40)
            .map(|i| {
                let a = i as f32 * 0.15;
                [3.0 * a.cos(), 3.0 * a.sin(), 0.1 * i as f32 - 1.0]
            })
            .collect();
        map.insert(&points, [0.1, 0.2, 0.0], None).unwrap();
        map.insert(&points[..20], [-0.5, 0.3, 0.2], None).unwrap();
        let model = *map.model();
        // And a free leaf of 4³ voxels in a corner.
        let block = tree_from_leaves::<3, f32>(MAP_LEVEL, &[(0, 2, model.clamp_min)]).unwrap();
        let log_odds = map.log_odds().overlay(&block).unwrap();
        let map = OccupancyMap::from_log_odds(*map.grid(), model, log_odds).unwrap();
        let mut leaves: Vec<Leaf<Rgb>> = Vec::new();
        for (cell, l) in map.log_odds().value_leaves() {
            let Some(l) = l else { continue };
            let (o, side) = (cell.origin(), 1u32 << cell.log_side());
            assert!(side <= 8, "a leaf of {side}³ voxels");
            for x in o[0]..o[0] + side {
                for y in o[1]..o[1] + side {
                    for z in o[2]..o[2] + side {
                        let c = if model.is_occupied(l) {
                            [x as u8, y as u8, (z as u8).wrapping_mul(7)]
                        } else {
                            [(x % 2 * 100) as u8, 20, 30]
                        };
                        leaves.push((morton_encode([x, y, z]), 0, c));
                    }
                }
            }
        }
        leaves.sort_unstable_by_key(|l| l.0);
        let colours = tree_from_leaves::<3, Rgb>(MAP_LEVEL, &leaves).unwrap();
        (map, colours)
    }

    #[test]
    fn colours_round_trip_and_the_plain_reader_reads_the_same_map() {
        let (map, colours) = coloured_map();
        assert_eq!(colours.shape(), map.log_odds().shape());
        let mut bytes = Vec::new();
        write_color_ot_map(&mut bytes, &map, &colours).unwrap();
        // The free leaf of several voxels splits by its colours: more nodes than in the plain file.
        let mut plain = Vec::new();
        write_ot_map(&mut plain, &map).unwrap();
        let size = |b: &[u8]| {
            let text =
                String::from_utf8_lossy(&b[..b.windows(5).position(|w| w == b"data\n").unwrap()]);
            let line = text
                .lines()
                .find_map(|l| l.strip_prefix("size "))
                .unwrap()
                .to_string();
            line.parse::<u64>().unwrap()
        };
        assert!(size(&bytes) > size(&plain), "{} nodes", size(&bytes));
        let (back, back_colours) = read_color_ot_map(&bytes, "c.ot", *map.model()).unwrap();
        assert_eq!(back, map);
        assert_eq!(back_colours, colours);
        assert_eq!(read_ot_map(&bytes, "c.ot", *map.model()).unwrap(), map);
        // White is OctoMap's "no colour": a white voxel reads back without one.
        let some = colours
            .value_leaves()
            .find_map(|(c, v)| v.map(|_| c))
            .unwrap();
        let white = KTree::<3, Rgb>::from_value_runs(
            &crate::rays::ValueRuns::from_runs(
                MAP_LEVEL,
                vec![(
                    crate::Ray::new(some.origin(), some.origin()[2] + 1),
                    NO_COLOUR,
                )],
            )
            .unwrap(),
        );
        let whitened = colours.overlay(&white).unwrap();
        bytes.clear();
        write_color_ot_map(&mut bytes, &map, &whitened).unwrap();
        let (_, back_colours) = read_color_ot_map(&bytes, "w.ot", *map.model()).unwrap();
        assert_eq!(back_colours.value_at(some.origin()), None);
        assert_eq!(
            back_colours.shape().voxel_count() + 1,
            colours.shape().voxel_count()
        );
    }

    #[test]
    fn inner_nodes_hold_their_childrens_largest_log_odds_and_average_colour() {
        // Two voxels of one parent (keys 0 and 1 along x of the last level): log-odds 1 and 2, colours
        // (10, 20, 30) and none; a third sibling with (21, 0, 255).
        let leaves = [(0u64, 0u32, 1.0f32), (1, 0, 2.0), (2, 0, -1.0)];
        let tree = tree_from_leaves::<3, f32>(MAP_LEVEL, &leaves).unwrap();
        let map =
            OccupancyMap::from_log_odds(MapGrid::new(1.0).unwrap(), SensorModel::default(), tree)
                .unwrap();
        let colours =
            tree_from_leaves::<3, Rgb>(MAP_LEVEL, &[(0, 0, [10, 20, 30]), (2, 0, [21, 0, 255])])
                .unwrap();
        let mut bytes = Vec::new();
        write_color_ot_map(&mut bytes, &map, &colours).unwrap();
        let data = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        // 16 inner nodes down to the parent, then its three children.
        assert_eq!(bytes.len() - data, (16 + 3) * 8);
        for depth in 0..16 {
            let node = &bytes[data + 8 * depth..data + 8 * depth + 8];
            assert_eq!(f32::from_le_bytes(node[..4].try_into().unwrap()), 2.0);
            assert_eq!(&node[4..7], &[15, 10, 142]);
            assert_eq!(node[7], if depth == 15 { 0b111 } else { 1 });
        }
        let second = &bytes[data + 8 * 17..data + 8 * 18];
        assert_eq!(&second[4..], &[255, 255, 255, 0]);
        let (back, back_colours) = read_color_ot_map(&bytes, "i.ot", *map.model()).unwrap();
        assert_eq!((back, back_colours), (map, colours));
    }

    #[test]
    fn bad_colour_files_and_colours_name_the_problem() {
        let (map, colours) = coloured_map();
        let model = *map.model();
        let mut bytes = Vec::new();
        write_color_ot_map(&mut bytes, &map, &colours).unwrap();
        // A plain OcTree is not a ColorOcTree.
        let mut plain = Vec::new();
        write_ot_map(&mut plain, &map).unwrap();
        let e = read_color_ot_map(&plain, "plain.ot", model).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Unsupported(_)), "{e}");
        assert!(e.to_string().contains("plain.ot"), "{e}");
        // Truncated or padded, at every length of the last node.
        for cut in 1..=8 {
            let e = read_color_ot_map(&bytes[..bytes.len() - cut], "cut.ot", model).unwrap_err();
            assert!(e.to_string().contains("cut.ot"), "{e}");
        }
        let mut padded = bytes.clone();
        padded.push(0);
        let e = read_color_ot_map(&padded, "pad.ot", model).unwrap_err();
        assert_eq!(
            e.location.place,
            crate::io::Place::Byte(bytes.len() as u64),
            "{e}"
        );
        // A header claiming more nodes than the bytes hold is refused before reading them.
        let mut huge =
            format!("{OT_HEADER}\nid ColorOcTree\nsize 4000000000\nres 1\ndata\n").into_bytes();
        huge.resize(200, 0);
        let e = read_color_ot_map(&huge, "huge.ot", model).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
        // Every byte of the data changed in turn: an error or a map, never a panic.
        let data = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        for i in (data..bytes.len()).step_by(7) {
            let mut bad = bytes.clone();
            bad[i] ^= 0xa5;
            let _ = read_color_ot_map(&bad, "flip.ot", model);
        }
        // Colours where the map knows nothing, or of another level, are not written.
        let everywhere = KTree::<3>::full(MAP_LEVEL).unwrap();
        let unknown = colours
            .overlay(&everywhere.map_values(|()| Some([1u8, 2, 3])).unwrap())
            .unwrap();
        let e = write_color_ot_map(Vec::new(), &map, &unknown).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        let shallow = KTree::<3, Rgb>::from_dense_values(1, &[None; 8]).unwrap();
        let e = write_color_ot_map(Vec::new(), &map, &shallow).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
    }
}
