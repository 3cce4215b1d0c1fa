//! `ktree convert` of a tree with values (a version 3 `.ktree`) and `ktree voxelize VOLUME --window LO:HI`:
//! the values go to a NIfTI volume (`.nii`, `.nii.gz`: labels, densities or colours as its samples), to an
//! OpenVDB typed grid (`.vdb`: `Int32Grid`, `FloatGrid`, `Vec3SGrid`), to VTK files for ParaView (`.vtu`,
//! `.htg`: the values as the cell data `value`) or to another `.ktree`; an OpenVDB typed grid comes in as a
//! valued `.ktree`; a volume's window of intensities comes in as `float32` values.

use std::path::Path;

use ktree::export::vtk::{write_values_time_slices, write_values_vtk_file};
use ktree::io::ktree::v3::{read_valued_ktree, read_valued_ktree_framed, write_valued_ktree_file};
use ktree::io::{read_vdb_values, write_nifti_file, write_vdb_values};
use ktree::solid::volume::Volume;
use ktree::space::WorldFrame;
use ktree::value::{Dtype, Value};
use ktree::KTree;

use crate::common::error::{cannot_read, CliError, CliResult};
use crate::outln;

/// Where `--voxel-size` and `--origin` place the output: given, or (VTK files) the input's world frame,
/// else voxels of 1 from 0.
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

/// Converts the valued tree in `input` to `output` (`.nii`, `.nii.gz`, `.vdb`, `.vtu`, `.htg` or `.ktree`),
/// placed by `placement` (VTK files: the rest as the input's world frame places it).
pub fn convert_valued(input: &Path, output: &Path, placement: Placement) -> CliResult {
    let (k, dtype) = crate::values::file_dtype(input)?;
    let dtype = dtype.ok_or_else(|| format!("{}: the tree holds no values", input.display()))?;
    let name = output.to_string_lossy();
    let nifti = name.ends_with(".nii") || name.ends_with(".nii.gz");
    let ktree = name.ends_with(".ktree");
    let vdb = name.ends_with(".vdb");
    let vtk = name.ends_with(".vtu") || name.ends_with(".htg");
    if vtk {
        if k != 2 && k != 3 {
            return Err(format!(
                "{}: VTK files hold quadtrees and octrees (K = 2, 3); {} has K = {k}",
                output.display(),
                input.display()
            )
            .into());
        }
        return ktree::with_valued!(k, dtype, KK, V => write_vtk::<KK, V>(input, output, placement),
            else Err(format!("{}: K = {k} is not 1 to 4", input.display()).into()));
    }
    let frame = &placement.frame(None);
    if !(nifti || ktree || vdb) {
        return Err(format!(
            "{}: a tree with values ({}) converts to NIfTI (.nii, .nii.gz), OpenVDB (.vdb), VTK (.vtu, .htg) \
             or .ktree",
            output.display(),
            dtype.name()
        )
        .into());
    }
    if (nifti || vdb) && k != 3 {
        return Err(format!(
            "{}: NIfTI volumes and OpenVDB grids hold octrees (K = 3); {} has K = {k}",
            output.display(),
            input.display()
        )
        .into());
    }
    ktree::with_valued!(k, dtype, KK, V => {
        if KK == 3 {
            return write_octree::<V>(input, output, frame);
        }
        // Any other K: a .ktree to a .ktree is a checked copy.
        let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
        ktree::fs::write_atomic(output, &bytes).map_err(CliError::caused)?;
        outln!("{}: copied (K = {k}, {})", output.display(), dtype.name());
        Ok(())
    }, else Err(format!("{}: K = {k} is not 1 to 4", input.display()).into()))
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
    let name = input.display().to_string();
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    let files = ktree::with_valued!(4, dtype, KK, V => {
        let (tree, kept) =
            read_valued_ktree_framed::<4, V>(&bytes, &name).map_err(CliError::caused)?;
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

/// The valued tree of `input` as a VTK file, `value` its cell data.
fn write_vtk<const K: usize, V: Value>(
    input: &Path,
    output: &Path,
    placement: Placement,
) -> CliResult {
    let name = input.display().to_string();
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    let (tree, kept) = read_valued_ktree_framed::<K, V>(&bytes, &name).map_err(CliError::caused)?;
    write_values_vtk_file(output, &tree, &placement.frame(kept)).map_err(CliError::caused)?;
    outln!(
        "{}: K = {K}, L = {}, {} values as cell data, {} nodes, {} voxels",
        output.display(),
        tree.level(),
        V::DTYPE.map_or("", Dtype::name),
        tree.node_count(),
        tree.voxel_count()
    );
    Ok(())
}

fn write_octree<V: Value>(input: &Path, output: &Path, frame: &WorldFrame) -> CliResult {
    let name = input.display().to_string();
    let bytes = std::fs::read(input).map_err(|e| cannot_read(input, e))?;
    let tree = read_valued_ktree::<3, V>(&bytes, &name).map_err(CliError::caused)?;
    if output.extension().is_some_and(|e| e == "ktree") {
        write_valued_ktree_file(output, &tree).map_err(CliError::caused)?;
    } else if output.extension().is_some_and(|e| e == "vdb") {
        ktree::fs::write_atomic_with(output, |w| write_vdb_values(w, &tree, [0; 3], frame))
            .map_err(CliError::caused)?;
    } else {
        write_nifti_file(output, &tree, frame).map_err(CliError::caused)?;
    }
    outln!(
        "{}: K = 3, L = {}, {} values, {} nodes, {} voxels",
        output.display(),
        tree.level(),
        V::DTYPE.map_or("", Dtype::name),
        tree.node_count(),
        tree.voxel_count()
    );
    Ok(())
}

/// `ktree convert IN.vdb OUT.ktree` of a grid with values (not a `BoolGrid`, `MaskGrid` or level set):
/// a valued `.ktree` of its active voxels, placed by `level` and `offset` (ktree voxel = grid index +
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
    ktree::with_valued!(&read.tree, t => write_valued_ktree_file(output, t))
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
