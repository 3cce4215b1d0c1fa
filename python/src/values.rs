//! Trees with values (`ktree::AnyValuedTree`): a numeric array in (`from_dense` of a non-boolean array),
//! values out (`to_dense`, `values`), the value operations (`select`, `mask`, `overlay`, `combine`,
//! `relabel`, `value_stats`), each one call of the library on the `KTree<K, V>` inside. `Scalar` is the one
//! conversion between a value type and numpy's numbers and Python's objects.

use std::collections::{BTreeMap, HashMap};

use ktree::io::ktree::notes::label_note;
use ktree::io::ktree::Notes;
use ktree::ops::values::Rule;
use ktree::space::{Universe, DENSE_LIMIT};
use ktree::value::{Dtype, Rgb, Value};
use ktree::{with_dim, with_valued, AnyTree, AnyValuedTree, KTree};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike2, PyArrayLikeDyn};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::arrays::{rows, Numbers};
use crate::failure::Failure;
use crate::Tree;

/// A value type as numpy and Python see it: `CHANNELS` numbers of `Elem` (3 `uint8` for a colour).
pub(crate) trait Scalar: Value {
    /// numpy's element.
    type Elem: numpy::Element + Copy + Send;
    /// Numbers a value (1, or 3 for a colour).
    const CHANNELS: usize;
    /// The value of `CHANNELS` numbers.
    fn of_elems(e: &[Self::Elem]) -> Self;
    /// Appends the value's numbers.
    fn push(self, out: &mut Vec<Self::Elem>);
    /// The value equal to `x`, if the type holds it exactly (a colour: the grey `(x, x, x)`).
    fn of_f64(x: f64) -> Option<Self>;
    /// The value of a Python object (a number, or a 3-tuple for a colour).
    fn of_py(object: &Bound<'_, PyAny>) -> Result<Self, Failure>;
    /// The value as a Python object.
    fn to_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>>;
}

macro_rules! scalar_int {
    ($($t:ty),*) => {$(
        impl Scalar for $t {
            type Elem = $t;
            const CHANNELS: usize = 1;
            fn of_elems(e: &[$t]) -> Self { e[0] }
            fn push(self, out: &mut Vec<$t>) { out.push(self) }
            fn of_f64(x: f64) -> Option<Self> {
                (x.fract() == 0.0 && x >= <$t>::MIN as f64 && x <= <$t>::MAX as f64).then(|| x as $t)
            }
            fn of_py(object: &Bound<'_, PyAny>) -> Result<Self, Failure> {
                let n: i128 = object.extract().map_err(|_| {
                    Failure::Value(format!("{object}: an integer was expected for {} values", stringify_dtype::<$t>()))
                })?;
                <$t>::try_from(n).map_err(|_| {
                    Failure::Value(format!("{n} is not a {} value", stringify_dtype::<$t>()))
                })
            }
            fn to_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                Ok(self.into_pyobject(py)?.into_any())
            }
        }
    )*};
}
scalar_int!(u8, u16, u32, i8);

fn stringify_dtype<V: Value>() -> &'static str {
    V::DTYPE.map_or("boolean", Dtype::name)
}

impl Scalar for f32 {
    type Elem = f32;
    const CHANNELS: usize = 1;
    fn of_elems(e: &[f32]) -> Self {
        e[0]
    }
    fn push(self, out: &mut Vec<f32>) {
        out.push(self)
    }
    fn of_f64(x: f64) -> Option<Self> {
        let y = x as f32;
        (f64::from(y) == x || x.is_infinite()).then_some(y)
    }
    fn of_py(object: &Bound<'_, PyAny>) -> Result<Self, Failure> {
        let x: f64 = object.extract().map_err(|_| {
            Failure::Value(format!(
                "{object}: a number was expected for float32 values"
            ))
        })?;
        if x.is_nan() {
            return Err(Failure::Value("NaN is not a value a voxel may hold".into()));
        }
        Ok(x as f32)
    }
    fn to_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(f64::from(self).into_pyobject(py)?.into_any())
    }
}

