//! `Tree.from_points(points, voxel_size, values=…, reduce=…)`: a point cloud's values in its voxels — each
//! voxel's value reduced from the values of the points in it (the mean, largest, smallest or most frequent,
//! or the points' count), by the library's [`CloudVoxelizer::voxelize_values`].

use ktree::solid::cloud::{mean_colour, CloudVoxelizer};
use ktree::tree::{AnyValuedTree, Dtype, Rgb};
use ktree::{with_valued, KTree};
use numpy::{AllowTypeChange, PyArrayLike1, PyArrayLike2};
use pyo3::prelude::*;

use crate::failure::Failure;
use crate::values::{dtype_for, Scalar};

/// How a voxel's points give it one value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reduce {
    Mean,
    Max,
    Min,
    Mode,
    Count,
}

impl Reduce {
    fn parse(name: &str) -> Result<Self, Failure> {
        Ok(match name {
            "mean" => Reduce::Mean,
            "max" => Reduce::Max,
            "min" => Reduce::Min,
            "mode" => Reduce::Mode,
            "count" => Reduce::Count,
            _ => {
                return Err(Failure::Value(format!(
                    "from_points: reduce {name:?}: one of \"mean\", \"max\", \"min\", \"mode\", \"count\""
                )))
            }
        })
    }

    /// The value of numbers (never none): the mean summed in `f64`; the most frequent, the smallest of
    /// equally frequent.
    fn numbers(self, xs: &[f64]) -> f64 {
        match self {
            Reduce::Mean => xs.iter().sum::<f64>() / xs.len() as f64,
            Reduce::Max => xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            Reduce::Min => xs.iter().copied().fold(f64::INFINITY, f64::min),
            Reduce::Mode => {
                let mut sorted = xs.to_vec();
                sorted.sort_by(f64::total_cmp);
                most_frequent(&sorted)
            }
            Reduce::Count => xs.len() as f64,
        }
    }
}

/// The most frequent of sorted items (never none); of items equally frequent, the first.
fn most_frequent<T: Copy + PartialEq>(sorted: &[T]) -> T {
    let mut best = (0usize, sorted[0]);
    for run in sorted.chunk_by(|a, b| a == b) {
        if run.len() > best.0 {
            best = (run.len(), run[0]);
        }
    }
    best.1
}

/// A voxel's value of type `V` from the reduction of its points' numbers: a float as it is, an integer
/// rounded (halves up) and clamped to the type.
fn value_of<V: Scalar>(x: f64, dtype: Dtype) -> V {
    if dtype == Dtype::F32 {
        return V::of_f64(x).unwrap_or_else(|| V::of_f64(f64::from(x as f32)).expect("a float32"));
    }
    let (lo, hi) = match dtype {
        Dtype::U8 => (0.0, 255.0),
        Dtype::U16 => (0.0, 65535.0),
        Dtype::I8 => (-128.0, 127.0),
        _ => (0.0, 4294967295.0),
    };
    V::of_f64((x + 0.5).floor().clamp(lo, hi)).expect("an integer in the type's range")
}

/// The valued tree of `points` voxelized by `voxelizer`, each voxel holding the reduction of its points'
/// `values` (an (n,) array of numbers, or (n, 3) uint8 colours; `None` with `reduce="count"`: the count).
pub(crate) fn tree_of_point_values(
    py: Python<'_>,
    points: &[[f64; 3]],
    voxelizer: &CloudVoxelizer,
    values: Option<&Bound<'_, PyAny>>,
    reduce: &str,
) -> PyResult<AnyValuedTree> {
    let reduce = Reduce::parse(reduce)?;
    let fail = |e: ktree::solid::SolidError| Failure::Value(format!("from_points: {e}"));
    let counted = |per_point: &[u8]| -> PyResult<AnyValuedTree> {
        let voxels = py
            .detach(|| voxelizer.voxelize_values(points, per_point, |g| g.len() as u32))
            .map_err(fail)?;
        Ok(AnyValuedTree::from(KTree::from_value_runs(&voxels.runs)))
    };
    let Some(values) = values else {
        if reduce != Reduce::Count {
            return Err(Failure::Value(
                "from_points: a reduction other than \"count\" needs values".into(),
            )
            .into());
        }
        return counted(&vec![0u8; points.len()]);
    };
    if reduce == Reduce::Count {
        return counted(&vec![0u8; points.len()]);
    }
    let array = py.import("numpy")?.call_method1("asarray", (values,))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let name: String = array.getattr("dtype")?.getattr("name")?.extract()?;
    if shape == [points.len(), 3] && name == "uint8" {
        let colours: PyArrayLike2<'_, u8, AllowTypeChange> = array.extract()?;
        let colours: Vec<Rgb> = colours
            .as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect();
        let voxels = match reduce {
            Reduce::Mean => py.detach(|| voxelizer.voxelize_values(points, &colours, mean_colour)),
            Reduce::Mode => py.detach(|| {
                voxelizer.voxelize_values(points, &colours, |g| {
                    let mut sorted = g.to_vec();
                    sorted.sort_unstable();
                    most_frequent(&sorted)
                })
            }),
            _ => {
                return Err(Failure::Value(
                    "from_points: colours are reduced by \"mean\", \"mode\" or \"count\"".into(),
                )
                .into())
            }
        }
        .map_err(fail)?;
        return Ok(AnyValuedTree::from(KTree::from_value_runs(&voxels.runs)));
    }
    if shape != [points.len()] {
        return Err(Failure::Value(format!(
            "from_points: values must be an ({n},) array of numbers or an ({n}, 3) uint8 array of colours, not of shape {shape:?} and dtype {name}",
            n = points.len()
        ))
        .into());
    }
    let numbers: PyArrayLike1<'_, f64, AllowTypeChange> =
        array.call_method1("astype", ("float64",))?.extract()?;
    let numbers: Vec<f64> = numbers.as_array().iter().copied().collect();
    if let Some(i) = numbers.iter().position(|x| x.is_nan()) {
        return Err(Failure::Value(format!("from_points: value {i} is NaN")).into());
    }
    let (lo, hi) = numbers
        .iter()
        .fold((0.0f64, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
    let dtype = dtype_for(&name, lo, hi)?.ok_or_else(|| {
        Failure::Value("from_points: values must be numbers, not booleans".into())
    })?;
    with_valued!(3, dtype, K, V => {
        let voxels = py
            .detach(|| {
                voxelizer.voxelize_values(points, &numbers, |g| value_of::<V>(reduce.numbers(g), dtype))
            })
            .map_err(fail)?;
        Ok(AnyValuedTree::from(KTree::<3, V>::from_value_runs(&voxels.runs)))
    }, else Err(Failure::Value(format!("from_points: values of dtype {name}")).into()))
}
