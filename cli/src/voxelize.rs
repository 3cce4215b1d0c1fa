//! `ktree voxelize MESH|VOLUME --level L (--fit | --transform s,tx,ty,tz) --out FILE`: a triangle mesh (OBJ,
//! STL, PLY) or a volume (raw + JSON sidecar, NIfTI) to rays or a tree.
//!
//! `ktree voxelize CLOUD --voxel-size S [--origin x,y,z] [--level L] [--min-points N] [--crop] --out FILE`: a
//! point cloud (PLY without faces, PCD, XYZ/CSV, LAS/LAZ) to the voxels holding at least N points;
//! with `--value rgb|intensity|class|count [--reduce mean|max]`, a tree whose voxels hold a value reduced
//! from their points' (a `.ktree` output).

use crate::common::error::{chain, CliError, CliResult};
use crate::outln;

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use crate::values::write_runs;
use ktree::input::{voxel_source, voxelize, VoxelSource};
use ktree::io::ktree::notes::label_note;
use ktree::io::ktree::Notes;
use ktree::io::{Format, ReadOptions};
use ktree::rays::{RaySource, SlabRuns};
use ktree::solid::mesh::MeshTransform;
use ktree::space::WorldFrame;
use ktree::Universe;

use crate::common::output::{is_tree_file, write_output, TreeOutput};
use crate::common::vector::vector;

/// Arguments of `ktree voxelize`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input: a mesh (.obj, .stl, .ply), a volume (.json sidecar or its .raw, .nii, .nii.gz) or a point
    /// cloud (.ply without faces, .pcd, .xyz, .csv, .txt, .las, .laz).
    input: PathBuf,
    /// With --labels: more meshes (.obj, .stl, .ply), voxelized with the first into one tree of labels,
    /// each file one label in the order given.
    #[arg(value_name = "MESH")]
    more: Vec<PathBuf>,
    /// Universe level L (meshes: required; volumes and clouds: default the smallest level that holds them).
    #[arg(long)]
    level: Option<u32>,
    /// Mesh: scale uniformly and centre into the universe with a one-voxel margin (prints the transform).
    #[arg(long, conflicts_with = "transform")]
    fit: bool,
    /// Mesh: voxel coordinate = s·v + t, given as s,tx,ty,tz.
    #[arg(long, value_name = "S,TX,TY,TZ", allow_hyphen_values = true, value_parser = MeshTransform::parse)]
    transform: Option<MeshTransform>,
    #[command(flatten)]
    volume: crate::common::args::VolumeArgs,
    /// Volume: every sample's label kept, 0 the background; meshes: each mesh one label (1, 2, … in the
    /// order given; one .obj file: each of its groups or objects), the later mesh winning where they
    /// overlap, placed together by --fit or --transform. A tree with values (a .ktree output).
    #[arg(long, conflicts_with_all = ["threshold", "label"])]
    labels: bool,
    /// Volume: the samples from LO to HI (both included) kept as float32 values, the rest the
    /// background: a tree with values (a .ktree output).
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true,
          value_parser = crate::convert_values::parse_window,
          conflicts_with_all = ["threshold", "label", "labels"])]
    window: Option<(f64, f64)>,
    /// With --labels: the label type, uint8, uint16 or uint32 (default: the smallest that holds them).
    #[arg(long, requires = "labels")]
    dtype: Option<String>,
    /// Volume: where the volume's sample (0, 0, 0) goes in the universe, as x,y,z.
    #[arg(long, default_value = "0,0,0", value_name = "X,Y,Z", allow_hyphen_values = true,
          value_parser = vector::<u32, 3>)]
    offset: [u32; 3],
    /// Point cloud: the side of a voxel; a point p is in voxel floor((p - origin) / S).
    #[arg(long)]
    voxel_size: Option<f64>,
    /// Point cloud: the corner of voxel (0, 0, 0), as x,y,z (default: the minimum corner of the points).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<f64, 3>)]
    origin: Option<[f64; 3]>,
    /// Point cloud: the points a voxel must hold to be full.
    #[arg(long, default_value_t = 1)]
    min_points: u64,
    /// Point cloud with --level: drop the points outside the universe (default: they are an error).
    #[arg(long)]
    crop: bool,
    /// Point cloud: each voxel holds a value from its points (a .ktree output): rgb (their mean colour),
    /// intensity (their mean or largest, float32: --reduce), class (the most frequent, ties to the
    /// smallest; uint8) or count (how many, uint32).
    #[arg(long, value_enum)]
    value: Option<crate::values::CloudValue>,
    /// With --value intensity: mean or max.
    #[arg(long, value_enum, requires = "value")]
    reduce: Option<crate::values::Reduce>,
    #[command(flatten)]
    out: crate::common::args::RaysOrTreeOut,
    #[command(flatten)]
    build: crate::common::memory::BuildArgs,
}

