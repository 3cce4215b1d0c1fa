//! Any input file as a tree: tree files read by [`io`], meshes and volumes voxelized by
//! [`solid`](crate::solid) on the way in.
//!
//! [`read_tree`] and [`read_tree_placed`] read every input the library knows, chosen by the file's
//! extension: `.ktree`, `.rays`, `.binvox`, `.bt` and `.vdb` through [`io::read_tree_placed`], a triangle
//! mesh (`.obj`, `.stl`, `.ply`; [`ReadOptions::level`] required, placed by
//! [`ReadOptions::mesh_placement`] or fitted into the universe) or a volume (`.json` + raw, `.raw`, `.nii`,
//! `.nii.gz`; [`ReadOptions::select`] required) voxelized into an octree. [`voxelize`] gives a mesh's or a
//! volume's rays, [`voxel_source`] the same rays slab by slab, for building out of core; [`open_tree`] maps
//! a `.ktree` in place and reads anything else into memory; [`voxelize_mesh_labels`] voxelizes several
//! meshes (or the groups of one OBJ file) together into one tree of labels. Errors are [`IoError`]s: a mesh or volume that
//! cannot be voxelized is [`IoError::Solid`], a missing option [`IoError::Usage`].
//!
//! ```
//! use ktree::input::read_tree;
//! use ktree::io::{write_tree, ReadOptions, WriteOptions};
//! use std::path::Path;
//! let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/fandisk.obj");
//! let tree = read_tree(&mesh, &ReadOptions { level: Some(5), ..ReadOptions::default() }).unwrap();
//! assert_eq!(tree.k(), 3);
//! // Tree files are read as `io` reads them.
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("fandisk.ktree");
//! write_tree(&path, &tree, &WriteOptions::default()).unwrap();
//! assert_eq!(read_tree(&path, &ReadOptions::default()).unwrap(), tree);
//! ```

use std::path::Path;

use crate::io::{self, format_of, usage, FileTree, Format, IoError, ReadOptions, ReadTree};
use crate::rays::RaySet;
#[cfg(any(feature = "mesh", feature = "volume"))]
use crate::solid::SolidError;
use crate::tree::AnyTree;
use crate::KTree;

/// Reads a tree from any input file, chosen by extension: a tree file as [`io::read_tree`] reads it, a
/// mesh or a volume voxelized ([`voxelize`]) and built into an octree.
///
/// ```
/// use ktree::input::read_tree;
/// use ktree::io::ReadOptions;
/// use ktree::solid::volume::Select;
/// use std::path::Path;
/// let skull = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/volumes/skull_grey.json");
/// let options = ReadOptions { select: Some(Select::AtLeast(1.0)), ..ReadOptions::default() };
/// let tree = read_tree(&skull, &options).unwrap();
/// assert_eq!((tree.k(), tree.level()), (3, 6)); // the smallest universe that holds 64³ samples
/// assert!(tree.counts().full > 0);
/// // A volume needs its selection.
/// assert!(read_tree(&skull, &ReadOptions::default()).is_err());
/// ```
///
/// # Errors
/// [`IoError`]: as [`io::read_tree`] for tree files, as [`voxelize`] for meshes and volumes.
pub fn read_tree(path: &Path, options: &ReadOptions) -> Result<AnyTree, IoError> {
    read_tree_placed(path, options).map(|r| r.tree)
}

/// Like [`read_tree`], with the placement, metadata and remarks of the reading (for a mesh: the transform
/// it was fitted with, and whether it is closed).
///
/// ```
/// use ktree::input::read_tree_placed;
/// use ktree::io::ReadOptions;
/// use std::path::Path;
/// let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/fandisk.obj");
/// let read = read_tree_placed(&mesh, &ReadOptions { level: Some(5), ..ReadOptions::default() }).unwrap();
/// assert!(read.remarks[0].starts_with("the mesh was fitted with the transform"));
/// assert!(read.placement.is_none()); // grids only
/// ```
///
/// # Errors
/// As [`read_tree`].
pub fn read_tree_placed(path: &Path, options: &ReadOptions) -> Result<ReadTree, IoError> {
    if !matches!(Format::of(path), Some(Format::Mesh | Format::Volume)) {
        return io::read_tree_placed(path, options);
    }
    let v = voxelize(path, options)?;
    let mut remarks = Vec::new();
    if let Some(t) = &v.fitted {
        remarks.push(format!("the mesh was fitted with the transform {t}"));
    }
    if v.open_edges > 0 {
        remarks.push(format!(
            "the mesh is not closed ({} edges not shared by exactly two triangles); inside is \
             decided by the winding along each column, so some columns may leak or lose runs",
            v.open_edges
        ));
    }
    Ok(ReadTree {
        tree: AnyTree::K3(KTree::from_rays(&v.rays)),
        placement: None,
        meta: None,
        remarks,
    })
}

