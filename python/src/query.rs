//! The questions asked of a tree from Python, each one call of the library's queries (`ktree::query`):
//! its size, points (one or an `(N, K)` array, and `tree[x, y, z]`), dense windows and slices, boxes
//! (bounding box, `count` and `crop` of `[lo, hi)`), the full cells, ray casts, nearest voxels and
//! distances, statistics, and interference with another tree. Point arrays are read in place
//! ([`crate::arrays`]) and answered without the interpreter lock.

use ktree::query::{self, DenseError, DenseOrder, RayCast};
use ktree::space::DENSE_LIMIT;
use ktree::{with_dim, AnyTree, KTree};
use numpy::ndarray::{Array1, Array2, ArrayD, IxDyn, ShapeBuilder};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArrayDyn, PyArrayLikeDyn};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PySlice, PyTuple};

use crate::arrays::{rows, Numbers};
use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
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
    ///
    /// For a tree with values, the values (of its dtype; colours with a last axis of 3) with `background`
    /// where the tree is empty (default: the background it was made with), the window by default the
    /// bounding box of the voxels with a value.
    #[pyo3(signature = (origin = None, shape = None, background = None))]
    fn to_dense<'py>(
        &self,
        py: Python<'py>,
        origin: Option<Vec<i64>>,
        shape: Option<Vec<usize>>,
        background: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = self.inner.k();
        check_lengths(
            "to_dense",
            k,
            &[
                ("origin", origin.as_deref().map(<[i64]>::len)),
                ("shape", shape.as_deref().map(<[usize]>::len)),
            ],
        )?;
        if let Some(values) = &self.values {
            return crate::values::to_dense(
                py,
                self,
                values,
                origin.as_deref(),
                shape.as_deref(),
                background,
            );
        }
        let array = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let (o, s) = default_window(t, origin.as_deref(), shape.as_deref());
                window(t, o, s)
            })
        })?;
        Ok(array.into_pyarray(py).into_any())
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
        check_lengths(
            "signed_distance",
            k,
            &[
                ("origin", origin.as_deref().map(<[i64]>::len)),
                ("shape", shape.as_deref().map(<[usize]>::len)),
            ],
        )?;
        let array = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let (o, s) = default_window(t, origin.as_deref(), shape.as_deref());
                signed_distance(t, o, s)
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
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = self.inner.k();
        let what = format!("contains: the points of a K = {k} tree");
        let (inside, single) = match Numbers::in_place(points) {
            // The library's own points (`[u32; K]`), read in place.
            Some(points) => {
                let single = points.rows_of(k, true, &what)?;
                let flat = points.flat();
                let inside =
                    py.detach(|| with_dim!(&self.inner, AnyTree, t => t.contains_many(rows(flat))));
                (inside, single)
            }
            // Any other array (int64 C-ordered read in place), converted by numpy where it must be.
            None => {
                let points: PyArrayLikeDyn<'py, i64, AllowTypeChange> = points.extract()?;
                let points = Numbers::new(points);
                let single = points.rows_of(k, true, &what)?;
                let flat = points.flat();
                let inside = py.detach(|| with_dim!(&self.inner, AnyTree, t => contains(t, flat)));
                (inside, single)
            }
        };
        if single {
            return Ok(PyBool::new(py, inside[0]).to_owned().into_any());
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
        let items: Vec<Bound<'py, PyAny>> = match key.cast::<PyTuple>() {
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
            if let Ok(slice) = item.cast::<PySlice>() {
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
            let inside = with_dim!(&self.inner, AnyTree, t => contains(t, &origin));
            return Ok(PyBool::new(py, inside[0]).to_owned().into_any());
        }
        let mut array = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => window(
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

    /// The number of full voxels in the box `[lo, hi)` (K integers each, hi exclusive; the box may reach
    /// outside the universe, which is empty there): one walk that descends only into the cells crossing
    /// the box's faces.
    fn count(&self, py: Python<'_>, lo: Vec<i64>, hi: Vec<i64>) -> PyResult<u128> {
        check_lengths(
            "count",
            self.inner.k(),
            &[("lo", Some(lo.len())), ("hi", Some(hi.len()))],
        )?;
        Ok(py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let (lo, hi) = voxel_box(&lo, &hi);
                t.count(lo, hi)
            })
        }))
    }

    /// The object cut to the box `[lo, hi)` (as in `count`), in the same universe.
    fn crop(&self, py: Python<'_>, lo: Vec<i64>, hi: Vec<i64>) -> PyResult<Self> {
        check_lengths(
            "crop",
            self.inner.k(),
            &[("lo", Some(lo.len())), ("hi", Some(hi.len()))],
        )?;
        let out = py.detach(|| {
            with_dim!(&self.inner, AnyTree, t => {
                let (lo, hi) = voxel_box(&lo, &hi);
                AnyTree::from(t.crop(lo, hi))
            })
        });
        Ok(Self::binary(out))
    }

    /// The full leaves as an `(n, K + 1)` int64 array: each row a cell's corner coordinates (its smallest
    /// voxel), then its side; rows in Morton order.
    fn cells<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        py.detach(|| with_dim!(&self.inner, AnyTree, t => cells(t)))
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
        let (o, d) = (Numbers::new(origins), Numbers::new(directions));
        o.rows_of(
            k,
            true,
            &format!("cast_rays: the origins of a K = {k} tree"),
        )?;
        d.rows_of(
            k,
            true,
            &format!("cast_rays: the directions of a K = {k} tree"),
        )?;
        let (o, d) = (o.flat(), d.flat());
        let casts = py.detach(|| with_dim!(&self.inner, AnyTree, t => cast(t, o, d, max_t)))?;
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
        let k = self.inner.k();
        let points = Numbers::new(points);
        let single = points.rows_of(k, true, &format!("distance: the points of a K = {k} tree"))?;
        let flat = points.flat();
        let (distance, _) = py.detach(|| with_dim!(&self.inner, AnyTree, t => nearest(t, flat)));
        if single {
            return Ok(PyFloat::new(py, distance[0]).into_any());
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
        let points = Numbers::new(points);
        let single = points.rows_of(k, true, &format!("nearest: the points of a K = {k} tree"))?;
        let flat = points.flat();
        let (_, voxel) = py.detach(|| with_dim!(&self.inner, AnyTree, t => nearest(t, flat)));
        if single {
            return Ok(voxel.into_pyarray(py).into_any());
        }
        let n = voxel.len() / k;
        let array = Array2::from_shape_vec((n, k), voxel).map_err(Failure::value)?;
        Ok(array.into_pyarray(py).into_any())
    }

    /// The statistics as a dict with the keys of `ktree stats --json --measures`: k, level, rays (None),
    /// full, empty, partial, nodes, bytes_at_2_bits, memory_bytes, voxels, bounding_box ([lo, hi], hi
    /// exclusive; None when empty), per_level (a list of dicts with level, full, empty, partial),
    /// surface_area and, for K = 2 and 3, euler_number (connectivity K).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = py.detach(|| self.inner.stats(None));
        let d = PyDict::new(py);
        d.set_item("k", s.k)?;
        d.set_item("level", s.level)?;
        d.set_item("rays", s.rays)?;
        d.set_item("full", s.full)?;
        d.set_item("empty", s.empty)?;
        d.set_item("partial", s.partial)?;
        d.set_item("nodes", s.nodes)?;
        d.set_item("bytes_at_2_bits", s.bytes_at_2_bits)?;
        d.set_item("memory_bytes", s.memory_bytes)?;
        d.set_item("voxels", s.voxels)?;
        d.set_item("bounding_box", s.bounding_box)?;
        let per_level = s
            .per_level
            .iter()
            .map(|c| {
                let l = PyDict::new(py);
                l.set_item("level", c.level)?;
                l.set_item("full", c.full)?;
                l.set_item("empty", c.empty)?;
                l.set_item("partial", c.partial)?;
                Ok(l)
            })
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("per_level", per_level)?;
        crate::shape::add_measures(py, &self.inner, &d)?;
        Ok(d)
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
}