/// Voxelizes the input and writes it.
pub fn run(a: Args) -> CliResult {
    if !a.more.is_empty() || (a.labels && Format::of(&a.input) == Some(Format::Mesh)) {
        return run_mesh_labels(&a);
    }
    // A `.ply` is a cloud or a mesh by its header: a broken one is said as such.
    if ktree::io::is_cloud_file(&a.input).map_err(CliError::caused)? {
        return run_cloud(&a);
    }
    if a.voxel_size.is_some() || a.origin.is_some() || a.crop || a.value.is_some() {
        return Err(format!(
            "{}: --voxel-size, --origin, --crop and --value are for point clouds (.ply without faces, .pcd, .xyz, .csv, .txt, .las, .laz)",
            a.input.display()
        )
        .into());
    }
    let mut options = ReadOptions {
        level: a.level,
        ..ReadOptions::default()
    };
    if Format::of(&a.input) == Some(Format::Mesh) {
        if a.level.is_none() {
            return Err("--level L is required for a mesh".into());
        }
        options.mesh_placement = match (a.transform, a.fit) {
            (Some(t), _) => Some(t),
            (None, true) => None,
            (None, false) => return Err("a mesh needs --fit or --transform s,tx,ty,tz".into()),
        };
    } else {
        if (a.labels || a.window.is_some()) && !is_tree_file(&a.out.out) {
            return Err(format!(
                "--{} writes a tree with values: the output must be a .ktree, not {}",
                if a.labels { "labels" } else { "window" },
                a.out.out.display()
            )
            .into());
        }
        if let Some(window) = a.window {
            return crate::convert_values::voxelize_window(
                &a.input, window, a.level, a.offset, &a.out.out, &a.build,
            );
        }
        if a.labels {
            return crate::values::voxelize_labels(
                &a.input,
                a.level,
                a.offset,
                a.dtype.as_deref(),
                &a.out.out,
                &a.build,
            );
        }
        options.select = Some(
            a.volume
                .select()
                .ok_or("a volume needs --threshold T or --label V")?,
        );
        options.offset = Some(a.offset.map(i64::from));
    }
    // In a run over several MPI ranks, rank 0 alone reports.
    let root = crate::distributed::ranks().is_root();
    if is_tree_file(&a.out.out) && crate::distributed::ranks().size == 1 {
        // Straight to a tree: the rays are made slab by slab as the cells are stacked, never held whole.
        // (Across MPI ranks, every rank makes the rays whole and keeps its slabs: `write_output`.)
        let v = voxel_source(&a.input, &options).map_err(CliError::caused)?;
        remarks(&a.input, v.fitted.as_deref(), v.open_edges, root)?;
        outln!("{}", build_out_of_core(&v.source, &a)?);
        return Ok(());
    }
    let v = voxelize(&a.input, &options).map_err(CliError::caused)?;
    remarks(&a.input, v.fitted.as_deref(), v.open_edges, root)?;
    let written = write_output(&v.rays, &a.out.out, &a.build, mesh_frame(&a))?;
    crate::common::output::print_summary(&written)?;
    Ok(())
}

