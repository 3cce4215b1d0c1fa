//! Trees with values on the command line: `ktree voxelize VOLUME --labels` (a label volume into one valued
//! tree), `ktree voxelize CLOUD --value rgb|intensity|class|count` (a point cloud's voxels holding a value
//! reduced from their points'), `ktree select FILE --value V | --range LO:HI --out OUT` (the voxels of a value or a range, as a
//! tree without values) and the per-value statistics of `ktree stats` on a valued file.
//!
//! A valued `.ktree` (version 3) carries its dimension and value type; each command reads them from the
//! header and runs the same generic code for every `K` and type (`ktree::with_valued!` on the
//! `ktree::AnyValuedTree` read).

use std::path::{Path, PathBuf};

use ktree::io::ktree::notes::label_note;
use ktree::io::ktree::v3::{read_any_ktree_framed, valued_header, AnyKtree, MappedValuedTree};
use ktree::io::ktree::Notes;
use ktree::query::{stats, TreeStats};
use ktree::rays::ValueRuns;
use ktree::solid::cloud::{self, CloudVoxelizer, PointCloud};
use ktree::solid::volume_file::{label_slabs, SampleRule, VolumeFile, VolumeSlabs};
use ktree::solid::SolidError;
use ktree::space::WorldFrame;
use ktree::stacking::{BuildError, ValueSlabs, ValueSlabsReport};
use ktree::tree::valued::ValueLeaves;
use ktree::value::{Dtype, Value};
use ktree::{with_valued, AnyValuedTree, KTree};

use crate::common::error::{cannot_read, CliError, CliResult};
use crate::common::memory::BuildArgs;
use crate::common::tree_file::frame_text;
use crate::outln;

/// The dimension and value type of a `.ktree` file (`None`: no values).
pub fn file_dtype(path: &Path) -> CliResult<(usize, Option<Dtype>)> {
    let mut head = [0u8; 16];
    let read = std::fs::File::open(path).and_then(|mut f| {
        use std::io::Read;
        let mut n = 0;
        while n < head.len() {
            match f.read(&mut head[n..])? {
                0 => break,
                m => n += m,
            }
        }
        Ok(n)
    });
    let n = read.map_err(|e| cannot_read(path, e))?;
    let (k, _, dtype) =
        valued_header(&head[..n], &path.display().to_string()).map_err(CliError::caused)?;
    Ok((k, dtype))
}

/// Whether `path` names a `.ktree` file that holds values.
pub fn is_valued(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "ktree") && matches!(file_dtype(path), Ok((_, Some(_))))
}

/// A valued `.ktree` file's tree, of the dimension and value type its header names.
pub fn read_valued(path: &Path) -> CliResult<AnyValuedTree> {
    read_valued_noted(path).map(|(tree, _)| tree)
}

/// [`read_valued`] with the file's notes (its labels' names).
fn read_valued_noted(path: &Path) -> CliResult<(AnyValuedTree, Notes)> {
    read_valued_framed(path).map(|(tree, _, notes)| (tree, notes))
}

/// [`read_valued`] with where its voxels are in the world, if the file says, and its notes.
fn read_valued_framed(path: &Path) -> CliResult<(AnyValuedTree, Option<WorldFrame>, Notes)> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| cannot_read(path, e))?;
    match read_any_ktree_framed(&bytes, &name).map_err(CliError::caused)? {
        (AnyKtree::Valued(tree), frame, notes) => Ok((tree, frame, notes)),
        (AnyKtree::Binary(..), ..) => Err(format!(
            "{name}: the tree holds no values (this takes a tree made with values, e.g. voxelize --labels)"
        )
        .into()),
    }
}

/// The values held at once while a volume is read: slabs of up to 64 MiB of values, and at most a
/// quarter of `--max-memory`.
const SLAB_BYTES: u64 = 64 << 20;

/// What [`write_volume_slabs`] wrote: the tree's voxels and nodes.
pub struct WrittenTree {
    pub voxels: u128,
    pub nodes: u64,
}

