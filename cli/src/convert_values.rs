//! `ktree convert` of a tree with values (a version 3 `.ktree`) and `ktree voxelize VOLUME --window LO:HI`:
//! the values go to a NIfTI volume (`.nii`, `.nii.gz`: labels, densities or colours as its samples), to an
//! OpenVDB typed grid (`.vdb`: `Int32Grid`, `FloatGrid`, `Vec3SGrid`), to VTK files for ParaView (`.vtu`,
//! `.htg`: the values as the cell data `value`), to the surfaces of its values with their colours (`.ply`,
//! `.obj`, `.glb`) or to another `.ktree`, each placed by the file's world frame unless `--voxel-size` or
//! `--origin` say otherwise; an OpenVDB typed grid comes in as a valued `.ktree`; a volume's window of
//! intensities comes in as `float32` values.

use std::path::Path;

use ktree::export::vtk::write_values_time_slices;
use ktree::io::ktree::v3::read_valued_ktree_noted;
use ktree::io::ktree::Notes;
use ktree::io::{read_vdb_values, write_valued_tree, WriteOptions, WrittenValues};
use ktree::solid::volume_file::{window_slabs, VolumeFile};
use ktree::space::WorldFrame;
use ktree::tree::AnyValuedTree;
use ktree::value::Value;
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

/// Converts the valued tree in `input` to `output` (`.nii`, `.nii.gz`, `.vdb`, `.vtu`, `.htg`, `.ply`,
/// `.obj`, `.glb` or `.ktree`: see [`write_valued_tree`]), placed by `placement`, the rest as the input's
/// world frame places it; a `.ktree` keeps the input's notes (its labels' names).
pub fn convert_valued(input: &Path, output: &Path, placement: Placement) -> CliResult {
    let (k, dtype) = crate::values::file_dtype(input)?;
    let dtype = dtype.ok_or_else(|| format!("{}: the tree holds no values", input.display()))?;
    let (tree, kept, notes) = ktree::with_valued!(k, dtype, KK, V => {
        let (tree, kept, notes) = read_noted::<KK, V>(input)?;
        (AnyValuedTree::from(tree), kept, notes)
    }, else return Err(format!("{}: K = {k} is not 1 to 4", input.display()).into()));
    // The frame is kept, or given; a tree without one stays without (in a `.ktree`).
    let given = placement.voxel_size.is_some() || placement.origin.is_some();
    let frame = (kept.is_some() || given).then(|| placement.frame(kept));
    write_and_report(output, &tree, frame, notes)
}

/// The valued tree of a `.ktree` file, the world frame it keeps and its notes.
pub fn read_noted<const K: usize, V: Value>(
    input: &Path,
) -> CliResult<(KTree<K, V>, Option<WorldFrame>, Notes)> {
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    read_valued_ktree_noted::<K, V>(&bytes, &input.display().to_string()).map_err(CliError::caused)
}

/// Writes `tree` to `output` (ktree voxel 0 at `frame`'s origin; a `.ktree` with `notes`) and says what
/// was written.
fn write_and_report(
    output: &Path,
    tree: &AnyValuedTree,
    frame: Option<WorldFrame>,
    notes: Notes,
) -> CliResult {
    let options = WriteOptions {
        offset: [0; 3],
        meta: frame,
        notes,
    };
    let written = write_valued_tree(output, tree, &options).map_err(CliError::caused)?;
    let dtype = tree.dtype().name();
    match written {
        WrittenValues::Surfaces { surfaces, written } => outln!(
            "{}: the surfaces of {surfaces} {dtype} values, {} vertices, {} triangles",
            output.display(),
            written.vertices,
            written.elements
        ),
        WrittenValues::Voxels => outln!(
            "{}: K = {}, L = {}, {dtype} values, {} nodes, {} voxels",
            output.display(),
            tree.k(),
            tree.level(),
            ktree::with_valued!(tree, t => t.node_count()),
            ktree::with_valued!(tree, t => t.voxel_count())
        ),
    }
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
        let (tree, kept, _) = read_noted::<4, V>(input)?;
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

/// `ktree convert IN.vdb OUT` of a grid with values (not a `BoolGrid`, `MaskGrid` or level set): its
/// active voxels, placed by `level` and `offset` (ktree voxel = grid index + offset; by default those the
/// file was written with, else the smallest universe from 0), written with the grid's world frame to any
/// output that keeps values (see [`write_valued_tree`]).
pub fn vdb_to_valued(
    input: &Path,
    output: &Path,
    level: Option<u32>,
    offset: Option<[i64; 3]>,
) -> CliResult {
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    let read = read_vdb_values(&bytes, &input.display().to_string(), offset, level)
        .map_err(CliError::caused)?;
    outln!(
        "{}: grid index + {:?} = ktree voxel",
        input.display(),
        read.placement.offset
    );
    // The grid's world placement, counted from ktree voxel 0.
    let frame = read.meta.counted_from(read.placement.offset.map(|o| -o));
    write_and_report(output, &read.tree, Some(frame), Notes::new())
}

/// `ktree voxelize VOLUME --window LO:HI`: the samples from `lo` to `hi` kept as `float32` values, the
/// volume read slab by slab along z and the tree written out of core.
pub fn voxelize_window(
    input: &Path,
    window: (f64, f64),
    level: Option<u32>,
    offset: [u32; 3],
    out: &Path,
    build: &crate::common::memory::BuildArgs,
) -> CliResult {
    let shape = VolumeFile::open(input).map_err(CliError::caused)?.shape();
    let level = level.unwrap_or_else(|| fitting_level(shape, offset));
    let slabs = window_slabs(input, level, offset, window.0, window.1)
        .map_err(|e| CliError::in_file(input, e))?;
    let Some(written) = crate::values::write_volume_slabs(input, level, slabs, build, out)? else {
        return Ok(());
    };
    outln!(
        "{}: {} voxels from {} to {} kept as float32, L = {level}, {} nodes",
        out.display(),
        written.voxels,
        window.0,
        window.1,
        written.nodes
    );
    Ok(())
}

/// The smallest level whose universe holds a volume of `shape` samples placed at `offset`.
pub fn fitting_level(shape: [usize; 3], offset: [u32; 3]) -> u32 {
    let fits = [0, 1, 2].map(|a| offset[a] as usize + shape[a]);
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
