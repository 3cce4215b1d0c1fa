//! VTK XML files for ParaView: an unstructured grid (`.vtu`) of one voxel (octrees) or pixel (quadtrees)
//! cell per full leaf, and a hyper tree grid (`.htg`), the form VTK keeps a tree in.
//!
//! A 4-D tree goes out as a time series of its 3-D slices ([`write_time_slices`], with values
//! [`write_values_time_slices`]), with a `.pvd` collection for ParaView's time controls.
//!
//! Both carry the cell data `level` (the leaf's depth in the tree, 0 at the root) and `side` (the leaf's
//! edge in world units). Arrays are raw little-endian binary in the appended section (header UInt64).
//!
//! A valued tree ([`write_values_vtu`], [`write_values_htg`], [`write_values_vtk_file`]; K = 2, 3) is
//! written the same way, with one more cell data array, `value`, the active scalars
//! (`<CellData Scalars="value">`, which ParaView colours by): `UInt8`, `UInt16`, `UInt32`, `Int8` or
//! `Float32` by the value type, three `UInt8` components for colours (shown as they are with ParaView's
//! *Map Scalars* off). The `.vtu` has a cell per leaf where one value holds, with that value; the `.htg`
//! gives each vertex a value: a full leaf its own, a vertex with children (partial or mixed) and a masked
//! (empty) leaf NaN for `float32` and 0 for the other types.
//!
//! ```
//! use ktree::export::{vtk::write_vtu, Frame};
//! let tree = ktree::KTree::<3>::full(1).unwrap();
//! let mut bytes = Vec::new();
//! write_vtu(&mut bytes, &tree, &Frame::default()).unwrap();
//! let text = String::from_utf8_lossy(&bytes);
//! assert!(text.contains(r#"<Piece NumberOfPoints="8" NumberOfCells="1">"#));
//! ```

use std::collections::HashMap;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::{ExportError, Frame};
use crate::fs::write_atomic_with;
use crate::space::Cell;
use crate::tree::cursor::Walk;
use crate::tree::storage::TreeStorage;
use crate::tree::valued::{
    try_walk_values, BinaryValues, ValueLeaves, ValueNode, ValueStorage, ValueVisitor,
};
use crate::tree::{NodeState, StorageError, ValueState};
use crate::value::{Dtype, Value};

/// One array of the appended section.
struct Array {
    name: &'static str,
    kind: &'static str,
    components: usize,
    bytes: Vec<u8>,
}

impl Array {
    fn new(name: &'static str, kind: &'static str, components: usize) -> Self {
        Self {
            name,
            kind,
            components,
            bytes: Vec::new(),
        }
    }