/// Writes the tree of a volume read slab by slab (at most 64 MiB of values at once, and a quarter of
/// `--max-memory`) to the `.ktree` file `out`, its cells' subtrees spilled next to it (or in
/// `--temp-dir`) as they are built: the tree is never held whole. Started over MPI ranks, each rank reads its own share of the planes and rank 0 writes the file
/// (the same bytes). Errors of the volume name `input`; those of the files, the file. `None` on the ranks
/// other than 0, which neither write nor print.
pub fn write_volume_slabs<V, R>(
    input: &Path,
    level: u32,
    mut slabs: VolumeSlabs<V, R>,
    build: &BuildArgs,
    out: &Path,
) -> CliResult<Option<WrittenTree>>
where
    V: Value + Send + Sync,
    R: SampleRule<V>,
{
    let box_slabs = ValueSlabs {
        level,
        region: slabs.region.clone(),
        background: slabs.background,
        slab_bytes: (build.budget.budget() / 4).min(SLAB_BYTES) as usize,
    };
    let temp_dir = build.temp_dir.as_deref();
    let read = |planes, values: &mut Vec<V>| slabs.read(planes, values);
    #[cfg(feature = "mpi")]
    let report = if crate::distributed::ranks().size > 1 {
        crate::distributed::build_values_across_ranks(
            box_slabs.slabs_in_box(),
            out,
            None,
            &Notes::new(),
            |mine| {
                box_slabs
                    .stack_part_files(mine, out, temp_dir, read)
                    .map_err(|e| build_error(input, out, e))
            },
        )?
    } else {
        Some(write_file(&box_slabs, input, out, temp_dir, read)?)
    };
    #[cfg(not(feature = "mpi"))]
    let report = Some(write_file(&box_slabs, input, out, temp_dir, read)?);
    Ok(report.map(|report| {
        let counts = &report.counts_per_level;
        WrittenTree {
            voxels: counts
                .iter()
                .map(|c| u128::from(c.full) << (3 * (level - c.level)))
                .sum(),
            nodes: counts.iter().map(|c| c.full + c.empty + c.partial).sum(),
        }
    }))
}

/// [`ValueSlabs::write_file`] of `slabs` read by `read` (from `input`) into `out`, in this process.
fn write_file<V: Value + Send + Sync>(
    slabs: &ValueSlabs<3, V>,
    input: &Path,
    out: &Path,
    temp_dir: Option<&Path>,
    read: impl FnMut(std::ops::Range<u32>, &mut Vec<V>) -> Result<(), SolidError>,
) -> CliResult<ValueSlabsReport> {
    slabs
        .write_file(out, temp_dir, None, &Notes::new(), read)
        .map_err(|e| build_error(input, out, e))
}

/// The error of a build from `input` into `out`: the source's names `input`; the files', the file.
fn build_error<E: std::error::Error + Send + Sync + 'static>(
    input: &Path,
    out: &Path,
    e: BuildError<E>,
) -> CliError {
    match e {
        BuildError::Source(e) => CliError::in_file(input, e),
        other => crate::common::output::describe(out, other, 0),
    }
}

/// Writes the tree of `runs` to the `.ktree` file `out` (with `frame` and `notes`) out of core: its
/// cells built slab by slab and spilled next to it (or in `--temp-dir`), the tree never held whole.
/// Started over MPI ranks (each holding the runs), each rank builds its own slabs and rank 0 writes the
/// file (the same bytes). The report on rank 0; `None` on the others, which neither write nor print.
pub fn write_runs<V: Value + Send + Sync>(
    runs: &ValueRuns<3, V>,
    build: &BuildArgs,
    out: &Path,
    frame: Option<&WorldFrame>,
    notes: &Notes,
) -> CliResult<Option<ValueSlabsReport>> {
    let temp_dir = build.temp_dir.as_deref();
    let depth = runs.default_cell_depth();
    #[cfg(feature = "mpi")]
    if crate::distributed::ranks().size > 1 {
        return crate::distributed::build_values_across_ranks(
            0..1 << depth,
            out,
            frame,
            notes,
            |mine| {
                runs.stack_part_files(depth, mine, out, temp_dir)
                    .map_err(|e| crate::common::output::describe(out, e, 0))
            },
        );
    }
    let report = runs
        .write_file(out, temp_dir, frame, notes, depth)
        .map_err(|e| crate::common::output::describe(out, e, 0))?;
    Ok(Some(report))
}

