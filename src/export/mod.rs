//! The boundary of a tree out to the tools that look at surfaces: an octree as a closed triangle mesh
//! ([`surface`]), a quadtree as closed polylines ([`outline`]), written as PLY, OBJ, STL or glTF binary
//! ([`files`]) in real-world units ([`Frame`]); any tree as an interactive 3-D view in one HTML page
//! ([`view`]).
//!
//! ```
//! use ktree::export::{write_mesh, Frame};
//! use ktree::{AnyTree, KTree};
//! let dir = tempfile::tempdir().unwrap();
//! let tree = AnyTree::K3(KTree::<3>::full(1).unwrap());
//! let path = dir.path().join("block.ply");
//! let written = write_mesh(&path, &tree, &Frame::default()).unwrap();
//! assert_eq!((written.vertices, written.elements), (8, 12));
//! ```

pub mod files;
#[cfg(feature = "png")]
pub mod grid_map;
pub mod outline;
pub mod surface;
pub mod view;
pub mod vtk;

use std::path::Path;

use thiserror::Error;

use crate::display::palette::colours_of_values;
use crate::fs::write_atomic_with;
use crate::space::Universe;
use crate::tree::storage::TreeStorage;
use crate::tree::{AnyTree, LevelCounts, NodeState, StorageError};
use crate::value::Value;

/// Where voxels are in the world for an export: ktree voxel `v` is at `origin + voxel_size · v` (the
/// universe's corner at `origin`; quadtrees use the first two coordinates). The crate's one world frame,
/// [`WorldFrame`](crate::space::WorldFrame).
pub type Frame = crate::space::WorldFrame;

/// A mesh file format, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// `.ply`, binary little-endian.
    Ply,
    /// `.obj`.
    Obj,
    /// `.stl`, binary.
    Stl,
    /// `.glb`, glTF 2.0 binary.
    Glb,
    /// `.svg`: outlines only.
    Svg,
}

impl MeshFormat {
    /// The format of a path, by its extension (case-insensitive).
    ///
    /// ```
    /// use ktree::export::MeshFormat;
    /// assert_eq!(MeshFormat::of(std::path::Path::new("a.GLB")), Some(MeshFormat::Glb));
    /// assert_eq!(MeshFormat::of(std::path::Path::new("a.ktree")), None);
    /// ```
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "ply" => Self::Ply,
            "obj" => Self::Obj,
            "stl" => Self::Stl,
            "glb" => Self::Glb,
            "svg" => Self::Svg,
            _ => return None,
        })
    }
}

/// What [`write_mesh`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Written {
    /// Vertices.
    pub vertices: usize,
    /// Triangles (octrees) or edges (quadtrees).
    pub elements: usize,
}

