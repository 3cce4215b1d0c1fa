//! `ktree query FILE --points P [--distance] [--nearest] [--json]` (on a tree with values: each point's
//! value too; on a map file: each point unknown, free or occupied, and its voxel's colour in a
//! `ColorOcTree` `.ot`) and
//! `ktree raycast FILE --rays R [--max-t T] [--json]` (on a map file: OctoMap's castRay,
//! `--ignore-unknown`, `--max-range`): point queries, nearest full voxels and ray casts
//! on a tree file. A version 2 file, and a version 3 file with values queried for its values, is read
//! through its memory map (so a tree larger than memory is queried without being loaded); others are
//! loaded.

use crate::common::error::{cannot_read, CliError, CliResult};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use ktree::io::ktree::v3::MappedValuedTree;
use ktree::io::ktree::MappedMap;
use ktree::io::{read_color_ot_map, FileTree, GridFileErrorKind};
use ktree::map::{MapView, OccupancyMap, SensorModel};
use ktree::query::{self, Query, RayCast, RayHit};
use ktree::tree::AnyValuedTree;
use ktree::tree::ValueStorage;
use ktree::value::Rgb;
use ktree::value::{Dtype, Value};
use ktree::{with_tree, with_valued, KTree};

use crate::common::error::read_error;

use crate::table;

/// Arguments of `ktree query`.
#[derive(Debug, clap::Args)]
pub struct QueryArgs {
    /// The tree file, or an occupancy map (.ot, .bt): then each point's state, unknown, free or occupied.
    tree: PathBuf,
    /// The points: a `.csv` or `.txt` of K integers a line, or a `.npy` `(N, K)` integer array; `-` for
    /// standard input. For a map: three world coordinates a line.
    #[arg(long)]
    points: PathBuf,
    /// Also print the distance to the nearest full voxel (between voxel centres; 0 inside).
    #[arg(long)]
    distance: bool,
    /// Also print the nearest full voxel.
    #[arg(long)]
    nearest: bool,
    /// Print a JSON array of objects (`point`, `inside`, and `distance`, `nearest` when asked, `value` for
    /// a tree with values: a number, `[r, g, b]`, or null where the voxel is empty; for a map
    /// `point` and `state`, and `colour` for an OctoMap `ColorOcTree` .ot: `[r, g, b]`, or null where the
    /// voxel has none).
    #[arg(long)]
    json: bool,
}

/// Arguments of `ktree raycast`.
#[derive(Debug, clap::Args)]
pub struct RaycastArgs {
    /// The tree file, or an occupancy map (.ot, .bt): then OctoMap's castRay, to the first occupied
    /// voxel, stopping at unknown ones unless --ignore-unknown.
    tree: PathBuf,
    /// The rays: a `.csv` or `.txt` of 2K numbers a line (origin, then direction), or a `.npy` `(N, 2K)`
    /// array; `-` for standard input.
    #[arg(long)]
    rays: PathBuf,
    /// The largest ray parameter `t` (default: no limit).
    #[arg(long, default_value_t = f64::INFINITY)]
    max_t: f64,
    /// Print a JSON array of objects (`hit`, `voxel`, `t`, `axis`, `sign`; for a map `end`, `key`,
    /// `point`).
    #[arg(long)]
    json: bool,
    /// A map: rays pass through unknown voxels (OctoMap's ignoreUnknown).
    #[arg(long)]
    ignore_unknown: bool,
    /// A map: rays stop beyond this distance, in world units (default: no limit).
    #[arg(long)]
    max_range: Option<f64>,
}

/// The tree of a file: mapped (version 2) or loaded; the queries run on either.
fn open(path: &Path) -> CliResult<FileTree> {
    ktree::input::open_tree(path, &ktree::io::ReadOptions::default()).map_err(CliError::caused)
}

/// Standard output, buffered; writes end the command quietly on a closed pipe.
fn out() -> BufWriter<std::io::StdoutLock<'static>> {
    BufWriter::with_capacity(1 << 16, std::io::stdout().lock())
}