/// The tree of any input file over the storage that suits it: a mesh or a volume voxelized into memory
/// ([`read_tree`]), any tree file as [`FileTree::open`] opens it (a `.ktree` of the current version mapped
/// in place).
///
/// ```
/// use ktree::input::open_tree;
/// use ktree::io::{write_ktree_file, FileTree, ReadOptions};
/// use ktree::KTree;
/// use std::path::Path;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// write_ktree_file(&path, &KTree::<2>::full(3).unwrap()).unwrap();
/// assert!(matches!(open_tree(&path, &ReadOptions::default()).unwrap(), FileTree::Mapped(_)));
/// let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/fandisk.obj");
/// let options = ReadOptions { level: Some(4), ..ReadOptions::default() };
/// assert!(matches!(open_tree(&mesh, &options).unwrap(), FileTree::Memory(_)));
/// ```
///
/// # Errors
/// As [`read_tree`].
pub fn open_tree(path: &Path, options: &ReadOptions) -> Result<FileTree, IoError> {
    match Format::of(path) {
        Some(Format::Mesh | Format::Volume) => Ok(FileTree::Memory(read_tree(path, options)?)),
        _ => FileTree::open(path, options),
    }
}

/// A mesh or a volume as rays, with what was chosen or noticed on the way.
#[derive(Debug, Clone)]
pub struct Voxelized {
    /// The voxels inside.
    pub rays: RaySet<3>,
    /// Meshes placed by fitting: the transform chosen, as `s,tx,ty,tz`.
    pub fitted: Option<String>,
    /// Meshes: edges not shared by exactly two triangles (0 for a closed mesh).
    pub open_edges: usize,
}

/// Voxelizes a mesh or a volume file into rays ([`Format::Mesh`], [`Format::Volume`]): a mesh needs
/// [`ReadOptions::level`], a volume [`ReadOptions::select`]; the volume's sample `(i, j, k)` goes to voxel
/// `offset + (i, j, k)`.
///
/// ```
/// use ktree::input::voxelize;
/// use ktree::io::ReadOptions;
/// use ktree::solid::volume::Select;
/// use std::path::Path;
/// let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
/// let options = ReadOptions { level: Some(5), ..ReadOptions::default() };
/// let mesh = voxelize(&data.join("meshes/fandisk.obj"), &options).unwrap();
/// assert!(mesh.fitted.is_some() && !mesh.rays.is_empty()); // placed by fitting into the universe
/// let options = ReadOptions { select: Some(Select::AtLeast(1.0)), ..ReadOptions::default() };
/// let volume = voxelize(&data.join("volumes/skull_grey.json"), &options).unwrap();
/// assert_eq!((volume.fitted, volume.open_edges), (None, 0));
/// ```
///
/// # Errors
/// [`IoError::Solid`] from reading or voxelizing, [`IoError::Usage`] for another format or a missing option.
pub fn voxelize(path: &Path, options: &ReadOptions) -> Result<Voxelized, IoError> {
    match format_of(path)? {
        Format::Mesh => voxelize_mesh(path, options),
        Format::Volume => voxelize_volume(path, options),
        _ => Err(usage(path, "not a mesh or a volume")),
    }
}

/// A missing or unreadable input is said as such (an I/O error) before any option is asked for.
#[cfg(feature = "volume")]
fn readable(path: &Path) -> Result<(), SolidError> {
    std::fs::File::open(path)
        .map(drop)
        .map_err(|source| SolidError::Io {
            path: path.to_path_buf(),
            source,
        })
}

#[cfg(any(feature = "mesh", feature = "volume"))]
fn solid_error(path: &Path) -> impl Fn(SolidError) -> IoError + '_ {
    move |error| match error {
        SolidError::Io { path, source } => IoError::Read(crate::fs::FileOpError::new(
            crate::fs::FileOp::Read,
            &path,
            source,
        )),
        error => IoError::Solid {
            file: path.to_path_buf(),
            error,
        },
    }
}

