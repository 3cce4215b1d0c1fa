//! Tree files in and out through the library's dispatch by extension (`ktree::input::read_tree`, which
//! voxelizes meshes and volumes, and `ktree::io::write_tree`, with their default options): `.ktree`, `.rays`, binvox, OctoMap `.bt` and OpenVDB
//! `.vdb`, meshes (voxelized when read; the tree's boundary when written, with `.glb` and `.svg`), VTK
//! files (`.vtu`, `.htg`) as outputs and volumes as inputs; the `.ktree` bytes of a tree, and pickling
//! through them. Errors of the file system become `OSError`, the others `ValueError`; an `OSError` is of
//! the subclass its kind names (`FileNotFoundError`, `PermissionError`, …) with `filename` set.

use std::path::{Path, PathBuf};

use ktree::io::ktree::v3::{read_any_ktree_noted, valued_header, write_any_valued_ktree, AnyKtree};
use ktree::io::ktree::Notes;
use ktree::io::{ReadOptions, WriteOptions};
use ktree::with_dim;
use ktree::AnyTree;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::failure::Failure;
use crate::Tree;

#[pymethods]
impl Tree {
    /// Reads a tree file; the format is chosen by the extension. A `.ktree` file with values (version 3)
    /// or an OpenVDB grid with values (`Int32Grid`, `FloatGrid`, `Vec3SGrid`, …) gives a tree with values
    /// (background 0).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        if path.extension().is_some_and(|e| e == "vdb") {
            let name = path.display().to_string();
            let bytes = std::fs::read(&path).map_err(|e| Failure::of_error(&e, &path))?;
            if ktree::io::vdb_holds_values(&bytes, &name).unwrap_or(false) {
                let read = py.detach(|| {
                    ktree::io::read_vdb_values(&bytes, &name, None, None)
                        .map_err(|e| Failure::of_error(&e, &path))
                })?;
                return Ok(Self::valued(read.tree, 0.0));
            }
        }
        if path.extension().is_some_and(|e| e == "ktree") && file_holds_values(&path) {
            let tree = py.detach(|| {
                let name = path.display().to_string();
                let bytes = std::fs::read(&path).map_err(|e| Failure::of_error(&e, &path))?;
                read_any_ktree_noted(&bytes, &name).map_err(|e| Failure::of_error(&e, &path))
            })?;
            return Ok(Self::of_file(tree, 0.0));
        }
        let tree = py.detach(|| read_tree_with(&path, &ReadOptions::default()))?;
        Ok(Self::binary(tree))
    }

    /// Writes the tree (atomically: a temporary file renamed); the format is chosen by the extension. A
    /// tree with values keeps them in `.ktree` (version 3), OpenVDB typed grids (`.vdb`), NIfTI (`.nii`,
    /// `.nii.gz`), VTK cell data (`.vtu`, `.htg`) and the coloured surfaces of its values (`.ply`, `.obj`,
    /// `.glb`); other formats would drop the values: save `tree.shape()` for them. A `.ktree` keeps the
    /// labels' names (`label_names`); a mesh names each label's part by them.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let options = WriteOptions {
            notes: self.notes.clone(),
            ..WriteOptions::default()
        };
        Ok(py.detach(|| {
            match &self.values {
                Some(values) => ktree::io::write_valued_tree(&path, values, &options).map(drop),
                None => ktree::io::write_tree(&path, &self.inner, &options),
            }
            .map_err(|e| Failure::of_error(&e, &path))
        })?)
    }

    /// The tree in the `.ktree` format (version 2: 2 bits a node, checksums per level; version 3 with the
    /// values for a tree with values), as bytes.
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = py.detach(|| {
            let mut out = Vec::new();
            match &self.values {
                Some(values) => write_any_valued_ktree(&mut out, values, &self.notes),
                None => with_dim!(&self.inner, AnyTree, t => ktree::io::write_ktree(&mut out, t)),
            }
            .map(|()| out)
        });
        let bytes = bytes.map_err(Failure::value)?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The tree of bytes in the `.ktree` format (as `to_bytes` gives); a tree with values gets
    /// `background` as the background of its dense arrays.
    #[staticmethod]
    #[pyo3(signature = (data, background = 0.0))]
    fn from_bytes(py: Python<'_>, data: &[u8], background: f64) -> PyResult<Self> {
        let tree = py.detach(|| read_any_ktree_noted(data, "<bytes>").map_err(Failure::value))?;
        Ok(Self::of_file(tree, background))
    }

    /// Pickling: the tree is rebuilt from its `.ktree` bytes (and its background).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Rebuild<'py>> {
        let rebuild = slf.get_type().getattr("from_bytes")?;
        Ok((
            rebuild,
            (slf.get().to_bytes(slf.py())?, slf.get().background),
        ))
    }
}

impl Tree {
    /// The Python object of a `.ktree` file's tree and its notes.
    fn of_file((tree, notes): (AnyKtree, Notes), background: f64) -> Self {
        match tree {
            AnyKtree::Binary(t) => Self::binary(t),
            AnyKtree::Valued(t) => Self {
                notes,
                ..Self::valued(t, background)
            },
        }
    }
}

/// Whether a `.ktree` file's header says it holds values (a file that cannot be read says no: the reader
/// of every format then reports it).
fn file_holds_values(path: &Path) -> bool {
    use std::io::Read;
    let mut head = Vec::new();
    let read = std::fs::File::open(path).and_then(|f| f.take(16).read_to_end(&mut head));
    read.is_ok() && matches!(valued_header(&head, ""), Ok((_, _, Some(_))))
}

/// What pickling calls to rebuild a tree, and its arguments (the `.ktree` bytes and the background).
type Rebuild<'py> = (Bound<'py, PyAny>, (Bound<'py, PyBytes>, f64));

/// Reads a tree from a file of any format the library reads, chosen by extension, with `options`.
pub(crate) fn read_tree_with(path: &Path, options: &ReadOptions) -> Result<AnyTree, Failure> {
    ktree::input::read_tree(path, options).map_err(|e| Failure::of_error(&e, path))
}