/// The points of a table, each of `K` integers.
fn points<const K: usize>(t: &table::Table<i64>) -> Vec<[i64; K]> {
    t.rows
        .iter()
        .map(|r| std::array::from_fn(|a| r[a]))
        .collect()
}

/// A value as JSON: a number, `[r, g, b]` for a colour, a float without a JSON number (an infinity) as
/// its text.
fn value_json<V: Value>(v: V) -> serde_json::Value {
    let text = v.text();
    let parsed = if V::DTYPE == Some(Dtype::Rgb) {
        serde_json::from_str(&format!("[{text}]"))
    } else {
        serde_json::from_str(&text)
    };
    parsed.unwrap_or(serde_json::Value::String(text))
}

/// The values of a valued tree at voxels (`K` coordinates each, the tree's own `K`), as JSON (null where
/// empty).
fn values_at<const K: usize>(tree: &AnyValuedTree, voxels: &[[u32; K]]) -> Vec<serde_json::Value> {
    with_valued!(tree, t => {
        let points: Vec<_> = voxels
            .iter()
            .map(|p| std::array::from_fn(|a| p.get(a).copied().unwrap_or(u32::MAX)))
            .collect();
        t.values_at(&points)
            .into_iter()
            .map(|v| v.map_or(serde_json::Value::Null, value_json))
            .collect()
    })
}

/// The points of `args` as voxels (points beyond the `u32` range are outside every universe).
fn voxels_of<const K: usize>(pts: &[[i64; K]]) -> Vec<[u32; K]> {
    pts.iter()
        .map(|p| p.map(|v| u32::try_from(v).unwrap_or(u32::MAX)))
        .collect()
}

/// Answers the point queries of a `.ktree` file with values read in place (its memory map): each point's
/// value, inside where it has one, and its distance and nearest voxel with a value when asked.
fn answer_mapped_values(args: &QueryArgs, k: usize, dtype: Dtype) -> CliResult {
    with_valued!(k, dtype, KK, V => {
        let tree = MappedValuedTree::<KK, V>::open(&args.tree).map_err(CliError::caused)?;
        let pts = points::<KK>(&table::read::<i64>(&args.points, KK)?);
        let values = query::values_at(&tree, &voxels_of(&pts)).map_err(CliError::caused)?;
        let inside: Vec<bool> = values.iter().map(Option::is_some).collect();
        let values: Vec<serde_json::Value> = values
            .into_iter()
            .map(|v| v.map_or(serde_json::Value::Null, value_json))
            .collect();
        let near = if args.distance || args.nearest {
            query::nearest_many_signed(&tree.leaves(), &pts).map_err(read_error)?
        } else {
            Vec::new()
        };
        print_points(&pts, &inside, Some(&values), &near, args)
    }, else Err(format!("{}: K = {k} is not 1 to 4", args.tree.display()).into()))
}

/// Answers the point queries on `tree` (with its values' tree if it has values) and prints them.
fn answer_points<const K: usize, T: Query<K>>(
    tree: &T,
    args: &QueryArgs,
    valued: Option<&AnyValuedTree>,
) -> CliResult {
    let table = table::read::<i64>(&args.points, K)?;
    let pts = points::<K>(&table);
    let voxels = voxels_of(&pts);
    let inside = tree.contains_many(&voxels).map_err(read_error)?;
    let values = valued.map(|v| values_at(v, &voxels));
    let near = if args.distance || args.nearest {
        query::nearest_many_signed(tree, &pts).map_err(read_error)?
    } else {
        Vec::new()
    };
    print_points(&pts, &inside, values.as_deref(), &near, args)
}