    fn tag(&self, offset: u64) -> String {
        let comps = if self.components > 1 {
            format!(r#" NumberOfComponents="{}""#, self.components)
        } else {
            String::new()
        };
        format!(
            r#"<DataArray type="{}" Name="{}"{comps} format="appended" offset="{offset}"/>"#,
            self.kind, self.name
        )
    }
}

/// Writes `<AppendedData>` for `arrays` (in the order their tags were given offsets).
fn appended(w: &mut dyn Write, arrays: &[&Array]) -> io::Result<()> {
    write!(w, "  <AppendedData encoding=\"raw\">\n   _")?;
    for a in arrays {
        w.write_all(&(a.bytes.len() as u64).to_le_bytes())?;
        w.write_all(&a.bytes)?;
    }
    writeln!(w, "\n  </AppendedData>\n</VTKFile>")
}

/// Offsets of each array in the appended section, in order.
fn offsets(arrays: &[&Array]) -> Vec<u64> {
    let mut at = 0u64;
    arrays
        .iter()
        .map(|a| {
            let o = at;
            at += 8 + a.bytes.len() as u64;
            o
        })
        .collect()
}

/// The full leaves of `tree` as an unstructured grid: `VTK_VOXEL` cells (K = 3) or `VTK_PIXEL` cells
/// (K = 2, in the plane z = `frame.origin[2]`), corners shared between cells, placed by `frame`. The tree
/// is read (any storage) before anything is written.
///
/// # Errors
/// The writer's; [`io::ErrorKind::InvalidInput`] for K other than 2 and 3; a read of the tree that fails,
/// as an [`io::ErrorKind::Other`] error carrying the [`StorageError`] ([`write_vtk_file`] keeps it apart).
pub fn write_vtu<const K: usize, T: TreeStorage<K>>(
    w: &mut dyn Write,
    tree: &T,
    frame: &Frame,
) -> io::Result<()> {
    write_values_vtu(w, &BinaryValues(tree), frame)
}

/// A valued tree's full leaves as an unstructured grid, as [`write_vtu`] writes a tree without values
/// (the leaves where one value holds: a mixed node's parts are cells of their own), with the cell data
/// `value`: each cell's value, the active scalars.
///
/// ```
/// use ktree::export::{vtk::write_values_vtu, Frame};
/// let tree = ktree::KTree::<2, u8>::from_dense_values(1, &[Some(3), Some(3), None, Some(7)]).unwrap();
/// let mut bytes = Vec::new();
/// write_values_vtu(&mut bytes, &tree, &Frame::default()).unwrap();
/// let text = String::from_utf8_lossy(&bytes);
/// assert!(text.contains(r#"NumberOfCells="3""#));
/// assert!(text.contains(r#"<DataArray type="UInt8" Name="value""#));
/// ```
///
/// # Errors
/// As [`write_vtu`].
pub fn write_values_vtu<const K: usize, T: ValueStorage<K>>(
    w: &mut dyn Write,
    tree: &T,
    frame: &Frame,
) -> io::Result<()> {
    check_dimension::<K>(".vtu")?;
    Grid::of(ValueLeaves::new(tree), frame)
        .map_err(read_error)?
        .write(w)
}

/// The VTK type of a value's components and their number: `UInt8`, `UInt16`, `UInt32`, `Int8`,
/// `Float32`; three `UInt8` for a colour.
fn vtk_type(dtype: Dtype) -> (&'static str, usize) {
    match dtype {
        Dtype::U8 => ("UInt8", 1),
        Dtype::U16 => ("UInt16", 1),
        Dtype::U32 => ("UInt32", 1),
        Dtype::I8 => ("Int8", 1),
        Dtype::F32 => ("Float32", 1),
        Dtype::Rgb => ("UInt8", 3),
    }
}

/// The value a hyper tree grid gives a vertex without one (a node with children, an empty leaf): NaN
/// for `float32`, else 0 (black for colours), as little-endian bytes.
fn no_value(dtype: Dtype) -> Vec<u8> {
    if dtype == Dtype::F32 {
        f32::NAN.to_le_bytes().to_vec()
    } else {
        vec![0; dtype.bytes()]
    }
}

/// The components of a value's little-endian `bytes` as ASCII, space-separated.
fn ascii_value(dtype: Dtype, bytes: &[u8]) -> String {
    match dtype {
        Dtype::U8 | Dtype::Rgb => bytes
            .iter()
            .map(u8::to_string)
            .collect::<Vec<_>>()
            .join(" "),
        Dtype::I8 => (bytes[0] as i8).to_string(),
        Dtype::U16 => u16::from_le_bytes([bytes[0], bytes[1]]).to_string(),
        Dtype::U32 => u32::from_le_bytes(bytes.try_into().expect("4 bytes")).to_string(),
        Dtype::F32 => {
            let x = f32::from_le_bytes(bytes.try_into().expect("4 bytes"));
            if x.is_nan() {
                "nan".into()
            } else {
                format!("{x:e}")
            }
        }
    }
}

/// The arrays of a `.vtu` file, read from the tree.
struct Grid {
    points: Array,
    point_count: usize,
    connectivity: Array,
    offsets: Array,
    types: Array,
    level: Array,
    side: Array,
    /// The leaves' values, for a tree with values.
    value: Option<Array>,
    cells: u64,
}

impl Grid {
    /// The cells of the full leaves among `leaves` (a leaf's cell and its value, `None` for an empty leaf;
    /// `Some(())` for a full leaf of a tree without values), in the order given; with values, the cell
    /// data `value` too (see [`write_vtu`] and [`write_values_vtu`]).
    fn of<const K: usize, V: Value, E>(
        leaves: impl Iterator<Item = Result<(Cell<K>, Option<V>), E>>,
        frame: &Frame,
    ) -> Result<Self, E> {
        let corners = 1usize << K;
        let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
        let mut grid = Grid {
            points: Array::new("Points", "Float64", 3),
            point_count: 0,
            connectivity: Array::new("connectivity", "Int64", 1),
            offsets: Array::new("offsets", "Int64", 1),
            types: Array::new("types", "UInt8", 1),
            level: Array::new("level", "Int32", 1),
            side: Array::new("side", "Float64", 1),
            value: V::DTYPE.map(|d| {
                let (kind, components) = vtk_type(d);
                Array::new("value", kind, components)
            }),
            cells: 0,
        };
        for leaf in leaves {
            let (cell, value) = leaf?;
            let Some(value) = value else {
                continue;
            };
            if let Some(values) = &mut grid.value {
                value.write_le(&mut values.bytes);
            }
            let s = cell.side() as u32;
            for o in 0..corners {
                let p: [u32; 3] = std::array::from_fn(|a| {
                    if a < K {
                        cell.origin[a] + if o >> a & 1 == 1 { s } else { 0 }
                    } else {
                        0
                    }
                });
                let next = ids.len() as u32;
                let points = &mut grid.points;
                let id = *ids.entry(p).or_insert_with(|| {
                    for (a, &pa) in p.iter().enumerate() {
                        let x = if a < K {
                            frame.origin[a] + frame.voxel_size * f64::from(pa)
                        } else {
                            frame.origin[a]
                        };
                        points.bytes.extend_from_slice(&x.to_le_bytes());
                    }
                    next
                });
                grid.connectivity
                    .bytes
                    .extend_from_slice(&i64::from(id).to_le_bytes());
            }
            grid.cells += 1;
            grid.offsets
                .bytes
                .extend_from_slice(&((grid.cells * corners as u64) as i64).to_le_bytes());
            grid.types.bytes.push(if K == 3 { 11 } else { 8 });
            grid.level
                .bytes
                .extend_from_slice(&(cell.level as i32).to_le_bytes());
            grid.side
                .bytes
                .extend_from_slice(&(frame.voxel_size * f64::from(s)).to_le_bytes());
        }
        grid.point_count = ids.len();
        Ok(grid)
    }

