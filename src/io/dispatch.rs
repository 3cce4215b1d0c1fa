//! Reading and writing a tree in any format, chosen by the file's extension: `.ktree`, `.rays` (the ray
//! text), `.binvox`, `.bt` (OctoMap), `.vdb` (OpenVDB) read and written; meshes (`.obj`, `.stl`, `.ply`)
//! written as the tree's boundary ([`crate::export`]), with `.glb`, `.svg` and VTK as outputs only; volumes
//! written as NIfTI. Meshes and volumes are read by voxelizing them, which [`crate::input`] does above
//! both the files and the solids: [`read_tree`] here refuses them.
//!
//! Grid formats index voxels by integers: ktree voxel = grid index + offset (see [`GridPlacement`]).
//! binvox, `.bt` and `.vdb` hold octrees only.

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::interop::{
    read_binvox, read_bt, read_vdb, write_binvox, write_bt, write_vdb, GridFileError,
    GridFileErrorKind, GridMeta, GridPlacement, PlacedTree,
};
use super::ktree::{read_ktree_file, write_ktree_file, KtreeFileError};
use super::rays::{read_rays_file, write_rays_file, RaysTextError};
use crate::fs::write_atomic_with;
use crate::solid::SolidError;
use crate::tree::{AnyTree, DimensionMismatch, KTree};

/// A file format known to [`read_tree`] and [`write_tree`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// `.ktree`: ktree's own tree file (read in either version, written as version 2).
    Ktree,
    /// `.rays`: the ray text format.
    Rays,
    /// `.binvox`.
    Binvox,
    /// `.bt`: OctoMap's binary occupancy tree.
    OctomapBt,
    /// `.vdb`: an OpenVDB grid.
    Vdb,
    /// `.obj`, `.stl`, `.ply`: a triangle mesh (voxelized when read, by [`crate::input`]; the tree's
    /// boundary when written).
    Mesh,
    /// `.glb`: a glTF binary mesh of the tree's boundary (output only).
    Glb,
    /// `.svg`: a quadtree's outline as one path (output only).
    Svg,
    /// `.vtu`: a VTK unstructured grid of the full leaves, for ParaView (output only).
    Vtu,
    /// `.htg`: a VTK hyper tree grid, for ParaView (output only).
    Htg,
    /// `.json` (+ raw samples), `.raw`, `.nii`, `.nii.gz`: a volume (voxelized when read, by
    /// [`crate::input`]; NIfTI also written).
    Volume,
}

impl Format {
    /// The format of a path, by its extension (case-insensitive).
    ///
    /// ```
    /// use ktree::io::Format;
    /// assert_eq!(Format::of(std::path::Path::new("map.BT")), Some(Format::OctomapBt));
    /// assert_eq!(Format::of(std::path::Path::new("head.nii.gz")), Some(Format::Volume));
    /// assert_eq!(Format::of(std::path::Path::new("notes.txt")), None);
    /// ```
    pub fn of(path: &Path) -> Option<Format> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        if name.ends_with(".nii.gz") {
            return Some(Format::Volume);
        }
        Some(match name.rsplit_once('.')?.1 {
            "ktree" => Format::Ktree,
            "rays" => Format::Rays,
            "binvox" => Format::Binvox,
            "bt" => Format::OctomapBt,
            "vdb" => Format::Vdb,
            "obj" | "stl" | "ply" => Format::Mesh,
            "glb" => Format::Glb,
            "svg" => Format::Svg,
            "vtu" => Format::Vtu,
            "htg" => Format::Htg,
            "json" | "raw" | "nii" => Format::Volume,
            _ => return None,
        })
    }
}

