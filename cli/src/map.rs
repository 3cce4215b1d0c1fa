//! `ktree map SCANS… --resolution R [--max-range M] [--sensor-origin X,Y,Z | --pose X,Y,Z,ROLL,PITCH,YAW]
//! --out MAP.ot|.bt|.ktree [--history HISTORY.ktree] [--static-map MAP] [--keep-within R]`: an occupancy map from range scans,
//! integrated as OctoMap's `insertPointCloud` integrates them, with its history as a 4-D tree and the
//! map without what moved; and the map branch of `ktree project` (a map's plane between two
//! heights, as a ROS map or a quadtree).

use std::path::{Path, PathBuf};
use std::time::Instant;

use ktree::export::grid_map::write_grid_map;
use ktree::export::Frame;
use ktree::io::ktree::read_map_ktree;
use ktree::io::ktree::v3::valued_header;
use ktree::io::scan::{read_scan_directory, read_scans, Pose, Scan, ScanNode};
use ktree::io::{
    read_bt_map, read_cloud, read_cloud_bytes, read_ot_map, write_bt_map, write_ot_map,
};
use ktree::map::{HistoryRecorder, OccupancyMap, SensorModel, MAP_LEVEL};
use ktree::tree::Dtype;

use crate::common::error::{cannot_read, CliError, CliResult};
use crate::common::vector::vector;
use crate::outln;

/// Arguments of `ktree map`.
#[derive(Debug, clap::Args)]
pub struct MapArgs {
    /// The scans, in order: OctoMap's scan graphs (.graph) and logs (.log), which carry their poses; scan
    /// lists (.scans or .list: lines `POINTFILE x y z roll pitch yaw` or `POINTFILE x y z`); folders of
    /// point files; point files (PLY, PCD, XYZ/CSV/TXT, OctoMap's `x y z` .dat, LAS/LAZ). Point files and
    /// folders are in world coordinates seen from --sensor-origin, or in the sensor's frame at --pose.
    #[arg(required = true)]
    scans: Vec<PathBuf>,
    /// The side of a voxel, in the points' unit (metres).
    #[arg(long, allow_hyphen_values = true)]
    resolution: f64,
    /// Rays are cut at this distance from the sensor; points beyond it are no hits (default: no limit).
    #[arg(long, allow_hyphen_values = true)]
    max_range: Option<f64>,
    /// Where the sensor was, X,Y,Z in world coordinates.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<f64, 3>, default_value = "0,0,0", conflicts_with = "pose")]
    sensor_origin: [f64; 3],
    /// The sensor's pose for point files in its frame: X,Y,Z,ROLL,PITCH,YAW (metres, radians; OctoMap's
    /// Pose6D).
    #[arg(long, value_name = "X,Y,Z,ROLL,PITCH,YAW", allow_hyphen_values = true, value_parser = vector::<f64, 6>)]
    pose: Option<[f64; 6]>,
    /// The map: .ot (every log-odds, OctoMap's OcTree), .bt (free and occupied, OctoMap's binary) or
    /// .ktree (the log-odds as a float32 tree at the map's keys, with its resolution and origin as the
    /// file's world frame).
    #[arg(long)]
    out: PathBuf,
    /// Also write the map's history: a 4-D tree (.ktree, uint8) with time as its fourth axis, one position
    /// a step, recording where and when each voxel became free (1) or occupied (2).
    #[arg(long, value_name = "HISTORY.ktree")]
    history: Option<PathBuf>,
    /// Scans a step of the history (the last step may hold fewer).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    scans_per_step: u32,
    /// Also write the static map (.ot, .bt or .ktree): the map with every voxel that was occupied at some
    /// step and observed free at another made free — moving objects and their trails removed.
    #[arg(long, value_name = "MAP")]
    static_map: Option<PathBuf>,
    /// After each scan, forget the voxels farther than R from its sensor origin (they become unknown): a
    /// map of the region around the sensor on a long run, its memory bounded by the region, not the path.
    #[arg(long, value_name = "R", allow_hyphen_values = true, conflicts_with_all = ["history", "static_map"])]
    keep_within: Option<f64>,
    /// The probability a hit gives.
    #[arg(long, default_value_t = 0.7)]
    prob_hit: f64,
    /// The probability a miss gives.
    #[arg(long, default_value_t = 0.4)]
    prob_miss: f64,
    /// The lowest probability a voxel keeps.
    #[arg(long, default_value_t = 0.1192)]
    clamp_min: f64,
    /// The highest probability a voxel keeps.
    #[arg(long, default_value_t = 0.971)]
    clamp_max: f64,
    /// The probability from which a voxel is occupied.
    #[arg(long, default_value_t = 0.5)]
    occupancy: f64,
}