impl Scalar for Rgb {
    type Elem = u8;
    const CHANNELS: usize = 3;
    fn of_elems(e: &[u8]) -> Self {
        [e[0], e[1], e[2]]
    }
    fn push(self, out: &mut Vec<u8>) {
        out.extend(self)
    }
    fn of_f64(x: f64) -> Option<Self> {
        u8::of_f64(x).map(|g| [g; 3])
    }
    fn of_py(object: &Bound<'_, PyAny>) -> Result<Self, Failure> {
        let (r, g, b): (u8, u8, u8) = object.extract().map_err(|_| {
            Failure::Value(format!(
                "{object}: a colour (r, g, b) of 0..255 was expected"
            ))
        })?;
        Ok([r, g, b])
    }
    fn to_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyTuple::new(py, self)?.into_any())
    }
}

/// The value type a numpy array of dtype `name` becomes (other integer types: the smallest that holds
/// `lo..=hi`, the array's range; float64 and float16: float32); `None` for a boolean array.
pub(crate) fn dtype_for(name: &str, lo: f64, hi: f64) -> Result<Option<Dtype>, Failure> {
    if name == "bool" {
        return Ok(None);
    }
    if let Some(d) = Dtype::parse(name).filter(|d| *d != Dtype::Rgb) {
        return Ok(Some(d));
    }
    if name.starts_with("float") {
        return Ok(Some(Dtype::F32));
    }
    if !(name.starts_with("int") || name.starts_with("uint")) {
        return Err(Failure::Value(format!(
            "from_dense: an array of dtype {name}: bool, an integer type or a float type was expected"
        )));
    }
    let fits = |d: Dtype| match d {
        Dtype::U8 => lo >= 0.0 && hi <= 255.0,
        Dtype::U16 => lo >= 0.0 && hi <= 65535.0,
        Dtype::U32 => lo >= 0.0 && hi <= 4294967295.0,
        Dtype::I8 => lo >= -128.0 && hi <= 127.0,
        _ => false,
    };
    [Dtype::U8, Dtype::I8, Dtype::U16, Dtype::U32]
        .into_iter()
        .find(|&d| fits(d))
        .map(Some)
        .ok_or_else(|| {
            Failure::Value(format!(
                "from_dense: values {lo} to {hi} of dtype {name} fit none of uint8, int8, uint16, uint32"
            ))
        })
}

/// The valued tree of a numpy array (of `V`'s numbers) indexed `[x, y, z, ...]` placed at the origin of a
/// universe of level `level`, the voxels equal to `background` empty.
pub(crate) fn from_dense<const K: usize, V: Scalar>(
    py: Python<'_>,
    array: PyArrayLikeDyn<'_, V::Elem, AllowTypeChange>,
    level: u32,
    background: f64,
) -> Result<AnyValuedTree, Failure> {
    let background = V::of_f64(background).ok_or_else(|| {
        Failure::Value(format!(
            "background {background} is not a {} value",
            stringify_dtype::<V>()
        ))
    })?;
    let view = array.as_array();
    let channels = V::CHANNELS;
    let shape = if channels > 1 {
        &view.shape()[..K] // the caller checked the last axis
    } else {
        view.shape()
    };
    let universe = Universe::<K>::new(level)?;
    let len = universe.dense_len(DENSE_LIMIT)?;
    let side = universe.side() as usize;
    if let Some(n) = shape.iter().find(|&&n| n > side) {
        return Err(Failure::Value(format!(
            "an array of shape {shape:?} does not fit a level-{level} universe of side {side} ({n} > {side})"
        )));
    }
    let mut dense = vec![background; len];
    // The values in C order (the last axis fastest), `channels` numbers each.
    let numbers: Vec<V::Elem> = view.iter().copied().collect();
    let mut index = vec![0usize; K];
    for value in numbers.chunks_exact(channels) {
        let flat = (0..K).rev().fold(0, |acc, a| acc * side + index[a]);
        dense[flat] = V::of_elems(value);
        for a in (0..K).rev() {
            index[a] += 1;
            if index[a] < shape[a] {
                break;
            }
            index[a] = 0;
        }
    }
    py.detach(|| {
        let tree = KTree::<K, V>::from_dense_background(level, &dense, background)
            .map_err(Failure::value)?;
        Ok(AnyValuedTree::from(tree))
    })
}