/// An error writing a mesh.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The format does not fit the file or the tree.
    #[error("{}: {message}", file.display())]
    Usage {
        /// The file.
        file: std::path::PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Writing failed (the message names the file).
    #[error(transparent)]
    Write(#[from] crate::fs::FileOpError),
    /// A smooth surface ([`surface::smooth_mesh`]) would have more unit faces than it makes at most; the
    /// exact boundary ([`surface::boundary_mesh`]) merges them and has no such bound.
    #[error("a smooth surface of {faces} unit faces is more than the {limit} made at most; write the exact boundary")]
    TooLarge {
        /// The unit faces of the boundary.
        faces: u128,
        /// [`surface::SMOOTH_FACE_LIMIT`].
        limit: u64,
    },
    /// Reading the tree failed (a file read in place was changed after it was opened).
    #[error(transparent)]
    Storage(#[from] StorageError),
}

/// Writes the boundary of `tree` to `path` in the format its extension names, atomically: an octree as a
/// closed triangle mesh (`.ply`, `.obj`, `.stl`, `.glb`), a quadtree as closed polylines (`.ply` edges,
/// `.obj` lines, `.svg`), placed by `frame`.
///
/// # Errors
/// [`ExportError::Usage`] for an unknown extension or a format that cannot hold the tree's boundary;
/// [`ExportError::Write`] from the file system.
pub fn write_mesh(path: &Path, tree: &AnyTree, frame: &Frame) -> Result<Written, ExportError> {
    crate::with_dim!(tree, AnyTree, t => write_mesh_of(path, t, frame))
}

/// [`write_mesh`] of a tree whose dimension is known, on any storage (a mapped `.ktree` file is read in
/// place).
///
/// # Errors
/// As [`write_mesh`]; [`ExportError::Storage`] if a read of the tree fails.
pub fn write_mesh_of<const K: usize, T: TreeStorage<K>>(
    path: &Path,
    tree: &T,
    frame: &Frame,
) -> Result<Written, ExportError> {
    let usage = |message: &str| ExportError::Usage {
        file: path.to_path_buf(),
        message: message.into(),
    };
    let format = MeshFormat::of(path)
        .ok_or_else(|| usage("unknown mesh extension: expected .ply, .obj, .stl, .glb or .svg"))?;
    let write = |fill: &dyn Fn(&mut dyn std::io::Write) -> std::io::Result<()>| {
        write_atomic_with(path, |w| fill(w)).map_err(ExportError::Write)
    };
    if let Some(t) = Dimension::<_, K>::of::<3>(tree) {
        if format == MeshFormat::Svg {
            return Err(usage(
                "SVG holds the outlines of quadtrees (K = 2); this tree has K = 3",
            ));
        }
        let mesh = surface::try_boundary_mesh(&t).map_err(|e| ExportError::Storage(e.into()))?;
        write_surface(path, &mesh.placed(frame))
    } else if let Some(t) = Dimension::<_, K>::of::<2>(tree) {
        let loops = outline::try_boundary_loops(&t).map_err(|e| ExportError::Storage(e.into()))?;
        let loops = place_loops(&loops, frame);
        match format {
            MeshFormat::Ply => write(&|w| files::write_ply_edges(w, &loops))?,
            MeshFormat::Obj => write(&|w| files::write_obj_lines(w, &loops))?,
            MeshFormat::Svg => write(&|w| files::write_svg(w, &loops))?,
            MeshFormat::Stl | MeshFormat::Glb => {
                return Err(usage(
                    "a quadtree's boundary is polylines: write .ply, .obj or .svg",
                ))
            }
        }
        let n = loops.iter().map(Vec::len).sum();
        Ok(Written {
            vertices: n,
            elements: n,
        })
    } else {
        Err(usage(&format!(
            "meshes are written for octrees (K = 3) and outlines for quadtrees (K = 2); this tree has K = {K}"
        )))
    }
}

/// A tree of dimension `K` read as one of dimension `J`, made only when `J == K` ([`Dimension::of`]): how
/// code generic over `K` calls the code of one dimension (an octree's mesh, a quadtree's outline) on any
/// storage. Every read is the tree's own.
struct Dimension<'a, T, const K: usize>(&'a T);

impl<'a, T: TreeStorage<K>, const K: usize> Dimension<'a, T, K> {
    /// `tree` as a tree of dimension `J`, if that is its dimension.
    fn of<const J: usize>(tree: &'a T) -> Option<Self> {
        (J == K).then_some(Self(tree))
    }
}

impl<T: TreeStorage<K>, const K: usize, const J: usize> TreeStorage<J> for Dimension<'_, T, K> {
    type Error = T::Error;

    fn universe(&self) -> Universe<J> {
        Universe::new(self.0.level()).expect("a tree's level is in range for its own dimension")
    }

    fn depth_count(&self) -> usize {
        self.0.depth_count()
    }

    fn level_len(&self, depth: usize) -> usize {
        self.0.level_len(depth)
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.0.counts_per_level()
    }

    #[inline]
    fn root_state(&self) -> Result<NodeState, Self::Error> {
        self.0.root_state()
    }

    #[inline(always)]
    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, Self::Error> {
        self.0.partial_rank(depth, index)
    }

    #[inline(always)]
    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, Self::Error> {
        self.0.block_codes(depth, first)
    }

    #[inline(always)]
    fn first_child(&self, depth: usize, index: usize) -> Result<usize, Self::Error> {
        self.0.first_child(depth, index)
    }

    #[inline(always)]
    fn slots(&self, depth: usize, first: usize, n: usize) -> Result<u64, Self::Error> {
        self.0.slots(depth, first, n)
    }

    #[inline(always)]
    fn state(&self, depth: usize, index: usize) -> Result<NodeState, Self::Error> {
        self.0.state(depth, index)
    }
}

