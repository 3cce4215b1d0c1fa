//! Tree files in and out through the library's dispatch by extension (`ktree::io::read_tree` and
//! `ktree::io::write_tree` with their default options): `.ktree`, `.rays`, binvox, OctoMap `.bt` and OpenVDB
//! `.vdb`, meshes (voxelized when read; the tree's boundary when written, with `.glb` and `.svg`), VTK
//! files (`.vtu`, `.htg`) as outputs and volumes as inputs; the `.ktree` bytes of a tree, and pickling
//! through them. Errors of the file system become `OSError`, the others `ValueError`; an `OSError` is of
//! the subclass its kind names (`FileNotFoundError`, `PermissionError`, …) with `filename` set.

use std::path::{Path, PathBuf};

use ktree::io::{ReadOptions, WriteOptions};
use ktree::with_dim;
use ktree::AnyTree;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
    /// Reads a tree file; the format is chosen by the extension.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let tree = py.detach(|| read_tree_with(&path, &ReadOptions::default()))?;
        Ok(Self { inner: tree })
    }

    /// Writes the tree (atomically: a temporary file renamed); the format is chosen by the extension.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        Ok(py.detach(|| {
            ktree::io::write_tree(&path, &self.inner, &WriteOptions::default())
                .map_err(|e| Failure::of_error(&e, &path))
        })?)
    }

    /// The tree in the `.ktree` format (version 2: 2 bits a node, checksums per level), as bytes.
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = py.detach(|| {
            let mut out = Vec::new();
            with_dim!(&self.inner, AnyTree, t => ktree::io::write_ktree(&mut out, t)).map(|()| out)
        });
        let bytes = bytes.map_err(Failure::value)?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The tree of bytes in the `.ktree` format (as `to_bytes` gives).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let tree =
            py.detach(|| ktree::io::read_ktree_any(data, "<bytes>").map_err(Failure::value))?;
        Ok(Self { inner: tree })
    }

    /// Pickling: the tree is rebuilt from its `.ktree` bytes.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let rebuild = slf.get_type().getattr("from_bytes")?;
        Ok((rebuild, (slf.get().to_bytes(slf.py())?,)))
    }
}

/// Reads a tree from a file of any format the library reads, chosen by extension, with `options`.
pub(crate) fn read_tree_with(path: &Path, options: &ReadOptions) -> Result<AnyTree, Failure> {
    ktree::io::read_tree(path, options).map_err(|e| Failure::of_error(&e, path))
}
