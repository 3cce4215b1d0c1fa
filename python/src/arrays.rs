//! Arrays in from numpy, one way for every method: an array of numbers read in place when numpy's memory
//! allows it (the dtype asked for, C-contiguous: a read-only view, no copy), otherwise converted by numpy
//! (`numpy.asarray(a, dtype)`) and, when not C-contiguous, copied once; then seen as rows of `N` numbers
//! (points, ray origins, vertices, runs) without another copy.

use numpy::ndarray::{Dimension, IxDyn};
use numpy::{AllowTypeChange, Element, PyArray, PyArrayLike, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::failure::Failure;

/// The numbers of a numpy array in C order (row after row), borrowed where possible.
pub(crate) struct Numbers<'py, T: Element, D: Dimension> {
    array: PyArrayLike<'py, T, D, AllowTypeChange>,
    /// The numbers in C order when the array's memory is not (a copy); `None` when borrowed.
    copy: Option<Vec<T>>,
}

impl<'py, T: Element + Copy, D: Dimension> Numbers<'py, T, D> {
    /// The numbers of `array` (already of dtype `T`, by numpy's conversion where it was not).
    pub(crate) fn new(array: PyArrayLike<'py, T, D, AllowTypeChange>) -> Self {
        let copy = (!array.is_c_contiguous()).then(|| array.as_array().iter().copied().collect());
        Self { array, copy }
    }

    /// The array's shape.
    pub(crate) fn shape(&self) -> &[usize] {
        self.array.shape()
    }

    /// The numbers in C order: the array's own memory when it is C-contiguous.
    pub(crate) fn flat(&self) -> &[T] {
        match &self.copy {
            Some(copy) => copy,
            None => self.array.as_slice().unwrap_or_default(),
        }
    }

    /// The shape checked to be `(N, k)`, or `(k,)` (one row) when `one_row` allows it; whether it was one
    /// row. `what` names the array in the error.
    pub(crate) fn rows_of(&self, k: usize, one_row: bool, what: &str) -> Result<bool, Failure> {
        match self.shape() {
            [n] if one_row && *n == k => Ok(true),
            [_, c] if *c == k => Ok(false),
            shape => Err(Failure::Value(if one_row {
                format!("{what}: {k} coordinates or an (N, {k}) array, got shape {shape:?}")
            } else {
                format!("{what} must be (n, {k}), got {shape:?}")
            })),
        }
    }
}

impl<'py> Numbers<'py, u32, IxDyn> {
    /// The numbers of `object` when it is already a C-contiguous array of dtype uint32 (read in place),
    /// otherwise `None`.
    pub(crate) fn in_place(object: &Bound<'py, PyAny>) -> Option<Self> {
        let array = object.cast::<PyArray<u32, IxDyn>>().ok()?;
        if !array.is_c_contiguous() {
            return None;
        }
        Some(Self::new(object.extract().ok()?))
    }
}

/// Numbers in C order seen as rows of `N` (a trailing partial row is left out: the callers check shapes).
pub(crate) fn rows<const N: usize, T>(flat: &[T]) -> &[[T; N]] {
    flat.as_chunks::<N>().0
}