    /// The `.vtu` file.
    fn write(&self, w: &mut dyn Write) -> io::Result<()> {
        let mut order = vec![
            &self.level,
            &self.side,
            &self.points,
            &self.connectivity,
            &self.offsets,
            &self.types,
        ];
        order.extend(&self.value);
        let at = offsets(&order);
        writeln!(
            w,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\">\n <UnstructuredGrid>\n  \
             <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.point_count, self.cells
        )?;
        let scalars = if self.value.is_some() {
            "value"
        } else {
            "level"
        };
        writeln!(
            w,
            "   <CellData Scalars=\"{scalars}\">\n    {}\n    {}",
            self.level.tag(at[0]),
            self.side.tag(at[1])
        )?;
        if let Some(value) = &self.value {
            writeln!(w, "    {}", value.tag(at[6]))?;
        }
        writeln!(w, "   </CellData>")?;
        writeln!(
            w,
            "   <Points>\n    {}\n   </Points>",
            self.points.tag(at[2])
        )?;
        writeln!(
            w,
            "   <Cells>\n    {}\n    {}\n    {}\n   </Cells>",
            self.connectivity.tag(at[3]),
            self.offsets.tag(at[4]),
            self.types.tag(at[5])
        )?;
        writeln!(w, "  </Piece>\n </UnstructuredGrid>")?;
        appended(w, &order)
    }
}

/// [`io::ErrorKind::InvalidInput`] unless `K` is 2 or 3, the dimensions VTK's files of `ext` hold.
fn check_dimension<const K: usize>(ext: &str) -> io::Result<()> {
    if K != 2 && K != 3 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{ext} holds quadtrees and octrees; this tree has K = {K}"),
        ));
    }
    Ok(())
}

/// A storage's read error as an I/O error that carries it.
fn read_error(e: impl Into<StorageError>) -> io::Error {
    io::Error::other(e.into())
}

/// The nodes of a tree breadth first, as VTK's hyper tree descriptor wants them: per depth, each node's
/// state in level order — [`NodeState::Partial`] for a node with children (a valued tree's mixed node
/// too) — and its value (`None` unless it is a full leaf; `Some(())` in a tree without values).
struct Depths<const K: usize, V> {
    nodes: Vec<Vec<(NodeState, Option<V>)>>,
}

impl<const K: usize, V> Depths<K, V> {
    fn push(&mut self, depth: usize, state: NodeState, value: Option<V>) {
        if self.nodes.len() <= depth {
            self.nodes.resize_with(depth + 1, Vec::new);
        }
        self.nodes[depth].push((state, value));
    }
}