/// Voxelizes meshes together into one tree of labels, prints each label's name and writes the tree
/// (with the world frame of the placement when its scale is positive).
fn run_mesh_labels(a: &Args) -> CliResult {
    let inputs: Vec<&Path> = std::iter::once(&a.input)
        .chain(&a.more)
        .map(PathBuf::as_path)
        .collect();
    if !a.labels {
        return Err(format!(
            "{}: several inputs are voxelized together only as labels (--labels: each mesh one label)",
            a.more[0].display()
        )
        .into());
    }
    if let Some(other) = inputs.iter().find(|p| Format::of(p) != Some(Format::Mesh)) {
        return Err(format!(
            "{}: not a mesh: --labels over several inputs takes meshes (.obj, .stl, .ply); a label volume is given alone",
            other.display()
        )
        .into());
    }
    if a.voxel_size.is_some() || a.origin.is_some() || a.crop || a.value.is_some() {
        return Err(format!(
            "{}: --voxel-size, --origin, --crop and --value are for point clouds, not mesh labels",
            a.input.display()
        )
        .into());
    }
    if a.dtype.is_some() {
        return Err(
            "--dtype is for label volumes: mesh labels are uint8 up to 255 meshes, uint16 beyond"
                .into(),
        );
    }
    if !is_tree_file(&a.out.out) {
        return Err(format!(
            "--labels writes a tree with values: the output must be a .ktree, not {}",
            a.out.out.display()
        )
        .into());
    }
    let level = a.level.ok_or("--level L is required for a mesh")?;
    let mesh_placement = match (a.transform, a.fit) {
        (Some(t), _) => Some(t),
        (None, true) => None,
        (None, false) => return Err("a mesh needs --fit or --transform s,tx,ty,tz".into()),
    };
    let options = ReadOptions {
        level: Some(level),
        mesh_placement,
        ..ReadOptions::default()
    };
    // The meshes ray cast into runs of labels, their tree written out of core (over MPI ranks, every
    // rank casts them and builds its own slabs; rank 0 alone writes and reports).
    let labels = ktree::input::mesh_label_runs(&inputs, &options).map_err(CliError::caused)?;
    let root = crate::distributed::ranks().is_root();
    if let Some(t) = labels.fitted.as_ref().filter(|_| root) {
        outln!("--fit chose --transform {t}");
    }
    for (i, (name, voxels)) in labels.names.iter().zip(&labels.voxels).enumerate() {
        if root {
            outln!("label {}: {name} ({voxels} voxels)", i + 1);
        }
    }
    let frame = labels.transform.world_frame();
    // Each label's name kept in the file (`ktree stats` prints them).
    let notes: Notes = labels
        .names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            (
                label_note(&(i + 1).to_string()),
                name.replace(['\n', '\r'], " "),
            )
        })
        .collect();
    use ktree::input::LabelRuns;
    let (out, frame) = (&a.out.out, frame.as_ref());
    let (report, dtype) = match &labels.tree {
        LabelRuns::U8(runs) => (write_runs(runs, &a.build, out, frame, &notes)?, "uint8"),
        LabelRuns::U16(runs) => (write_runs(runs, &a.build, out, frame, &notes)?, "uint16"),
        LabelRuns::U32(runs) => (write_runs(runs, &a.build, out, frame, &notes)?, "uint32"),
    };
    let Some(report) = report else {
        return Ok(());
    };
    let nodes: u64 = report
        .counts_per_level
        .iter()
        .map(|c| c.empty + c.full + c.partial)
        .sum();
    let voxels: u64 = labels.voxels.iter().sum();
    let used = labels.voxels.iter().filter(|&&v| v > 0).count();
    outln!(
        "{}: {voxels} voxels labelled with {used} of {} labels ({dtype}), L = {level}, {nodes} nodes",
        out.display(),
        labels.names.len(),
    );
    Ok(())
}

/// Voxelizes a point cloud and writes it.
fn run_cloud(a: &Args) -> CliResult {
    use ktree::solid::cloud::CloudVoxelizer;
    let size = a
        .voxel_size
        .ok_or_else(|| format!("{}: a point cloud needs --voxel-size S", a.input.display()))?;
    let mut v = CloudVoxelizer::new(size)
        .map_err(|e| CliError::about("--voxel-size", e))?
        .min_points(a.min_points)
        .crop(a.crop);
    if a.crop && a.level.is_none() {
        return Err("--crop needs --level L (without it the universe holds every point)".into());
    }
    if let Some(o) = a.origin {
        v = v.origin(o);
    }
    if let Some(l) = a.level {
        v = v.level(l);
    }
    if a.value.is_some() && !is_tree_file(&a.out.out) {
        return Err(format!(
            "--value writes a tree with values: the output must be a .ktree, not {}",
            a.out.out.display()
        )
        .into());
    }
    let cloud = ktree::io::read_cloud(&a.input).map_err(CliError::caused)?;
    if let Some(value) = a.value {
        return crate::values::voxelize_cloud_values(
            &a.input,
            &cloud,
            &v,
            (value, a.reduce),
            &a.out.out,
            &a.build,
        );
    }
    let voxels = v
        .voxelize(cloud.points())
        .map_err(|e| cloud_error(&a.input, e))?;
    let root = crate::distributed::ranks().is_root();
    if root {
        let o = voxels.origin;
        let chosen = if a.origin.is_none() {
            " (the minimum corner of the points)"
        } else {
            ""
        };
        outln!(
            "{}: {} points, origin {},{},{}{chosen}, level {}, {} voxels with at least {} point{}{}",
            a.input.display(),
            cloud.len(),
            o[0],
            o[1],
            o[2],
            voxels.rays.level(),
            voxels.rays.voxel_count(),
            a.min_points.max(1),
            if a.min_points > 1 { "s" } else { "" },
            if voxels.cropped > 0 {
                format!(", {} points outside the universe dropped", voxels.cropped)
            } else {
                String::new()
            }
        );
    }
    // Voxel (0, 0, 0) has its lower corner at the origin.
    let frame = WorldFrame {
        voxel_size: size,
        origin: voxels.origin,
    };
    let written = write_output(&voxels.rays, &a.out.out, &a.build, Some(frame))?;
    crate::common::output::print_summary(&written)?;
    Ok(())
}