/// How to read a file. Every field has a default that suits a file holding the whole object. The mesh and
/// volume fields are those of [`crate::input`], which voxelizes them.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// The universe level. Grids and volumes: default the smallest level that holds the grid. Meshes:
    /// required.
    pub level: Option<u32>,
    /// Grids and volumes: ktree voxel = grid index + `offset`. Default: 0, except that an axis with
    /// negative indices is shifted so that its smallest index becomes 0, or a little more to keep the grid's
    /// aligned cells aligned (see [`GridPlacement::choose`]).
    pub offset: Option<[i64; 3]>,
    /// OctoMap: read unknown cells inside the universe as full (default: as empty).
    pub unknown_full: bool,
    /// Meshes: voxel = s·v + t. Default: the mesh scaled and centred into the universe with one voxel of
    /// margin.
    #[cfg(feature = "mesh")]
    pub mesh_placement: Option<crate::solid::mesh::MeshTransform>,
    /// Volumes: which samples are inside (required for a volume).
    #[cfg(feature = "volume")]
    pub select: Option<crate::solid::volume::Select>,
}

/// How to write a file.
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// Grids: grid index = ktree voxel − `offset` (the inverse of [`ReadOptions::offset`]). binvox needs 0;
    /// OctoMap takes any offset that keeps the universe inside its keys (a universe that is not at a
    /// multiple of its side there is written as the smallest one around it that is).
    pub offset: [i64; 3],
    /// Grids: voxel size and world origin (binvox `translate`/`scale`, OctoMap `res`, OpenVDB's transform).
    /// Default: unit voxels at the origin.
    pub meta: Option<GridMeta>,
    /// A `.ktree` with values: the notes kept with the tree (a label's name as `label.N`; see
    /// [`Notes`](crate::io::ktree::Notes)). Other formats have nowhere to keep them.
    pub notes: crate::io::ktree::Notes,
}

/// A tree read by [`read_tree_placed`] (or [`crate::input::read_tree_placed`]), with what the reader chose
/// or noticed.
#[derive(Debug, Clone)]
pub struct ReadTree {
    /// The object.
    pub tree: AnyTree,
    /// Grids: where the grid was placed.
    pub placement: Option<GridPlacement>,
    /// Grids: their world metadata.
    pub meta: Option<GridMeta>,
    /// Things worth telling a user: the transform a mesh was fitted with, a mesh that is not closed.
    pub remarks: Vec<String>,
}