/// Writes a triangle mesh (already placed in the world) to `path` as `.ply`, `.obj`, `.stl` or `.glb`, by
/// its extension, atomically — for instance a [`surface::smooth_mesh`].
///
/// ```
/// use ktree::export::{surface::smooth_mesh, write_surface, Frame};
/// let dir = tempfile::tempdir().unwrap();
/// let mesh = smooth_mesh(&ktree::KTree::<3>::full(2).unwrap(), 5).unwrap().placed(&Frame::default());
/// let written = write_surface(&dir.path().join("smooth.obj"), &mesh).unwrap();
/// assert_eq!(written.elements, mesh.triangles.len());
/// ```
///
/// # Errors
/// [`ExportError::Usage`] for an extension that is not one of these; [`ExportError::Write`] from the file
/// system.
pub fn write_surface(path: &Path, mesh: &surface::SurfaceMesh) -> Result<Written, ExportError> {
    let write = |fill: &dyn Fn(&mut dyn std::io::Write) -> std::io::Result<()>| {
        write_atomic_with(path, |w| fill(w)).map_err(ExportError::Write)
    };
    match MeshFormat::of(path) {
        Some(MeshFormat::Ply) => write(&|w| files::write_ply(w, mesh))?,
        Some(MeshFormat::Obj) => write(&|w| files::write_obj(w, mesh))?,
        Some(MeshFormat::Stl) => write(&|w| files::write_stl(w, mesh))?,
        Some(MeshFormat::Glb) => write(&|w| files::write_glb(w, mesh))?,
        _ => {
            return Err(ExportError::Usage {
                file: path.to_path_buf(),
                message: "a triangle mesh is written as .ply, .obj, .stl or .glb".into(),
            })
        }
    }
    Ok(Written {
        vertices: mesh.vertices.len(),
        elements: mesh.triangles.len(),
    })
}

/// Writes the surfaces of a tree's values (already placed in the world) to `path` with their colours,
/// atomically, by its extension: `.ply` with every face once and its values and colour as face
/// properties ([`files::write_value_ply`]), `.obj` with a group per value and its materials in a `.mtl`
/// beside it ([`files::write_value_obj`]), `.glb` with a mesh and material per value
/// ([`files::write_value_glb`]). Labels are coloured by
/// [`label_colour`](crate::display::palette::label_colour), floats along
/// [`ramp`](crate::display::palette::ramp) from the smallest value to the largest, colours as they are.
///
/// ```
/// use ktree::export::{surface::value_boundary_mesh, write_value_surface, Frame};
/// let dir = tempfile::tempdir().unwrap();
/// let mut dense = [None; 8];
/// (dense[0], dense[1]) = (Some(1u8), Some(2));
/// let tree = ktree::KTree::<3, u8>::from_dense_values(1, &dense).unwrap();
/// let mesh = value_boundary_mesh(&tree).placed(&Frame::default());
/// let written = write_value_surface(&dir.path().join("labels.obj"), &mesh).unwrap();
/// assert_eq!(written.elements, 24); // two cubes, each closed in its group
/// assert!(dir.path().join("labels.mtl").exists());
/// ```
///
/// # Errors
/// [`ExportError::Usage`] for another extension; [`ExportError::Write`] from the file system.
pub fn write_value_surface<V: Value>(
    path: &Path,
    mesh: &surface::ValueMesh<V>,
) -> Result<Written, ExportError> {
    let colour = colours_of_values(mesh.surfaces.iter().map(|s| s.value));
    let write = |path: &Path, fill: &dyn Fn(&mut dyn std::io::Write) -> std::io::Result<()>| {
        write_atomic_with(path, |w| fill(w)).map_err(ExportError::Write)
    };
    let all = mesh.surfaces.iter().map(|s| s.mesh.triangles.len()).sum();
    let elements =
        match MeshFormat::of(path) {
            Some(MeshFormat::Ply) => {
                write(path, &|w| files::write_value_ply(w, mesh, &colour))?;
                mesh.faces_once().count()
            }
            Some(MeshFormat::Obj) => {
                let mtl = path.with_extension("mtl");
                write(&mtl, &|w| files::write_value_mtl(w, mesh, &colour))?;
                let name = mtl.file_name().map(|n| n.to_string_lossy().into_owned());
                write(path, &|w| files::write_value_obj(w, mesh, name.as_deref()))?;
                all
            }
            Some(MeshFormat::Glb) => {
                write(path, &|w| files::write_value_glb(w, mesh, &colour))?;
                all
            }
            _ => return Err(ExportError::Usage {
                file: path.to_path_buf(),
                message:
                    "the surfaces of values are written with their colours as .ply, .obj or .glb"
                        .into(),
            }),
        };
    Ok(Written {
        vertices: mesh.vertex_count(),
        elements,
    })
}

/// Outline loops in world units (see [`Frame`]).
pub fn place_loops(loops: &[outline::Loop], frame: &Frame) -> Vec<outline::Loop> {
    loops
        .iter()
        .map(|l| {
            l.iter()
                .map(|v| std::array::from_fn(|a| frame.origin[a] + frame.voxel_size * v[a]))
                .collect()
        })
        .collect()
}