/// A mesh or a volume producing its rays slab by slab ([`MeshSource`](crate::solid::mesh::MeshSource),
/// [`VolumeSource`](crate::solid::volume::VolumeSource)), for building its tree out of core without
/// holding the whole ray set; the runs are those of [`voxelize`] with the same options.
#[cfg(any(feature = "mesh", feature = "volume"))]
#[derive(Debug, Clone)]
pub enum VoxelSource {
    /// A placed mesh.
    #[cfg(feature = "mesh")]
    Mesh(crate::solid::mesh::MeshSource),
    /// A volume with its selection and offset.
    #[cfg(feature = "volume")]
    Volume(crate::solid::volume::VolumeSource),
}

#[cfg(any(feature = "mesh", feature = "volume"))]
impl VoxelSource {
    /// The bytes the source holds (see `heap_bytes` of each source).
    pub fn heap_bytes(&self) -> u64 {
        match self {
            #[cfg(feature = "mesh")]
            Self::Mesh(m) => m.heap_bytes(),
            #[cfg(feature = "volume")]
            Self::Volume(v) => v.heap_bytes(),
        }
    }
}

#[cfg(any(feature = "mesh", feature = "volume"))]
impl crate::rays::RaySource<3> for VoxelSource {
    type Error = std::convert::Infallible;

    fn universe(&self) -> crate::Universe<3> {
        match self {
            #[cfg(feature = "mesh")]
            Self::Mesh(m) => m.universe(),
            #[cfg(feature = "volume")]
            Self::Volume(v) => v.universe(),
        }
    }

    fn slab(
        &self,
        x: std::ops::Range<u32>,
    ) -> Result<crate::rays::SlabRuns<'_>, std::convert::Infallible> {
        match self {
            #[cfg(feature = "mesh")]
            Self::Mesh(m) => m.slab(x),
            #[cfg(feature = "volume")]
            Self::Volume(v) => v.slab(x),
        }
    }

    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        match self {
            #[cfg(feature = "mesh")]
            Self::Mesh(s) => s.occupied_slabs(m),
            #[cfg(feature = "volume")]
            Self::Volume(v) => v.occupied_slabs(m),
        }
    }
}

/// A mesh or a volume as a [`VoxelSource`], with what was chosen or noticed on the way.
#[cfg(any(feature = "mesh", feature = "volume"))]
#[derive(Debug, Clone)]
pub struct VoxelizedSource {
    /// The source of the voxels inside.
    pub source: VoxelSource,
    /// Meshes placed by fitting: the transform chosen, as `s,tx,ty,tz`.
    pub fitted: Option<String>,
    /// Meshes: edges not shared by exactly two triangles (0 for a closed mesh).
    pub open_edges: usize,
}

/// Like [`voxelize`], producing the rays slab by slab: reads the mesh or volume, checks the options and
/// the placement, and returns a source whose slabs hold the runs [`voxelize`] returns.
///
/// ```
/// use ktree::input::{voxel_source, voxelize};
/// use ktree::io::ReadOptions;
/// use ktree::stacking::{paper::stack, Builder};
/// use std::path::Path;
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/fandisk.obj");
/// let options = ReadOptions { level: Some(5), ..ReadOptions::default() };
/// let slabs = voxel_source(&path, &options).unwrap();
/// let whole = voxelize(&path, &options).unwrap();
/// assert_eq!((&slabs.fitted, slabs.open_edges), (&whole.fitted, whole.open_edges));
/// assert_eq!(Builder::new(&slabs.source).split_depth(2).build().unwrap(), stack(&whole.rays));
/// ```
///
/// # Errors
/// As [`voxelize`].
#[cfg(any(feature = "mesh", feature = "volume"))]
pub fn voxel_source(path: &Path, options: &ReadOptions) -> Result<VoxelizedSource, IoError> {
    let solid = solid_error(path);
    match format_of(path)? {
        #[cfg(feature = "mesh")]
        Format::Mesh => {
            let (mesh, level, placement, fitted) = mesh_input(path, options)?;
            let source =
                crate::solid::mesh::MeshSource::new(&mesh, level, &placement).map_err(&solid)?;
            Ok(VoxelizedSource {
                source: VoxelSource::Mesh(source),
                fitted,
                open_edges: mesh.open_edges(),
            })
        }
        #[cfg(feature = "volume")]
        Format::Volume => {
            let (volume, level, offset, select) = volume_input(path, options)?;
            let source = crate::solid::volume::VolumeSource::new(volume, level, offset, select)
                .map_err(&solid)?;
            Ok(VoxelizedSource {
                source: VoxelSource::Volume(source),
                fitted: None,
                open_edges: 0,
            })
        }
        #[cfg(not(feature = "mesh"))]
        Format::Mesh => Err(usage(path, "meshes are read with the `mesh` feature")),
        #[cfg(not(feature = "volume"))]
        Format::Volume => Err(usage(path, "volumes are read with the `volume` feature")),
        _ => Err(usage(path, "not a mesh or a volume")),
    }
}

