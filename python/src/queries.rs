//! The questions asked of a tree from Python: points (one or an `(N, K)` array), dense windows, the full
//! cells, ray casts and nearest voxels. Arrays are read into plain vectors first, so that the work runs
//! without the interpreter lock.

use ktree::query::{self, DenseError, DenseOrder, RayCast};
use ktree::space::DENSE_LIMIT;
use ktree::KTree;
use numpy::ndarray::{Array1, Array2, ArrayD, ArrayViewD, IxDyn, ShapeBuilder};

use crate::failure::Failure;

/// Rows of `k` numbers, row after row, and whether they were one point (a 1-D array).
pub(crate) struct Rows<T> {
    pub(crate) flat: Vec<T>,
    pub(crate) single: bool,
}

/// The rows of a 1-D array of `k` numbers (one point) or an `(N, k)` array.
pub(crate) fn rows<T: Copy>(
    view: &ArrayViewD<'_, T>,
    k: usize,
    what: &str,
) -> Result<Rows<T>, Failure> {
    let ok = match view.shape() {
        [n] => *n == k,
        [_, c] => *c == k,
        _ => false,
    };
    if !ok {
        return Err(Failure::Value(format!(
            "{what} of a K = {k} tree: {k} coordinates or an (N, {k}) array, got shape {:?}",
            view.shape()
        )));
    }
    Ok(Rows {
        flat: view.iter().copied().collect(),
        single: view.ndim() == 1,
    })
}

/// The points of flat rows.
fn points<const K: usize>(flat: &[i64]) -> Vec<[i64; K]> {
    flat.chunks_exact(K)
        .map(|r| std::array::from_fn(|a| r[a]))
        .collect()
}

/// Whether each point is inside (outside the universe, negative coordinates included: no).
pub(crate) fn contains<const K: usize>(tree: &KTree<K>, flat: &[i64]) -> Vec<bool> {
    let voxels: Vec<[u32; K]> = points::<K>(flat)
        .iter()
        .map(|p| p.map(|v| u32::try_from(v).unwrap_or(u32::MAX)))
        .collect();
    tree.contains_many(&voxels)
}

/// The distance to the nearest full voxel and that voxel (`inf` and −1s for an empty tree).
pub(crate) fn nearest<const K: usize>(tree: &KTree<K>, flat: &[i64]) -> (Vec<f64>, Vec<i64>) {
    let found = query::nearest_many_signed(tree, &points::<K>(flat)).unwrap_or_else(|e| match e {});
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
pub(crate) fn window<const K: usize>(
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
pub(crate) fn signed_distance<const K: usize>(
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

/// The default window: the bounding box (from `origin` when given), empty for an empty tree.
pub(crate) fn default_window<const K: usize>(
    tree: &KTree<K>,
    origin: Option<[i64; K]>,
    shape: Option<[usize; K]>,
) -> ([i64; K], [usize; K]) {
    let bounds = tree.bounding_box();
    let origin = origin.unwrap_or_else(|| bounds.map_or([0; K], |(lo, _)| lo.map(i64::from)));
    let shape = shape.unwrap_or_else(|| match bounds {
        Some((_, hi)) => std::array::from_fn(|a| (i64::from(hi[a]) - origin[a]).max(0) as usize),
        None => [0; K],
    });
    (origin, shape)
}

/// The full leaves as an `(n, K + 1)` array: corner coordinates, then side.
pub(crate) fn cells<const K: usize>(tree: &KTree<K>) -> Array2<i64> {
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
pub(crate) struct Casts {
    pub(crate) hit: Array1<bool>,
    pub(crate) voxel: Array2<i64>,
    pub(crate) t: Array1<f64>,
    pub(crate) axis: Array1<i8>,
    pub(crate) sign: Array1<i8>,
}

/// Casts the rays of flat `(N, K)` origins and directions.
pub(crate) fn cast<const K: usize>(
    tree: &KTree<K>,
    origins: &[f64],
    directions: &[f64],
    max_t: f64,
) -> Result<Casts, Failure> {
    let n = origins.len() / K;
    if directions.len() != origins.len() {
        return Err(Failure::Value(format!(
            "{n} origins and {} directions: give as many of each",
            directions.len() / K
        )));
    }
    let rays = (0..n)
        .map(|i| {
            RayCast::new(
                std::array::from_fn(|a| origins[i * K + a]),
                std::array::from_fn(|a| directions[i * K + a]),
                max_t,
            )
            .map_err(|e| Failure::Value(format!("ray {i}: {e}")))
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
