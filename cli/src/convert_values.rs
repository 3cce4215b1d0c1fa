//! `ktree convert` of a tree with values (a version 3 `.ktree`) and `ktree voxelize VOLUME --window LO:HI`:
//! the values go to a NIfTI volume (`.nii`, `.nii.gz`: labels, densities or colours as its samples), to an
//! OpenVDB typed grid (`.vdb`: `Int32Grid`, `FloatGrid`, `Vec3SGrid`), to VTK files for ParaView (`.vtu`,
//! `.htg`: the values as the cell data `value`), to the surfaces of its values with their colours (`.ply`,
//! `.obj`, `.glb`) or to another `.ktree`, each placed by the file's world frame unless `--voxel-size` or
//! `--origin` say otherwise; an OpenVDB typed grid comes in as a valued `.ktree`; a volume's window of
//! intensities comes in as `float32` values.

use std::path::Path;

use ktree::export::surface::value_boundary_mesh;
use ktree::export::vtk::{write_values_time_slices, write_values_vtk_file};
use ktree::export::{write_value_surface, MeshFormat};
use ktree::io::ktree::v3::{
    read_valued_ktree_framed, write_valued_ktree_file, write_valued_ktree_file_framed,
};
use ktree::io::{read_vdb_values, write_nifti_file, write_vdb_values};
use ktree::solid::volume::Volume;
use ktree::space::WorldFrame;
use ktree::tree::AnyValuedTree;
use ktree::value::{Dtype, Value};
use ktree::KTree;

use crate::common::error::{cannot_read, CliError, CliResult};
use crate::outln;

/// Where `--voxel-size` and `--origin` place the output: given, or the input's world frame, else voxels of
/// 1 from 0.
#[derive(Debug, Clone, Copy, Default)]
pub struct Placement {
    /// `--voxel-size`.
    pub voxel_size: Option<f64>,
    /// `--origin`: the world position of ktree voxel 0.
    pub origin: Option<[f64; 3]>,
}

impl Placement {
    /// The frame given, the rest from `kept` (a file's world frame), else voxels of 1 from 0.
    fn frame(self, kept: Option<WorldFrame>) -> WorldFrame {
        let kept = kept.unwrap_or_default();
        WorldFrame {
            voxel_size: self.voxel_size.unwrap_or(kept.voxel_size),
            origin: self.origin.unwrap_or(kept.origin),
        }
    }
}

/// What a tree with values is written as, by the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    /// `.nii`, `.nii.gz` (octrees).
    Nifti,
    /// `.vdb`: an OpenVDB typed grid (octrees).
    Vdb,
    /// `.vtu`, `.htg` (quadtrees and octrees).
    Vtk,
    /// `.ply`, `.obj`, `.glb`: the surface of each value with its colour (octrees).
    Mesh,
    /// `.ktree` (any K).
    Ktree,
}

impl Output {
    fn of(output: &Path) -> Option<Self> {
        let name = output.to_string_lossy();
        let ends = |e: &str| name.ends_with(e);
        Some(if ends(".nii") || ends(".nii.gz") {
            Output::Nifti
        } else if ends(".vdb") {
            Output::Vdb
        } else if ends(".vtu") || ends(".htg") {
            Output::Vtk
        } else if ends(".ktree") {
            Output::Ktree
        } else if matches!(
            MeshFormat::of(output),
            Some(MeshFormat::Ply | MeshFormat::Obj | MeshFormat::Glb)
        ) {
            Output::Mesh
        } else {
            return None;
        })
    }

    /// Whether the output holds trees of `k` dimensions; else what it holds.
    fn holds(self, k: usize) -> Result<(), &'static str> {
        match self {
            Output::Ktree => Ok(()),
            Output::Vtk if k == 2 || k == 3 => Ok(()),
            Output::Vtk => Err("VTK files hold quadtrees and octrees (K = 2, 3)"),
            _ if k == 3 => Ok(()),
            Output::Nifti => Err("NIfTI volumes hold octrees (K = 3)"),
            Output::Vdb => Err("OpenVDB grids hold octrees (K = 3)"),
            Output::Mesh => Err("the surfaces of values are made for octrees (K = 3)"),
        }
    }
}