/// The values of a window (`shape` voxels from `origin`) as numbers in C order, `background` where empty.
pub(crate) fn window<const K: usize, V: Scalar>(
    tree: &KTree<K, V>,
    origin: &[i64],
    shape: &[usize],
    background: f64,
) -> Result<ArrayD<V::Elem>, Failure> {
    let background = V::of_f64(background).ok_or_else(|| {
        Failure::Value(format!(
            "background {background} is not a {} value",
            stringify_dtype::<V>()
        ))
    })?;
    let n = shape
        .iter()
        .try_fold(1u128, |n, &s| n.checked_mul(s as u128))
        .filter(|&n| n <= DENSE_LIMIT)
        .ok_or_else(|| {
            Failure::Value(format!(
                "a window of shape {shape:?} is more than {DENSE_LIMIT} voxels: ask for a smaller one"
            ))
        })? as usize;
    let points: Vec<[u32; K]> = (0..n)
        .map(|mut i| {
            let mut p = [0u32; K];
            for a in (0..K).rev() {
                let c = origin[a] + (i % shape[a].max(1)) as i64;
                i /= shape[a].max(1);
                p[a] = u32::try_from(c).unwrap_or(u32::MAX);
            }
            p
        })
        .collect();
    let out = numbers(&tree.values_at(&points), background);
    let mut dims = shape.to_vec();
    if V::CHANNELS > 1 {
        dims.push(V::CHANNELS);
    }
    ArrayD::from_shape_vec(IxDyn(&dims), out).map_err(Failure::value)
}

/// Values as numbers, `background` for `None`.
fn numbers<V: Scalar>(values: &[Option<V>], background: V) -> Vec<V::Elem> {
    let mut out = Vec::with_capacity(values.len() * V::CHANNELS);
    for v in values {
        v.unwrap_or(background).push(&mut out);
    }
    out
}

/// A valued tree's other operand: the same `K` and value type.
fn same<'a, const K: usize, V: Value>(
    other: &'a Tree,
    what: &str,
) -> Result<&'a KTree<K, V>, Failure> {
    let found = other.values.as_ref().ok_or_else(|| {
        Failure::Value(format!(
            "{what}: the other tree holds no values (use mask for a shape)"
        ))
    })?;
    found.as_typed::<K, V>().ok_or_else(|| {
        Failure::Value(format!(
            "{what}: trees of K = {K} and {} values were expected, the other is K = {} with {} values",
            stringify_dtype::<V>(),
            found.k(),
            found.dtype().name()
        ))
    })
}

impl Tree {
    /// The tree's values, or a `ValueError` naming `what`.
    fn values_or_fail(&self, what: &str) -> Result<&AnyValuedTree, Failure> {
        self.values.as_ref().ok_or_else(|| {
            Failure::Value(format!(
                "{what}: the tree holds no values (make one with from_dense of a numeric array)"
            ))
        })
    }

    /// The background of a valued tree's dense arrays: the one given, else the one it was made with.
    pub(crate) fn background_or(&self, background: Option<f64>) -> f64 {
        background.unwrap_or(self.background)
    }
}