/// A voxelizer's error on the cloud `input`, with a hint of the flags that avoid it.
pub(crate) fn cloud_error(input: &Path, e: ktree::solid::SolidError) -> CliError {
    use ktree::solid::SolidError;
    let hint = match e {
        SolidError::PointsOutside { .. } => {
            ": use a larger --level or --voxel-size, another --origin, or --crop to drop them"
        }
        SolidError::PointBelowOrigin { .. } => {
            ": give --level and --crop to drop such points, or another --origin"
        }
        _ => return CliError::in_file(input, e),
    };
    CliError::Failed(format!("{}: {}{hint}", input.display(), chain(&e)))
}

/// Prints the transform `--fit` chose and warns about a mesh that is not closed (`root`: this process
/// reports).
fn remarks(input: &Path, fitted: Option<&str>, open_edges: usize, root: bool) -> CliResult {
    if let (Some(t), true) = (fitted, root) {
        outln!("--fit chose --transform {t}");
    }
    if open_edges > 0 && root {
        eprintln!(
            "warning: {}: the mesh is not closed ({open_edges} edges not shared by exactly two triangles); \
             inside is decided by the winding along each column, so some columns may leak or lose runs",
            input.display(),
        );
    }
    Ok(())
}

/// Where a mesh's voxels are in the world, when `--transform` places it (scale `s` > 0: voxels of
/// `1 / s`); a mesh fitted into the universe keeps none.
fn mesh_frame(a: &Args) -> Option<WorldFrame> {
    let mesh = Format::of(&a.input) == Some(Format::Mesh);
    a.transform.filter(|_| mesh).and_then(|t| t.world_frame())
}

/// Stacks the source straight into the output, out of core, in the budget less what the source holds;
/// returns the summary (the one [`write_output`] prints for a tree).
fn build_out_of_core(source: &VoxelSource, a: &Args) -> CliResult<String> {
    let what = match source {
        VoxelSource::Mesh(_) => format!("the placed triangles of {}", a.input.display()),
        VoxelSource::Volume(_) => format!("the samples of {}", a.input.display()),
    };
    let counted = CountedRuns::new(source);
    let held = (what.as_str(), source.heap_bytes());
    let built = TreeOutput::new(&a.out.out, &a.build)
        .framed(mesh_frame(a))
        .write(&counted, Some(held))?;
    Ok(built
        .map(|b| b.summary(Some(counted.runs())))
        .unwrap_or_default())
}

/// A source that counts the runs of its slabs as they are made (a slab made twice is counted once).
struct CountedRuns<'a, S> {
    source: &'a S,
    /// The runs of each slab made, by its first column along axis 0.
    runs: Mutex<BTreeMap<u32, u64>>,
}

impl<'a, S> CountedRuns<'a, S> {
    fn new(source: &'a S) -> Self {
        Self {
            source,
            runs: Mutex::new(BTreeMap::new()),
        }
    }

    /// The runs of the slabs made.
    fn runs(&self) -> u64 {
        let runs = self.runs.lock().unwrap_or_else(PoisonError::into_inner);
        runs.values().sum()
    }
}

impl<S: RaySource<3>> RaySource<3> for CountedRuns<'_, S> {
    type Error = S::Error;

    fn universe(&self) -> Universe<3> {
        self.source.universe()
    }

    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, S::Error> {
        let slab = self.source.slab(x.clone())?;
        let mut runs = self.runs.lock().unwrap_or_else(PoisonError::into_inner);
        runs.insert(x.start, slab.runs.len() as u64);
        Ok(slab)
    }

    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        self.source.occupied_slabs(m)
    }
}