/// Converts the valued tree in `input` to `output` (`.nii`, `.nii.gz`, `.vdb`, `.vtu`, `.htg`, `.ply`,
/// `.obj`, `.glb` or `.ktree`), placed by `placement`, the rest as the input's world frame places it.
pub fn convert_valued(input: &Path, output: &Path, placement: Placement) -> CliResult {
    let (k, dtype) = crate::values::file_dtype(input)?;
    let dtype = dtype.ok_or_else(|| format!("{}: the tree holds no values", input.display()))?;
    let Some(format) = Output::of(output) else {
        return Err(format!(
            "{}: a tree with values ({}) converts to NIfTI (.nii, .nii.gz), OpenVDB (.vdb), VTK (.vtu, \
             .htg), the surfaces of its values with their colours (.ply, .obj, .glb) or .ktree",
            output.display(),
            dtype.name()
        )
        .into());
    };
    format.holds(k).map_err(|holds| {
        format!(
            "{}: {holds}; {} has K = {k}",
            output.display(),
            input.display()
        )
    })?;
    ktree::with_valued!(k, dtype, KK, V => write_valued::<KK, V>(input, output, format, placement),
        else Err(format!("{}: K = {k} is not 1 to 4", input.display()).into()))
}

/// The valued tree of a `.ktree` file and the world frame it keeps.
pub fn read_framed<const K: usize, V: Value>(
    input: &Path,
) -> CliResult<(KTree<K, V>, Option<WorldFrame>)> {
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    read_valued_ktree_framed::<K, V>(&bytes, &input.display().to_string()).map_err(CliError::caused)
}

/// Writes the valued tree of `input` to `output` as `format` (which holds `K` dimensions).
fn write_valued<const K: usize, V: Value>(
    input: &Path,
    output: &Path,
    format: Output,
    placement: Placement,
) -> CliResult {
    let (tree, kept) = read_framed::<K, V>(input)?;
    let frame = placement.frame(kept);
    let tree = AnyValuedTree::from(tree);
    let typed = tree
        .as_typed::<K, V>()
        .ok_or("the tree is of its own dimension and type")?;
    let octree = || {
        tree.as_typed::<3, V>()
            .ok_or("the formats of octrees were checked to get K = 3")
    };
    let mut what = "values";
    match format {
        Output::Ktree => {
            // The frame is kept, or given; a tree without one stays without.
            let given = placement.voxel_size.is_some() || placement.origin.is_some();
            let keep = (kept.is_some() || given).then_some(frame);
            write_valued_ktree_file_framed(output, typed, keep.as_ref())
                .map_err(CliError::caused)?
        }
        Output::Vtk => {
            write_values_vtk_file(output, typed, &frame).map_err(CliError::caused)?;
            what = "values as cell data";
        }
        Output::Nifti => write_nifti_file(output, octree()?, &frame).map_err(CliError::caused)?,
        Output::Vdb => {
            let octree = octree()?;
            ktree::fs::write_atomic_with(output, |w| write_vdb_values(w, octree, [0; 3], &frame))
                .map_err(CliError::caused)?
        }
        Output::Mesh => {
            let mesh = value_boundary_mesh(octree()?).placed(&frame);
            let written = write_value_surface(output, &mesh).map_err(CliError::caused)?;
            outln!(
                "{}: the surfaces of {} {} values, {} vertices, {} triangles",
                output.display(),
                mesh.surfaces.len(),
                V::DTYPE.map_or("", Dtype::name),
                written.vertices,
                written.elements
            );
            return Ok(());
        }
    }
    outln!(
        "{}: K = {K}, L = {}, {} {what}, {} nodes, {} voxels",
        output.display(),
        typed.level(),
        V::DTYPE.map_or("", Dtype::name),
        typed.node_count(),
        typed.voxel_count()
    );
    Ok(())
}