#[pymethods]
impl Tree {
    /// The value type of the voxels, as numpy names it ("uint8", "uint16", "uint32", "int8", "float32";
    /// "rgb8" for colours), or None for a tree without values.
    #[getter]
    fn dtype(&self) -> Option<&'static str> {
        self.values.as_ref().map(|t| t.dtype().name())
    }

    /// The names of the labels, a dict from label to name: those a `.ktree` file keeps (`ktree voxelize
    /// --labels` names each mesh or OBJ group), those of `from_meshes`, or those given to
    /// `with_label_names`. Empty when the labels have no names.
    #[getter]
    fn label_names(&self) -> BTreeMap<i64, String> {
        self.notes
            .iter()
            .filter_map(|(note, name)| {
                let label = note.strip_prefix("label.")?.parse().ok()?;
                Some((label, name.clone()))
            })
            .collect()
    }

    /// This tree with its labels named by `names` (a dict from integer label to name; the names it had are
    /// replaced). `save` to `.ktree`, `to_bytes` and pickling keep them, as do `mask`, `overlay`,
    /// `combine` and the transforms; `relabel` drops them. A tree of integer labels only.
    fn with_label_names(&self, names: BTreeMap<i64, String>) -> PyResult<Self> {
        let values = self.values_or_fail("with_label_names")?;
        let dtype = values.dtype();
        let (lo, hi) = match dtype {
            Dtype::U8 => (0, i64::from(u8::MAX)),
            Dtype::U16 => (0, i64::from(u16::MAX)),
            Dtype::U32 => (0, i64::from(u32::MAX)),
            Dtype::I8 => (i64::from(i8::MIN), i64::from(i8::MAX)),
            Dtype::F32 | Dtype::Rgb => {
                return Err(Failure::Value(format!(
                    "with_label_names: the tree holds {} values, not integer labels",
                    dtype.name()
                ))
                .into())
            }
        };
        let mut notes: Notes = self
            .notes
            .iter()
            .filter(|(note, _)| !note.starts_with("label."))
            .map(|(n, t)| (n.clone(), t.clone()))
            .collect();
        for (label, name) in names {
            if !(lo..=hi).contains(&label) {
                return Err(Failure::Value(format!(
                    "with_label_names: label {label} is not a {} value",
                    dtype.name()
                ))
                .into());
            }
            if name.contains(['\n', '\r']) {
                return Err(Failure::Value(format!(
                    "with_label_names: the name of label {label} holds a line break"
                ))
                .into());
            }
            notes.insert(label_note(&label.to_string()), name);
        }
        // The same voxels and values: only the names change.
        Ok(Self {
            inner: self.inner.clone(),
            values: self.values.clone(),
            background: self.background,
            notes,
        })
    }

    /// The voxels that hold a value, as a tree without values (a tree without values: itself).
    fn shape(&self) -> Self {
        Self::binary(self.inner.clone())
    }

    /// The values at points: an (n, K) integer array (or K integers) in, a numpy array of the tree's dtype
    /// out ((n, 3) for colours), `background` (default: the one the tree was made with) where a point is
    /// empty or outside the universe.
    #[pyo3(signature = (points, background = None))]
    fn values<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLike2<'py, i64, AllowTypeChange>,
        background: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let tree = self.values_or_fail("values")?;
        let background = self.background_or(background);
        let input = Numbers::new(points);
        input.rows_of(tree.k(), false, "values: points")?;
        let flat = input.flat();
        let n = input.shape()[0];
        fn at<'py, const K: usize, V: Scalar>(
            py: Python<'py>,
            t: &KTree<K, V>,
            flat: &[i64],
            n: usize,
            background: f64,
        ) -> PyResult<Bound<'py, PyAny>> {
            let points: Vec<[u32; K]> = rows::<K, i64>(flat)
                .iter()
                .map(|p| p.map(|c| u32::try_from(c).unwrap_or(u32::MAX)))
                .collect();
            let background = V::of_f64(background).ok_or_else(|| {
                Failure::Value(format!(
                    "background {background} is not a {} value",
                    stringify_dtype::<V>()
                ))
            })?;
            let out = py.detach(|| numbers(&t.values_at(&points), background));
            let dims: Vec<usize> = if V::CHANNELS > 1 {
                vec![n, V::CHANNELS]
            } else {
                vec![n]
            };
            let array = ArrayD::from_shape_vec(IxDyn(&dims), out).map_err(Failure::value)?;
            Ok(array.into_pyarray(py).into_any())
        }
        with_valued!(tree, t => at(py, t, flat, n, background))
    }

    /// The voxels holding `value` (or, with `hi`, a value from `value` to `hi`, both included; on every
    /// channel for colours), as a tree without values.
    #[pyo3(signature = (value, hi = None))]
    fn select(
        &self,
        py: Python<'_>,
        value: &Bound<'_, PyAny>,
        hi: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let tree = self.values_or_fail("select")?;
        fn of<const K: usize, V: Scalar>(
            py: Python<'_>,
            t: &KTree<K, V>,
            lo: &Bound<'_, PyAny>,
            hi: Option<&Bound<'_, PyAny>>,
        ) -> Result<AnyTree, Failure> {
            let lo = V::of_py(lo)?;
            let hi = hi.map(V::of_py).transpose()?;
            Ok(py.detach(|| match hi {
                None => AnyTree::from(t.select(lo)),
                Some(hi) => AnyTree::from(t.select_range(lo, hi)),
            }))
        }
        Ok(Self::binary(with_valued!(tree, t => of(py, t, value, hi))?))
    }

    /// The values of the voxels inside `tree` (its shape when it holds values); the others empty.
    fn mask(&self, py: Python<'_>, tree: PyRef<'_, Tree>) -> PyResult<Self> {
        let mine = self.values_or_fail("mask")?;
        fn of<const K: usize, V: Value>(
            t: &KTree<K, V>,
            mask: &AnyTree,
        ) -> Result<AnyValuedTree, Failure> {
            let mask = mask.as_dim::<K>().ok_or_else(|| {
                Failure::Value(format!(
                    "mask: a tree of K = {K} was expected, got K = {}",
                    mask.k()
                ))
            })?;
            Ok(AnyValuedTree::from(t.mask(mask)))
        }
        let mask = &tree.inner;
        let out = py.detach(|| with_valued!(mine, t => of(t, mask)))?;
        Ok(self.with_values(out))
    }

    /// `tree`'s values where it has them (painted over this tree), this tree's elsewhere (the same K and
    /// dtype).
    fn overlay(&self, py: Python<'_>, tree: PyRef<'_, Tree>) -> PyResult<Self> {
        let mine = self.values_or_fail("overlay")?;
        let tree: &Tree = &tree;
        let out = py.detach(|| {
            with_valued!(mine, t => {
                let other = same(tree, "overlay")?;
                t.overlay(other).map(AnyValuedTree::from).map_err(Failure::value)
            })
        })?;
        Ok(self.with_values(out))
    }

    /// The voxels of either tree (the same K and dtype); where both hold a value, `rule` decides: "first"
    /// (this tree's), "min", "max" or "sum" (saturating for integers).
    fn combine(&self, py: Python<'_>, tree: PyRef<'_, Tree>, rule: &str) -> PyResult<Self> {
        let mine = self.values_or_fail("combine")?;
        let rule = Rule::parse(rule).ok_or_else(|| {
            Failure::Value(format!(
                "combine: rule '{rule}' is not one of first, min, max, sum"
            ))
        })?;
        let tree: &Tree = &tree;
        let out = py.detach(|| {
            with_valued!(mine, t => {
                let other = same(tree, "combine")?;
                t.combine(other, rule).map(AnyValuedTree::from).map_err(Failure::value)
            })
        })?;
        Ok(self.with_values(out))
    }

    /// The tree with values replaced by `mapping` (a dict from value to value; a value mapped to None is
    /// removed); values not in it are kept. The labels' names are dropped.
    fn relabel(&self, py: Python<'_>, mapping: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mine = self.values_or_fail("relabel")?;
        fn of<const K: usize, V: Scalar>(
            py: Python<'_>,
            t: &KTree<K, V>,
            mapping: &Bound<'_, PyDict>,
        ) -> Result<AnyValuedTree, Failure> {
            let mut table = HashMap::new();
            for (from, to) in mapping.iter() {
                let to = if to.is_none() {
                    None
                } else {
                    Some(V::of_py(&to)?)
                };
                table.insert(V::of_py(&from)?.key(), to);
            }
            py.detach(|| {
                t.relabel(&table)
                    .map(AnyValuedTree::from)
                    .map_err(Failure::value)
            })
        }
        let out = with_valued!(mine, t => of(py, t, mapping))?;
        // The labels change: their names no longer apply.
        Ok(Self::valued(out, self.background))
    }

    /// For each value (a number, or an (r, g, b) tuple), a dict of its `voxels`, `bounding_box` (lo, hi:
    /// hi excluded), `centroid` (the mean of voxel centres, v + 0.5) and `surface_area` (faces between a
    /// voxel of the value and one without it).
    fn value_stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mine = self.values_or_fail("value_stats")?;
        fn of<'py, const K: usize, V: Scalar>(
            py: Python<'py>,
            t: &KTree<K, V>,
        ) -> PyResult<Bound<'py, PyDict>> {
            let stats = py.detach(|| t.value_stats());
            let out = PyDict::new(py);
            for s in stats.into_values() {
                let d = PyDict::new(py);
                d.set_item("voxels", s.voxels)?;
                d.set_item(
                    "bounding_box",
                    (s.bounding_box.0.to_vec(), s.bounding_box.1.to_vec()),
                )?;
                d.set_item("centroid", s.centroid.to_vec())?;
                d.set_item("surface_area", s.surface_area)?;
                out.set_item(s.value.to_py(py)?, d)?;
            }
            Ok(out)
        }
        with_valued!(mine, t => of(py, t))
    }
}