/// Checks that each of the named lists given has `k` numbers.
fn check_lengths(what: &str, k: usize, lists: &[(&str, Option<usize>)]) -> Result<(), Failure> {
    for &(name, len) in lists {
        if let Some(len) = len.filter(|&n| n != k) {
            return Err(Failure::Value(format!(
                "{what}: {name} of a K = {k} tree has {k} numbers, got {len}"
            )));
        }
    }
    Ok(())
}

/// The box `[lo, hi)` of `K` numbers each (checked) in the library's voxel coordinates: whatever lies
/// below 0 or past the last coordinate is outside every universe, so the bounds are clamped there.
fn voxel_box<const K: usize>(lo: &[i64], hi: &[i64]) -> ([u32; K], [u32; K]) {
    let clamp = |v: i64| v.clamp(0, i64::from(u32::MAX)) as u32;
    (
        std::array::from_fn(|a| clamp(lo[a])),
        std::array::from_fn(|a| clamp(hi[a])),
    )
}

/// Whether each point of flat rows of `K` numbers is inside (outside the universe, negative coordinates
/// included: no), read in place by the library's batch query.
fn contains<const K: usize>(tree: &KTree<K>, flat: &[i64]) -> Vec<bool> {
    let found = query::contains_many_signed(tree, rows::<K, _>(flat));
    found.unwrap_or_else(|e| match e {})
}