/// An error reading or writing a file in any format.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IoError {
    /// A bad `.ktree` file.
    #[error(transparent)]
    Ktree(#[from] KtreeFileError),
    /// A bad ray file.
    #[error(transparent)]
    Rays(#[from] RaysTextError),
    /// A bad binvox, `.bt` or `.vdb` file.
    #[error(transparent)]
    Grid(#[from] GridFileError),
    /// A point cloud or mesh file that could not be read.
    #[cfg(any(feature = "cloud", feature = "mesh"))]
    #[error(transparent)]
    Geometry(#[from] super::GeometryFileError),
    /// A mesh or volume that could not be parsed or voxelized by [`crate::input`] (one that cannot be read
    /// is [`IoError::Read`]).
    #[error("{}", with_file(.file, .error))]
    Solid {
        /// The file.
        file: PathBuf,
        /// What is wrong (part of the message: it names the file where it can).
        error: SolidError,
    },
    /// A file could not be read.
    #[error(transparent)]
    Read(crate::fs::FileOpError),
    /// The format or the options do not fit the file: an unknown extension, an output-only or input-only
    /// format, a dimension the format cannot hold, a missing option.
    #[error("{}: {message}", file.display())]
    Usage {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Writing failed (the message names the file).
    #[error(transparent)]
    Write(#[from] crate::fs::FileOpError),
    /// A NIfTI file could not be written (the message names it).
    #[cfg(feature = "volume")]
    #[error(transparent)]
    Nifti(#[from] super::NiftiWriteError),
    /// The file holds a tree of another dimension than the one asked for.
    #[error("{}", file.display())]
    Dimension {
        /// The file.
        file: PathBuf,
        /// The dimensions.
        source: DimensionMismatch,
    },
}

/// A solid's error naming its file once (a file that cannot be read or parsed names itself).
fn with_file(file: &Path, e: &SolidError) -> String {
    match e {
        SolidError::Io { .. } | SolidError::Parse { .. } => e.to_string(),
        _ => format!("{}: {e}", file.display()),
    }
}

pub(crate) fn usage(path: &Path, message: impl Into<String>) -> IoError {
    IoError::Usage {
        file: path.to_path_buf(),
        message: message.into(),
    }
}

pub(crate) fn format_of(path: &Path) -> Result<Format, IoError> {
    Format::of(path).ok_or_else(|| {
        usage(
            path,
            "unknown extension: expected .ktree, .rays, .binvox, .bt, .vdb, a mesh (.obj, .stl, .ply; \
             .glb and .svg written only), VTK (.vtu, .htg; written only) or a volume (.json, .raw, .nii, .nii.gz)",
        )
    })
}

/// Reads a tree from a tree file of any format, chosen by extension: `.ktree`, `.rays`, `.binvox`, `.bt`,
/// `.vdb`. Meshes and volumes are voxelized by [`crate::input::read_tree`], which reads every input.
///
/// ```
/// use ktree::io::{read_tree, write_tree, ReadOptions, WriteOptions};
/// use ktree::AnyTree;
/// let dir = tempfile::tempdir().unwrap();
/// let tree = AnyTree::K3(ktree::stacking::paper::stack(&ktree::rays::ball_rays::<3>(4, [8, 8, 8], 6).unwrap()));
/// for name in ["ball.ktree", "ball.rays", "ball.binvox", "ball.bt", "ball.vdb"] {
///     let path = dir.path().join(name);
///     write_tree(&path, &tree, &WriteOptions::default()).unwrap();
///     assert_eq!(read_tree(&path, &ReadOptions::default()).unwrap(), tree, "{name}");
/// }
/// // A mesh is voxelized by `ktree::input::read_tree`, not read here.
/// let mesh = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/fandisk.obj");
/// let options = ReadOptions { level: Some(5), ..ReadOptions::default() };
/// assert!(matches!(read_tree(&mesh, &options), Err(ktree::io::IoError::Usage { .. })));
/// ```
///
/// # Errors
/// [`IoError`]: the format's own error naming the file and the line or byte, or [`IoError::Usage`] (an
/// output-only format, a mesh or a volume, an unknown extension).
pub fn read_tree(path: &Path, options: &ReadOptions) -> Result<AnyTree, IoError> {
    read_tree_placed(path, options).map(|r| r.tree)
}

/// Like [`read_tree`], with the placement, metadata and remarks of the reading.
///
/// # Errors
/// As [`read_tree`].
pub fn read_tree_placed(path: &Path, options: &ReadOptions) -> Result<ReadTree, IoError> {
    let name = path.display().to_string();
    let plain = |tree: AnyTree| ReadTree {
        tree,
        placement: None,
        meta: None,
        remarks: Vec::new(),
    };
    let grid = |p: PlacedTree| ReadTree {
        tree: AnyTree::K3(p.tree),
        placement: Some(p.placement),
        meta: Some(p.meta),
        remarks: Vec::new(),
    };
    let bytes = || {
        std::fs::read(path)
            .map_err(|e| GridFileError::new(&name, 0, GridFileErrorKind::Io(e.into())))
    };
    match format_of(path)? {
        Format::Glb | Format::Svg | Format::Vtu | Format::Htg => Err(usage(
            path,
            "this format is written only: read .ktree, .rays, .binvox, .bt, .vdb, a mesh or a volume",
        )),
        Format::Ktree => Ok(plain(read_ktree_file(path)?)),
        Format::Rays => Ok(plain(read_rays_file(path)?.build())),
        Format::Binvox => Ok(grid(read_binvox(
            &bytes()?,
            &name,
            options.offset,
            options.level,
        )?)),
        Format::OctomapBt => Ok(grid(read_bt(
            &bytes()?,
            &name,
            options.offset,
            options.level,
            options.unknown_full,
        )?)),
        Format::Vdb => Ok(grid(read_vdb(
            &bytes()?,
            &name,
            options.offset,
            options.level,
        )?)),
        Format::Mesh | Format::Volume => Err(usage(
            path,
            "meshes and volumes are voxelized when read: read them with ktree::input::read_tree (a mesh \
             needs a level, a volume a threshold or a label)",
        )),
    }
}

/// Writes a tree to a file of the format its extension names, atomically ([`crate::fs::write_atomic`]).
/// Meshes (`.ply`, `.obj`, `.stl`, `.glb`, `.svg`) are the tree's boundary ([`crate::export::write_mesh`]),
/// ktree voxel `v` at `meta.origin + (v − offset) · meta.voxel_size`.
///
/// # Errors
/// [`IoError::Usage`] for an input-only format or a tree the format cannot hold (binvox, `.bt` and `.vdb`
/// hold octrees; meshes octrees and quadtrees); [`IoError::Write`] for the file system or a placement the
/// format cannot express.
pub fn write_tree(path: &Path, tree: &AnyTree, options: &WriteOptions) -> Result<(), IoError> {
    crate::with_dim!(tree, AnyTree, t => write_typed(path, t, options))
}

/// [`write_tree`] of a tree whose dimension is known.
fn write_typed<const K: usize>(
    path: &Path,
    tree: &KTree<K>,
    options: &WriteOptions,
) -> Result<(), IoError> {
    let format = format_of(path)?;
    let meta = options.meta.unwrap_or_default();
    let octree = || {
        (tree as &dyn std::any::Any)
            .downcast_ref::<KTree<3>>()
            .ok_or_else(|| {
                usage(
                    path,
                    format!("this format holds octrees (K = 3), the tree has K = {K}"),
                )
            })
    };
    let write = |fill: &dyn Fn(&mut dyn std::io::Write) -> std::io::Result<()>| {
        write_atomic_with(path, |w| fill(w)).map_err(IoError::Write)
    };
    // Meshes and VTK files: ktree voxel v is at meta.origin + (v − offset) · voxel_size.
    let frame = crate::export::Frame {
        voxel_size: meta.voxel_size,
        origin: std::array::from_fn(|a| {
            meta.origin[a] - options.offset[a] as f64 * meta.voxel_size
        }),
    };
    match format {
        Format::Ktree => write_ktree_file(path, tree).map_err(IoError::Write),
        Format::Rays => write_rays_file(path, &tree.to_rays()).map_err(IoError::Write),
        Format::Binvox => {
            let t = octree()?;
            if options.offset != [0; 3] {
                return Err(usage(
                    path,
                    "binvox grids start at index 0: write with offset 0",
                ));
            }
            write(&|w| write_binvox(w, t, &meta))
        }
        Format::OctomapBt => {
            let t = octree()?;
            // OctoMap puts grid index 0 at the world origin: a world origin is carried by shifting the
            // indices by whole voxels, and refused where it is not a whole number of them.
            let shift = whole_voxels(&meta).ok_or_else(|| {
                usage(
                    path,
                    format!(
                        "OctoMap .bt files put their voxels at multiples of the voxel size ({}) from the \
                         world origin; the origin {:?} is not one: give an origin that is (e.g. --origin \
                         0,0,0)",
                        meta.voxel_size, meta.origin
                    ),
                )
            })?;
            let offset = std::array::from_fn(|a| options.offset[a] - shift[a]);
            let (t, offset) = on_octomap_keys(t, offset).ok_or_else(|| {
                usage(
                    path,
                    format!(
                        "grid index = ktree voxel − {offset:?} puts the level-{} universe outside \
                         OctoMap's keys (−32768 … 32767 on each axis)",
                        t.level()
                    ),
                )
            })?;
            write(&|w| write_bt(w, &t, offset, meta.voxel_size))
        }
        Format::Vdb => {
            let t = octree()?;
            write(&|w| write_vdb(w, t, options.offset, &meta))
        }
        Format::Vtu | Format::Htg => crate::export::vtk::write_vtk_file(path, tree, &frame)
            .map_err(|e| export_error(path, e)),
        Format::Mesh | Format::Glb | Format::Svg => {
            crate::export::write_mesh_of(path, tree, &frame)
                .map(drop)
                .map_err(|e| export_error(path, e))
        }
        #[cfg(feature = "volume")]
        Format::Volume if is_nifti(path) => {
            crate::io::write_nifti_file(path, octree()?, &frame).map_err(IoError::Nifti)
        }
        Format::Volume => Err(usage(
            path,
            "volumes are written as NIfTI (.nii, .nii.gz) only: write .ktree, .rays, .binvox, .bt, .vdb, .nii, \
             VTK or a mesh",
        )),
    }
}

/// Whether `path` names a NIfTI file (`.nii`, `.nii.gz`).
#[cfg(feature = "volume")]
pub(crate) fn is_nifti(path: &Path) -> bool {
    let name = path.to_string_lossy();
    name.ends_with(".nii") || name.ends_with(".nii.gz")
}

/// The tree and offset to write to a `.bt` so that grid index = ktree voxel − `offset`: OctoMap's keys hold
/// a universe only at multiples of its side, so a universe elsewhere is written as the smallest one around
/// it that is (the tree grown and moved into it; the larger universe is marked known). `None` if no
/// universe of OctoMap's 16 levels holds it.
fn on_octomap_keys(tree: &KTree<3>, offset: [i64; 3]) -> Option<(KTree<3>, [i64; 3])> {
    use crate::io::BT_DEPTH;
    let centre = 1i64 << (BT_DEPTH - 1);
    let side = 1i64 << tree.level();
    // The universe's lowest key on each axis.
    let corner: [i64; 3] = std::array::from_fn(|a| centre - offset[a]);
    for level in tree.level()..=BT_DEPTH {
        let big = 1i64 << level;
        let base: [i64; 3] = std::array::from_fn(|a| corner[a].div_euclid(big) * big);
        let fits = (0..3).all(|a| {
            corner[a] + side <= base[a] + big && base[a] >= 0 && base[a] + big <= 2 * centre
        });
        if fits {
            if level == tree.level() {
                return Some((tree.clone(), offset));
            }
            let grown = crate::ops::grow(tree, &vec![0; (level - tree.level()) as usize]).ok()?;
            let moved = crate::tree::storage::infallible(crate::ops::translate(
                &grown,
                std::array::from_fn(|a| corner[a] - base[a]),
            ));
            return Some((moved, std::array::from_fn(|a| centre - base[a])));
        }
    }
    None
}

/// The frame's origin as a whole number of voxels, if it is one (to a millionth of a voxel).
fn whole_voxels(meta: &GridMeta) -> Option<[i64; 3]> {
    let mut shift = [0i64; 3];
    for (s, o) in shift.iter_mut().zip(meta.origin) {
        let v = o / meta.voxel_size;
        let r = v.round();
        if !(r.is_finite() && (v - r).abs() <= 1e-6 && r.abs() < (1u64 << 40) as f64) {
            return None;
        }
        *s = r as i64;
    }
    Some(shift)
}

/// An export's error as a file error of `path`.
pub(crate) fn export_error(path: &Path, e: crate::export::ExportError) -> IoError {
    use crate::export::ExportError;
    match e {
        ExportError::Write(e) => IoError::Write(e),
        ExportError::Usage { file, message } => IoError::Usage { file, message },
        e => usage(path, e.to_string()),
    }
}

impl<const K: usize> KTree<K> {
    /// Reads a tree of dimension `K` from a file of any format ([`read_tree`] with default options).
    ///
    /// ```
    /// use ktree::{rays::ball_rays, KTree};
    /// let ball = KTree::from_rays(&ball_rays::<3>(4, [8, 8, 8], 6).unwrap());
    /// let dir = tempfile::tempdir().unwrap();
    /// let path = dir.path().join("ball.ktree");
    /// ball.save(&path).unwrap();
    /// assert_eq!(KTree::<3>::load(&path).unwrap(), ball);
    /// assert!(KTree::<2>::load(&path).is_err()); // an octree is not a quadtree
    /// ```
    ///
    /// # Errors
    /// As [`read_tree`], and [`IoError::Dimension`] for a tree of another dimension.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, IoError> {
        let path = path.as_ref();
        read_tree(path, &ReadOptions::default())?
            .try_into()
            .map_err(|source| IoError::Dimension {
                file: path.to_path_buf(),
                source,
            })
    }

    /// Writes the tree to a file of the format its extension names, atomically ([`write_tree`] with
    /// default options; a `.ktree` is always of the current version).
    ///
    /// # Errors
    /// As [`write_tree`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), IoError> {
        write_typed(path.as_ref(), self, &WriteOptions::default())
    }
}
