//! The Python module `ktree`: k-trees (K = 1…4) with numpy arrays in and out.
//!
//! One class, `ktree.Tree`, wraps the library's [`AnyTree`]; `K` comes from the input (an array's `ndim`, a
//! ray array's width, a file's header). Every call that may take long releases the interpreter lock, and
//! every error of the library becomes a Python exception (`ValueError` for bad input, `OSError` for files)
//! with the library's message.

use std::ffi::CString;
use std::path::PathBuf;

use ktree::display::{self, HiddenLineMethod, RenderOptions, ISO_TOWARD_EYE};
use ktree::ops::{self, BoolOp};
use ktree::shape::{Element, ShapeError};
use ktree::solid::mesh::{MeshTransform, TriangleMesh};
use ktree::solid::volume::{Select, Volume};
use ktree::space::{Universe, DENSE_LIMIT};
use ktree::AnyTree;
use ktree::{with_dim, KTree};
use numpy::ndarray::{Array3, ArrayViewD};
use numpy::{
    AllowTypeChange, IntoPyArray, PyArray2, PyArray3, PyArrayDyn, PyArrayLike2, PyArrayLikeDyn,
};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyString};

mod failure;
mod files;
mod geometry;
mod queries;
mod rays;

use failure::Failure;
use geometry::Factor;

/// Runs `$body` with `K` bound as a constant, for `$k` in 1…4, or fails.
macro_rules! with_k {
    ($k:expr, $what:expr, K => $body:expr) => {
        match $k {
            1 => {
                const K: usize = 1;
                $body
            }
            2 => {
                const K: usize = 2;
                $body
            }
            3 => {
                const K: usize = 3;
                $body
            }
            4 => {
                const K: usize = 4;
                $body
            }
            k => Err(Failure::Value(format!(
                "{}: K = {k} is not supported (1 to 4)",
                $what
            ))),
        }
    };
}

/// A k-tree of dimension K = 1…4 (bintree, quadtree, octree, 4-D tree) over a universe of side 2**level.
///
/// Coordinates are `[x, y, z, ...]` as in the command-line tool: a dense array `a` has `a[x, y, z]` for
/// voxel (x, y, z), and rays run along the last axis. Trees are immutable: operations return new trees.
/// Two trees compare equal when they hold the same object in the same universe.
#[pyclass(frozen, name = "Tree", module = "ktree")]
struct Tree {
    inner: AnyTree,
}

impl Tree {
    fn wrap(inner: impl Into<AnyTree>) -> Self {
        Self {
            inner: inner.into(),
        }
    }
}

/// The smallest level whose side holds `n` voxels.
fn level_for(n: usize) -> u32 {
    n.max(1).next_power_of_two().trailing_zeros()
}

/// The dense array (axis 0 fastest, as the library lays it out) of a numpy array indexed `[x, y, z, …]`,
/// placed at the origin of a universe of level `level`.
fn dense_of_view<const K: usize>(
    view: &ArrayViewD<'_, bool>,
    level: u32,
) -> Result<Vec<bool>, Failure> {
    let universe = Universe::<K>::new(level)?;
    let len = universe.dense_len(DENSE_LIMIT)?;
    let side = universe.side() as usize;
    if let Some(n) = view.shape().iter().find(|&&n| n > side) {
        return Err(Failure::Value(format!(
            "an array of shape {:?} does not fit a level-{level} universe of side {side} ({n} > {side})",
            view.shape()
        )));
    }
    let mut dense = vec![false; len];
    if view.shape().iter().all(|&n| n == side) {
        // Reversing the axes makes axis 0 the fastest in logical order.
        for (d, &v) in dense.iter_mut().zip(view.t().iter()) {
            *d = v;
        }
    } else {
        for (index, &v) in view.indexed_iter() {
            if v {
                let flat = (0..K).rev().fold(0, |acc, a| acc * side + index[a]);
                dense[flat] = true;
            }
        }
    }
    Ok(dense)
}

/// A view direction from the object towards the viewer: a name or three numbers.
fn view_direction(view: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    if let Ok(name) = view.cast::<PyString>() {
        let view: display::View = name
            .to_str()?
            .parse()
            .map_err(|e: display::ViewError| Failure::Value(e.to_string()))?;
        return Ok(view.toward_eye());
    }
    let v: [f64; 3] = view.extract().map_err(|_| {
        Failure::Value("a view is a name or three numbers (x, y, z) towards the viewer".into())
    })?;
    display::View::new(v)
        .map(|v| v.toward_eye())
        .map_err(|e| Failure::Value(e.to_string()).into())
}

/// The plane of a rotation: an axis name in 3-D or a pair of axes.
fn rotation_plane(k: usize, axes: &Bound<'_, PyAny>) -> PyResult<(usize, usize)> {
    if let Ok(name) = axes.cast::<PyString>() {
        return match (name.to_str()?, k) {
            ("x", 3) => Ok((1, 2)),
            ("y", 3) => Ok((2, 0)),
            ("z", 3) => Ok((0, 1)),
            (other, _) => Err(Failure::Value(format!(
                "axis '{other}': named axes x, y, z are for K = 3; give a pair of axes (i, j) for K = {k}"
            ))
            .into()),
        };
    }
    axes.extract::<(usize, usize)>().map_err(|_| {
        Failure::Value("axes must be a pair (i, j) (or 'x', 'y', 'z' in 3-D)".into()).into()
    })
}

/// A mesh placement: `(s, tx, ty, tz)` (voxel = s·v + t), or fitted into the universe.
fn placement(
    mesh: &TriangleMesh,
    level: u32,
    transform: Option<[f64; 4]>,
) -> Result<MeshTransform, Failure> {
    match transform {
        Some([scale, tx, ty, tz]) => {
            if !(scale.is_finite() && tx.is_finite() && ty.is_finite() && tz.is_finite()) {
                return Err(Failure::Value(format!(
                    "transform {:?} must be four finite numbers",
                    [scale, tx, ty, tz]
                )));
            }
            Ok(MeshTransform {
                scale,
                translate: [tx, ty, tz],
            })
        }
        None => Ok(MeshTransform::fit(mesh, level)?),
    }
}