/// The distance to the nearest full voxel and that voxel (`inf` and −1s for an empty tree).
fn nearest<const K: usize>(tree: &KTree<K>, flat: &[i64]) -> (Vec<f64>, Vec<i64>) {
    let found = query::nearest_many_signed(tree, rows::<K, _>(flat)).unwrap_or_else(|e| match e {});
    let distance = found
        .iter()
        .map(|n| n.map_or(f64::INFINITY, |n| n.distance()))
        .collect();
    let voxel = found
        .iter()
        .flat_map(|n| match n {
            Some(n) => n.voxel.map(i64::from),
            None => [-1; K],
        })
        .collect();
    (distance, voxel)
}

/// The voxels of the window of `shape` from `origin` as an array indexed `[x, y, z, …]` (memory in
/// Fortran order: the library's dense window, axis 0 fastest); voxels outside the universe are `False`.
fn window<const K: usize>(
    tree: &KTree<K>,
    origin: [i64; K],
    shape: [usize; K],
) -> Result<ArrayD<bool>, Failure> {
    let too_large = || {
        Failure::Value(format!(
            "a window of shape {shape:?} is more than {DENSE_LIMIT} voxels: ask for a smaller one"
        ))
    };
    shape
        .iter()
        .try_fold(1u128, |n, &s| n.checked_mul(s as u128))
        .filter(|&n| n <= DENSE_LIMIT)
        .ok_or_else(too_large)?;
    let end: [i64; K] = std::array::from_fn(|a| origin[a].saturating_add(shape[a] as i64));
    let data = query::dense_window(tree, origin, end, DenseOrder::FirstAxisFastest).map_err(
        |e| match e {
            DenseError::TooLarge { .. } => too_large(),
            e => Failure::value(e),
        },
    )?;
    ArrayD::from_shape_vec(IxDyn(&shape).f(), data).map_err(Failure::value)
}