/// A label volume into a valued tree of the smallest label type that holds it (or `dtype`), read slab by
/// slab along z and written out of core: neither the volume nor the tree is held whole, so one larger
/// than memory is voxelized.
pub fn voxelize_labels(
    input: &Path,
    level: Option<u32>,
    offset: [u32; 3],
    dtype: Option<&str>,
    out: &Path,
    options: &BuildArgs,
) -> CliResult {
    let file = VolumeFile::open(input).map_err(CliError::caused)?;
    let shape = file.shape();
    let dtype = match dtype {
        // A first pass over the file finds the smallest type that holds every label.
        None => file
            .label_dtype()
            .map_err(|e| CliError::in_file(input, e))?,
        Some(name) => match Dtype::parse(name) {
            Some(d @ (Dtype::U8 | Dtype::U16 | Dtype::U32)) => d,
            _ => {
                return Err(format!("--dtype '{name}': labels are uint8, uint16 or uint32").into())
            }
        },
    };
    let level = level.unwrap_or_else(|| crate::convert_values::fitting_level(shape, offset));
    fn build<V: Value + TryFrom<u32> + Send + Sync>(
        input: &Path,
        level: u32,
        offset: [u32; 3],
        out: &Path,
        build: &BuildArgs,
    ) -> CliResult {
        let slabs =
            label_slabs::<V>(input, level, offset).map_err(|e| CliError::in_file(input, e))?;
        let Some(written) = write_volume_slabs(input, level, slabs, build, out)? else {
            return Ok(());
        };
        // The labels counted from the file, read in place.
        let mapped = MappedValuedTree::<3, V>::open(out).map_err(CliError::caused)?;
        let mut labels = std::collections::HashSet::new();
        for leaf in ValueLeaves::new(&mapped) {
            if let (_, Some(v)) = leaf.map_err(CliError::caused)? {
                labels.insert(v.key());
            }
        }
        outln!(
            "{}: {} voxels labelled with {} labels ({}), L = {level}, {} nodes",
            out.display(),
            written.voxels,
            labels.len(),
            V::DTYPE.map_or("", Dtype::name),
            written.nodes
        );
        Ok(())
    }
    match dtype {
        Dtype::U8 => build::<u8>(input, level, offset, out, options),
        Dtype::U16 => build::<u16>(input, level, offset, out, options),
        _ => build::<u32>(input, level, offset, out, options),
    }
}

/// What a point cloud's voxel holds (`ktree voxelize CLOUD --value`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CloudValue {
    /// The mean colour of its points (rgb8).
    Rgb,
    /// The mean or largest intensity of its points (float32, --reduce).
    Intensity,
    /// The most frequent class of its points, ties to the smallest (uint8).
    Class,
    /// How many points it holds (uint32).
    Count,
}

/// How `--value intensity` reduces a voxel's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Reduce {
    /// Their mean.
    Mean,
    /// The largest.
    Max,
}

/// Voxelizes `cloud` (read from `input`) with `voxelizer`, each voxel holding `value` of its points, into
/// the valued tree `out`.
pub fn voxelize_cloud_values(
    input: &Path,
    cloud: &PointCloud,
    voxelizer: &CloudVoxelizer,
    (value, reduce): (CloudValue, Option<Reduce>),
    out: &Path,
    options: &BuildArgs,
) -> CliResult {
    if reduce.is_some() && value != CloudValue::Intensity {
        return Err("--reduce is for --value intensity".into());
    }
    let missing = |what: &str| -> CliError {
        let has = cloud.attributes().names();
        format!(
            "{}: --value {}: the file has no {what} (it has {})",
            input.display(),
            match value {
                CloudValue::Rgb => "rgb",
                CloudValue::Intensity => "intensity",
                CloudValue::Class => "class",
                CloudValue::Count => "count",
            },
            if has.is_empty() {
                "points only".to_string()
            } else {
                format!("{} per point", has.join(", "))
            }
        )
        .into()
    };
    let points = cloud.points();
    match value {
        CloudValue::Rgb => {
            let colours = cloud.colours().ok_or_else(|| missing("colour"))?;
            build(
                input,
                voxelizer,
                points,
                colours,
                cloud::mean_colour,
                (out, options),
            )
        }
        CloudValue::Intensity => {
            let intensities = cloud.intensities().ok_or_else(|| missing("intensity"))?;
            let reduce = match reduce.unwrap_or(Reduce::Mean) {
                Reduce::Mean => cloud::mean_intensity,
                Reduce::Max => cloud::max_intensity,
            };
            build(
                input,
                voxelizer,
                points,
                intensities,
                reduce,
                (out, options),
            )
        }
        CloudValue::Class => {
            let classes = cloud.classes().ok_or_else(|| missing("class"))?;
            build(
                input,
                voxelizer,
                points,
                classes,
                cloud::most_frequent_class,
                (out, options),
            )
        }
        CloudValue::Count => {
            let ones = vec![(); points.len()];
            build(
                input,
                voxelizer,
                points,
                &ones,
                |g: &[()]| g.len() as u32,
                (out, options),
            )
        }
    }
}

