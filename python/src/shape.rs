//! Shapes from shapes and their measures, each one call of the library: the Booleans (`|`, `&`, `-`, `^`,
//! `~`), morphology (`dilate`, `erode`, `opening`, `closing`), connected components, and the measures
//! (surface area, Euler number, mass properties).

use ktree::ops::{self, BoolOp};
use ktree::shape::{Element, ShapeError};
use ktree::{with_dim, AnyTree, KTree};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
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
        Self::binary(out)
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
        Ok(parts.into_iter().map(Self::binary).collect())
    }

    /// The largest connected component (an empty tree if there is none).
    #[pyo3(signature = (connectivity = 1))]
    fn largest_component(&self, py: Python<'_>, connectivity: usize) -> PyResult<Self> {
        let out = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => t.largest_component(connectivity).map(AnyTree::from))
                .map_err(Failure::value)
        })?;
        Ok(Self::binary(out))
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
                let m = ktree::tree::storage::infallible(ops::mass_properties(t));
                let p = tolerance.map(|tol| {
                    let p = ktree::tree::storage::infallible(ops::mass_progressive(t, tol));
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
}

/// The surface area and, for K = 2 and 3, the Euler number (connectivity K), as `ktree stats --json --measures`
/// adds them.
pub(crate) fn add_measures(py: Python<'_>, tree: &AnyTree, d: &Bound<'_, PyDict>) -> PyResult<()> {
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
    Ok(Tree::binary(out))
}

/// Runs a Boolean operation without the interpreter lock.
fn boolean(py: Python<'_>, a: &Tree, b: &Tree, op: BoolOp) -> PyResult<Tree> {
    let out = py.detach(|| a.inner.boolean(&b.inner, op).map_err(Failure::from))?;
    Ok(Tree::binary(out))
}