impl<const K: usize, V: Value> ValueVisitor<K, V> for Depths<K, V> {
    fn visit(&mut self, node: &ValueNode<K, V>) -> Walk {
        let (state, value) = match node.state {
            ValueState::Empty => (NodeState::Empty, None),
            ValueState::Full(v) => (NodeState::Full, Some(v)),
            ValueState::Partial | ValueState::Mixed => (NodeState::Partial, None),
        };
        self.push(node.cell.level as usize, state, value);
        Walk::Descend
    }
}

/// Bits packed most significant first, as VTK's `Bit` arrays are.
fn pack_bits(bits: impl Iterator<Item = bool>) -> Vec<u8> {
    let mut out = Vec::new();
    for (i, b) in bits.enumerate() {
        if i % 8 == 0 {
            out.push(0);
        }
        if b {
            *out.last_mut().unwrap() |= 0x80 >> (i % 8);
        }
    }
    out
}

/// The tree as a VTK hyper tree grid (XML, version 2.0, ASCII arrays): one tree of branch factor 2 over
/// the universe, refined where the tree is partial, the empty leaves masked; cell data `level` and `side`
/// on every node. The file lists nodes breadth first, children in VTK's order (x fastest), which is the
/// tree's level order and child code.
///
/// # Errors
/// As [`write_vtu`].
pub fn write_htg<const K: usize, T: TreeStorage<K>>(
    w: &mut dyn Write,
    tree: &T,
    frame: &Frame,
) -> io::Result<()> {
    write_values_htg(w, &BinaryValues(tree), frame)
}

/// A valued tree as a hyper tree grid, as [`write_htg`] writes a tree without values — refined where a
/// node has children (partial or mixed), the empty leaves masked — with the cell data `value` on every
/// vertex: a full leaf's value; NaN (`float32`) or 0 (the other types; black for colours) at a vertex
/// with children and at a masked (empty) leaf, which ParaView does not draw.
///
/// ```
/// use ktree::export::{vtk::write_values_htg, Frame};
/// let tree = ktree::KTree::<2, f32>::from_dense_values(1, &[Some(0.5), None, None, Some(2.0)]).unwrap();
/// let mut bytes = Vec::new();
/// write_values_htg(&mut bytes, &tree, &Frame::default()).unwrap();
/// let text = String::from_utf8_lossy(&bytes);
/// assert!(text.contains(r#"Name="value" NumberOfTuples="5" format="ascii">nan 5e-1 nan nan 2e0 <"#));
/// ```
///
/// # Errors
/// As [`write_vtu`].
pub fn write_values_htg<const K: usize, T: ValueStorage<K>>(
    w: &mut dyn Write,
    tree: &T,
    frame: &Frame,
) -> io::Result<()> {
    check_dimension::<K>(".htg")?;
    Depths::of_values(tree)
        .map_err(read_error)?
        .write(w, tree.level(), frame)
}

impl<const K: usize, V: Value> Depths<K, V> {
    /// The nodes of a valued tree (a binary one through [`BinaryValues`]), read before anything is
    /// written. Level order is breadth first: each depth's nodes in index order, which a depth-first
    /// walk meets in the same order.
    fn of_values<T: ValueStorage<K, Value = V>>(tree: &T) -> Result<Self, T::Error> {
        let mut depths = Depths { nodes: Vec::new() };
        try_walk_values(tree, &mut depths)?;
        Ok(depths)
    }

