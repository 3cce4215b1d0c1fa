//! Writing a tree with values in any format that keeps them, chosen by the file's extension: `.ktree`
//! (version 3, any K), OpenVDB typed grids (`.vdb`), NIfTI volumes (`.nii`, `.nii.gz`), VTK files with the
//! values as cell data (`.vtu`, `.htg`) and the surfaces of the values with their colours (`.ply`, `.obj`
//! with its `.mtl`, `.glb`). Formats that would drop the values (`.rays`, binvox, `.bt`, STL, SVG) are
//! refused: write the tree's shape with [`super::write_tree`] instead.
//!
//! ```
//! use ktree::io::{write_valued_tree, WriteOptions, WrittenValues};
//! let dir = tempfile::tempdir().unwrap();
//! let mut dense = [None; 8];
//! (dense[0], dense[7]) = (Some(1u8), Some(2));
//! let tree = ktree::AnyValuedTree::from(ktree::KTree::<3, u8>::from_dense_values(1, &dense).unwrap());
//! let out = dir.path().join("labels.ply");
//! let written = write_valued_tree(&out, &tree, &WriteOptions::default()).unwrap();
//! assert!(matches!(written, WrittenValues::Surfaces { surfaces: 2, .. }));
//! assert!(write_valued_tree(&dir.path().join("labels.bt"), &tree, &WriteOptions::default()).is_err());
//! ```

use std::path::Path;

use super::dispatch::{export_error, format_of, usage};
use super::{Format, IoError, WriteOptions};
use crate::export::{surface::value_boundary_mesh, write_value_surface, Written};
use crate::io::ktree::notes::label_note;
use crate::io::ktree::v3::write_valued_ktree_file_noted;
use crate::value::Value;
use crate::{AnyValuedTree, KTree};

/// What [`write_valued_tree`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WrittenValues {
    /// The voxels and their values (`.ktree`, `.vdb`, NIfTI, VTK).
    Voxels,
    /// The surface of each value with its colour.
    Surfaces {
        /// The distinct values with a surface.
        surfaces: usize,
        /// Vertices and triangles (faces between two values counted once in PLY).
        written: Written,
    },
}

/// Writes a tree with values to `path` (atomically: a temporary file renamed), the format chosen by the
/// extension. `options.meta` places grid index 0 in the world and grid index = ktree voxel −
/// `options.offset`, as for [`super::write_tree`]; a `.ktree` keeps that world frame when `options.meta`
/// is given, and `options.notes`; a mesh names each label's group, material or mesh by its note
/// (`label.3` = `liver`, see [`ValueMesh::with_names`](crate::export::surface::ValueMesh::with_names)).
///
/// # Errors
/// [`IoError::Usage`] for a format that would drop the values or cannot hold the tree's dimension (`.vdb`,
/// NIfTI and meshes hold octrees, VTK quadtrees and octrees); [`IoError::Write`] from the file system.
pub fn write_valued_tree(
    path: &Path,
    tree: &AnyValuedTree,
    options: &WriteOptions,
) -> Result<WrittenValues, IoError> {
    crate::with_valued!(tree, t => write_typed(path, t, options))
}

/// [`write_valued_tree`] of a tree whose dimension and value type are known.
fn write_typed<const K: usize, V: Value>(
    path: &Path,
    tree: &KTree<K, V>,
    options: &WriteOptions,
) -> Result<WrittenValues, IoError> {
    let format = format_of(path)?;
    let meta = options.meta.unwrap_or_default();
    // ktree voxel v is at meta.origin + (v − offset) · voxel_size.
    let frame = meta.counted_from(options.offset.map(|o| -o));
    let octree = || {
        (tree as &dyn std::any::Any)
            .downcast_ref::<KTree<3, V>>()
            .ok_or_else(|| {
                usage(
                    path,
                    format!("this format holds octrees (K = 3), the tree has K = {K}"),
                )
            })
    };
    let drops = |what: &str| {
        usage(
            path,
            format!(
                "{what} hold no values: write .ktree, OpenVDB (.vdb), NIfTI (.nii, .nii.gz), VTK (.vtu, \
                 .htg), or the surfaces of the values as .ply, .obj or .glb (or the tree's shape to this \
                 format)"
            ),
        )
    };
    match format {
        Format::Ktree => write_valued_ktree_file_noted(
            path,
            tree,
            options.meta.map(|_| frame).as_ref(),
            &options.notes,
        )?,
        Format::Vdb => {
            let t = octree()?;
            crate::fs::write_atomic_with(path, |w| {
                super::write_vdb_values(w, t, options.offset, &meta)
            })?
        }
        Format::Vtu | Format::Htg => crate::export::vtk::write_values_vtk_file(path, tree, &frame)
            .map_err(|e| export_error(path, e))?,
        Format::Mesh | Format::Glb if is_stl(path) => return Err(drops("STL files")),
        Format::Mesh | Format::Glb => {
            // Each label named by the notes (`label.3` = `liver`) under its name.
            let mesh = value_boundary_mesh(octree()?)
                .placed(&frame)
                .with_names(|v| options.notes.get(&label_note(&v.text())).cloned());
            let written = write_value_surface(path, &mesh).map_err(|e| export_error(path, e))?;
            return Ok(WrittenValues::Surfaces {
                surfaces: mesh.surfaces.len(),
                written,
            });
        }
        #[cfg(feature = "volume")]
        Format::Volume if super::dispatch::is_nifti(path) => {
            super::write_nifti_file(path, octree()?, &frame)?
        }
        Format::Volume => {
            return Err(usage(
                path,
                "volumes with values are written as NIfTI (.nii, .nii.gz)",
            ))
        }
        Format::Rays => return Err(drops("ray files")),
        Format::Binvox => return Err(drops("binvox files")),
        Format::OctomapBt => return Err(drops("OctoMap .bt files (occupancy only)")),
        Format::Svg => return Err(drops("SVG outlines")),
    }
    Ok(WrittenValues::Voxels)
}

/// Whether [`write_valued_tree`] writes the values to `path` (by its extension).
///
/// ```
/// use std::path::Path;
/// assert!(ktree::io::keeps_values(Path::new("labels.nii.gz")));
/// assert!(!ktree::io::keeps_values(Path::new("labels.stl")));
/// ```
pub fn keeps_values(path: &Path) -> bool {
    match Format::of(path) {
        Some(Format::Ktree | Format::Vdb | Format::Vtu | Format::Htg | Format::Glb) => true,
        Some(Format::Mesh) => !is_stl(path),
        #[cfg(feature = "volume")]
        Some(Format::Volume) => super::dispatch::is_nifti(path),
        _ => false,
    }
}

/// Whether `path` names an STL file.
fn is_stl(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("stl"))
}