/// The mesh of a file with its level and placement (and the placement as text when it was fitted).
#[cfg(feature = "mesh")]
fn mesh_input(
    path: &Path,
    options: &ReadOptions,
) -> Result<
    (
        crate::solid::mesh::TriangleMesh,
        u32,
        crate::solid::mesh::MeshTransform,
        Option<String>,
    ),
    IoError,
> {
    let solid = solid_error(path);
    std::fs::File::open(path).map_err(|e| crate::io::geometry_file::io_error(path, e))?;
    let level = options
        .level
        .ok_or_else(|| usage(path, "a mesh needs a universe level"))?;
    let mesh = crate::io::read_mesh(path)?;
    let (placement, fitted) =
        mesh_placement(options, std::slice::from_ref(&mesh), level).map_err(&solid)?;
    Ok((mesh, level, placement, fitted))
}

/// The placement of `meshes` together: [`ReadOptions::mesh_placement`], or the union of their bounding
/// boxes fitted into the universe (and then the transform as text).
#[cfg(feature = "mesh")]
fn mesh_placement(
    options: &ReadOptions,
    meshes: &[crate::solid::mesh::TriangleMesh],
    level: u32,
) -> Result<(crate::solid::mesh::MeshTransform, Option<String>), SolidError> {
    use crate::solid::mesh::Placement;
    match options.mesh_placement {
        Some(p) => Ok((p, None)),
        None => {
            let p = Placement::Fit.transform_all(meshes, level)?;
            Ok((p, Some(p.to_arg())))
        }
    }
}

/// Meshes voxelized together as labels ([`voxelize_mesh_labels`]), with the name of each label.
#[cfg(feature = "mesh")]
#[derive(Debug, Clone)]
pub struct MeshLabels<T = crate::AnyValuedTree> {
    /// An octree of labels ([`LabelRuns`] for [`mesh_label_runs`]): `u8` for up to 255 meshes, `u16` up
    /// to 65535, `u32` beyond.
    pub tree: T,
    /// Label `i + 1` is `names[i]`: the file, or the group of a single OBJ file.
    pub names: Vec<String>,
    /// Label `i + 1` is held by `voxels[i]` voxels (0 for a mesh the later ones hide).
    pub voxels: Vec<u64>,
    /// Where the meshes went: voxel coordinate = `scale · v + translate`.
    pub transform: crate::solid::mesh::MeshTransform,
    /// Placed by fitting: the transform chosen, as `s,tx,ty,tz`.
    pub fitted: Option<String>,
}