    /// The `.htg` file of a tree of universe level `top` whose nodes these are.
    fn write(&self, w: &mut dyn Write, top: u32, frame: &Frame) -> io::Result<()> {
        let depths = self;
        let all: Vec<(NodeState, u32)> = depths
            .nodes
            .iter()
            .enumerate()
            .flat_map(|(d, nodes)| nodes.iter().map(move |(s, _)| (*s, d as u32)))
            .collect();
        let u = (1u64 << top) as f64 * frame.voxel_size;
        // The descriptor: one bit per node of every depth but the last, refined or not.
        let inner = depths.nodes.len().saturating_sub(1);
        let descriptor = pack_bits(
            depths.nodes[..inner]
                .iter()
                .flatten()
                .map(|(s, _)| *s == NodeState::Partial),
        );
        let described: usize = depths.nodes[..inner].iter().map(Vec::len).sum();
        let mask = pack_bits(all.iter().map(|(s, _)| *s == NodeState::Empty));
        let per_depth: Vec<String> = depths.nodes.iter().map(|d| d.len().to_string()).collect();
        let dims = (0..3)
            .map(|a| if a < K { "2" } else { "1" })
            .collect::<Vec<_>>()
            .join(" ");
        writeln!(
            w,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"HyperTreeGrid\" version=\"2.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt32\">\n \
         <HyperTreeGrid BranchFactor=\"2\" TransposedRootIndexing=\"0\" Dimensions=\"{dims}\">"
        )?;
        writeln!(w, "  <Grid>")?;
        for (a, name) in ["XCoordinates", "YCoordinates", "ZCoordinates"]
            .iter()
            .enumerate()
        {
            let o = frame.origin[a];
            if a < K {
                writeln!(
                w,
                "   <DataArray type=\"Float64\" Name=\"{name}\" NumberOfTuples=\"2\" format=\"ascii\" \
                 RangeMin=\"{o}\" RangeMax=\"{}\">{o} {}</DataArray>",
                o + u,
                o + u
            )?;
            } else {
                writeln!(
                w,
                "   <DataArray type=\"Float64\" Name=\"{name}\" NumberOfTuples=\"1\" format=\"ascii\" \
                 RangeMin=\"{o}\" RangeMax=\"{o}\">{o}</DataArray>"
            )?;
            }
        }
        writeln!(w, "  </Grid>\n  <Trees>")?;
        let bits = |packed: &[u8], n: usize| -> String {
            (0..n)
                .map(|i| {
                    if packed[i / 8] >> (7 - i % 8) & 1 == 1 {
                        "1"
                    } else {
                        "0"
                    }
                })
                .collect::<Vec<_>>()
                .join(" ")
        };
        let array = |w: &mut dyn Write, kind: &str, name: &str, n: usize, text: &str| {
            writeln!(
            w,
            "   <DataArray type=\"{kind}\" Name=\"{name}\" NumberOfTuples=\"{n}\" format=\"ascii\">{text}</DataArray>"
        )
        };
        array(
            w,
            "Bit",
            "Descriptors",
            described,
            &bits(&descriptor, described),
        )?;
        array(
            w,
            "Int64",
            "NumberOfVerticesPerDepth",
            per_depth.len(),
            &per_depth.join(" "),
        )?;
        array(w, "Int64", "TreeIds", 1, "0")?;
        array(
            w,
            "UInt32",
            "DepthPerTree",
            1,
            &depths.nodes.len().to_string(),
        )?;
        array(w, "Bit", "Mask", all.len(), &bits(&mask, all.len()))?;
        let scalars = if V::STORED { " Scalars=\"value\"" } else { "" };
        writeln!(w, "  </Trees>\n  <CellData{scalars}>")?;
        let levels: Vec<String> = all.iter().map(|(_, d)| d.to_string()).collect();
        let sides: Vec<String> = all
            .iter()
            .map(|(_, d)| (frame.voxel_size * (1u64 << (top - d)) as f64).to_string())
            .collect();
        array(w, "Int32", "level", all.len(), &levels.join(" "))?;
        array(w, "Float64", "side", all.len(), &sides.join(" "))?;
        if let Some(dtype) = V::DTYPE {
            let (kind, components) = vtk_type(dtype);
            let none = no_value(dtype);
            let mut bytes = Vec::new();
            let values: Vec<String> = depths
                .nodes
                .iter()
                .flatten()
                .map(|(_, value)| match value {
                    Some(v) => {
                        bytes.clear();
                        v.write_le(&mut bytes);
                        ascii_value(dtype, &bytes)
                    }
                    None => ascii_value(dtype, &none),
                })
                .collect();
            // A space after the last number: VTK's ASCII reader fails on a `nan` or `inf` that ends the
            // text.
            writeln!(
                w,
                "   <DataArray type=\"{kind}\" Name=\"value\"{} NumberOfTuples=\"{}\" \
                 format=\"ascii\">{} </DataArray>",
                if components > 1 {
                    format!(" NumberOfComponents=\"{components}\"")
                } else {
                    String::new()
                },
                all.len(),
                values.join(" ")
            )?;
        }
        writeln!(w, "  </CellData>\n </HyperTreeGrid>\n</VTKFile>")
    }
}