/// The points of a point file, as `f32` (OctoMap's precision).
fn read_points(path: &Path) -> CliResult<Vec<[f32; 3]>> {
    let dat = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("dat"));
    let cloud = if dat {
        let bytes = std::fs::read(path).map_err(|e| cannot_read(path, e))?;
        read_cloud_bytes(&bytes, "xyz", path)
    } else {
        read_cloud(path)
    }
    .map_err(CliError::caused)?;
    Ok(cloud
        .points()
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect())
}

/// The scans of one argument of `ktree map`.
fn read_argument(path: &Path, origin: [f32; 3], pose: Option<Pose>) -> CliResult<Vec<Scan>> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let placed = |points: Vec<[f32; 3]>| match pose {
        Some(pose) => ScanNode {
            id: 0,
            pose,
            points,
        }
        .to_scan(),
        None => Scan { points, origin },
    };
    if path.is_dir() {
        let scans = read_scan_directory(path, origin).map_err(CliError::caused)?;
        return Ok(match pose {
            Some(_) => scans.into_iter().map(|s| placed(s.points)).collect(),
            None => scans,
        });
    }
    match ext.as_str() {
        "graph" | "log" | "scans" | "list" => read_scans(path).map_err(CliError::caused),
        _ => Ok(vec![placed(read_points(path)?)]),
    }
}

/// `ktree map`.
pub fn run_map(a: MapArgs) -> CliResult {
    let model = SensorModel::from_probabilities(
        a.prob_hit,
        a.prob_miss,
        a.clamp_min,
        a.clamp_max,
        a.occupancy,
    );
    if let Some(m) = a.max_range.filter(|m| !(m.is_finite() && *m > 0.0)) {
        return Err(format!("--max-range {m}: expected a positive number").into());
    }
    let kind = map_kind(&a.out)?;
    let static_kind = a.static_map.as_deref().map(map_kind).transpose()?;
    if let Some(h) = a.history.as_deref() {
        if !h
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ktree"))
        {
            return Err(format!("{}: a history is written as .ktree", h.display()).into());
        }
    }
    let mut map = OccupancyMap::<3>::with_model(a.resolution, model)
        .map_err(|e| format!("--resolution/probabilities: {e}"))?;
    let origin = a.sensor_origin.map(|c| c as f32);
    let pose = a
        .pose
        .map(|[x, y, z, r, p, w]| Pose::from_xyz_rpy(x as f32, y as f32, z as f32, r, p, w));
    let keep_history = a.history.is_some() || a.static_map.is_some();
    let mut recorder = keep_history.then(|| HistoryRecorder::new(*map.grid()));
    let (mut scans, mut points, mut outside, mut seconds) = (0usize, 0usize, 0usize, 0.0f64);
    for argument in &a.scans {
        for scan in read_argument(argument, origin, pose)? {
            let start = Instant::now();
            let update = map
                .insert(&scan.points, scan.origin, a.max_range)
                .map_err(|e| format!("{}: {e}", argument.display()))?;
            if let Some(radius) = a.keep_within {
                map.forget_outside(scan.origin.map(f64::from), radius)
                    .map_err(|e| format!("--keep-within: {e}"))?;
            }
            seconds += start.elapsed().as_secs_f64();
            scans += 1;
            points += scan.points.len();
            outside += update.rays_outside;
            if let Some(r) = recorder
                .as_mut()
                .filter(|_| scans % a.scans_per_step as usize == 0)
            {
                r.record(&map)
                    .map_err(|e| format!("{}: {e}", argument.display()))?;
            }
        }
    }
    if let Some(r) = recorder
        .as_mut()
        .filter(|_| scans % a.scans_per_step as usize != 0)
    {
        r.record(&map)?;
    }
    write_map(&a.out, kind, &map)?;
    if let Some(recorder) = recorder {
        let history = recorder.finish();
        let moved = history.moved();
        if let Some(path) = &a.history {
            ktree::io::ktree::write_history_ktree_file(path, &history).map_err(CliError::caused)?;
            outln!(
                "{}: the history of {} steps as a 4-D tree of {} nodes (the map: {} nodes)",
                path.display(),
                history.steps(),
                history.tree().node_count(),
                map.log_odds().node_count()
            );
        }
        if let (Some(path), Some(kind)) = (&a.static_map, static_kind) {
            let still = map.cleared(&moved)?;
            write_map(path, kind, &still)?;
            outln!(
                "{}: the static map: {} occupied voxels; {} voxels were occupied at some step and free at another",
                path.display(),
                still.occupied().voxel_count(),
                moved.voxel_count()
            );
        }
    }
    outln!(
        "{}: {scans} scans, {points} points integrated in {seconds:.3} s; {} occupied, {} free voxels of {} m",
        a.out.display(),
        map.occupied().voxel_count(),
        map.free().voxel_count(),
        a.resolution
    );
    if outside > 0 {
        outln!("{outside} rays left the map's 2^16 voxels a side and were skipped (as OctoMap skips them)");
    }
    Ok(())
}

