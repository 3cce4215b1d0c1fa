//! `ktree convert IN OUT`: any format to any format, chosen by extension (`.ktree`, `.rays`, `.binvox`, `.bt`,
//! `.vdb`; meshes voxelized as inputs and the tree's boundary as outputs, `.glb` and `.svg` outputs only;
//! volumes as inputs, NIfTI also as outputs; trees with values to NIfTI, OpenVDB, VTK (`.vtu`, `.htg`), the
//! surfaces of their values with colours (`.ply`, `.obj`, `.glb`) or `.ktree`, and an OpenVDB grid with
//! values to a valued `.ktree`).

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::{Path, PathBuf};

use ktree::export::surface::smooth_mesh;
use ktree::export::vtk::{write_time_slices, write_vtk_file};
use ktree::export::{write_mesh_of, write_surface, ExportError, Frame};
use ktree::input::read_tree_placed;
use ktree::io::{
    ktree_file_version, write_tree, AnyMappedTree, FileTree, Format, KtreeView, Notes, ReadOptions,
    WriteOptions, VERSION,
};
use ktree::solid::mesh::MeshTransform;
use ktree::tree::storage::TreeStorage;
use ktree::{with_tree, AnyTree};

use crate::common::tree_file::write_tree_framed;
use crate::common::vector::vector;

/// Arguments of `ktree convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input: .ktree, .rays, .binvox, .bt, .vdb, a mesh (.obj, .stl, .ply) or a volume (.json, .raw,
    /// .nii, .nii.gz).
    input: PathBuf,
    /// The output: .ktree, .rays, .binvox, .bt, .vdb, the tree's boundary as a mesh (.ply, .obj, .stl,
    /// .glb; a quadtree's outline as .ply edges, .obj lines or .svg; an octree with values as the surface
    /// of each value with its colour, .ply, .obj with a .mtl, .glb), or VTK for ParaView (.vtu: a cell per
    /// full leaf; .htg: a hyper tree grid).
    output: PathBuf,
    /// Universe level (grids, volumes: default the smallest that holds the input; meshes: required).
    #[arg(long)]
    level: Option<u32>,
    /// Grids and volumes: ktree voxel = grid index + offset, as x,y,z (default 0, or what moves negative
    /// indices to 0, rounded up to a multiple of the grid's largest aligned tile or node side).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<i64, 3>)]
    offset: Option<[i64; 3]>,
    /// Grid output: grid index = ktree voxel − offset, as x,y,z (default: .vdb and .bt keep the input's
    /// grid indices, binvox uses 0). The world stays where it is.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<i64, 3>)]
    out_offset: Option<[i64; 3]>,
    /// Grid and mesh output: the edge of a voxel in world units (default: the input grid's, else 1).
    #[arg(long)]
    voxel_size: Option<f64>,
    /// Grid and mesh output: the world position of the universe's corner (ktree voxel 0), as x,y,z
    /// (default: where the input grid puts it, else 0,0,0).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<f64, 3>)]
    origin: Option<[f64; 3]>,
    /// 4-D trees: write the slices along this axis as a VTK time series — OUT.pvd (a collection of
    /// OUT_NNNN.vtu slices), or OUT_NNNN.vtu / OUT_NNNN.htg files only.
    #[arg(long)]
    time_axis: Option<usize>,
    /// OctoMap input: how unknown cells read.
    #[arg(long, value_parser = ["empty", "full"], default_value = "empty")]
    unknown: String,
    /// Mesh: voxel coordinate = s·v + t, given as s,tx,ty,tz (default: fit into the universe).
    #[arg(long, value_name = "S,TX,TY,TZ", allow_hyphen_values = true, value_parser = MeshTransform::parse)]
    transform: Option<MeshTransform>,
    #[command(flatten)]
    volume: crate::common::args::VolumeArgs,
    /// Mesh output (.ply, .obj, .stl, .glb) of an octree: a smooth surface for display (surface nets,
    /// relaxed within half a voxel) instead of the exact boundary; not for round trips.
    #[arg(long)]
    smooth: bool,
}

/// Relaxation steps of `--smooth`.
const SMOOTH_ITERATIONS: usize = 10;