/// Voxelizes a mesh, warning (as the command-line tool does) when the mesh is not closed.
fn mesh_tree(
    py: Python<'_>,
    mesh: TriangleMesh,
    level: u32,
    transform: Option<[f64; 4]>,
    name: &str,
) -> PyResult<Tree> {
    let (tree, open_edges) = py.detach(|| -> Result<_, Failure> {
        let placed = placement(&mesh, level, transform)?;
        let r = mesh.to_rays(level, &placed)?;
        Ok((KTree::from_rays(&r.rays), r.open_edges))
    })?;
    if open_edges > 0 {
        let message = format!(
            "{name}: the mesh is not closed ({open_edges} edges not shared by exactly two triangles); inside is \
             decided by the winding along each column, so some columns may leak or lose runs"
        );
        let message = CString::new(message).unwrap_or_default();
        PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, 1)?;
    }
    Ok(Tree::wrap(tree))
}

/// Runs a Boolean operation without the interpreter lock.
/// The surface area and, for K = 2 and 3, the Euler number (connectivity K), as `ktree stats --json` adds them.
fn add_measures(py: Python<'_>, tree: &AnyTree, d: &Bound<'_, PyDict>) -> PyResult<()> {
    fn of<const K: usize>(t: &KTree<K>) -> (u128, Option<i64>) {
        let euler = matches!(K, 2 | 3).then(|| t.euler_number(K).ok()).flatten();
        (t.surface_area(), euler)
    }
    let (area, euler) = py.detach(|| with_dim!(tree, AnyTree, t => of(t)));
    d.set_item("surface_area", area)?;
    if let Some(e) = euler {
        d.set_item("euler_number", e)?;
    }
    Ok(())
}

/// A morphology operation on the wrapped tree.
fn morph(
    py: Python<'_>,
    tree: &Tree,
    r: f64,
    shape: &str,
    op: fn(&AnyTree, f64, Element) -> Result<AnyTree, ShapeError>,
) -> PyResult<Tree> {
    let element: Element = shape.parse().map_err(Failure::Value)?;
    let out = py.detach(|| op(&tree.inner, r, element).map_err(Failure::value))?;
    Ok(Tree { inner: out })
}

fn boolean(py: Python<'_>, a: &Tree, b: &Tree, op: BoolOp) -> PyResult<Tree> {
    let out = py.detach(|| a.inner.boolean(&b.inner, op).map_err(Failure::from))?;
    Ok(Tree { inner: out })
}

#[pymethods]
impl Tree {
    /// The tree of a boolean array indexed `[x, y, z, ...]` (K = `array.ndim`, 1 to 4). The array is placed
    /// at the origin of a universe of level `level` (default: the smallest whose side 2**level holds the
    /// longest axis); other values than booleans are converted by numpy (non-zero is inside).
    #[staticmethod]
    #[pyo3(signature = (array, level = None))]
    fn from_dense(
        py: Python<'_>,
        array: PyArrayLikeDyn<'_, bool, AllowTypeChange>,
        level: Option<u32>,
    ) -> PyResult<Self> {
        let view = array.as_array();
        let level =
            level.unwrap_or_else(|| level_for(view.shape().iter().copied().max().unwrap_or(1)));
        let tree = with_k!(view.ndim(), "from_dense: an array with that many dimensions", K => {
            let dense = dense_of_view::<K>(&view, level)?;
            py.detach(|| KTree::<K>::from_dense(level, &dense).map(AnyTree::from).map_err(Failure::from))
        })?;
        Ok(Self { inner: tree })
    }

    /// The empty tree of dimension `k` and level `level`.
    #[staticmethod]
    fn empty(k: usize, level: u32) -> PyResult<Self> {
        let tree = with_k!(k, "empty", K => KTree::<K>::empty(level).map(AnyTree::from).map_err(Failure::from))?;
        Ok(Self { inner: tree })
    }

    /// The tree of the whole universe of dimension `k` and level `level`.
    #[staticmethod]
    fn full(k: usize, level: u32) -> PyResult<Self> {
        let tree = with_k!(k, "full", K => KTree::<K>::full(level).map(AnyTree::from).map_err(Failure::from))?;
        Ok(Self { inner: tree })
    }

    /// The tree of runs along the last axis: an `(n, K + 1)` integer array whose rows are a column's `K - 1`
    /// coordinates, then `z1` and `z2` (the run covers `z1 <= z < z2`), in a universe of level `level`.
    /// Runs of a column that overlap or touch are merged. The tree is built by stacking.
    #[staticmethod]
    fn from_rays(
        py: Python<'_>,
        rays: PyArrayLike2<'_, i64, AllowTypeChange>,
        level: u32,
    ) -> PyResult<Self> {
        let view = rays.as_array();
        let what = format!(
            "from_rays: an array of {} columns (K + 1 for K = 1 to 4)",
            view.ncols()
        );
        let tree = with_k!(view.ncols().wrapping_sub(1), what, K => {
            let set = rays::rays_of_array::<K>(view, level)?;
            Ok(AnyTree::from(py.detach(|| KTree::from_rays(&set))))
        })?;
        Ok(Self { inner: tree })
    }