#[derive(Debug, Clone, Copy)]
enum MapKind {
    Ot,
    Bt,
    Ktree,
}

fn map_kind(out: &Path) -> CliResult<MapKind> {
    match out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("ot") => Ok(MapKind::Ot),
        Some("bt") => Ok(MapKind::Bt),
        Some("ktree") => Ok(MapKind::Ktree),
        _ => Err(format!("{}: a map is written as .ot, .bt or .ktree", out.display()).into()),
    }
}

fn write_map(out: &Path, kind: MapKind, map: &OccupancyMap<3>) -> CliResult {
    match kind {
        MapKind::Ot => ktree::fs::write_atomic_with(out, |w| write_ot_map(w, map)),
        MapKind::Bt => ktree::fs::write_atomic_with(out, |w| write_bt_map(w, map)),
        MapKind::Ktree => ktree::io::ktree::write_map_ktree_file(out, map),
    }
    .map_err(CliError::caused)
}

/// Whether a file holds an occupancy map: OctoMap's `.ot` and `.bt`, or a `.ktree` of float32 log-odds
/// in a map's universe (K = 3, level 16) with a world frame.
pub fn is_map_file(path: &Path) -> bool {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("ot" | "bt") => true,
        Some("ktree") => {
            let mut head = [0u8; 16];
            let read = std::fs::File::open(path)
                .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head));
            read.is_ok()
                && matches!(
                    valued_header(&head[..], ""),
                    Ok((3, MAP_LEVEL, Some(Dtype::F32)))
                )
                && head[11] & 1 == 1
        }
        _ => false,
    }
}

/// Reads an occupancy map file (`.ot`, `.bt`, or a `.ktree` of log-odds with its frame) with OctoMap's
/// default model.
pub fn read_map(path: &Path) -> CliResult<OccupancyMap<3>> {
    let bytes = std::fs::read(path).map_err(|e| cannot_read(path, e))?;
    let name = path.display().to_string();
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ktree"))
    {
        return read_map_ktree(&bytes, &name, SensorModel::default()).map_err(CliError::caused);
    }
    let bt = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("bt"));
    if bt {
        read_bt_map(&bytes, &name, SensorModel::default())
    } else {
        read_ot_map(&bytes, &name, SensorModel::default())
    }
    .map_err(CliError::caused)
}

/// `ktree project MAP --axis A [--range LO:HI] --out OUT` for an occupancy map: the plane of the map
/// between world coordinates LO and HI along the axis, as a ROS map (`.png` + `.yaml`: occupied, free and
/// unknown) or as the quadtree of its occupied cells (any tree file).
pub fn project_map(input: &Path, axis: usize, range: Option<(f64, f64)>, out: &Path) -> CliResult {
    if axis > 2 {
        return Err(format!("{}: a map has axes x, y and z", input.display()).into());
    }
    let map = read_map(input)?;
    let (lo, hi) = range.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    let plane = map
        .plane(axis, lo, hi)
        .map_err(|e| format!("{}: {e}", input.display()))?;
    let png = out.extension().is_some_and(|e| e == "png");
    if png {
        let frame = Frame {
            voxel_size: plane.resolution,
            origin: [plane.origin[0], plane.origin[1], 0.0],
        };
        let yaml = write_grid_map(out, &plane.occupied, Some(&plane.known), &frame)
            .map_err(CliError::caused)?;
        outln!(
            "{} and {}: the map between {lo} and {hi} along axis {axis}: {} occupied and {} free cells of {} m, {}² cells from ({}, {})",
            out.display(),
            yaml.display(),
            plane.occupied.voxel_count(),
            plane.known.voxel_count() - plane.occupied.voxel_count(),
            plane.resolution,
            1u64 << plane.known.level(),
            plane.origin[0],
            plane.origin[1]
        );
        return Ok(());
    }
    crate::common::tree_file::write_tree(out, &plane.occupied).map_err(CliError::caused)?;
    outln!(
        "{}: the occupied cells of the map between {lo} and {hi} along axis {axis}: {} of {}², cell (0, 0) at ({}, {}), {} m",
        out.display(),
        plane.occupied.voxel_count(),
        1u64 << plane.occupied.level(),
        plane.origin[0],
        plane.origin[1],
        plane.resolution
    );
    Ok(())
}