/// Prints the answers to the point queries: each point, whether it is inside, its value (a tree with
/// values), and its distance and nearest voxel when asked (`near`).
fn print_points<const K: usize>(
    pts: &[[i64; K]],
    inside: &[bool],
    values: Option<&[serde_json::Value]>,
    near: &[Option<query::Nearest<K>>],
    args: &QueryArgs,
) -> CliResult {
    let mut w = out();
    let io = crate::common::error::CliError::from_output;
    if args.json {
        w.write_all(b"[").map_err(io)?;
    }
    for (i, p) in pts.iter().enumerate() {
        let n = near.get(i).copied().flatten();
        if args.json {
            let mut o = serde_json::Map::new();
            o.insert("point".into(), serde_json::json!(p.to_vec()));
            o.insert("inside".into(), inside[i].into());
            if args.distance {
                // JSON has no infinity: null when the object is empty.
                o.insert(
                    "distance".into(),
                    serde_json::json!(n.map(|n| n.distance())),
                );
            }
            if args.nearest {
                o.insert(
                    "nearest".into(),
                    serde_json::json!(n.map(|n| n.voxel.to_vec())),
                );
            }
            if let Some(values) = values {
                o.insert("value".into(), values[i].clone());
            }
            let sep = if i == 0 { "\n" } else { ",\n" };
            write!(w, "{sep}{}", serde_json::Value::Object(o)).map_err(io)?;
            continue;
        }
        let coords: Vec<String> = p.iter().map(i64::to_string).collect();
        write!(
            w,
            "{} {}",
            coords.join(" "),
            if inside[i] { "inside" } else { "outside" }
        )
        .map_err(io)?;
        if let Some(v) = values.map(|v| &v[i]).filter(|v| !v.is_null()) {
            write!(w, " value {v}").map_err(io)?;
        }
        if args.distance {
            match n {
                Some(n) => write!(w, " distance {}", n.distance()),
                None => write!(w, " distance inf"),
            }
            .map_err(io)?;
        }
        if args.nearest {
            match n {
                Some(n) => {
                    let v: Vec<String> = n.voxel.iter().map(u32::to_string).collect();
                    write!(w, " nearest {}", v.join(" "))
                }
                None => write!(w, " nearest none"),
            }
            .map_err(io)?;
        }
        writeln!(w).map_err(io)?;
    }
    if args.json {
        writeln!(w, "{}]", if pts.is_empty() { "" } else { "\n" }).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Runs `ktree query`.
pub fn run_query(args: QueryArgs) -> CliResult {
    if crate::project::is_map_file(&args.tree) {
        return answer_map_points(&args);
    }
    if crate::values::is_valued(&args.tree) {
        let (k, dtype) = crate::values::file_dtype(&args.tree)?;
        // Values, distances and nearest voxels are read in place.
        if let Some(dtype) = dtype {
            return answer_mapped_values(&args, k, dtype);
        }
        let valued = crate::values::read_valued(&args.tree)?;
        let shape = FileTree::Memory(valued.shape());
        return with_tree!(&shape, t => answer_points(t, &args, Some(&valued)));
    }
    with_tree!(&open(&args.tree)?, t => answer_points(t, &args, None))
}

/// `ktree query` of an occupancy map (`.ot`, `.bt`): the state (unknown, free or occupied) of the voxel
/// holding each point, the points in world coordinates (three numbers a line); with `--json`, also the
/// voxel's colour for a `ColorOcTree` `.ot`.
fn answer_map_points(args: &QueryArgs) -> CliResult {
    if args.distance || args.nearest {
        return Err(format!(
            "{}: --distance and --nearest are for trees; a map's query answers unknown, free or occupied",
            args.tree.display()
        )
        .into());
    }
    if is_ktree(&args.tree) {
        let map = MappedMap::open(&args.tree, SensorModel::default()).map_err(CliError::caused)?;
        return write_map_states(&map.view(), None, args);
    }
    let (map, colours) = read_map_and_colours(&args.tree)?;
    write_map_states(&map.view(), colours.as_ref(), args)
}

/// Whether `path` names a `.ktree` file (a map read in place).
fn is_ktree(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ktree"))
}

/// Prints the state of the voxel of each point of `args.points` in `map` (and its colour from `colours`).
fn write_map_states<S>(
    map: &MapView<'_, 3, S>,
    colours: Option<&KTree<3, Rgb>>,
    args: &QueryArgs,
) -> CliResult
where
    S: ValueStorage<3, Value = f32> + Sync,
    S::Error: Send,
{
    let table = table::read::<f64>(&args.points, 3)?;
    let pts: Vec<[f32; 3]> = table
        .rows
        .iter()
        .map(|r| [r[0] as f32, r[1] as f32, r[2] as f32])
        .collect();
    let states = map.states(&pts).map_err(read_error)?;
    let colours = colours.map(|c| {
        let keys: Vec<[u32; 3]> = pts
            .iter()
            .map(|&p| map.grid().keys(p).unwrap_or([u32::MAX; 3]))
            .collect();
        c.values_at(&keys)
    });
    let name = |s: ktree::map::VoxelState| match s {
        ktree::map::VoxelState::Unknown => "unknown",
        ktree::map::VoxelState::Free => "free",
        ktree::map::VoxelState::Occupied => "occupied",
    };
    let mut w = out();
    let io = crate::common::error::CliError::from_output;
    if args.json {
        w.write_all(b"[").map_err(io)?;
    }
    for (i, (row, state)) in table.rows.iter().zip(&states).enumerate() {
        if args.json {
            let sep = if i == 0 { "\n" } else { ",\n" };
            let mut o = serde_json::json!({"point": row[..3].to_vec(), "state": name(*state)});
            if let Some(colours) = &colours {
                o["colour"] = serde_json::json!(colours[i]);
            }
            write!(w, "{sep}{o}").map_err(io)?;
        } else {
            writeln!(w, "{} {} {} {}", row[0], row[1], row[2], name(*state)).map_err(io)?;
        }
    }
    if args.json {
        writeln!(w, "{}]", if states.is_empty() { "" } else { "\n" }).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// A map file and, for an OctoMap `ColorOcTree` `.ot` file, its voxels' colours.
fn read_map_and_colours(path: &Path) -> CliResult<(OccupancyMap<3>, Option<KTree<3, Rgb>>)> {
    let ot = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ot"));
    if ot {
        let bytes = std::fs::read(path).map_err(|e| cannot_read(path, e))?;
        let name = path.display().to_string();
        match read_color_ot_map(&bytes, &name, SensorModel::default()) {
            Ok((map, colours)) => return Ok((map, Some(colours))),
            // Another tree type (an `OcTree`): read as a map without colours.
            Err(e) if matches!(e.kind, GridFileErrorKind::Unsupported(_)) => {}
            Err(e) => return Err(CliError::caused(e)),
        }
    }
    Ok((crate::map::read_map(path)?, None))
}

/// The rays of a table, each of `2K` numbers, checked.
fn rays<const K: usize>(t: &table::Table<f64>, max_t: f64) -> CliResult<Vec<RayCast<K>>> {
    t.rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            RayCast::new(
                std::array::from_fn(|a| r[a]),
                std::array::from_fn(|a| r[K + a]),
                max_t,
            )
            .map_err(|e| CliError::about(t.place(i), e))
        })
        .collect()
}

/// Casts the rays on `tree` and prints the hits.
fn answer_rays<const K: usize, T: Query<K>>(tree: &T, args: &RaycastArgs) -> CliResult {
    if args.max_t.is_nan() || args.max_t < 0.0 {
        return Err(format!(
            "--max-t must be a number >= 0 (inf for no limit), got {}",
            args.max_t
        )
        .into());
    }
    let table = table::read::<f64>(&args.rays, 2 * K)?;
    let casts = rays::<K>(&table, args.max_t)?;
    let hits: Vec<Option<RayHit<K>>> = tree.cast_rays(&casts).map_err(read_error)?;
    let mut w = out();
    let io = crate::common::error::CliError::from_output;
    if args.json {
        w.write_all(b"[").map_err(io)?;
    }
    for (i, h) in hits.iter().enumerate() {
        if args.json {
            let o = serde_json::json!({
                "hit": h.is_some(),
                "voxel": h.map(|h| h.voxel.to_vec()),
                "t": h.map(|h| h.t),
                "axis": h.and_then(|h| h.face).map(|f| f.axis),
                "sign": h.and_then(|h| h.face).map(|f| f.sign),
            });
            let sep = if i == 0 { "\n" } else { ",\n" };
            write!(w, "{sep}{o}").map_err(io)?;
            continue;
        }
        match h {
            None => writeln!(w, "miss"),
            Some(h) => {
                let v: Vec<String> = h.voxel.iter().map(u32::to_string).collect();
                let face = h.face.map_or("inside".to_string(), |f| {
                    format!("face {}{}", if f.sign < 0 { '-' } else { '+' }, f.axis)
                });
                writeln!(w, "hit {} t {} {face}", v.join(" "), h.t)
            }
        }
        .map_err(io)?;
    }
    if args.json {
        writeln!(w, "{}]", if hits.is_empty() { "" } else { "\n" }).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Runs `ktree raycast`.
pub fn run_raycast(args: RaycastArgs) -> CliResult {
    if crate::project::is_map_file(&args.tree) {
        return answer_map_rays(&args);
    }
    if args.ignore_unknown || args.max_range.is_some() {
        return Err("--ignore-unknown and --max-range are for occupancy maps (.ot, .bt)".into());
    }
    with_tree!(&open(&args.tree)?, t => answer_rays(t, &args))
}

/// `ktree raycast` of an occupancy map: per ray (origin and direction in world coordinates), how it
/// ended — `occupied` (a hit), `unknown`, `range` (beyond --max-range) or `outside` the map — with the
/// key and the world centre of the voxel where it ended (for `outside`, the last voxel inside the map; none
/// when the origin is outside it).
fn answer_map_rays(args: &RaycastArgs) -> CliResult {
    if is_ktree(&args.tree) {
        let map = MappedMap::open(&args.tree, SensorModel::default()).map_err(CliError::caused)?;
        return write_map_casts(&map.view(), args);
    }
    write_map_casts(&crate::map::read_map(&args.tree)?.view(), args)
}

/// Prints how each ray of `args.rays` cast on `map` ended.
fn write_map_casts<S: ValueStorage<3, Value = f32>>(
    map: &MapView<'_, 3, S>,
    args: &RaycastArgs,
) -> CliResult {
    let table = table::read::<f64>(&args.rays, 6)?;
    let range = match args.max_range {
        Some(m) if !(m.is_finite() && m > 0.0) => {
            return Err(format!("--max-range {m}: expected a positive number").into())
        }
        Some(m) => m,
        None => -1.0,
    };
    let mut w = out();
    let io = crate::common::error::CliError::from_output;
    if args.json {
        w.write_all(b"[").map_err(io)?;
    }
    for (i, r) in table.rows.iter().enumerate() {
        let f = |a: usize| r[a] as f32;
        let end = map
            .cast_ray(
                [f(0), f(1), f(2)],
                [f(3), f(4), f(5)],
                args.ignore_unknown,
                range,
            )
            .map_err(read_error)?;
        let (name, key) = match end {
            ktree::map::CastEnd::Occupied(k) => ("occupied", Some(k)),
            ktree::map::CastEnd::Unknown(k) => ("unknown", Some(k)),
            ktree::map::CastEnd::Range(k) => ("range", Some(k)),
            ktree::map::CastEnd::Outside(k) => ("outside", k),
        };
        let point = key.map(|k| k.map(|c| map.grid().centre(c)));
        if args.json {
            let sep = if i == 0 { "\n" } else { ",\n" };
            let o = serde_json::json!({"end": name, "key": key, "point": point});
            write!(w, "{sep}{o}").map_err(io)?;
        } else {
            match (key, point) {
                (Some(k), Some(p)) => writeln!(
                    w,
                    "{name} {} {} {} {} {} {}",
                    k[0], k[1], k[2], p[0], p[1], p[2]
                ),
                _ => writeln!(w, "{name}"),
            }
            .map_err(io)?;
        }
    }
    if args.json {
        writeln!(w, "{}]", if table.rows.is_empty() { "" } else { "\n" }).map_err(io)?;
    }
    w.flush().map_err(io)
}