/// Voxelizes mesh files together into one tree of labels ([`KTree::from_label_meshes`]): each file one
/// label (1, 2, … in the order given), or, for a single `.obj` file, each of its groups and objects one
/// label, in the order they appear ([`io::read_obj_groups`]; a file without groups is one label). Where
/// meshes overlap, the later one wins. All share one placement: [`ReadOptions::mesh_placement`], or
/// their union fitted into the universe; [`ReadOptions::level`] is required. Every mesh must be closed.
///
/// ```
/// use ktree::input::voxelize_mesh_labels;
/// use ktree::io::ReadOptions;
/// use std::path::Path;
/// let dir = tempfile::tempdir().unwrap();
/// let scene = dir.path().join("scene.obj");
/// let mut obj = String::new();
/// for (group, at) in [("left", 0), ("right", 3)] {
///     obj += &format!("g {group}\n");
///     for i in 0..8 {
///         let c = [at + (i & 1), (i >> 1) & 1, (i >> 2) & 1];
///         obj += &format!("v {} {} {}\n", c[0], c[1], c[2]);
///     }
///     let base = if at == 0 { 0 } else { 8 };
///     for t in [[1, 3, 2], [2, 3, 4], [5, 6, 7], [6, 8, 7], [1, 2, 5], [2, 6, 5],
///               [3, 7, 4], [4, 7, 8], [1, 5, 3], [3, 5, 7], [2, 4, 6], [4, 8, 6]] {
///         obj += &format!("f {} {} {}\n", base + t[0], base + t[1], base + t[2]);
///     }
/// }
/// std::fs::write(&scene, obj).unwrap();
/// let labels = voxelize_mesh_labels(&[&scene], &ReadOptions { level: Some(4), ..ReadOptions::default() }).unwrap();
/// assert_eq!(labels.names, ["left", "right"]);
/// assert!(labels.voxels.iter().all(|&n| n > 0)); // the voxels of each label
/// let ktree::AnyValuedTree::K3U8(tree) = labels.tree else { panic!("labels of u8") };
/// assert_eq!(tree.value_stats().into_keys().collect::<Vec<_>>(), [1, 2]);
/// // A missing file is named.
/// let missing = dir.path().join("missing.stl");
/// let e = voxelize_mesh_labels(&[&scene, &missing], &ReadOptions { level: Some(4), ..ReadOptions::default() });
/// assert!(e.unwrap_err().to_string().contains("missing.stl"));
/// ```
///
/// # Errors
/// [`IoError::Usage`] for no file, a file that is not a mesh, or no level; [`IoError::Read`] and
/// [`IoError::Geometry`] for a file that cannot be read or parsed; [`IoError::Solid`] naming the file
/// (and the group) for a mesh that is not closed, or meshes that cannot be placed.
#[cfg(feature = "mesh")]
pub fn voxelize_mesh_labels(
    paths: &[impl AsRef<Path>],
    options: &ReadOptions,
) -> Result<MeshLabels, IoError> {
    let labels = mesh_label_runs(paths, options)?;
    let tree = match &labels.tree {
        LabelRuns::U8(runs) => crate::AnyValuedTree::from(KTree::from_value_runs(runs)),
        LabelRuns::U16(runs) => crate::AnyValuedTree::from(KTree::from_value_runs(runs)),
        LabelRuns::U32(runs) => crate::AnyValuedTree::from(KTree::from_value_runs(runs)),
    };
    Ok(MeshLabels {
        tree,
        names: labels.names,
        voxels: labels.voxels,
        transform: labels.transform,
        fitted: labels.fitted,
    })
}

/// [`voxelize_mesh_labels`] as the runs of labels the tree is built from (the meshes ray cast, the
/// tree not built): what a build out of core or across processes takes
/// ([`ValueRuns::write_file`](crate::rays::ValueRuns::write_file)).
///
/// # Errors
/// As [`voxelize_mesh_labels`].
#[cfg(feature = "mesh")]
pub fn mesh_label_runs(
    paths: &[impl AsRef<Path>],
    options: &ReadOptions,
) -> Result<MeshLabels<LabelRuns>, IoError> {
    use crate::solid::mesh::TriangleMesh;
    let Some(first) = paths.first().map(AsRef::as_ref) else {
        return Err(usage(Path::new(""), "no mesh to voxelize as labels"));
    };
    // Each mesh with its file and, for the groups of one OBJ file, its group's name.
    let mut meshes: Vec<(TriangleMesh, &Path, Option<String>)> = Vec::new();
    for path in paths.iter().map(AsRef::as_ref) {
        if format_of(path)? != Format::Mesh {
            return Err(usage(
                path,
                "not a mesh: labels are voxelized from meshes (.obj, .stl, .ply)",
            ));
        }
        std::fs::File::open(path).map_err(|e| crate::io::geometry_file::io_error(path, e))?;
        let obj = crate::io::geometry_file::extension(path) == "obj";
        if paths.len() == 1 && obj {
            let groups = io::read_obj_groups(path)?;
            let named = groups.len() > 1;
            for (name, mesh) in groups {
                meshes.push((mesh, path, named.then_some(name)));
            }
        } else {
            meshes.push((io::read_mesh(path)?, path, None));
        }
    }
    for (mesh, path, group) in &meshes {
        let open = mesh.open_edges();
        if open > 0 {
            let what = group
                .as_ref()
                .map_or("the mesh".to_string(), |g| format!("group '{g}'"));
            return Err(solid_error(path)(SolidError::BadParameter(format!(
                "{what} is not closed ({open} edges not shared by exactly two triangles): \
                 a label is the inside of a closed mesh"
            ))));
        }
    }
    let level = options
        .level
        .ok_or_else(|| usage(first, "meshes need a universe level"))?;
    let names = meshes
        .iter()
        .map(|(_, path, group)| group.clone().unwrap_or_else(|| path.display().to_string()))
        .collect();
    let meshes: Vec<TriangleMesh> = meshes.into_iter().map(|(m, _, _)| m).collect();
    let (transform, fitted) =
        mesh_placement(options, &meshes, level).map_err(solid_error(first))?;
    // The voxels of each label counted on the runs.
    let (tree, voxels) = match meshes.len() {
        0..=255 => crate::solid::mesh::label_runs::<u8>(&meshes, level, &transform)
            .map(|l| (LabelRuns::U8(l.runs), l.voxels)),
        256..=65535 => crate::solid::mesh::label_runs::<u16>(&meshes, level, &transform)
            .map(|l| (LabelRuns::U16(l.runs), l.voxels)),
        _ => crate::solid::mesh::label_runs::<u32>(&meshes, level, &transform)
            .map(|l| (LabelRuns::U32(l.runs), l.voxels)),
    }
    .map_err(solid_error(first))?;
    Ok(MeshLabels {
        tree,
        names,
        voxels,
        transform,
        fitted,
    })
}