/// Writes `tree` to `path` as the VTK file its extension names, atomically: `.vtu` ([`write_vtu`]) or
/// `.htg` ([`write_htg`]), placed by `frame`. The tree (any storage) is read before the file is opened.
///
/// ```
/// use ktree::export::{vtk::write_vtk_file, Frame};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("square.htg");
/// write_vtk_file(&path, &ktree::KTree::<2>::full(2).unwrap(), &Frame::default()).unwrap();
/// assert!(std::fs::read_to_string(&path).unwrap().contains("HyperTreeGrid"));
/// ```
///
/// # Errors
/// [`ExportError::Usage`] for another extension or a tree that is not a quadtree or an octree;
/// [`ExportError::Storage`] if a read of the tree fails; [`ExportError::Write`] from the file system.
pub fn write_vtk_file<const K: usize, T: TreeStorage<K>>(
    path: &Path,
    tree: &T,
    frame: &Frame,
) -> Result<(), ExportError> {
    write_values_vtk_file(path, &BinaryValues(tree), frame)
}

/// Writes the valued tree `tree` to `path` as the VTK file its extension names, atomically: `.vtu`
/// ([`write_values_vtu`]) or `.htg` ([`write_values_htg`]), placed by `frame`; the values are the cell
/// data `value`. The tree (any storage) is read before the file is opened.
///
/// ```
/// use ktree::export::{vtk::write_values_vtk_file, Frame};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("colours.vtu");
/// let tree = ktree::KTree::<3, ktree::value::Rgb>::from_dense_values(0, &[Some([255, 0, 0])]).unwrap();
/// write_values_vtk_file(&path, &tree, &Frame::default()).unwrap();
/// let text = String::from_utf8_lossy(&std::fs::read(&path).unwrap()).into_owned();
/// assert!(text.contains(r#"<DataArray type="UInt8" Name="value" NumberOfComponents="3""#));
/// ```
///
/// # Errors
/// As [`write_vtk_file`].
pub fn write_values_vtk_file<const K: usize, T: ValueStorage<K>>(
    path: &Path,
    tree: &T,
    frame: &Frame,
) -> Result<(), ExportError> {
    let htg = vtk_file_kind::<K>(path)?;
    let storage = |e: T::Error| ExportError::Storage(e.into());
    if htg {
        let depths = Depths::of_values(tree).map_err(storage)?;
        write_atomic_with(path, |w| depths.write(w, tree.level(), frame))
    } else {
        let grid = Grid::of(ValueLeaves::new(tree), frame).map_err(storage)?;
        write_atomic_with(path, |w| grid.write(w))
    }
    .map_err(ExportError::Write)
}

