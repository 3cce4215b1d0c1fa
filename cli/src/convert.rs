//! `ktree convert IN OUT`: any format to any format, chosen by extension (`.ktree`, `.rays`, `.binvox`, `.bt`,
//! `.vdb`; meshes voxelized as inputs and the tree's boundary as outputs, `.glb` and `.svg` outputs only;
//! volumes as inputs).

use crate::common::error::CliResult;
use crate::outln;

use std::path::PathBuf;

use ktree::io::{read_tree_placed, write_tree, Format, ReadOptions, WriteOptions};
use ktree::solid::mesh::MeshTransform;
use ktree::solid::volume::Select;

/// Arguments of `ktree convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input: .ktree, .rays, .binvox, .bt, .vdb, a mesh (.obj, .stl, .ply) or a volume (.json, .raw,
    /// .nii, .nii.gz).
    input: PathBuf,
    /// The output: .ktree, .rays, .binvox, .bt, .vdb, the tree's boundary as a mesh (.ply, .obj, .stl,
    /// .glb; a quadtree's outline as .ply edges, .obj lines or .svg), or VTK for ParaView (.vtu: a cell per
    /// full leaf; .htg: a hyper tree grid).
    output: PathBuf,
    /// Universe level (grids, volumes: default the smallest that holds the input; meshes: required).
    #[arg(long)]
    level: Option<u32>,
    /// Grids and volumes: ktree voxel = grid index + offset, as x,y,z (default 0, or what moves negative
    /// indices to 0).
    #[arg(long, allow_hyphen_values = true)]
    offset: Option<String>,
    /// Grid output: grid index = ktree voxel − offset, as x,y,z (default: .vdb keeps the input's grid
    /// indices, binvox and .bt use 0).
    #[arg(long, allow_hyphen_values = true)]
    out_offset: Option<String>,
    /// Grid and mesh output: the edge of a voxel in world units (default: the input grid's, else 1).
    #[arg(long)]
    voxel_size: Option<f64>,
    /// Grid and mesh output: the world position of the universe's corner (ktree voxel 0), as x,y,z
    /// (default: where the input grid puts it, else 0,0,0).
    #[arg(long, allow_hyphen_values = true)]
    origin: Option<String>,
    /// 4-D trees: write the slices along this axis as a VTK time series — OUT.pvd (a collection of
    /// OUT_NNNN.vtu slices), or OUT_NNNN.vtu / OUT_NNNN.htg files only.
    #[arg(long)]
    time_axis: Option<usize>,
    /// OctoMap input: how unknown cells read.
    #[arg(long, value_parser = ["empty", "full"], default_value = "empty")]
    unknown: String,
    /// Mesh: voxel coordinate = s·v + t, given as s,tx,ty,tz (default: fit into the universe).
    #[arg(long)]
    transform: Option<String>,
    /// Volume: samples with value ≥ this are inside.
    #[arg(long, conflicts_with = "label")]
    threshold: Option<f64>,
    /// Volume: samples equal to this label are inside.
    #[arg(long)]
    label: Option<f64>,
    /// Mesh output (.ply, .obj, .stl, .glb) of an octree: a smooth surface for display (surface nets,
    /// relaxed within half a voxel) instead of the exact boundary; not for round trips.
    #[arg(long)]
    smooth: bool,
}

/// Relaxation steps of `--smooth`.
const SMOOTH_ITERATIONS: usize = 10;