/// The 4-D valued tree of `input` as a time series of VTK files along `axis` (`.pvd` with `.vtu` slices,
/// or `.vtu` or `.htg` slices alone), `value` their cell data.
pub fn time_series(input: &Path, output: &Path, axis: usize, placement: Placement) -> CliResult {
    let (k, dtype) = crate::values::file_dtype(input)?;
    let dtype = dtype.ok_or_else(|| format!("{}: the tree holds no values", input.display()))?;
    if k != 4 {
        return Err(format!(
            "{}: --time-axis slices 4-D trees; this tree has K = {k}",
            input.display()
        )
        .into());
    }
    let files = ktree::with_valued!(4, dtype, KK, V => {
        let (tree, kept) = read_framed::<4, V>(input)?;
        write_values_time_slices(output, &tree, axis, &placement.frame(kept))
            .map_err(CliError::caused)?
    }, else return Err(format!("{}: K = {k} is not 1 to 4", input.display()).into()));
    outln!(
        "{}: K = 4, {} values, slices along axis {axis} ({} files)",
        output.display(),
        dtype.name(),
        files.len()
    );
    Ok(())
}

/// `ktree convert IN.vdb OUT.ktree` of a grid with values (not a `BoolGrid`, `MaskGrid` or level set):
/// a valued `.ktree` of its active voxels and the grid's world frame, placed by `level` and `offset` (ktree voxel = grid index +
/// offset; by default those the file was written with, else the smallest universe from 0).
pub fn vdb_to_valued(
    input: &Path,
    output: &Path,
    level: Option<u32>,
    offset: Option<[i64; 3]>,
) -> CliResult {
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    let read = read_vdb_values(&bytes, &input.display().to_string(), offset, level)
        .map_err(CliError::caused)?;
    // The grid's world placement, counted from ktree voxel 0.
    let frame = read.meta.counted_from(read.placement.offset.map(|o| -o));
    ktree::with_valued!(&read.tree, t => write_valued_ktree_file_framed(output, t, Some(&frame)))
        .map_err(CliError::caused)?;
    let tree = &read.tree;
    outln!(
        "{}: K = 3, L = {}, {} values, {} voxels (grid index + {:?} = ktree voxel)",
        output.display(),
        tree.level(),
        tree.dtype().name(),
        ktree::with_valued!(tree, t => t.voxel_count()),
        read.placement.offset
    );
    Ok(())
}

/// `ktree voxelize VOLUME --window LO:HI`: the samples from `lo` to `hi` kept as `float32` values.
pub fn voxelize_window(
    input: &Path,
    window: (f64, f64),
    level: Option<u32>,
    offset: [u32; 3],
    out: &Path,
) -> CliResult {
    let volume = Volume::read(input).map_err(CliError::caused)?;
    let level = level.unwrap_or_else(|| fitting_level(&volume, offset));
    let runs = volume
        .to_window_runs(level, offset, window.0, window.1)
        .map_err(|e| CliError::in_file(input, e))?;
    let tree = KTree::from_value_runs(&runs);
    write_valued_ktree_file(out, &tree).map_err(CliError::caused)?;
    outln!(
        "{}: {} voxels from {} to {} kept as float32, L = {level}, {} nodes",
        out.display(),
        tree.voxel_count(),
        window.0,
        window.1,
        tree.node_count()
    );
    Ok(())
}

/// The smallest level whose universe holds `volume` placed at `offset`.
pub fn fitting_level(volume: &Volume, offset: [u32; 3]) -> u32 {
    let fits = [0, 1, 2].map(|a| offset[a] as usize + volume.shape()[a]);
    let m = fits.into_iter().max().unwrap_or(1).max(1);
    m.next_power_of_two().trailing_zeros()
}

/// A window `LO:HI` of two numbers.
pub fn parse_window(text: &str) -> Result<(f64, f64), String> {
    let (lo, hi) = text
        .split_once(':')
        .ok_or_else(|| format!("'{text}': expected LO:HI"))?;
    let number = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{t}' in '{text}' is not a number"))
    };
    let (lo, hi) = (number(lo)?, number(hi)?);
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(format!("'{text}': LO and HI are finite and LO ≤ HI"));
    }
    Ok((lo, hi))
}