/// Reads the input, writes the output, prints a one-line summary.
pub fn run(a: Args) -> CliResult {
    if crate::values::is_valued(&a.input) {
        if let Some(v) = a.voxel_size.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(format!("--voxel-size {v}: expected a positive number").into());
        }
        let placement = crate::convert_values::Placement {
            voxel_size: a.voxel_size,
            origin: a.origin,
        };
        if let Some(axis) = a.time_axis {
            return crate::convert_values::time_series(&a.input, &a.output, axis, placement);
        }
        return crate::convert_values::convert_valued(&a.input, &a.output, placement);
    }
    // A typed grid keeps its values in every output that holds them; the others get its shape.
    if Format::of(&a.input) == Some(Format::Vdb)
        && ktree::io::keeps_values(&a.output)
        && vdb_with_values(&a.input)
    {
        return crate::convert_values::vdb_to_valued(&a.input, &a.output, a.level, a.offset);
    }
    let options = ReadOptions {
        level: a.level,
        offset: a.offset,
        unknown_full: a.unknown == "full",
        mesh_placement: a.transform,
        select: a.volume.select(),
    };
    let format = Format::of(&a.output);
    let exported = matches!(
        format,
        Some(Format::Mesh | Format::Glb | Format::Svg | Format::Vtu | Format::Htg)
    );
    // Meshes and VTK files of a version 2 .ktree are made from its memory map, whatever its size; every
    // other input is read into memory, with the placement and metadata of its format.
    // A version 2 .ktree may keep where its voxels are in the world, and notes.
    let input_v2 = Format::of(&a.input) == Some(Format::Ktree)
        && ktree_file_version(&a.input).is_ok_and(|v| v == VERSION);
    let (kept_frame, notes) = match input_v2.then(|| KtreeView::open(&a.input)) {
        Some(Ok(view)) => (view.frame(), view.notes().clone()),
        _ => (None, Notes::new()),
    };
    let (file, placement, read_meta) =
        if (exported || a.time_axis.is_some() || a.smooth) && input_v2 {
            let mapped = AnyMappedTree::open(&a.input).map_err(CliError::caused)?;
            (FileTree::Mapped(mapped), None, None)
        } else {
            let read = read_tree_placed(&a.input, &options).map_err(CliError::caused)?;
            for r in &read.remarks {
                eprintln!("note: {}: {r}", a.input.display());
            }
            (FileTree::Memory(read.tree), read.placement, read.meta)
        };
    let read_meta = read_meta.or(kept_frame);
    // The input grid's index 0 is ktree voxel `read_offset`; the output grid's, `out_offset`: by default
    // the input's grid indices are kept where the output has indices of its own (.vdb, .bt; binvox starts
    // at 0).
    let read_offset = placement.map_or([0; 3], |p| p.offset);
    let out_offset = match (a.out_offset, format) {
        (Some(o), _) => o,
        (
            None,
            Some(
                Format::Vdb
                | Format::OctomapBt
                | Format::Mesh
                | Format::Glb
                | Format::Svg
                | Format::Vtu
                | Format::Htg,
            ),
        ) => read_offset,
        _ => [0; 3],
    };
    let mut meta = read_meta.unwrap_or_default();
    if let Some(v) = a.voxel_size {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("--voxel-size {v}: expected a positive number").into());
        }
        meta.voxel_size = v;
    }
    // The world stays where it is: ktree voxel 0 is at --origin, or where the input grid puts it.
    let corner = match a.origin {
        Some(origin) => origin,
        None => meta.counted_from(read_offset.map(|o| -o)).origin,
    };
    meta = Frame {
        voxel_size: meta.voxel_size,
        origin: corner,
    }
    .counted_from(out_offset);
    // Whether the voxels have a place in the world to keep.
    let placed = kept_frame.is_some()
        || read_meta.is_some_and(|m| m != Frame::default())
        || read_offset != [0; 3]
        || a.origin.is_some()
        || a.voxel_size.is_some()
        || a.out_offset.is_some();
    if format == Some(Format::Rays) && placed {
        // Say what is lost: these files hold voxels only.
        eprintln!(
            "note: {}: a ray file holds no world placement: voxel size {}, ktree voxel 0 at {:?} are not \
             kept (give --voxel-size and --origin when converting it back to a grid or a mesh)",
            a.output.display(),
            meta.voxel_size,
            corner
        );
    }
    if let Some(axis) = a.time_axis {
        let frame = Frame {
            voxel_size: meta.voxel_size,
            origin: meta.origin,
        };
        let files = match &file {
            FileTree::Memory(AnyTree::K4(t)) => write_time_slices(&a.output, t, axis, &frame),
            FileTree::Mapped(AnyMappedTree::K4(t)) => write_time_slices(&a.output, t, axis, &frame),
            other => {
                return Err(format!(
                    "{}: --time-axis slices 4-D trees; this tree has K = {}",
                    a.input.display(),
                    other.k()
                )
                .into())
            }
        }
        .map_err(CliError::caused)?;
        outln!(
            "{}: K = 4, L = {}, {} slices along axis {axis} ({} files)",
            a.output.display(),
            file.level(),
            1u64 << file.level(),
            files.len()
        );
        return Ok(());
    }
    // Meshes and VTK files: ktree voxel v is at meta.origin + (v − out_offset) · voxel_size.
    let frame = Frame {
        voxel_size: meta.voxel_size,
        origin: std::array::from_fn(|i| meta.origin[i] - out_offset[i] as f64 * meta.voxel_size),
    };
    if a.smooth {
        let mesh = match &file {
            FileTree::Memory(AnyTree::K3(t)) => smooth_mesh(t, SMOOTH_ITERATIONS),
            FileTree::Mapped(AnyMappedTree::K3(t)) => smooth_mesh(t, SMOOTH_ITERATIONS),
            other => {
                return Err(format!(
                    "{}: --smooth makes surfaces of octrees (K = 3); this tree has K = {}",
                    a.input.display(),
                    other.k()
                )
                .into())
            }
        }
        .map_err(|e| CliError::in_file(&a.input, e))?
        .placed(&frame);
        let written = write_surface(&a.output, &mesh).map_err(CliError::caused)?;
        outln!(
            "{}: smooth surface of {} vertices, {} triangles",
            a.output.display(),
            written.vertices,
            written.elements
        );
        return Ok(());
    }
    if exported {
        with_tree!(&file, t => export(&a.output, t, &frame)).map_err(CliError::caused)?;
    } else {
        let FileTree::Memory(tree) = &file else {
            unreachable!("only meshes and VTK files are made from a file read in place")
        };
        if format == Some(Format::Ktree) {
            // The version --format-version asks for, as every command that writes trees, with the world
            // frame of ktree voxel 0 if the voxels have a place.
            let frame = placed.then_some(Frame {
                voxel_size: meta.voxel_size,
                origin: corner,
            });
            ktree::with_dim!(tree, AnyTree, t => {
                write_tree_framed(&a.output, t, frame.as_ref(), &notes)
            })
            .map_err(CliError::caused)?;
        } else {
            let write_options = WriteOptions {
                offset: out_offset,
                meta: Some(meta),
                ..WriteOptions::default()
            };
            write_tree(&a.output, tree, &write_options).map_err(CliError::caused)?;
        }
    }
    let (c, voxels) = with_tree!(&file, t => (TreeStorage::counts(t), TreeStorage::voxel_count(t)));
    let placed = placement.map_or(String::new(), |p| {
        format!(" (grid index + {:?} = ktree voxel)", p.offset)
    });
    outln!(
        "{}: K = {}, L = {}, {} nodes, {voxels} voxels{placed}",
        a.output.display(),
        file.k(),
        file.level(),
        c.nodes(),
    );
    Ok(())
}

/// Whether `path` is an OpenVDB file whose first grid read holds values (a file that cannot be read says
/// no: the reader of every format then reports it).
fn vdb_with_values(path: &Path) -> bool {
    std::fs::read(path).is_ok_and(|b| {
        ktree::io::vdb_holds_values(&b, &path.display().to_string()).unwrap_or(false)
    })
}

/// Writes the tree's boundary (a mesh or an outline) or a VTK file, by the output's extension.
fn export<const K: usize, T: TreeStorage<K>>(
    path: &Path,
    tree: &T,
    frame: &Frame,
) -> Result<(), ExportError> {
    match Format::of(path) {
        Some(Format::Vtu | Format::Htg) => write_vtk_file(path, tree, frame),
        _ => write_mesh_of(path, tree, frame).map(drop),
    }
}
