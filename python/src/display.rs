//! Pictures of a tree: a rendered image as an RGB array (`render`: hidden surfaces of an octree, the cells
//! of a quadtree, time slices of a 4-D tree) and a line drawing with hidden lines removed as SVG text
//! (`lines`), each one call of the library's `display`.

use ktree::display::{self, HiddenLineMethod, RenderOptions, View, ISO_TOWARD_EYE};
use ktree::AnyTree;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
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
            Some(v) => view_direction(v)?.toward_eye(),
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
            Some(v) => view_direction(v)?.toward_eye(),
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
}

/// A view: a name or three numbers (x, y, z) from the object towards the viewer.
pub(crate) fn view_direction(view: &Bound<'_, PyAny>) -> PyResult<View> {
    if let Ok(name) = view.cast::<PyString>() {
        return Ok(name
            .to_str()?
            .parse()
            .map_err(|e: display::ParseViewError| Failure::Value(e.to_string()))?);
    }
    let v: [f64; 3] = view.extract().map_err(|_| {
        Failure::Value("a view is a name or three numbers (x, y, z) towards the viewer".into())
    })?;
    View::new(v).map_err(|e| Failure::Value(e.to_string()).into())
}
