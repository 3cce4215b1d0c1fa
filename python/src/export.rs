//! The tree handed to other tools: its runs as an array (`to_rays`, the library's `rays_of`), its boundary
//! as a triangle mesh (`to_mesh`) and the interactive viewer page (`view`, the library's
//! `export::view` page writer, as `ktree view` writes it).

use std::path::PathBuf;

use ktree::export::view::{write_view, ViewOptions};
use ktree::{with_dim, AnyTree};
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::display::view_direction;
use crate::failure::Failure;
use crate::Tree;

/// The default box budget, written out in `view`'s signature so that Python shows it.
const _: () = assert!(ktree::export::view::DEFAULT_BUDGET == 100_000);

#[pymethods]
impl Tree {
    /// The tree's voxels as runs along the last axis: an `(n, K + 1)` int64 array as `from_rays` reads
    /// (maximal runs, columns in lexicographic order).
    fn to_rays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let array = py.detach(|| with_dim!(&self.inner, AnyTree, t => crate::rays::tree_rays(t).map(|r| crate::rays::array_of_rays(&r))))?;
        Ok(array.into_pyarray(py))
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

    /// Writes the interactive 3-D view of the tree to `path`: one self-contained HTML page (WebGL2, no
    /// request), as `ktree view` writes it. A quadtree is drawn as flat squares, an octree as boxes, a 4-D
    /// tree as boxes with a slider along `time_axis`. At most `budget` boxes: where the budget does not
    /// reach, coarser levels are drawn as boxes of their partial cells. `camera` is the first view (a name:
    /// iso, top, bottom, front, back, left, right, or three numbers towards the eye; default iso, top for a
    /// quadtree), `title` the page's title. Returns a dict: boxes (in the page), coarse (of which partial
    /// cells), complete (whether the tree is shown to the voxel) and bytes (the page's size).
    #[pyo3(signature = (path, *, budget = 100000, camera = None, time_axis = 3, title = "ktree"))]
    fn view<'py>(
        &self,
        py: Python<'py>,
        path: PathBuf,
        budget: usize,
        camera: Option<Bound<'py, PyAny>>,
        time_axis: usize,
        title: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let options = ViewOptions {
            budget,
            camera: camera.as_ref().map(view_direction).transpose()?,
            time_axis,
            title: title.to_owned(),
        };
        let page = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => write_view(&path, t, &options))
                .map_err(|e| Failure::of_error(&e, &path))
        })?;
        let d = PyDict::new(py);
        d.set_item("boxes", page.boxes)?;
        d.set_item("coarse", page.coarse)?;
        d.set_item("complete", page.complete)?;
        d.set_item("bytes", page.html.len())?;
        Ok(d)
    }
}
