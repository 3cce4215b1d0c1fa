//! The Python module `ktree`: k-trees (K = 1…4) with numpy arrays in and out.
//!
//! One class, `ktree.Tree`, wraps the library's [`AnyTree`]; `K` comes from the input (an array's `ndim`, a
//! ray array's width, a file's header). Every call that may take long releases the interpreter lock, and
//! every error of the library becomes a Python exception (`ValueError` for bad input, `OSError` for files)
//! with the library's message.
//!
//! The class is defined here with what makes it a value (equality, hash, repr); its methods are grouped by
//! concern, each module one `#[pymethods]` block of a thin layer over one library call per method:
//! `construct` (trees from arrays, meshes, points and volumes), `files` (files, bytes, pickling),
//! `query` (points, windows, boxes, rays, distances, statistics), `shape` (Booleans, morphology,
//! components, measures), `geometry` (translations, rotations, scales, matrices), `export` (runs,
//! meshes, the viewer page) and `display` (pictures and line drawings). Arrays come in through
//! `arrays` (borrowed from numpy where its memory allows) and errors go out through `failure`.
//!
//! A second class, `ktree.OccupancyMap` (module `map`), wraps the library's occupancy maps; its parts are
//! `Tree` objects.

use std::hash::{DefaultHasher, Hash, Hasher};

use ktree::io::ktree::Notes;
use ktree::{with_dim, with_valued};
use ktree::{AnyTree, AnyValuedTree};
use pyo3::prelude::*;

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
            k => Err($crate::failure::Failure::Value(format!(
                "{}: K = {k} is not supported (1 to 4)",
                $what
            ))),
        }
    };
}

mod arrays;
mod construct;
mod display;
mod export;
mod failure;
mod files;
mod geometry;
mod map;
mod point_values;
mod query;
mod rays;
mod shape;
mod values;

/// A k-tree of dimension K = 1…4 (bintree, quadtree, octree, 4-D tree) over a universe of side 2**level.
///
/// Coordinates are `[x, y, z, ...]` as in the command-line tool: a dense array `a` has `a[x, y, z]` for
/// voxel (x, y, z), and rays run along the last axis. Trees are immutable: operations return new trees.
/// Two trees compare equal when they hold the same object in the same universe.
///
/// A tree made from a numeric array holds a value per voxel (`dtype` names its type; voxels equal to the
/// background are empty): `values`, `to_dense`, `select`, `mask`, `overlay`, `combine`, `relabel` and
/// `value_stats` use the values; every other method works on its shape (the voxels that hold a value) and
/// returns trees without values.
#[pyclass(frozen, name = "Tree", module = "ktree")]
pub(crate) struct Tree {
    /// The tree, or the shape of a tree with values (the voxels that hold one): what the methods of trees
    /// without values work on.
    pub(crate) inner: AnyTree,
    /// The values, for a tree made with them.
    pub(crate) values: Option<AnyValuedTree>,
    /// What dense arrays of the values hold where the tree is empty (the background it was made with).
    pub(crate) background: f64,
    /// The notes a `.ktree` file keeps with the values (the labels' names, `label.N`).
    pub(crate) notes: Notes,
}

impl Tree {
    /// The Python object of a library tree of any `K`.
    pub(crate) fn wrap(inner: impl Into<AnyTree>) -> Self {
        Self::binary(inner.into())
    }

    /// The Python object of a tree without values.
    pub(crate) fn binary(inner: AnyTree) -> Self {
        Self {
            inner,
            values: None,
            background: 0.0,
            notes: Notes::new(),
        }
    }

    /// The Python object of a tree with values whose dense arrays hold `background` where it is empty.
    pub(crate) fn valued(values: AnyValuedTree, background: f64) -> Self {
        Self {
            inner: values.shape(),
            values: Some(values),
            background,
            notes: Notes::new(),
        }
    }

    /// A tree with other values of the same meaning (masked, combined, moved): this tree's background
    /// and the names of its labels.
    pub(crate) fn with_values(&self, values: AnyValuedTree) -> Self {
        Self {
            notes: self.notes.clone(),
            ..Self::valued(values, self.background)
        }
    }
}

#[pymethods]
impl Tree {
    /// Same object in the same universe (trees are canonical, so this compares nodes) and, for trees with
    /// values, the same values of the same dtype: a tree with values never equals one without.
    fn __eq__(&self, other: PyRef<'_, Tree>) -> bool {
        match (&self.values, &other.values) {
            (None, None) => self.inner == other.inner,
            (Some(a), Some(b)) => a == b,
            _ => false,
        }
    }

    /// A hash of the object and its universe: equal trees hash equal (in every process: the hasher's keys
    /// are fixed), so trees can be set members and dict keys.
    fn __hash__(&self, py: Python<'_>) -> u64 {
        py.detach(|| {
            let mut h = DefaultHasher::new();
            self.inner.k().hash(&mut h);
            match &self.values {
                None => with_dim!(&self.inner, AnyTree, t => t.hash(&mut h)),
                Some(values) => {
                    values.dtype().hash(&mut h);
                    with_valued!(values, t => t.hash(&mut h));
                }
            }
            h.finish()
        })
    }

    fn __repr__(&self) -> String {
        let c = self.inner.counts();
        let dtype = self
            .values
            .as_ref()
            .map_or(String::new(), |v| format!(", dtype={}", v.dtype().name()));
        format!(
            "Tree(k={}, level={}{dtype}, nodes={}, full={}, partial={})",
            self.inner.k(),
            self.inner.level(),
            c.nodes(),
            c.full,
            c.partial
        )
    }
}

/// k-trees (bintrees, quadtrees, octrees, 4-D trees) with numpy arrays in and out: see `ktree.Tree`, and
/// occupancy maps made of them: see `ktree.OccupancyMap`.
#[pymodule]
#[pyo3(name = "ktree")]
fn ktree_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Tree>()?;
    m.add_class::<map::OccupancyMapPy>()?;
    m.add_class::<map::MapHistoryPy>()?;
    // What `Tree.cast_rays` returns.
    let fields = ["hit", "voxel", "t", "axis", "sign"];
    let hits = m
        .py()
        .import("collections")?
        .getattr("namedtuple")?
        .call1(("RayHits", fields))?;
    hits.setattr("__module__", "ktree")?;
    m.add("RayHits", hits)?;
    // What `OccupancyMap.cast_rays` returns.
    let fields = ["hit", "end", "key", "reason"];
    let hits = m
        .py()
        .import("collections")?
        .getattr("namedtuple")?
        .call1(("MapRayHits", fields))?;
    hits.setattr("__module__", "ktree")?;
    m.add("MapRayHits", hits)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