/// Whether `path` names a `.htg` file (else a `.vtu` one); [`ExportError::Usage`] for another extension
/// or a dimension VTK's files do not hold.
fn vtk_file_kind<const K: usize>(path: &Path) -> Result<bool, ExportError> {
    let usage = |message: String| ExportError::Usage {
        file: path.to_path_buf(),
        message,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext != "vtu" && ext != "htg" {
        return Err(usage("a VTK file is written as .vtu or .htg".into()));
    }
    if K != 2 && K != 3 {
        return Err(usage(format!(
            "VTK files are written for quadtrees and octrees (K = 2, 3); this tree has K = {K}"
        )));
    }
    Ok(ext == "htg")
}

/// A 4-D tree as a time series for ParaView: the octree of each slice along `time_axis` (the other axes
/// in order, placed by `frame`) written beside `path` as `STEM_NNNN.vtu` (or `.htg`), atomically. With
/// `path` ending in `.pvd`, the slices are `.vtu` files and `path` is a VTK collection listing them, the
/// timestep being the slice's position; with `.vtu` or `.htg`, only the slices are written. Returns the
/// files written.
///
/// ```
/// use ktree::export::{vtk::write_time_slices, Frame};
/// let dir = tempfile::tempdir().unwrap();
/// let tree = ktree::KTree::<4>::full(1).unwrap();
/// let files = write_time_slices(&dir.path().join("run.pvd"), &tree, 3, &Frame::default()).unwrap();
/// assert_eq!(files.len(), 3); // two slices and the collection
/// assert!(files[0].ends_with("run_0000.vtu"));
/// ```
///
/// # Errors
/// [`ExportError::Usage`] for another extension or an axis past 3; [`ExportError::Storage`] if a read of
/// the tree fails; [`ExportError::Write`] from the file system.
pub fn write_time_slices<T: TreeStorage<4>>(
    path: &Path,
    tree: &T,
    time_axis: usize,
    frame: &Frame,
) -> Result<Vec<PathBuf>, ExportError> {
    write_values_time_slices(path, &BinaryValues(tree), time_axis, frame)
}

/// A 4-D tree with values as a time series for ParaView, as [`write_time_slices`] writes a tree without:
/// each slice along `time_axis` ([`crate::ops::slice_values`]) an octree with its `value` cell data
/// ([`write_values_vtu`], [`write_values_htg`]).
///
/// ```
/// use ktree::export::{vtk::write_values_time_slices, Frame};
/// use ktree::KTree;
/// // Two time steps of a 2⁴ universe: label 1 at t = 0, label 2 at t = 1, over the whole space.
/// let dense: Vec<Option<u8>> = (0..16).map(|i| Some(1 + (i / 8) as u8)).collect();
/// let tree = KTree::<4, u8>::from_dense_values(1, &dense).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let files = write_values_time_slices(&dir.path().join("run.pvd"), &tree, 3, &Frame::default()).unwrap();
/// assert_eq!(files.len(), 3);
/// let second = std::fs::read(&files[1]).unwrap(); // XML with raw binary arrays appended
/// assert!(String::from_utf8_lossy(&second).contains(r#"Name="value""#));
/// ```
///
/// # Errors
/// As [`write_time_slices`].
pub fn write_values_time_slices<T: ValueStorage<4>>(
    path: &Path,
    tree: &T,
    time_axis: usize,
    frame: &Frame,
) -> Result<Vec<PathBuf>, ExportError> {
    let side = tree.universe().side();
    write_time_series(path, side, time_axis, |file, t, htg| {
        let slice =
            crate::ops::slice_values::<4, 3, T>(tree, time_axis, t).map_err(|e| match e {
                crate::ops::OpsError::Storage(e) => ExportError::Storage(e),
                e => ExportError::Usage {
                    file: path.to_path_buf(),
                    message: e.to_string(),
                },
            })?;
        write_atomic_with(file, |w| {
            if htg {
                write_values_htg(w, &slice, frame)
            } else {
                write_values_vtu(w, &slice, frame)
            }
        })
        .map_err(ExportError::Write)
    })
}

/// The time series of a 4-D tree of side `side`: `write_slice(file, t, htg)` writes the slice at `t` to
/// `file` (a `.htg` if `htg`, else a `.vtu`); the files are named and the `.pvd` collection written as
/// [`write_time_slices`] says.
fn write_time_series(
    path: &Path,
    side: u64,
    time_axis: usize,
    mut write_slice: impl FnMut(&Path, u32, bool) -> Result<(), ExportError>,
) -> Result<Vec<PathBuf>, ExportError> {
    let usage = |message: String| ExportError::Usage {
        file: path.to_path_buf(),
        message,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let (slice_ext, collection) = match ext.as_str() {
        "pvd" => ("vtu", true),
        "vtu" | "htg" => (ext.as_str(), false),
        _ => {
            return Err(usage(
                "a time series is written as .pvd (with .vtu slices), .vtu or .htg".into(),
            ))
        }
    };
    if time_axis > 3 {
        return Err(usage(format!(
            "--time-axis {time_axis}: a 4-D tree has axes 0 … 3"
        )));
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = path.parent().unwrap_or(Path::new(""));
    let digits = side.saturating_sub(1).to_string().len().max(4);
    let mut written = Vec::new();
    let mut entries = String::new();
    for t in 0..side as u32 {
        let name = format!("{stem}_{t:0digits$}.{slice_ext}");
        let file = dir.join(&name);
        write_slice(&file, t, slice_ext == "htg")?;
        entries.push_str(&format!(
            "  <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
            xml_escape(&name)
        ));
        written.push(file);
    }
    if collection {
        let text = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n <Collection>\n{entries} </Collection>\n</VTKFile>\n"
        );
        crate::fs::write_atomic(path, text.as_bytes()).map_err(ExportError::Write)?;
        written.push(path.to_path_buf());
    }
    Ok(written)
}

/// `text` with XML's special characters escaped, for an attribute.
fn xml_escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