/// The runs of labels of [`mesh_label_runs`], of the smallest label type that holds the meshes.
#[derive(Debug, Clone, PartialEq)]
pub enum LabelRuns {
    /// Up to 255 meshes.
    U8(crate::rays::ValueRuns<3, u8>),
    /// Up to 65535 meshes.
    U16(crate::rays::ValueRuns<3, u16>),
    /// More.
    U32(crate::rays::ValueRuns<3, u32>),
}

#[cfg(feature = "mesh")]
fn voxelize_mesh(path: &Path, options: &ReadOptions) -> Result<Voxelized, IoError> {
    let (mesh, level, placement, fitted) = mesh_input(path, options)?;
    let r = mesh.to_rays(level, &placement).map_err(solid_error(path))?;
    Ok(Voxelized {
        rays: r.rays,
        fitted,
        open_edges: r.open_edges,
    })
}

#[cfg(not(feature = "mesh"))]
fn voxelize_mesh(path: &Path, _: &ReadOptions) -> Result<Voxelized, IoError> {
    Err(usage(path, "meshes are read with the `mesh` feature"))
}

/// The volume of a file with its level, offset and selection.
#[cfg(feature = "volume")]
fn volume_input(
    path: &Path,
    options: &ReadOptions,
) -> Result<
    (
        crate::solid::volume::Volume,
        u32,
        [u32; 3],
        crate::solid::volume::Select,
    ),
    IoError,
> {
    use crate::solid::volume::Volume;
    let solid = solid_error(path);
    readable(path).map_err(&solid)?;
    let select = options
        .select
        .ok_or_else(|| usage(path, "a volume needs a threshold or a label"))?;
    let offset = options.offset.unwrap_or([0; 3]);
    let Ok(offset) = offset
        .map(u32::try_from)
        .into_iter()
        .collect::<Result<Vec<u32>, _>>()
    else {
        return Err(usage(path, "a volume's offset must be non-negative"));
    };
    let v = Volume::read(path).map_err(&solid)?;
    let level = options.level.unwrap_or_else(|| v.fitting_level());
    Ok((v, level, [offset[0], offset[1], offset[2]], select))
}

#[cfg(feature = "volume")]
fn voxelize_volume(path: &Path, options: &ReadOptions) -> Result<Voxelized, IoError> {
    let (v, level, offset, select) = volume_input(path, options)?;
    let rays = v
        .to_rays(level, offset, select)
        .map_err(solid_error(path))?;
    Ok(Voxelized {
        rays,
        fitted: None,
        open_edges: 0,
    })
}

#[cfg(not(feature = "volume"))]
fn voxelize_volume(path: &Path, _: &ReadOptions) -> Result<Voxelized, IoError> {
    Err(usage(path, "volumes are read with the `volume` feature"))
}