/// The window of a valued `to_dense`: `shape` voxels from `origin`, by default the bounding box of the
/// voxels with a value (as for a tree without values).
pub(crate) fn to_dense<'py>(
    py: Python<'py>,
    tree: &Tree,
    values: &AnyValuedTree,
    origin: Option<&[i64]>,
    shape: Option<&[usize]>,
    background: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (origin, shape): (Vec<i64>, Vec<usize>) = with_dim!(&tree.inner, AnyTree, t => {
        let (o, s) = crate::query::default_window(t, origin, shape);
        (o.to_vec(), s.to_vec())
    });
    let background = tree.background_or(background);
    fn of<'py, const K: usize, V: Scalar>(
        py: Python<'py>,
        t: &KTree<K, V>,
        origin: &[i64],
        shape: &[usize],
        background: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let array = py.detach(|| window(t, origin, shape, background))?;
        Ok(array.into_pyarray(py).into_any())
    }
    with_valued!(values, t => of(py, t, &origin, &shape, background))
}

/// The valued tree of a non-boolean numpy array (see `Tree.from_dense`).
pub(crate) fn tree_of_array(
    py: Python<'_>,
    array: &Bound<'_, PyAny>,
    k: usize,
    dtype: Dtype,
    level: u32,
    background: f64,
) -> PyResult<AnyValuedTree> {
    let elements = if dtype == Dtype::Rgb {
        "uint8"
    } else {
        dtype.name()
    };
    let array = array.call_method1("astype", (elements,))?;
    with_valued!(k, dtype, K, V => {
        let typed: PyArrayLikeDyn<'_, <V as Scalar>::Elem, AllowTypeChange> = array.extract()?;
        Ok(from_dense::<K, V>(py, typed, level, background)?)
    }, else Err(Failure::Value(format!(
        "from_dense: an array with {k} dimensions (1 to 4 are supported)"
    )).into()))
}
