//! Geometric transforms of a tree of any `K`: exact integer operations where the parameters allow (integer
//! translations, quarter turns, rational scales), one affine (or projective) overlay pass otherwise: the
//! methods `translate`, `rotate`, `scale` and `affine`. A tree with values keeps each voxel's value (the
//! value of the voxel its centre maps back into: values are never blended).

use ktree::ops::{Affine, AxisMap, Geometry, Projective};
use ktree::{with_dim, with_valued, AnyTree, AnyValuedTree};
use numpy::{AllowTypeChange, PyArrayLike2};
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
    /// Translated by `offset` (K numbers): exactly by whole voxels when all are integers (voxels leaving the
    /// universe are lost), by an affine pass otherwise.
    fn translate(&self, py: Python<'_>, offset: Vec<f64>) -> PyResult<Self> {
        self.transformed(py, &Step::Translate(offset))
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
        self.transformed(py, &Step::Rotate(degrees, from, to))
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
        self.transformed(py, &Step::Scale(factor))
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
        self.transformed(py, &Step::Matrix(m))
    }
}

impl Tree {
    /// This tree moved by `step`: a tree with values keeps each voxel's value.
    fn transformed(&self, py: Python<'_>, step: &Step) -> PyResult<Self> {
        Ok(match &self.values {
            Some(values) => {
                let out = py.detach(
                    || with_valued!(values, t => step.apply(t, t.level()).map(AnyValuedTree::from)),
                )?;
                self.with_values(out)
            }
            None => {
                let out = py.detach(
                    || with_dim!(&self.inner, AnyTree, t => step.apply(t, t.level()).map(AnyTree::from)),
                )?;
                Self::binary(out)
            }
        })
    }
}

/// One transform asked of a tree of any `K`, with or without values.
enum Step {
    /// By `K` numbers.
    Translate(Vec<f64>),
    /// By degrees in the plane of two axes.
    Rotate(f64, usize, usize),
    /// By a factor about the origin corner.
    Scale(Factor),
    /// By a homogeneous matrix, row-major.
    Matrix(Vec<f64>),
}

impl Step {
    /// The step applied to `tree`, of level `level`.
    fn apply<const K: usize, T: Geometry<K> + Clone>(
        &self,
        tree: &T,
        level: u32,
    ) -> Result<T, Failure> {
        match self {
            Step::Translate(t) => translate(tree, t),
            Step::Rotate(degrees, from, to) => rotate(tree, level, *degrees, *from, *to),
            Step::Scale(factor) => scale(tree, *factor),
            Step::Matrix(m) => matrix(tree, m),
        }
    }
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

/// A uniform scale factor: an exact ratio `p/q`, or any positive number.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Factor {
    /// `p/q`, computed exactly by rational overlays.
    Ratio(u32, u32),
    /// Any other factor, by an affine pass.
    Real(f64),
}

/// Translated by `t` (K numbers): exactly when all are whole numbers (voxels leaving the universe are
/// dropped), by an affine pass otherwise.
fn translate<const K: usize, T: Geometry<K>>(tree: &T, t: &[f64]) -> Result<T, Failure> {
    let t: [f64; K] = t.try_into().map_err(|_| {
        Failure::Value(format!(
            "a translation of a K = {K} tree needs {K} numbers, got {}",
            t.len()
        ))
    })?;
    if t.iter().any(|v| !v.is_finite()) {
        return Err(Failure::Value(format!("translation {t:?} is not finite")));
    }
    if t.iter().all(|v| v.fract() == 0.0 && v.abs() < 9.0e15) {
        return Ok(tree.translated(t.map(|v| v as i64)));
    }
    Ok(tree.affine(&Affine::translation(t))?)
}

/// Rotated by `degrees` in the plane of axes `from` → `to`, about the universe's centre: by reordering
/// children for multiples of 90°, by an affine pass otherwise.
fn rotate<const K: usize, T: Geometry<K> + Clone>(
    tree: &T,
    level: u32,
    degrees: f64,
    from: usize,
    to: usize,
) -> Result<T, Failure> {
    if !degrees.is_finite() {
        return Err(Failure::Value(format!("angle {degrees} is not finite")));
    }
    if degrees % 90.0 == 0.0 {
        let quarter = AxisMap::<K>::quarter_turn(from, to)?;
        let turns = ((degrees / 90.0) % 4.0) as i64;
        let mut out = tree.clone();
        for _ in 0..turns.rem_euclid(4) {
            out = out.rotated(&quarter);
        }
        return Ok(out);
    }
    let centre = Affine::<K>::universe_centre(level);
    let m = Affine::rotation_about(from, to, degrees, centre)?;
    Ok(tree.affine(&m)?)
}

/// Scaled by `factor` about the universe's origin corner.
fn scale<const K: usize, T: Geometry<K>>(tree: &T, factor: Factor) -> Result<T, Failure> {
    match factor {
        Factor::Ratio(p, q) => Ok(tree.scaled(p, q)?),
        Factor::Real(s) if s.is_finite() && s > 0.0 => {
            Ok(tree.affine(&Affine::scaling_about(s, [0.0; K]))?)
        }
        Factor::Real(s) => Err(Failure::Value(format!(
            "the scale factor must be a positive number, got {s}"
        ))),
    }
}

/// Mapped by a homogeneous `(K + 1) × (K + 1)` matrix (row-major, acting on column vectors `[x; 1]`):
/// affine when the last row is `0 … 0 1`, projective otherwise.
fn matrix<const K: usize, T: Geometry<K>>(tree: &T, m: &[f64]) -> Result<T, Failure> {
    match Affine::<K>::from_homogeneous(m) {
        Ok(a) => Ok(tree.affine(&a)?),
        Err(_) => {
            let p = Projective::<K>::from_homogeneous(m)?;
            Ok(tree.projective(&p)?)
        }
    }
}