/// The signed distances of a window (inside the universe), C order: an array indexed `[x, y, z, …]`.
fn signed_distance<const K: usize>(
    tree: &KTree<K>,
    origin: [i64; K],
    shape: [usize; K],
) -> Result<ArrayD<f32>, Failure> {
    let side = tree.universe().side() as i64;
    let lo: [u32; K] = std::array::from_fn(|a| origin[a].clamp(0, side) as u32);
    if (0..K).any(|a| i64::from(lo[a]) != origin[a]) {
        return Err(Failure::Value(format!(
            "signed_distance: origin {origin:?} is outside the universe (side {side})"
        )));
    }
    let data = tree
        .signed_distance_window(lo, shape)
        .map_err(Failure::value)?;
    ArrayD::from_shape_vec(IxDyn(&shape), data).map_err(Failure::value)
}

/// The window asked for (`K` numbers each, checked), by default the bounding box (from `origin` when
/// given), empty for an empty tree.
pub(crate) fn default_window<const K: usize>(
    tree: &KTree<K>,
    origin: Option<&[i64]>,
    shape: Option<&[usize]>,
) -> ([i64; K], [usize; K]) {
    let bounds = tree.bounding_box();
    let origin = origin.map_or_else(
        || bounds.map_or([0; K], |(lo, _)| lo.map(i64::from)),
        |o| std::array::from_fn(|a| o[a]),
    );
    let shape = match (shape, bounds) {
        (Some(s), _) => std::array::from_fn(|a| s[a]),
        (None, Some((_, hi))) => {
            std::array::from_fn(|a| (i64::from(hi[a]) - origin[a]).max(0) as usize)
        }
        (None, None) => [0; K],
    };
    (origin, shape)
}

/// The full leaves as an `(n, K + 1)` array: corner coordinates, then side.
fn cells<const K: usize>(tree: &KTree<K>) -> Array2<i64> {
    let mut flat = Vec::new();
    for cell in tree.full_cells() {
        flat.extend(cell.origin().map(i64::from));
        flat.push(cell.side() as i64);
    }
    let n = flat.len() / (K + 1);
    Array2::from_shape_vec((n, K + 1), flat).expect("n rows of K + 1")
}

/// Ray casts: hit, voxel (−1s for a miss), t (`inf` for a miss), axis and sign of the face entered (−1
/// and 0 for a miss or an origin inside a full voxel).
struct Casts {
    hit: Array1<bool>,
    voxel: Array2<i64>,
    t: Array1<f64>,
    axis: Array1<i8>,
    sign: Array1<i8>,
}

/// Casts the rays of flat `(N, K)` origins and directions.
fn cast<const K: usize>(
    tree: &KTree<K>,
    origins: &[f64],
    directions: &[f64],
    max_t: f64,
) -> Result<Casts, Failure> {
    let (origins, directions) = (rows::<K, _>(origins), rows::<K, _>(directions));
    let n = origins.len();
    if directions.len() != n {
        return Err(Failure::Value(format!(
            "{n} origins and {} directions: give as many of each",
            directions.len()
        )));
    }
    let rays = origins
        .iter()
        .zip(directions)
        .enumerate()
        .map(|(i, (&o, &d))| {
            RayCast::new(o, d, max_t).map_err(|e| Failure::Value(format!("ray {i}: {e}")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let hits = tree.cast_rays(&rays);
    let mut voxel = Vec::with_capacity(n * K);
    for h in &hits {
        match h {
            Some(h) => voxel.extend(h.voxel.map(i64::from)),
            None => voxel.extend([-1; K]),
        }
    }
    Ok(Casts {
        hit: hits.iter().map(Option::is_some).collect(),
        voxel: Array2::from_shape_vec((n, K), voxel).expect("n rows of K"),
        t: hits
            .iter()
            .map(|h| h.map_or(f64::INFINITY, |h| h.t))
            .collect(),
        axis: hits
            .iter()
            .map(|h| h.and_then(|h| h.face).map_or(-1, |f| f.axis as i8))
            .collect(),
        sign: hits
            .iter()
            .map(|h| h.and_then(|h| h.face).map_or(0, |f| f.sign))
            .collect(),
    })
}