fn parse_xyz(name: &str, text: &str) -> Result<[i64; 3], String> {
    let v: Vec<i64> = text
        .split(',')
        .map(|x| x.trim().parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--{name} '{text}': expected x,y,z (integers)"))?;
    v.try_into()
        .map_err(|_| format!("--{name} '{text}': expected three integers"))
}

fn parse_point(name: &str, text: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--{name} '{text}': expected x,y,z (numbers)"))?;
    match <[f64; 3]>::try_from(v) {
        Ok(p) if p.iter().all(|x| x.is_finite()) => Ok(p),
        _ => Err(format!("--{name} '{text}': expected three finite numbers")),
    }
}

/// Reads the input, writes the output, prints a one-line summary.
pub fn run(a: Args) -> CliResult {
    let options = ReadOptions {
        level: a.level,
        offset: a
            .offset
            .as_deref()
            .map(|t| parse_xyz("offset", t))
            .transpose()?,
        unknown_full: a.unknown == "full",
        mesh_placement: a
            .transform
            .as_deref()
            .map(MeshTransform::parse)
            .transpose()
            .map_err(|e| e.to_string())?,
        select: match (a.threshold, a.label) {
            (Some(t), _) => Some(Select::AtLeast(t)),
            (None, Some(l)) => Some(Select::Label(l)),
            (None, None) => None,
        },
    };
    let read = read_tree_placed(&a.input, &options).map_err(|e| e.to_string())?;
    for r in &read.remarks {
        eprintln!("note: {}: {r}", a.input.display());
    }
    let out_offset = match (&a.out_offset, Format::of(&a.output), read.placement) {
        (Some(t), _, _) => parse_xyz("out-offset", t)?,
        (
            None,
            Some(
                Format::Vdb | Format::Mesh | Format::Glb | Format::Svg | Format::Vtu | Format::Htg,
            ),
            Some(p),
        ) => p.offset,
        _ => [0; 3],
    };
    let mut meta = read.meta.unwrap_or_default();
    if let Some(v) = a.voxel_size {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("--voxel-size {v}: expected a positive number").into());
        }
        meta.voxel_size = v;
    }
    if let Some(t) = &a.origin {
        let origin = parse_point("origin", t)?;
        // The grid's index 0 is ktree voxel `out_offset`.
        meta.origin = std::array::from_fn(|i| origin[i] + out_offset[i] as f64 * meta.voxel_size);
    }
    let write_options = WriteOptions {
        offset: out_offset,
        meta: Some(meta),
    };
    if let Some(axis) = a.time_axis {
        let ktree::AnyTree::K4(t) = &read.tree else {
            return Err(format!(
                "{}: --time-axis slices 4-D trees; this tree has K = {}",
                a.input.display(),
                read.tree.k()
            )
            .into());
        };
        let frame = ktree::export::Frame {
            voxel_size: meta.voxel_size,
            origin: meta.origin,
        };
        let files = ktree::export::vtk::write_time_slices(&a.output, t, axis, &frame)
            .map_err(|e| e.to_string())?;
        outln!(
            "{}: K = 4, L = {}, {} slices along axis {axis} ({} files)",
            a.output.display(),
            t.level(),
            t.universe().side(),
            files.len()
        );
        return Ok(());
    }
    if a.smooth {
        let ktree::AnyTree::K3(t) = &read.tree else {
            return Err(format!(
                "{}: --smooth makes surfaces of octrees (K = 3); this tree has K = {}",
                a.input.display(),
                read.tree.k()
            )
            .into());
        };
        // ktree voxel v is at meta.origin + (v − out_offset) · voxel_size, as for the exact boundary.
        let frame = ktree::export::Frame {
            voxel_size: meta.voxel_size,
            origin: std::array::from_fn(|i| {
                meta.origin[i] - out_offset[i] as f64 * meta.voxel_size
            }),
        };
        let mesh = ktree::export::surface::smooth_mesh(t, SMOOTH_ITERATIONS)
            .map_err(|e| format!("{}: {e}", a.input.display()))?
            .placed(&frame);
        let written = ktree::export::write_surface(&a.output, &mesh).map_err(|e| e.to_string())?;
        outln!(
            "{}: smooth surface of {} vertices, {} triangles",
            a.output.display(),
            written.vertices,
            written.elements
        );
        return Ok(());
    }
    if Format::of(&a.output) == Some(Format::Ktree) {
        // The version --format-version asks for, as every command that writes trees.
        ktree::with_dim!(&read.tree, AnyTree, t => crate::common::tree_file::write_tree(&a.output, t))
            .map_err(|e| format!("cannot write {}: {e}", a.output.display()))?;
    } else {
        write_tree(&a.output, &read.tree, &write_options).map_err(|e| e.to_string())?;
    }
    let c = read.tree.counts();
    let placed = read.placement.map_or(String::new(), |p| {
        format!(" (grid index + {:?} = ktree voxel)", p.offset)
    });
    outln!(
        "{}: K = {}, L = {}, {} nodes, {} voxels{placed}",
        a.output.display(),
        read.tree.k(),
        read.tree.level(),
        c.nodes(),
        ktree::with_dim!(&read.tree, AnyTree, t => t.voxel_count()),
    );
    Ok(())
}