/// Voxelizes `points` with their values `per_point` reduced by `reduce`, writes the tree to `out` and
/// says what it holds.
fn build<T: Copy, V: Value + Send + Sync>(
    input: &Path,
    voxelizer: &CloudVoxelizer,
    points: &[[f64; 3]],
    per_point: &[T],
    reduce: impl FnMut(&[T]) -> V,
    (out, options): (&Path, &BuildArgs),
) -> CliResult {
    let voxels = voxelizer
        .voxelize_values(points, per_point, reduce)
        .map_err(|e| crate::voxelize::cloud_error(input, e))?;
    // Written out of core (over MPI ranks, each rank builds its own slabs of the runs).
    // Voxel (0, 0, 0) has its lower corner at the origin.
    let frame = WorldFrame {
        voxel_size: voxelizer.voxel_size(),
        origin: voxels.origin,
    };
    let Some(report) = write_runs(&voxels.runs, options, out, Some(&frame), &Notes::new())? else {
        return Ok(());
    };
    let distinct: std::collections::HashSet<_> =
        voxels.runs.runs().iter().map(|r| r.value.key()).collect();
    let nodes: u64 = report
        .counts_per_level
        .iter()
        .map(|c| c.empty + c.full + c.partial)
        .sum();
    let o = voxels.origin;
    outln!(
        "{}: {} points, origin {},{},{}, level {}, {} voxels of {} ({} distinct values){}; {}: {} nodes",
        input.display(),
        points.len(),
        o[0],
        o[1],
        o[2],
        voxels.runs.universe().level(),
        voxels.runs.voxel_count(),
        V::DTYPE.map_or("", Dtype::name),
        distinct.len(),
        if voxels.cropped > 0 {
            format!(", {} points outside the universe dropped", voxels.cropped)
        } else {
            String::new()
        },
        out.display(),
        nodes
    );
    Ok(())
}

/// Arguments of `ktree select`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("which").required(true).args(["value", "range"])))]
pub struct SelectArgs {
    /// A `.ktree` file with values.
    input: PathBuf,
    /// The value whose voxels are kept (a number, or r,g,b for a colour).
    #[arg(long, allow_hyphen_values = true)]
    value: Option<String>,
    /// The values kept, LO:HI, both included (on every channel for colours).
    #[arg(long, allow_hyphen_values = true)]
    range: Option<String>,
    /// The output `.ktree`: the selected voxels, without values, with the input's world frame and notes.
    #[arg(long)]
    out: PathBuf,
}

/// `ktree select`.
pub fn run_select(a: SelectArgs) -> CliResult {
    let (tree, frame, notes) = read_valued_framed(&a.input)?;
    with_valued!(&tree, t => select(t, frame.as_ref(), &notes, &a))
}

/// The voxels chosen of `tree` written as a tree without values, with the input's world frame and
/// notes (its labels' names among them).
fn select<const K: usize, V: Value>(
    tree: &KTree<K, V>,
    frame: Option<&WorldFrame>,
    notes: &Notes,
    a: &SelectArgs,
) -> CliResult {
    // The name of the label chosen, if the file names it.
    let mut named = String::new();
    let chosen = match (&a.value, &a.range) {
        (Some(v), _) => {
            let value = V::parse(v).map_err(|e| format!("--value {e}"))?;
            if let Some(name) = notes.get(&label_note(&value.text())) {
                named = format!(" (label {}: {name})", value.text());
            }
            tree.select(value)
        }
        (None, Some(r)) => {
            let (lo, hi) = r
                .split_once(':')
                .ok_or_else(|| format!("--range '{r}': expected LO:HI"))?;
            let lo = V::parse(lo).map_err(|e| format!("--range {e}"))?;
            let hi = V::parse(hi).map_err(|e| format!("--range {e}"))?;
            tree.select_range(lo, hi)
        }
        (None, None) => unreachable!("clap requires --value or --range"),
    };
    ktree::io::write_ktree_file_framed(&a.out, &chosen, frame, notes).map_err(CliError::caused)?;
    outln!(
        "{}: {} voxels selected{named}, {} nodes",
        a.out.display(),
        chosen.voxel_count(),
        chosen.node_count()
    );
    Ok(())
}