    /// The tree's voxels as runs along the last axis: an `(n, K + 1)` int64 array as `from_rays` reads
    /// (maximal runs, columns in lexicographic order).
    fn to_rays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let array = py.detach(|| with_dim!(&self.inner, AnyTree, t => rays::tree_rays(t).map(|r| rays::array_of_rays(&r))))?;
        Ok(array.into_pyarray(py))
    }

    /// The octree of a triangle mesh file (OBJ, STL, PLY) in a universe of level `level`. `transform`
    /// `(s, tx, ty, tz)` places vertex v at voxel s*v + t; without it the mesh is scaled and centred to fit
    /// with one voxel of margin. Voxels whose centres are inside are in the tree. A mesh that is not closed
    /// gives a `UserWarning`.
    #[staticmethod]
    #[pyo3(signature = (path, level, transform = None))]
    fn from_mesh(
        py: Python<'_>,
        path: PathBuf,
        level: u32,
        transform: Option<[f64; 4]>,
    ) -> PyResult<Self> {
        let mesh =
            py.detach(|| ktree::io::read_mesh(&path).map_err(|e| Failure::of_error(&e, &path)))?;
        mesh_tree(py, mesh, level, transform, &path.display().to_string())
    }

    /// The octree of a triangle mesh given as an `(n, 3)` float array of vertices and an `(m, 3)` integer
    /// array of triangles (vertex indices, counter-clockwise seen from outside); otherwise as `from_mesh`.
    #[staticmethod]
    #[pyo3(signature = (vertices, faces, level, transform = None))]
    fn from_mesh_arrays(
        py: Python<'_>,
        vertices: PyArrayLike2<'_, f64, AllowTypeChange>,
        faces: PyArrayLike2<'_, i64, AllowTypeChange>,
        level: u32,
        transform: Option<[f64; 4]>,
    ) -> PyResult<Self> {
        let (v, f) = (vertices.as_array(), faces.as_array());
        if v.ncols() != 3 || f.ncols() != 3 {
            return Err(Failure::Value(format!(
                "vertices must be (n, 3) and faces (m, 3), got {:?} and {:?}",
                v.shape(),
                f.shape()
            ))
            .into());
        }
        let n = v.nrows();
        let vertices: Vec<[f64; 3]> = v.outer_iter().map(|r| [r[0], r[1], r[2]]).collect();
        let mut triangles = Vec::with_capacity(f.nrows());
        for (i, r) in f.outer_iter().enumerate() {
            let mut t = [0u32; 3];
            for (slot, &x) in t.iter_mut().zip(r.iter()) {
                *slot = u32::try_from(x)
                    .ok()
                    .filter(|&x| (x as usize) < n)
                    .ok_or_else(|| {
                        Failure::Value(format!("face {i}: vertex index {x} is not below {n}"))
                    })?;
            }
            triangles.push(t);
        }
        if let Some(i) = vertices
            .iter()
            .position(|p| p.iter().any(|x| !x.is_finite()))
        {
            return Err(Failure::Value(format!("vertex {i} is not finite")).into());
        }
        let mesh = TriangleMesh::new(vertices, triangles).map_err(Failure::value)?;
        mesh_tree(py, mesh, level, transform, "from_mesh_arrays")
    }

    /// The octree of the voxels holding points of an `(n, 3)` float array: point p is in voxel
    /// `floor((p - origin) / voxel_size)` (as numpy computes it), `origin` defaults to the points' minimum
    /// corner and `level` to the smallest that holds every voxel; with `level` given, points outside the
    /// universe are a `ValueError`.
    #[staticmethod]
    #[pyo3(signature = (points, voxel_size, origin = None, level = None))]
    fn from_points(
        py: Python<'_>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        voxel_size: f64,
        origin: Option<[f64; 3]>,
        level: Option<u32>,
    ) -> PyResult<Self> {
        let p = points.as_array();
        if p.ncols() != 3 {
            return Err(
                Failure::Value(format!("points must be (n, 3), got {:?}", p.shape())).into(),
            );
        }
        let points: Vec<[f64; 3]> = p.outer_iter().map(|r| [r[0], r[1], r[2]]).collect();
        let tree = py.detach(|| KTree::from_points(&points, voxel_size, origin, level));
        let hint = match &tree {
            Err(ktree::solid::SolidError::PointsOutside { .. }) => {
                ": use a larger level or voxel_size, or another origin"
            }
            Err(ktree::solid::SolidError::PointBelowOrigin { .. }) => {
                ": give another origin (or none: the points' minimum corner)"
            }
            _ => "",
        };
        Ok(Tree::wrap(
            tree.map_err(|e| Failure::Value(format!("{e}{hint}")))?,
        ))
    }

    /// The octree of a volume file (a .json sidecar or its .raw, .nii, .nii.gz): samples with value
    /// `>= threshold` (or `== label`) are inside. The volume's sample (0, 0, 0) goes to voxel `offset`
    /// (default (0, 0, 0)); `level` defaults to the smallest that holds the volume.
    #[staticmethod]
    #[pyo3(signature = (path, threshold = None, *, label = None, level = None, offset = None))]
    fn from_volume(
        py: Python<'_>,
        path: PathBuf,
        threshold: Option<f64>,
        label: Option<f64>,
        level: Option<u32>,
        offset: Option<(u32, u32, u32)>,
    ) -> PyResult<Self> {
        let offset = offset.unwrap_or((0, 0, 0));
        let select = match (threshold, label) {
            (Some(t), None) => Select::AtLeast(t),
            (None, Some(l)) => Select::Label(l),
            _ => {
                return Err(Failure::Value("give exactly one of threshold and label".into()).into())
            }
        };
        let tree = py.detach(|| -> Result<_, Failure> {
            let v = Volume::read(&path)?;
            let level = level.unwrap_or_else(|| v.fitting_level());
            let rays = v.to_rays(level, [offset.0, offset.1, offset.2], select)?;
            Ok(KTree::from_rays(&rays))
        })?;
        Ok(Self::wrap(tree))
    }

    /// Reads a tree file; the format is chosen by the extension.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let tree = py.detach(|| files::read_tree(&path))?;
        Ok(Self { inner: tree })
    }

    /// Writes the tree (atomically: a temporary file renamed); the format is chosen by the extension.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        Ok(py.detach(|| files::write_tree(&path, &self.inner))?)
    }

    /// The tree in the `.ktree` format (version 2: 2 bits a node, checksums per level), as bytes.
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = py.detach(|| {
            let mut out = Vec::new();
            with_dim!(&self.inner, AnyTree, t => ktree::io::write_ktree(&mut out, t)).map(|()| out)
        });
        let bytes = bytes.map_err(Failure::value)?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The tree of bytes in the `.ktree` format (as `to_bytes` gives).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let tree =
            py.detach(|| ktree::io::read_ktree_any(data, "<bytes>").map_err(Failure::value))?;
        Ok(Self { inner: tree })
    }

    /// Pickling: the tree is rebuilt from its `.ktree` bytes.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let rebuild = slf.get_type().getattr("from_bytes")?;
        Ok((rebuild, (slf.get().to_bytes(slf.py())?,)))
    }

    /// The dimension K.
    #[getter]
    fn k(&self) -> usize {
        self.inner.k()
    }

    /// The universe level L (the side is 2**L).
    #[getter]
    fn level(&self) -> u32 {
        self.inner.level()
    }

    /// The universe's side, 2**level.
    #[getter]
    fn side(&self) -> u64 {
        1u64 << self.inner.level()
    }

    /// The number of voxels inside the object.
    #[getter]
    fn voxel_count(&self, py: Python<'_>) -> u128 {
        py.detach(|| with_dim!(&self.inner, AnyTree, t => t.voxel_count()))
    }

    /// The number of nodes.
    #[getter]
    fn node_count(&self) -> u64 {
        self.inner.counts().nodes()
    }

    /// The voxels of a window as a boolean array indexed `[x, y, z, ...]`: `shape` voxels from `origin` (K
    /// integers each; voxels outside the universe are False). By default the window is the bounding box
    /// of the full voxels (from `origin` when only it is given), not the universe: an empty tree gives an
    /// array of shape (0,) * K. `to_dense((0,) * k, (side,) * k)` is the whole universe.
    #[pyo3(signature = (origin = None, shape = None))]
    fn to_dense<'py>(
        &self,
        py: Python<'py>,
        origin: Option<Vec<i64>>,
        shape: Option<Vec<usize>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<bool>>> {
        let k = self.inner.k();
        for (name, len) in [
            ("origin", origin.as_ref().map(Vec::len)),
            ("shape", shape.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&n| n != k) {
                return Err(Failure::Value(format!(
                    "to_dense: {name} of a K = {k} tree has {k} numbers, got {len}"
                ))
                .into());
            }
        }
        let array = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let (o, s) = queries::default_window(
                    t,
                    origin.as_ref().map(|o| std::array::from_fn(|a| o[a])),
                    shape.as_ref().map(|s| std::array::from_fn(|a| s[a])),
                );
                queries::window(t, o, s)
            })
        })?;
        Ok(array.into_pyarray(py))
    }

    /// Signed distances of a window as a float32 array indexed `[x, y, z, ...]`: Euclidean between voxel
    /// centres, positive outside (to the nearest full voxel), negative inside (to the nearest empty voxel)
    /// — scipy's `distance_transform_edt(~a) - distance_transform_edt(a)` on the whole universe as `a`
    /// (the window sees the whole tree, not only itself); inf for an empty tree, -inf for a full universe.
    /// The window is `shape` voxels from `origin`, inside the universe; by default the bounding box of the
    /// full voxels (from `origin` when only it is given).
    #[pyo3(signature = (origin = None, shape = None))]
    fn signed_distance<'py>(
        &self,
        py: Python<'py>,
        origin: Option<Vec<i64>>,
        shape: Option<Vec<usize>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let k = self.inner.k();
        for (name, len) in [
            ("origin", origin.as_ref().map(Vec::len)),
            ("shape", shape.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&n| n != k) {
                return Err(Failure::Value(format!(
                    "signed_distance: {name} of a K = {k} tree has {k} numbers, got {len}"
                ))
                .into());
            }
        }
        let array = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let (o, s) = queries::default_window(
                    t,
                    origin.as_ref().map(|o| std::array::from_fn(|a| o[a])),
                    shape.as_ref().map(|s| std::array::from_fn(|a| s[a])),
                );
                queries::signed_distance(t, o, s)
            })
        })?;
        Ok(array.into_pyarray(py))
    }

    /// Whether voxels are inside: one point (K integers) gives a bool, an `(N, K)` integer array an
    /// `(N,)` bool array (answered on all threads without the interpreter lock: a large batch first
    /// through a table of the tree's top levels, the points it leaves open in Morton order).
    /// Points outside the universe (negative ones too) are outside.
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLikeDyn<'py, i64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rows = queries::rows(&points.as_array(), self.inner.k(), "contains: the points")?;
        let inside =
            py.detach(|| with_dim!(&self.inner, AnyTree, t => queries::contains(t, &rows.flat)));
        if rows.single {
            return Ok(pyo3::types::PyBool::new(py, inside[0])
                .to_owned()
                .into_any());
        }
        Ok(inside.into_pyarray(py).into_any())
    }

    /// `tree[x, y, z]`: whether that voxel is inside (False outside the universe). With slices,
    /// `tree[x0:x1, y0:y1, z0:z1]` is the dense window of those voxels (as numpy slices the universe: negative
    /// bounds count from its side, bounds are clipped to it, steps must be 1; an integer drops its axis).
    fn __getitem__<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = self.inner.k();
        let items: Vec<Bound<'py, PyAny>> = match key.cast::<pyo3::types::PyTuple>() {
            Ok(t) => t.iter().collect(),
            Err(_) => vec![key.clone()],
        };
        if items.len() != k {
            return Err(pyo3::exceptions::PyIndexError::new_err(format!(
                "a K = {k} tree is indexed by {k} integers or slices, got {}",
                items.len()
            )));
        }
        let side = 1i64 << self.inner.level();
        let mut origin = vec![0i64; k];
        let mut shape = vec![1usize; k];
        let mut dropped = Vec::new();
        for (a, item) in items.iter().enumerate() {
            if let Ok(slice) = item.cast::<pyo3::types::PySlice>() {
                let ix = slice.indices(side as isize)?;
                if ix.step != 1 {
                    return Err(Failure::Value(format!(
                        "tree[...]: slice steps must be 1, got {} on axis {a}",
                        ix.step
                    ))
                    .into());
                }
                origin[a] = ix.start as i64;
                shape[a] = (ix.stop - ix.start).max(0) as usize;
            } else {
                origin[a] = item.extract::<i64>().map_err(|_| {
                    pyo3::exceptions::PyTypeError::new_err(format!(
                        "tree[...]: axis {a} takes an integer or a slice"
                    ))
                })?;
                dropped.push(a);
            }
        }
        if dropped.len() == k {
            let inside = with_dim!(&self.inner, AnyTree, t => queries::contains(t, &origin));
            return Ok(pyo3::types::PyBool::new(py, inside[0])
                .to_owned()
                .into_any());
        }
        let mut array = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => queries::window(
                t,
                std::array::from_fn(|a| origin[a]),
                std::array::from_fn(|a| shape[a]),
            ))
        })?;
        for &a in dropped.iter().rev() {
            array = array.index_axis_move(numpy::ndarray::Axis(a), 0);
        }
        Ok(array.into_pyarray(py).into_any())
    }

    /// The bounding box of the full voxels as `(lo, hi)` (K integers each, hi exclusive), or None when
    /// the tree is empty.
    fn bounding_box(&self, py: Python<'_>) -> Option<(Vec<u32>, Vec<u32>)> {
        py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => t.bounding_box().map(|(lo, hi)| (lo.to_vec(), hi.to_vec())))
        })
    }

    /// The full leaves as an `(n, K + 1)` int64 array: each row a cell's corner coordinates (its smallest
    /// voxel), then its side; rows in Morton order.
    fn cells<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        py.detach(|| with_dim!(&self.inner, AnyTree, t => queries::cells(t)))
            .into_pyarray(py)
    }

    /// Casts rays `origin + t * direction` (`(N, K)` float arrays, or one ray as K numbers each) for
    /// `0 <= t <= max_t`: a `RayHits` named tuple of `hit` (N,) bool, `voxel` (N, K) int64 (the first full
    /// voxel entered; -1s for a miss), `t` (N,) float64 (inf for a miss; 0 when the origin is in a full
    /// voxel), `axis` and `sign` (N,) int8 of the face entered (sign -1: the face at voxel[axis], entered
    /// moving up the axis; -1 and 0 for a miss or an origin inside). Where a ray passes exactly through an
    /// edge or corner shared by full voxels, the voxel is the one the ray is inside just after. Infinite or
    /// NaN coordinates are a ValueError.
    #[pyo3(signature = (origins, directions, max_t = f64::INFINITY))]
    fn cast_rays<'py>(
        &self,
        py: Python<'py>,
        origins: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        directions: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        max_t: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = self.inner.k();
        let o = queries::rows(&origins.as_array(), k, "cast_rays: the origins")?;
        let d = queries::rows(&directions.as_array(), k, "cast_rays: the directions")?;
        let casts = py.detach(
            || with_dim!(&self.inner, AnyTree, t => queries::cast(t, &o.flat, &d.flat, max_t)),
        )?;
        let hits = py.import("ktree")?.getattr("RayHits")?;
        hits.call1((
            casts.hit.into_pyarray(py),
            casts.voxel.into_pyarray(py),
            casts.t.into_pyarray(py),
            casts.axis.into_pyarray(py),
            casts.sign.into_pyarray(py),
        ))
    }

    /// The distance from each voxel's centre to the nearest full voxel's (as scipy's
    /// `distance_transform_edt(~dense)` measures it): 0 inside, inf for an empty tree. One point gives a
    /// float, an `(N, K)` integer array an `(N,)` float64 array. Points may lie outside the universe.
    fn distance<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLikeDyn<'py, i64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rows = queries::rows(&points.as_array(), self.inner.k(), "distance: the points")?;
        let (distance, _) =
            py.detach(|| with_dim!(&self.inner, AnyTree, t => queries::nearest(t, &rows.flat)));
        if rows.single {
            return Ok(pyo3::types::PyFloat::new(py, distance[0]).into_any());
        }
        Ok(distance.into_pyarray(py).into_any())
    }

    /// A nearest full voxel to each point: one point gives a (K,) int64 array, an `(N, K)` array an
    /// `(N, K)` int64 array; rows of -1 for an empty tree. Among equally near voxels, the one with the
    /// smallest Morton key.
    fn nearest<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLikeDyn<'py, i64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = self.inner.k();
        let rows = queries::rows(&points.as_array(), k, "nearest: the points")?;
        let (_, voxel) =
            py.detach(|| with_dim!(&self.inner, AnyTree, t => queries::nearest(t, &rows.flat)));
        if rows.single {
            return Ok(voxel.into_pyarray(py).into_any());
        }
        let n = voxel.len() / k;
        let array =
            numpy::ndarray::Array2::from_shape_vec((n, k), voxel).map_err(Failure::value)?;
        Ok(array.into_pyarray(py).into_any())
    }

    /// The statistics as a dict with the keys of `ktree stats --json`: k, level, rays (None), full, empty,
    /// partial, nodes, bytes_at_2_bits, memory_bytes, per_level (a list of dicts with level, full, empty,
    /// partial), surface_area and, for K = 2 and 3, euler_number (connectivity K).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let json = serde_json::to_string(&self.inner.stats(None)).map_err(Failure::value)?;
        let d = py.import("json")?.call_method1("loads", (json,))?;
        add_measures(py, &self.inner, d.cast::<PyDict>()?)?;
        Ok(d)
    }

    /// Translated by `offset` (K numbers): exactly by whole voxels when all are integers (voxels leaving the
    /// universe are lost), by an affine pass otherwise.
    fn translate(&self, py: Python<'_>, offset: Vec<f64>) -> PyResult<Self> {
        let out = py.detach(|| with_dim!(&self.inner, AnyTree, t => geometry::translate(t, &offset).map(AnyTree::from)))?;
        Ok(Self { inner: out })
    }

    /// Rotated by `degrees` about the universe's centre, in the plane of `axes` = (i, j) (turning axis i
    /// towards axis j; default (0, 1)) or, in 3-D, about the axis 'x', 'y' or 'z'. Multiples of 90 degrees
    /// are exact (children reordered); other angles take an affine pass.
    #[pyo3(signature = (degrees, axes = None))]
    fn rotate(
        &self,
        py: Python<'_>,
        degrees: f64,
        axes: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (from, to) = match axes {
            Some(a) => rotation_plane(self.inner.k(), &a)?,
            None => (0, 1),
        };
        let out = py.detach(|| with_dim!(&self.inner, AnyTree, t => geometry::rotate(t, degrees, from, to).map(AnyTree::from)))?;
        Ok(Self { inner: out })
    }

    /// Scaled by `factor` about the universe's origin corner: an int or a `fractions.Fraction` p/q is exact
    /// (p, q up to 2**20), a float takes an affine pass unless it is a whole number.
    fn scale(&self, py: Python<'_>, factor: &Bound<'_, PyAny>) -> PyResult<Self> {
        let ratio = || -> PyResult<(u32, u32)> {
            Ok((
                factor.getattr("numerator")?.extract()?,
                factor.getattr("denominator")?.extract()?,
            ))
        };
        let factor = match ratio() {
            Ok((p, q)) => Factor::Ratio(p, q),
            Err(_) => {
                let s: f64 = factor.extract()?;
                if s.fract() == 0.0 && s >= 1.0 && s <= f64::from(u32::MAX) {
                    Factor::Ratio(s as u32, 1)
                } else {
                    Factor::Real(s)
                }
            }
        };
        let out = py.detach(
            || with_dim!(&self.inner, AnyTree, t => geometry::scale(t, factor).map(AnyTree::from)),
        )?;
        Ok(Self { inner: out })
    }

    /// Mapped by a homogeneous (K + 1) x (K + 1) matrix acting on column vectors [x; 1], in one overlay
    /// pass: affine when the last row is 0 ... 0 1, projective otherwise.
    fn affine(
        &self,
        py: Python<'_>,
        matrix: PyArrayLike2<'_, f64, AllowTypeChange>,
    ) -> PyResult<Self> {
        let m: Vec<f64> = matrix.as_array().iter().copied().collect();
        let n = self.inner.k() + 1;
        if matrix.as_array().shape() != [n, n] {
            return Err(Failure::Value(format!(
                "a K = {} tree needs a {n} x {n} matrix, got shape {:?}",
                self.inner.k(),
                matrix.as_array().shape()
            ))
            .into());
        }
        let out = py.detach(
            || with_dim!(&self.inner, AnyTree, t => geometry::matrix(t, &m).map(AnyTree::from)),
        )?;
        Ok(Self { inner: out })
    }

    /// Mass properties as a dict with the keys of `ktree mass --json`: k, volume (voxels), centroid (voxel
    /// (x, y, ...) spans [x, x + 1) on each axis), central_moments and inertia_tensor (K x K lists), nodes;
    /// with `tolerance`, also Meagher's progressive bounds (progressive: a list of dicts with level, lower,
    /// upper, nodes_touched) and the estimate where they meet the tolerance (otherwise both None); and
    /// surface_area and, for K = 2 and 3, euler_number as `stats`.
    #[pyo3(signature = (tolerance = None))]
    fn mass<'py>(&self, py: Python<'py>, tolerance: Option<f64>) -> PyResult<Bound<'py, PyDict>> {
        if let Some(t) = tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(
                    Failure::Value(format!("tolerance must be a number >= 0, got {t}")).into(),
                );
            }
        }
        #[allow(clippy::type_complexity)]
        let (volume, centroid, moments, inertia, progressive): (
            u128,
            Vec<f64>,
            Vec<Vec<f64>>,
            Vec<Vec<f64>>,
            Option<(Vec<(u32, u128, u128, u64)>, f64)>,
        ) = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let m = ops::mass_properties(t);
                let p = tolerance.map(|tol| {
                    let p = ops::mass_progressive(t, tol);
                    let levels = p.levels.iter().map(|l| (l.level, l.lower, l.upper, l.nodes_touched)).collect();
                    (levels, p.estimate)
                });
                (
                    m.volume,
                    m.centroid.to_vec(),
                    m.central_moments.iter().map(|r| r.to_vec()).collect(),
                    m.inertia_tensor().iter().map(|r| r.to_vec()).collect(),
                    p,
                )
            })
        });
        let d = PyDict::new(py);
        d.set_item("k", self.inner.k())?;
        d.set_item("volume", volume)?;
        d.set_item("centroid", centroid)?;
        d.set_item("central_moments", moments)?;
        d.set_item("inertia_tensor", inertia)?;
        d.set_item("nodes", self.inner.counts().nodes())?;
        match progressive {
            Some((levels, estimate)) => {
                let list: Vec<Bound<'py, PyDict>> = levels
                    .into_iter()
                    .map(|(level, lower, upper, touched)| {
                        let l = PyDict::new(py);
                        l.set_item("level", level)?;
                        l.set_item("lower", lower)?;
                        l.set_item("upper", upper)?;
                        l.set_item("nodes_touched", touched)?;
                        Ok(l)
                    })
                    .collect::<PyResult<_>>()?;
                d.set_item("progressive", list)?;
                d.set_item("estimate", estimate)?;
            }
            None => {
                d.set_item("progressive", py.None())?;
                d.set_item("estimate", py.None())?;
            }
        }
        add_measures(py, &self.inner, &d)?;
        Ok(d)
    }

    /// The voxels within the element of radius `r` (a real number >= 0) of a full voxel, clipped to the
    /// universe: scipy's `binary_dilation` with the element as structure. `shape` is "ball" (|d|² <= r²),
    /// "box" (max |d_i| <= r) or "cross" (Σ |d_i| <= r).
    #[pyo3(signature = (r, shape = "ball"))]
    fn dilate(&self, py: Python<'_>, r: f64, shape: &str) -> PyResult<Self> {
        morph(
            py,
            self,
            r,
            shape,
            |t, r, e| with_dim!(t, AnyTree, t => t.dilate(r, e).map(AnyTree::from)),
        )
    }

    /// The voxels whose whole element lies in the object, outside the universe empty: scipy's
    /// `binary_erosion(..., border_value=0)`.
    #[pyo3(signature = (r, shape = "ball"))]
    fn erode(&self, py: Python<'_>, r: f64, shape: &str) -> PyResult<Self> {
        morph(
            py,
            self,
            r,
            shape,
            |t, r, e| with_dim!(t, AnyTree, t => t.erode(r, e).map(AnyTree::from)),
        )
    }

    /// The dilation of the erosion.
    #[pyo3(signature = (r, shape = "ball"))]
    fn opening(&self, py: Python<'_>, r: f64, shape: &str) -> PyResult<Self> {
        morph(
            py,
            self,
            r,
            shape,
            |t, r, e| with_dim!(t, AnyTree, t => t.opening(r, e).map(AnyTree::from)),
        )
    }

    /// The erosion of the dilation, both unbounded by the universe, then clipped to it (scipy's
    /// `binary_closing` on an array padded by more than `r`, cropped back).
    #[pyo3(signature = (r, shape = "ball"))]
    fn closing(&self, py: Python<'_>, r: f64, shape: &str) -> PyResult<Self> {
        morph(
            py,
            self,
            r,
            shape,
            |t, r, e| with_dim!(t, AnyTree, t => t.closing(r, e).map(AnyTree::from)),
        )
    }

    /// The connected components, largest first, each as its own Tree; `connectivity` 1 … K as scipy's
    /// `generate_binary_structure(K, connectivity)`. No dense label array is made.
    #[pyo3(signature = (connectivity = 1))]
    fn components(&self, py: Python<'_>, connectivity: usize) -> PyResult<Vec<Self>> {
        let parts: Vec<AnyTree> = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => t
                .components(connectivity)
                .map(|c| c.into_iter().map(|c| AnyTree::from(c.tree)).collect()))
            .map_err(Failure::value)
        })?;
        Ok(parts.into_iter().map(|inner| Self { inner }).collect())
    }

    /// The largest connected component (an empty tree if there is none).
    #[pyo3(signature = (connectivity = 1))]
    fn largest_component(&self, py: Python<'_>, connectivity: usize) -> PyResult<Self> {
        let out = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => t.largest_component(connectivity).map(AnyTree::from))
                .map_err(Failure::value)
        })?;
        Ok(Self { inner: out })
    }

    /// The number of (K - 1)-faces between a full voxel and an empty one (outside the universe empty).
    fn surface_area(&self, py: Python<'_>) -> u128 {
        py.detach(|| with_dim!(&self.inner, AnyTree, t => t.surface_area()))
    }

    /// The Euler number as scikit-image's `measure.euler_number(image, connectivity)`: connectivity 1 or K
    /// (default K).
    #[pyo3(signature = (connectivity = None))]
    fn euler_number(&self, py: Python<'_>, connectivity: Option<usize>) -> PyResult<i64> {
        let c = connectivity.unwrap_or(self.inner.k());
        Ok(py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => t.euler_number(c)).map_err(Failure::value)
        })?)
    }

    /// Whether the two objects share a voxel (same K and level).
    fn interferes(&self, py: Python<'_>, other: &Tree) -> PyResult<bool> {
        Ok(py.detach(|| self.inner.interferes(&other.inner).map_err(Failure::from))?)
    }

    /// Interference as a dict with the keys of `ktree collide --json`: collide, overlap_cells,
    /// overlap_voxels, first_contact (the first position along `time_axis` where they overlap, if given and
    /// they do), min_separation (smallest distance between voxel centres; 0.0 when they overlap, None if one
    /// is empty).
    #[pyo3(signature = (other, time_axis = None))]
    fn collide<'py>(
        &self,
        py: Python<'py>,
        other: &Tree,
        time_axis: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let c = py.detach(|| {
            self.inner
                .collision(&other.inner, time_axis)
                .map_err(Failure::from)
        })?;
        let d = PyDict::new(py);
        d.set_item("collide", c.collide)?;
        d.set_item("overlap_cells", c.overlap_cells)?;
        d.set_item("overlap_voxels", c.overlap_voxels)?;
        d.set_item("first_contact", c.first_contact)?;
        d.set_item("min_separation", c.min_separation)?;
        Ok(d)
    }

    /// The boundary of an octree as a closed, outward-oriented triangle mesh: `(vertices, faces)`, a float64
    /// array of shape (n, 3) and an int64 array of shape (m, 3), in world units (vertex = `origin` +
    /// `voxel_size` · voxel coordinate). Where solids touch only along an edge or at a corner the vertices
    /// are duplicated, so the mesh is 2-manifold. `smooth=True`: a smooth surface for display instead
    /// (surface nets relaxed within half a voxel, `ktree convert --smooth`), not the exact boundary.
    #[pyo3(signature = (voxel_size = 1.0, origin = None, smooth = false))]
    #[allow(clippy::type_complexity)]
    fn to_mesh<'py>(
        &self,
        py: Python<'py>,
        voxel_size: f64,
        origin: Option<Vec<f64>>,
        smooth: bool,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>)> {
        let AnyTree::K3(t) = &self.inner else {
            return Err(Failure::Value(format!(
                "to_mesh needs an octree (K = 3); this tree has K = {}",
                self.inner.k()
            ))
            .into());
        };
        if !(voxel_size.is_finite() && voxel_size > 0.0) {
            return Err(Failure::Value(format!(
                "voxel_size {voxel_size}: expected a positive number"
            ))
            .into());
        }
        let origin: [f64; 3] = match origin {
            None => [0.0; 3],
            Some(o) => match <[f64; 3]>::try_from(o) {
                Ok(o) if o.iter().all(|x| x.is_finite()) => o,
                _ => {
                    return Err(
                        Failure::Value("origin: expected three finite numbers".into()).into(),
                    )
                }
            },
        };
        let frame = ktree::export::Frame { voxel_size, origin };
        let mesh = py
            .detach(|| {
                if smooth {
                    ktree::export::surface::smooth_mesh(t, 10)
                } else {
                    Ok(ktree::export::surface::boundary_mesh(t))
                }
            })
            .map_err(|e| Failure::Value(e.to_string()))?
            .placed(&frame);
        let (n, m) = (mesh.vertices.len(), mesh.triangles.len());
        let vertices = numpy::ndarray::Array2::from_shape_vec(
            (n, 3),
            mesh.vertices.into_iter().flatten().collect(),
        )
        .map_err(Failure::value)?;
        let faces = numpy::ndarray::Array2::from_shape_vec(
            (m, 3),
            mesh.triangles
                .into_iter()
                .flatten()
                .map(i64::from)
                .collect(),
        )
        .map_err(Failure::value)?;
        Ok((vertices.into_pyarray(py), faces.into_pyarray(py)))
    }

    /// A picture as an RGB uint8 array of shape (height, width, 3). An octree: a hidden-surface image seen
    /// from `view` (a name: iso, top, bottom, front, back, left, right, or three numbers towards the eye),
    /// orthographic or with a vertical field of view `perspective` in degrees, framing the object. A
    /// quadtree: its cells, min(width, height) pixels square. A 4-D tree: a strip of `frames` slices along
    /// `time_axis`, each `height` pixels square.
    #[pyo3(signature = (view = None, width = 512, height = 512, *, perspective = None, time_axis = 3, frames = 6))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        view: Option<Bound<'py, PyAny>>,
        width: u32,
        height: u32,
        perspective: Option<f64>,
        time_axis: usize,
        frames: usize,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let toward = match &view {
            Some(v) => view_direction(v)?,
            None => ISO_TOWARD_EYE,
        };
        let (w, h, rgb) = py.detach(|| -> Result<_, Failure> {
            display::check_size(width, height)?;
            match &self.inner {
                AnyTree::K3(t) => {
                    let camera = display::default_camera(t, toward, perspective, width, height)?;
                    camera.check()?;
                    let options = RenderOptions {
                        width,
                        height,
                        ..Default::default()
                    };
                    let image = display::render(t, &camera, &options)?;
                    Ok((image.width, image.height, image.rgb))
                }
                AnyTree::K2(t) => {
                    let c = display::plane::quadtree_canvas(t, width.min(height))?;
                    Ok((c.width, c.height, c.rgb))
                }
                AnyTree::K4(t) => {
                    let (c, _) = display::slices::time_strip(t, time_axis, frames, height)?;
                    Ok((c.width, c.height, c.rgb))
                }
                AnyTree::K1(_) => Err(Failure::Value(
                    "a bintree (K = 1) has no picture; render needs K = 2, 3 or 4".into(),
                )),
            }
        })?;
        let image =
            Array3::from_shape_vec((h as usize, w as usize, 3), rgb).map_err(Failure::value)?;
        Ok(image.into_pyarray(py))
    }

    /// A line drawing of an octree with hidden lines removed (Veenstra & Ahuja), seen in parallel
    /// projection from `view` (as in `render`), as SVG text of `width` x `height` pixels. `method` is
    /// 'bucketed' (fast) or 'pairwise' (the paper's); `stroke` is the line width.
    #[pyo3(signature = (view = None, width = 800, height = 800, *, stroke = 1.0, method = "bucketed"))]
    fn lines(
        &self,
        py: Python<'_>,
        view: Option<Bound<'_, PyAny>>,
        width: u32,
        height: u32,
        stroke: f64,
        method: &str,
    ) -> PyResult<String> {
        let toward = match &view {
            Some(v) => view_direction(v)?,
            None => ISO_TOWARD_EYE,
        };
        let method = match method {
            "bucketed" => HiddenLineMethod::Bucketed,
            "pairwise" => HiddenLineMethod::Pairwise,
            other => {
                return Err(Failure::Value(format!(
                    "method '{other}' must be 'bucketed' or 'pairwise'"
                ))
                .into())
            }
        };
        if !(stroke.is_finite() && stroke > 0.0) {
            return Err(
                Failure::Value(format!("stroke must be a positive number, got {stroke}")).into(),
            );
        }
        let AnyTree::K3(tree) = &self.inner else {
            return Err(Failure::Value(format!(
                "line drawings need an octree (K = 3), this is a K = {} tree (try render)",
                self.inner.k()
            ))
            .into());
        };
        Ok(py.detach(|| -> Result<_, Failure> {
            display::check_size(width, height)?;
            let drawing = display::line_drawing(tree, toward, method)?;
            Ok(display::svg::lines_svg(
                &drawing.segments_2d(),
                width,
                height,
                stroke,
            ))
        })?)
    }

    /// Union.
    fn __or__(&self, py: Python<'_>, other: PyRef<'_, Tree>) -> PyResult<Self> {
        boolean(py, self, &other, BoolOp::Union)
    }

    /// Intersection.
    fn __and__(&self, py: Python<'_>, other: PyRef<'_, Tree>) -> PyResult<Self> {
        boolean(py, self, &other, BoolOp::Intersection)
    }

    /// Difference: voxels of this tree not in `other`.
    fn __sub__(&self, py: Python<'_>, other: PyRef<'_, Tree>) -> PyResult<Self> {
        boolean(py, self, &other, BoolOp::Difference)
    }

    /// Symmetric difference.
    fn __xor__(&self, py: Python<'_>, other: PyRef<'_, Tree>) -> PyResult<Self> {
        boolean(py, self, &other, BoolOp::SymmetricDifference)
    }

    /// Complement within the universe.
    fn __invert__(&self, py: Python<'_>) -> Self {
        let out =
            py.detach(|| with_dim!(&self.inner, AnyTree, t => AnyTree::from(ops::complement(t))));
        Self { inner: out }
    }

    /// Same object in the same universe (trees are canonical, so this compares nodes).
    fn __eq__(&self, other: PyRef<'_, Tree>) -> bool {
        self.inner == other.inner
    }

    fn __repr__(&self) -> String {
        let c = self.inner.counts();
        format!(
            "Tree(k={}, level={}, nodes={}, full={}, partial={})",
            self.inner.k(),
            self.inner.level(),
            c.nodes(),
            c.full,
            c.partial
        )
    }
}

/// k-trees (bintrees, quadtrees, octrees, 4-D trees) with numpy arrays in and out: see `ktree.Tree`.
#[pymodule]
#[pyo3(name = "ktree")]
fn ktree_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Tree>()?;
    // What `Tree.cast_rays` returns.
    let fields = ["hit", "voxel", "t", "axis", "sign"];
    let hits = m
        .py()
        .import("collections")?
        .getattr("namedtuple")?
        .call1(("RayHits", fields))?;
    hits.setattr("__module__", "ktree")?;
    m.add("RayHits", hits)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
