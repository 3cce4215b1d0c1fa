//! Trees made from Python's inputs, each by one call of the library: a dense array (`from_dense`), the
//! empty and the full universe, runs (`from_rays`), a mesh file or mesh arrays (`from_mesh`,
//! `from_mesh_arrays`: the slab-wise builder `KTree::from_mesh`, placed as the library places meshes;
//! several meshes as one tree of labels, `from_meshes`),
//! points (`from_points`) and a volume file (`from_volume`, read as `ktree::input::read_tree` reads volumes).

use std::ffi::CString;
use std::path::PathBuf;

use ktree::io::ktree::notes::label_note;
use ktree::io::ReadOptions;
use ktree::solid::cloud::CloudVoxelizer;
use ktree::solid::mesh::{MeshTransform, Placement, TriangleMesh};
use ktree::solid::volume::Select;
use ktree::solid::SolidError;
use ktree::space::{Universe, DENSE_LIMIT};
use ktree::value::Dtype;
use ktree::{AnyTree, KTree};
use numpy::ndarray::ArrayViewD;
use numpy::{AllowTypeChange, PyArrayLike2, PyArrayLikeDyn};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;

use crate::arrays::{rows, Numbers};
use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
    /// The tree of an array indexed `[x, y, z, ...]` (K = `array.ndim`, 1 to 4), placed at the origin of a
    /// universe of level `level` (default: the smallest whose side 2**level holds the longest axis).
    /// A boolean array gives a tree without values (True is inside). A numeric array gives a tree with
    /// values where the voxels equal to `background` are empty: uint8, uint16, uint32, int8 and float32
    /// are kept; other integer types become the smallest of uint8, int8, uint16, uint32 that holds their
    /// values (a ValueError if none does); float64 and float16 become float32. A NaN is a ValueError.
    /// `dtype` names the value type instead ("uint8", "uint16", "uint32", "int8", "float32", or "rgb":
    /// colours, the array's last axis their 3 channels of 0..255, K = `array.ndim - 1`, the background
    /// the grey (b, b, b)).
    #[staticmethod]
    #[pyo3(signature = (array, level = None, background = 0.0, dtype = None))]
    fn from_dense(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        level: Option<u32>,
        background: f64,
        dtype: Option<&str>,
    ) -> PyResult<Self> {
        let array = py.import("numpy")?.call_method1("asarray", (array,))?;
        let name: String = array.getattr("dtype")?.getattr("name")?.extract()?;
        let (lo, hi) = if array.getattr("size")?.extract::<usize>()? > 0 && name.contains("int") {
            (
                array.call_method0("min")?.extract()?,
                array.call_method0("max")?.extract()?,
            )
        } else {
            (0.0, 0.0)
        };
        let shape: Vec<usize> = array.getattr("shape")?.extract()?;
        let dtype = match dtype {
            None => crate::values::dtype_for(&name, lo, hi)?,
            Some(given) => Some(Dtype::parse(given).ok_or_else(|| {
                Failure::Value(format!(
                    "from_dense: dtype {given:?}: one of uint8, uint16, uint32, int8, float32, rgb was expected"
                ))
            })?),
        };
        // A colour array's last axis holds the channels.
        let k = match dtype {
            Some(Dtype::Rgb)
                if !(0.0..=255.0).contains(&lo) || hi > 255.0 || !name.contains("int") =>
            {
                return Err(Failure::Value(format!(
                    "from_dense: colours are integers of 0..255, got dtype {name} ({lo} to {hi})"
                ))
                .into())
            }
            Some(Dtype::Rgb) if shape.last() == Some(&3) => shape.len() - 1,
            Some(Dtype::Rgb) => {
                return Err(Failure::Value(format!(
                    "from_dense: colours need a last axis of 3 channels, got shape {shape:?}"
                ))
                .into())
            }
            _ => shape.len(),
        };
        let level =
            level.unwrap_or_else(|| level_for(shape[..k].iter().copied().max().unwrap_or(1)));
        if let Some(dtype) = dtype {
            let tree = crate::values::tree_of_array(py, &array, k, dtype, level, background)?;
            return Ok(Self::valued(tree, background));
        }
        let array: PyArrayLikeDyn<'_, bool, AllowTypeChange> = array.extract()?;
        let view = array.as_array();
        let tree = with_k!(view.ndim(), "from_dense: an array with that many dimensions", K => {
            let dense = dense_of_view::<K>(&view, level)?;
            py.detach(|| KTree::<K>::from_dense(level, &dense).map(AnyTree::from).map_err(Failure::from))
        })?;
        Ok(Self::binary(tree))
    }

    /// The empty tree of dimension `k` and level `level`.
    #[staticmethod]
    fn empty(k: usize, level: u32) -> PyResult<Self> {
        let tree = with_k!(k, "empty", K => KTree::<K>::empty(level).map(AnyTree::from).map_err(Failure::from))?;
        Ok(Self::binary(tree))
    }

    /// The tree of the whole universe of dimension `k` and level `level`.
    #[staticmethod]
    fn full(k: usize, level: u32) -> PyResult<Self> {
        let tree = with_k!(k, "full", K => KTree::<K>::full(level).map(AnyTree::from).map_err(Failure::from))?;
        Ok(Self::binary(tree))
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
        let numbers = Numbers::new(rays);
        let columns = numbers.shape()[1];
        let what = format!("from_rays: an array of {columns} columns (K + 1 for K = 1 to 4)");
        let flat = numbers.flat();
        let tree = with_k!(columns.wrapping_sub(1), what, K => {
            let set = crate::rays::rays_of_rows::<K>(flat, level)?;
            Ok(AnyTree::from(py.detach(|| KTree::from_rays(&set))))
        })?;
        Ok(Self::binary(tree))
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
        let placement = placement(transform)?;
        let mesh =
            py.detach(|| ktree::io::read_mesh(&path).map_err(|e| Failure::of_error(&e, &path)))?;
        mesh_tree(py, &mesh, level, placement, &path.display().to_string())
    }

    /// One octree of labels from several mesh files (OBJ, STL, PLY) placed together in a universe of level
    /// `level`: file i (in the order given) is label i + 1 (uint8 up to 255 meshes, uint16 beyond), or,
    /// for a single OBJ file, each of its groups/objects in file order; where meshes overlap, the later
    /// wins. `transform` places every mesh as in `from_mesh`; without it their union is fitted. Every mesh
    /// must be closed. Returns the tree and the name of each label (`names[i]` is label i + 1), which the
    /// tree keeps too (`label_names`).
    #[staticmethod]
    #[pyo3(signature = (paths, level, transform = None))]
    fn from_meshes(
        py: Python<'_>,
        paths: Vec<PathBuf>,
        level: u32,
        transform: Option<[f64; 4]>,
    ) -> PyResult<(Self, Vec<String>)> {
        let mesh_placement = match placement(transform)? {
            Placement::Transform(t) => Some(t),
            Placement::Fit => None,
        };
        let options = ReadOptions {
            level: Some(level),
            mesh_placement,
            ..ReadOptions::default()
        };
        let labels = py.detach(|| {
            ktree::input::voxelize_mesh_labels(&paths, &options).map_err(|e| {
                let path = match &e {
                    ktree::io::IoError::Solid { file, .. }
                    | ktree::io::IoError::Usage { file, .. } => file.clone(),
                    _ => PathBuf::new(),
                };
                Failure::of_error(&e, &path)
            })
        })?;
        // The tree keeps the names too, so that a `.ktree` it is saved to has them.
        let notes = (labels.names.iter().enumerate())
            .map(|(i, name)| (label_note(&(i + 1).to_string()), name.clone()))
            .collect();
        let tree = Self {
            notes,
            ..Self::valued(labels.tree, 0.0)
        };
        Ok((tree, labels.names))
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
        let (v, f) = (Numbers::new(vertices), Numbers::new(faces));
        if v.shape()[1] != 3 || f.shape()[1] != 3 {
            return Err(Failure::Value(format!(
                "vertices must be (n, 3) and faces (m, 3), got {:?} and {:?}",
                v.shape(),
                f.shape()
            ))
            .into());
        }
        let n = v.shape()[0];
        let triangles = rows::<3, _>(f.flat())
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let mut out = [0u32; 3];
                for (slot, &x) in out.iter_mut().zip(t) {
                    *slot = u32::try_from(x)
                        .ok()
                        .filter(|&x| (x as usize) < n)
                        .ok_or_else(|| {
                            Failure::Value(format!("face {i}: vertex index {x} is not below {n}"))
                        })?;
                }
                Ok(out)
            })
            .collect::<Result<Vec<_>, Failure>>()?;
        let mesh = TriangleMesh::new(rows::<3, _>(v.flat()).to_vec(), triangles)
            .map_err(Failure::value)?;
        let placement = placement(transform)?;
        mesh_tree(py, &mesh, level, placement, "from_mesh_arrays")
    }

    /// The octree of the voxels holding points of an `(n, 3)` float array: point p is in voxel
    /// `floor((p - origin) / voxel_size)` (as numpy computes it), `origin` defaults to the points' minimum
    /// corner and `level` to the smallest that holds every voxel; with `level` given, points outside the
    /// universe are a `ValueError`.
    ///
    /// With `values` (one per point: an (n,) array of numbers, or an (n, 3) uint8 array of colours) the
    /// tree holds a value in each voxel, reduced from its points' values by `reduce`: "mean" (integers
    /// rounded, halves up), "max", "min", "mode" (the most frequent, the smallest of equally frequent), or
    /// "count" (the number of points, uint32; `values` may then be None). The value type follows
    /// `from_dense`: float arrays give float32, integer arrays the smallest integer type holding them.
    #[staticmethod]
    #[pyo3(signature = (points, voxel_size, origin = None, level = None, values = None, reduce = "mean"))]
    #[allow(clippy::too_many_arguments)]
    fn from_points(
        py: Python<'_>,
        points: PyArrayLike2<'_, f64, AllowTypeChange>,
        voxel_size: f64,
        origin: Option<[f64; 3]>,
        level: Option<u32>,
        values: Option<&Bound<'_, PyAny>>,
        reduce: &str,
    ) -> PyResult<Self> {
        let numbers = Numbers::new(points);
        numbers.rows_of(3, false, "points")?;
        let points = rows::<3, _>(numbers.flat());
        let hint = |e: &SolidError| match e {
            SolidError::PointsOutside { .. } => {
                ": use a larger level or voxel_size, or another origin"
            }
            SolidError::PointBelowOrigin { .. } => {
                ": give another origin (or none: the points' minimum corner)"
            }
            _ => "",
        };
        if values.is_some() || reduce != "mean" {
            let mut voxelizer = CloudVoxelizer::new(voxel_size)
                .map_err(|e| Failure::Value(format!("from_points: {e}")))?;
            if let Some(o) = origin {
                voxelizer = voxelizer.origin(o);
            }
            if let Some(l) = level {
                voxelizer = voxelizer.level(l);
            }
            let tree =
                crate::point_values::tree_of_point_values(py, points, &voxelizer, values, reduce)?;
            return Ok(Self::valued(tree, 0.0));
        }
        let tree = py.detach(|| KTree::from_points(points, voxel_size, origin, level));
        Ok(Tree::wrap(tree.map_err(|e| {
            let h = hint(&e);
            Failure::Value(format!("{e}{h}"))
        })?))
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
        let select = match (threshold, label) {
            (Some(t), None) => Select::AtLeast(t),
            (None, Some(l)) => Select::Label(l),
            _ => {
                return Err(Failure::Value("give exactly one of threshold and label".into()).into())
            }
        };
        let options = ReadOptions {
            level,
            offset: offset.map(|(x, y, z)| [x, y, z].map(i64::from)),
            select: Some(select),
            ..ReadOptions::default()
        };
        let tree = py.detach(|| crate::files::read_tree_with(&path, &options))?;
        Ok(Self::binary(tree))
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

/// A mesh placement: `(s, tx, ty, tz)` (voxel = s·v + t), checked as the library checks the command
/// line's `--transform` (four finite numbers, s ≠ 0), or fitted into the universe.
fn placement(transform: Option<[f64; 4]>) -> Result<Placement, Failure> {
    match transform {
        // `{}` writes the shortest text that reads back as the same number.
        Some([s, x, y, z]) => Ok(Placement::Transform(MeshTransform::parse(&format!(
            "{s},{x},{y},{z}"
        ))?)),
        None => Ok(Placement::Fit),
    }
}

/// Voxelizes a mesh by the library's slab-wise builder, warning (as the command-line tool does) when the
/// mesh is not closed.
fn mesh_tree(
    py: Python<'_>,
    mesh: &TriangleMesh,
    level: u32,
    placement: Placement,
    name: &str,
) -> PyResult<Tree> {
    let (tree, open_edges) = py.detach(|| -> Result<_, Failure> {
        Ok((KTree::from_mesh(mesh, level, placement)?, mesh.open_edges()))
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