/// What `ktree stats` prints of a valued file: the statistics of its own nodes, the voxels and box of those
/// that hold a value, its value type and, per value, its voxels, box, centroid and surface area.
#[derive(serde::Serialize)]
pub struct ValuedStats {
    #[serde(flatten)]
    stats: TreeStats,
    dtype: &'static str,
    values: serde_json::Map<String, serde_json::Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    world_frame: Option<WorldFrame>,
}

/// The statistics of a valued `.ktree` file.
pub fn valued_stats(path: &Path) -> CliResult<ValuedStats> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| cannot_read(path, e))?;
    let (tree, frame, notes) = read_any_ktree_framed(&bytes, &name).map_err(CliError::caused)?;
    let AnyKtree::Valued(tree) = tree else {
        return Err(format!("{name}: the tree holds no values").into());
    };
    let mut s = with_valued!(&tree, t => stats_of(t, &notes))?;
    s.world_frame = frame;
    Ok(s)
}

/// The statistics of a valued tree; a value named by the file's notes (a label's name) with its name.
fn stats_of<const K: usize, V: Value>(tree: &KTree<K, V>, notes: &Notes) -> CliResult<ValuedStats> {
    let shape = tree.shape();
    let Ok(mut s) = stats(&shape, None);
    // The file's own nodes (mixed nodes counted with the partial ones: both have children).
    let per_level = tree.counts_per_level();
    let total = ktree::LevelCounts::total(tree.level(), &per_level);
    (s.full, s.empty, s.partial, s.nodes) = (total.full, total.empty, total.partial, total.nodes());
    s.bytes_at_2_bits = total.nodes().div_ceil(4);
    s.memory_bytes = tree.heap_bytes() as u64;
    s.per_level = per_level;
    let mut values = serde_json::Map::new();
    for v in tree.value_stats().into_values() {
        let text = v.value.text();
        let mut entry = serde_json::json!({
            "voxels": v.voxels,
            "bounding_box": [v.bounding_box.0.to_vec(), v.bounding_box.1.to_vec()],
            "centroid": v.centroid.to_vec(),
            "surface_area": v.surface_area,
        });
        if let Some(name) = notes.get(&label_note(&text)) {
            entry["name"] = serde_json::Value::from(name.as_str());
        }
        values.insert(text, entry);
    }
    Ok(ValuedStats {
        stats: s,
        dtype: V::DTYPE.map_or("", Dtype::name),
        values,
        world_frame: None,
    })
}

/// Prints a valued file's statistics, as JSON or as text.
pub fn print_valued_stats(path: &Path, json: bool) -> CliResult {
    let s = valued_stats(path)?;
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&s).map_err(CliError::caused)?
        );
        return Ok(());
    }
    outln!(
        "K = {}, L = {}, values {}: {} nodes ({} full, {} with children, {} empty), {} voxels with a value",
        s.stats.k,
        s.stats.level,
        s.dtype,
        s.stats.nodes,
        s.stats.full,
        s.stats.partial,
        s.stats.empty,
        s.stats.voxels
    );
    if let Some(frame) = &s.world_frame {
        outln!("world: {}", frame_text(frame));
    }
    for (value, m) in &s.values {
        let named = m["name"]
            .as_str()
            .map_or_else(|| value.clone(), |name| format!("{value} ({name})"));
        outln!(
            "  {named}: {} voxels, box {} to {}, centroid {}, surface area {}",
            m["voxels"],
            m["bounding_box"][0],
            m["bounding_box"][1],
            m["centroid"],
            m["surface_area"]
        );
    }
    Ok(())
}
