//! Occupancy maps (`ktree.OccupancyMap`): the library's [`OccupancyMap`] of dimension 2 or 3, scans in as
//! numpy arrays of world coordinates (converted to float32, as OctoMap stores points), voxel states and
//! keys out as numpy arrays, and the map's parts as `ktree.Tree` objects at the map's keys, so that every
//! operation of trees applies to them. The dimension is chosen at run time ([`AnyMap`]); each method is
//! one call of the library on the map inside.

use std::path::PathBuf;

use ktree::io::{
    read_bt_map, read_ot_map_with_colours, write_bt_map, write_color_ot_map, write_ot_map,
};
use ktree::map::{
    probability, CastEnd, HistoryRecorder, MapHistory, OccupancyMap, SensorModel, VoxelState,
};
use ktree::value::Rgb;
use ktree::{AnyTree, AnyValuedTree, KTree};
use numpy::ndarray::{Array1, Array2};
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLike2, PyArrayLikeDyn};
use pyo3::prelude::*;

use crate::arrays::{rows, Numbers};
use crate::failure::Failure;
use crate::Tree;

/// An occupancy map of a dimension known at run time.
#[derive(Debug, Clone)]
enum AnyMap {
    D2(OccupancyMap<2>),
    D3(OccupancyMap<3>),
}

/// Runs `$body` on the `OccupancyMap<K>` inside an [`AnyMap`] (`&` or `&mut`), with `K` bound as a constant.
macro_rules! with_map {
    ($map:expr, $m:ident, K => $body:expr) => {
        match $map {
            AnyMap::D2($m) => {
                #[allow(dead_code)]
                const K: usize = 2;
                $body
            }
            AnyMap::D3($m) => {
                #[allow(dead_code)]
                const K: usize = 3;
                $body
            }
        }
    };
}

/// The dimensions a map may have.
const DIMS: [usize; 2] = [2, 3];

/// A voxel's state as `states` returns it.
fn state_code(s: VoxelState) -> u8 {
    match s {
        VoxelState::Unknown => OccupancyMapPy::UNKNOWN,
        VoxelState::Free => OccupancyMapPy::FREE,
        VoxelState::Occupied => OccupancyMapPy::OCCUPIED,
    }
}

/// The world coordinates of an `(N, dim)` array of numbers (any numeric dtype; numpy converts it to
/// float32), row after row. `what` names the array in errors.
fn points_of<'py>(
    points: &Bound<'py, PyAny>,
    dim: usize,
    what: &str,
) -> Result<Numbers<'py, f32, numpy::ndarray::IxDyn>, Failure> {
    let array: PyArrayLikeDyn<'py, f32, AllowTypeChange> = points.extract().map_err(|e| {
        Failure::Value(format!(
            "{what} must be an (N, {dim}) array of numbers: {e}"
        ))
    })?;
    let numbers = Numbers::new(array);
    numbers.rows_of(dim, false, what)?;
    Ok(numbers)
}

/// `dim` numbers of a sequence as float32.
fn coordinates<const K: usize>(values: &[f64], what: &str) -> Result<[f32; K], Failure> {
    if values.len() != K {
        return Err(Failure::Value(format!(
            "{what} must have {K} coordinates, got {}",
            values.len()
        )));
    }
    Ok(std::array::from_fn(|i| values[i] as f32))
}

/// Ray casts on a map, as `cast_rays` returns them (`MapRayHits`): per ray whether it hit an occupied
/// voxel, the world centre and the keys of the voxel where it ended (NaN and -1 when it left the map) and
/// why it ended (a code of `OccupancyMapPy`).
struct MapCasts {
    hit: Array1<bool>,
    end: Array2<f64>,
    key: Array2<i64>,
    reason: Array1<u8>,
}

/// The rays of flat `(N, 3)` origins and directions (float32, row after row; a single row of either is
/// the same for every ray of the other) cast on `map` with OctoMap's castRay (`max_range` ≤ 0: none).
///
/// # Errors
/// A `ValueError` naming the ray for a coordinate that is not finite or a direction of length 0 (or one
/// whose squared length is beyond float32), and for counts of origins and directions that differ.
fn cast_map_rays(
    map: &OccupancyMap<3>,
    origins: &[f32],
    directions: &[f32],
    ignore_unknown: bool,
    max_range: f64,
) -> Result<MapCasts, Failure> {
    let (origins, directions) = (rows::<3, f32>(origins), rows::<3, f32>(directions));
    let n = match (origins.len(), directions.len()) {
        (1, n) | (n, 1) => n,
        (a, b) if a == b => a,
        (a, b) => {
            return Err(Failure::Value(format!(
                "cast_rays: {a} origins and {b} directions: give as many of each, or one origin or \
                 one direction for all rays"
            )))
        }
    };
    let nth = |rows: &[[f32; 3]], i: usize| rows[if rows.len() == 1 { 0 } else { i }];
    let grid = *map.grid();
    let mut out = MapCasts {
        hit: Array1::from_elem(n, false),
        end: Array2::from_elem((n, 3), f64::NAN),
        key: Array2::from_elem((n, 3), -1),
        reason: Array1::from_elem(n, OccupancyMapPy::OUTSIDE),
    };
    for i in 0..n {
        let (o, d) = (nth(origins, i), nth(directions, i));
        if o.iter().any(|c| !c.is_finite()) {
            return Err(Failure::Value(format!(
                "cast_rays: the origin of ray {i} has a coordinate that is not finite (as float32)"
            )));
        }
        if d.iter().any(|c| !c.is_finite()) {
            return Err(Failure::Value(format!(
                "cast_rays: the direction of ray {i} has a coordinate that is not finite (as float32)"
            )));
        }
        // The squared length as OctoMap's normalized() sums it, in float32.
        let length_sq: f32 = d.iter().map(|c| c * c).sum();
        if !(length_sq > 0.0 && length_sq.is_finite()) {
            return Err(Failure::Value(format!(
                "cast_rays: the direction of ray {i}, {d:?}, has no length as float32 (zero, or its \
                 squares under- or overflow)"
            )));
        }
        let (reason, key) = match map.cast_ray(o, d, ignore_unknown, max_range) {
            CastEnd::Occupied(k) => (OccupancyMapPy::OCCUPIED, k),
            CastEnd::Unknown(k) => (OccupancyMapPy::UNKNOWN, k),
            CastEnd::Range(k) => (OccupancyMapPy::BEYOND_RANGE, k),
            CastEnd::Outside(Some(k)) => (OccupancyMapPy::OUTSIDE, k),
            CastEnd::Outside(None) => continue,
        };
        out.hit[i] = reason == OccupancyMapPy::OCCUPIED;
        out.reason[i] = reason;
        for (a, &k) in key.iter().enumerate() {
            out.end[[i, a]] = grid.centre(k);
            out.key[[i, a]] = i64::from(k);
        }
    }
    Ok(out)
}

/// An occupancy map of dimension 2 or 3 from range scans, with OctoMap's semantics: voxels of side
/// `resolution` keyed as OctoMap keys them (2**16 a side, voxel key k along an axis covering world
/// coordinates [(k - 32768) * resolution, (k - 32767) * resolution)), each unknown (never observed), free
/// or occupied by its log-odds, updated by each scan as OctoMap's insertPointCloud updates them.
///
/// The parts (`occupied()`, `free()`, `unknown()`) are trees in a level-16 universe whose voxel
/// coordinates are the keys (`keys(points)` gives them for world points); `log_odds()` is a tree with
/// float32 values.
///
/// A map is changed in place by `insert` only, which releases the interpreter lock: another thread that
/// uses the same map meanwhile gets a RuntimeError (the map is borrowed), never a map half updated.
#[pyclass(name = "OccupancyMap", module = "ktree")]
pub(crate) struct OccupancyMapPy {
    map: AnyMap,
    /// The steps recorded, for a map made with `history=True`.
    recorder: Option<HistoryRecorder>,
    /// The voxels' colours, for a 3-D map given some (`set_colours`, or read from a `ColorOcTree`).
    colours: Option<KTree<3, Rgb>>,
}

impl OccupancyMapPy {
    /// The map's dimension.
    fn dim_of(&self) -> usize {
        with_map!(&self.map, _m, K => K)
    }
}

#[pymethods]
impl OccupancyMapPy {
    /// What `states` says of a voxel never observed.
    #[classattr]
    const UNKNOWN: u8 = 0;
    /// What `states` says of a voxel observed, with log-odds below the occupancy threshold.
    #[classattr]
    const FREE: u8 = 1;
    /// What `states` says of a voxel with log-odds at or above the occupancy threshold.
    #[classattr]
    const OCCUPIED: u8 = 2;
    /// What `cast_rays` says of a ray that went beyond its maximum range.
    #[classattr]
    const BEYOND_RANGE: u8 = 3;
    /// What `cast_rays` says of a ray that left the map, or started outside it.
    #[classattr]
    const OUTSIDE: u8 = 4;

    /// An empty map (every voxel unknown) of dimension `dim` (2 or 3) and voxels of side `resolution`,
    /// with a sensor model given by probabilities (OctoMap's defaults): of a hit, of a miss, the clamps
    /// of a voxel's probability, and the probability from which a voxel is occupied.
    ///
    /// With `history=True` (3-D maps), the map's state after each `insert` is kept as a step of its
    /// history (`history()`).
    #[new]
    #[pyo3(signature = (resolution, dim = 3, prob_hit = 0.7, prob_miss = 0.4, clamp_min = 0.1192, clamp_max = 0.971, occupancy = 0.5, history = false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        resolution: f64,
        dim: usize,
        prob_hit: f64,
        prob_miss: f64,
        clamp_min: f64,
        clamp_max: f64,
        occupancy: f64,
        history: bool,
    ) -> PyResult<Self> {
        let model =
            SensorModel::from_probabilities(prob_hit, prob_miss, clamp_min, clamp_max, occupancy);
        let map = match dim {
            2 => AnyMap::D2(OccupancyMap::with_model(resolution, model).map_err(Failure::Value)?),
            3 => AnyMap::D3(OccupancyMap::with_model(resolution, model).map_err(Failure::Value)?),
            _ => {
                return Err(Failure::Value(format!(
                    "an occupancy map has dimension {} or {}, not {dim}",
                    DIMS[0], DIMS[1]
                ))
                .into())
            }
        };
        let recorder = match (&map, history) {
            (_, false) => None,
            (AnyMap::D3(m), true) => Some(HistoryRecorder::new(*m.grid())),
            (AnyMap::D2(_), true) => {
                return Err(Failure::Value(
                    "a history is kept of 3-D maps (its time is the fourth axis)".into(),
                )
                .into())
            }
        };
        Ok(Self {
            map,
            recorder,
            colours: None,
        })
    }

    /// Integrates one scan: `points` an (N, dim) array of world coordinates (float64 and other numbers
    /// are converted to float32) seen from `origin` (dim numbers). Every ray from the origin marks the
    /// voxels it crosses before its point free (a miss) and the point's voxel occupied (a hit; hits win,
    /// each voxel is updated once a scan). With `max_range`, a ray is cut at that distance and a point
    /// beyond it is no hit. Rays leaving the map are skipped. Returns the number of voxels updated.
    #[pyo3(signature = (points, origin, max_range = None))]
    fn insert(
        &mut self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        origin: Vec<f64>,
        max_range: Option<f64>,
    ) -> PyResult<usize> {
        if let Some(m) = max_range {
            if m.is_nan() || m < 0.0 {
                return Err(Failure::Value(format!(
                    "insert: max_range must be a number at least 0 (or None), not {m}"
                ))
                .into());
            }
        }
        let dim = self.dim_of();
        let numbers = points_of(points, dim, "insert: points")?;
        let flat = numbers.flat();
        let updated = with_map!(&mut self.map, m, K => {
            let origin = coordinates::<K>(&origin, "insert: origin")?;
            py.detach(|| m.insert(rows::<K, f32>(flat), origin, max_range))
                .map_err(|e| Failure::Value(format!("insert: {e}")))?
                .len()
        });
        if let (Some(recorder), AnyMap::D3(m)) = (self.recorder.as_mut(), &self.map) {
            py.detach(|| recorder.record(m))
                .map_err(|e| Failure::Value(format!("insert: {e}")))?;
        }
        Ok(updated)
    }

    /// Forgets the voxels whose centres lie farther than `radius` from `centre` (dim numbers, world
    /// coordinates): they become unknown and lose their colours; the others keep their log-odds. A map
    /// kept within a distance of the sensor on a long run holds the region around it, not the whole path.
    fn forget_outside(&mut self, py: Python<'_>, centre: Vec<f64>, radius: f64) -> PyResult<()> {
        if self.recorder.is_some() {
            return Err(Failure::Value(
                "forget_outside: a map that keeps a history forgets nothing (its steps record what was seen)"
                    .into(),
            )
            .into());
        }
        with_map!(&mut self.map, m, K => {
            coordinates::<K>(&centre, "forget_outside: centre")?;
            let centre: [f64; K] = std::array::from_fn(|i| centre[i]);
            py.detach(|| m.forget_outside(centre, radius))
                .map_err(|e| Failure::Value(format!("forget_outside: {e}")))?;
        });
        if let (Some(colours), AnyMap::D3(m)) = (&self.colours, &self.map) {
            self.colours = Some(py.detach(|| colours.mask(&m.log_odds().shape())));
        }
        Ok(())
    }

    /// The map's history (a map made with `history=True`): one step for each `insert` so far.
    fn history(&self, py: Python<'_>) -> PyResult<MapHistoryPy> {
        let recorder = self.recorder.as_ref().ok_or_else(|| {
            Failure::Value("history: this map keeps none (make it with history=True)".into())
        })?;
        Ok(MapHistoryPy {
            history: py.detach(|| recorder.finish()),
        })
    }

    /// Colours the observed voxels holding `points` (an (N, 3) array of world coordinates, converted to
    /// float32) with `colours` (an (N, 3) uint8 array of red, green, blue): each voxel the mean of its
    /// points' colours (rounded), replacing the colour it had. Points in unknown voxels or outside the map
    /// colour nothing, as OctoMap's ColorOcTree colours only the nodes it has. The colours are kept by
    /// `save` to `.ot` (a ColorOcTree; white is its "no colour") and read back by `load`. Returns the
    /// number of voxels coloured. 3-D maps only.
    fn set_colours(
        &mut self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        colours: &Bound<'_, PyAny>,
    ) -> PyResult<u64> {
        let AnyMap::D3(map) = &self.map else {
            return Err(Failure::Value(
                "set_colours: colours are kept for 3-D maps (OctoMap's ColorOcTree)".into(),
            )
            .into());
        };
        let numbers = points_of(points, 3, "set_colours: points")?;
        let array: PyArrayLike2<'_, u8, AllowTypeChange> = colours.extract().map_err(|e| {
            Failure::Value(format!(
                "set_colours: colours must be an (N, 3) array of uint8: {e}"
            ))
        })?;
        let array = array.as_array();
        if array.ncols() != 3 {
            return Err(Failure::Value(format!(
                "set_colours: colours must be (N, 3), got {:?}",
                array.shape()
            ))
            .into());
        }
        let rgb: Vec<Rgb> = array
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect();
        let flat = numbers.flat();
        let (colours, coloured) = py.detach(|| -> Result<_, Failure> {
            let new = map
                .colours_of_points(rows::<3, f32>(flat), &rgb)
                .map_err(|e| Failure::Value(format!("set_colours: {e}")))?;
            let coloured = new.voxel_count() as u64;
            let all = match &self.colours {
                Some(old) => old
                    .overlay(&new)
                    .map_err(|e| Failure::Value(format!("set_colours: {e}")))?,
                None => new,
            };
            Ok((all, coloured))
        })?;
        self.colours = Some(colours);
        Ok(coloured)
    }

    /// The voxels' colours as a 3-D tree with rgb values at the map's keys (a level-16 universe, as
    /// `occupied()`), or None for a map given none.
    fn colours(&self) -> Option<Tree> {
        self.colours
            .as_ref()
            .map(|c| Tree::valued(AnyValuedTree::from(c.clone()), 0.0))
    }

    /// The state of the voxels holding `points` (an (N, dim) array of world coordinates, converted to
    /// float32): a uint8 array of `UNKNOWN` (also outside the map), `FREE` or `OCCUPIED`.
    fn states<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<u8>>> {
        let numbers = points_of(points, self.dim_of(), "states: points")?;
        let flat = numbers.flat();
        let out: Vec<u8> = with_map!(&self.map, m, K => py.detach(|| {
            m.states(rows::<K, f32>(flat)).into_iter().map(state_code).collect()
        }));
        Ok(out.into_pyarray(py))
    }

    /// Casts rays through a 3-D map as OctoMap's castRay casts them: from the voxel of each origin along
    /// its direction (world coordinates, converted to float32; `origins` and `directions` are (N, 3)
    /// arrays, or 3 numbers for one origin or one direction shared by all rays), voxel by voxel until an
    /// occupied voxel (a hit), an unknown voxel (unless `ignore_unknown`: then rays pass through them),
    /// the first voxel whose centre is farther than `max_range` from the origin, or the map's edge. A ray
    /// whose origin is in an occupied voxel hits it.
    ///
    /// Returns a `MapRayHits` named tuple: `hit` (N,) bool (the ray ended in an occupied voxel), `end`
    /// (N, 3) float64 (the world centre of the voxel where it ended — for `OUTSIDE`, the last voxel in
    /// the map, NaN if the origin is outside it), `key` (N, 3) int64 (that voxel's keys, or -1) and `reason` (N,) uint8: `OCCUPIED` (a hit), `UNKNOWN`
    /// (an unknown voxel stopped it), `BEYOND_RANGE` or `OUTSIDE` (it left the map, or its origin is
    /// outside it).
    ///
    /// A coordinate that is not finite, a direction of length 0, a `max_range` that is not a positive
    /// number, or counts of origins and directions that differ are a ValueError; so is a 2-D map.
    #[pyo3(signature = (origins, directions, ignore_unknown = false, max_range = None))]
    fn cast_rays<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        ignore_unknown: bool,
        max_range: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let AnyMap::D3(map) = &self.map else {
            return Err(Failure::Value(format!(
                "cast_rays: rays are cast on 3-D maps (OctoMap's castRay); this map has dimension {}",
                self.dim_of()
            ))
            .into());
        };
        let range = match max_range {
            None => -1.0,
            Some(m) if m > 0.0 => m,
            Some(m) => {
                return Err(Failure::Value(format!(
                    "cast_rays: max_range must be a positive number (or None), not {m}"
                ))
                .into())
            }
        };
        let rays = |a: &Bound<'py, PyAny>, what: &str| {
            let array: PyArrayLikeDyn<'py, f32, AllowTypeChange> = a.extract().map_err(|e| {
                Failure::Value(format!(
                    "cast_rays: {what} must be 3 numbers or an (N, 3) array of numbers: {e}"
                ))
            })?;
            let numbers = Numbers::new(array);
            numbers.rows_of(3, true, &format!("cast_rays: {what}"))?;
            Ok::<_, Failure>(numbers)
        };
        let (o, d) = (rays(origins, "origins")?, rays(directions, "directions")?);
        let (o, d) = (o.flat(), d.flat());
        let casts = py.detach(|| cast_map_rays(map, o, d, ignore_unknown, range))?;
        let hits = py.import("ktree")?.getattr("MapRayHits")?;
        hits.call1((
            casts.hit.into_pyarray(py),
            casts.end.into_pyarray(py),
            casts.key.into_pyarray(py),
            casts.reason.into_pyarray(py),
        ))
    }

    /// The keys of the voxels holding `points` (an (N, dim) array of world coordinates, converted to
    /// float32): an (N, dim) int64 array, the voxel coordinates of the map's trees; a row of -1 for a
    /// point outside the map.
    fn keys<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let dim = self.dim_of();
        let numbers = points_of(points, dim, "keys: points")?;
        let flat = numbers.flat();
        let out: Vec<i64> = with_map!(&self.map, m, K => {
            let grid = *m.grid();
            rows::<K, f32>(flat)
                .iter()
                .flat_map(|&p| match grid.keys(p) {
                    Some(k) => k.map(i64::from),
                    None => [-1; K],
                })
                .collect()
        });
        let array = Array2::from_shape_vec((flat.len() / dim, dim), out).map_err(Failure::value)?;
        Ok(array.into_pyarray(py))
    }

    /// The occupied voxels, as a tree (level 16, at the map's keys).
    fn occupied(&self, py: Python<'_>) -> Tree {
        Tree::binary(with_map!(&self.map, m, K => py.detach(|| AnyTree::from(m.occupied()))))
    }

    /// The free voxels (observed, not occupied), as a tree.
    fn free(&self, py: Python<'_>) -> Tree {
        Tree::binary(with_map!(&self.map, m, K => py.detach(|| AnyTree::from(m.free()))))
    }

    /// The unknown voxels (never observed), as a tree.
    fn unknown(&self, py: Python<'_>) -> Tree {
        Tree::binary(with_map!(&self.map, m, K => py.detach(|| AnyTree::from(m.unknown()))))
    }

    /// The log-odds of the observed voxels, as a tree with float32 values (unknown voxels are empty; dense
    /// arrays hold 0, the log-odds of probability 0.5, there).
    fn log_odds(&self, py: Python<'_>) -> Tree {
        let values =
            with_map!(&self.map, m, K => py.detach(|| AnyValuedTree::from(m.log_odds().clone())));
        Tree::valued(values, 0.0)
    }

    /// Writes a 3-D map as OctoMap's `.ot` (every log-odds; a ColorOcTree with the map's colours if it
    /// has some) or `.bt` (each known voxel free or occupied), or as a `.ktree` of its log-odds with its world frame (as `ktree map` writes, read in place by
    /// `ktree query` and `ktree raycast`), atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let AnyMap::D3(map) = &self.map else {
            return Err(Failure::Value(format!(
                "{}: OctoMap's files hold 3-D maps; this map has dimension 2",
                path.display()
            ))
            .into());
        };
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        Ok(py.detach(|| match ext.as_deref() {
            Some("ot") => ktree::fs::write_atomic_with(&path, |w| match &self.colours {
                Some(colours) => write_color_ot_map(w, map, colours),
                None => write_ot_map(w, map),
            })
            .map_err(|e| Failure::of_error(&e, &path)),
            Some("bt") => ktree::fs::write_atomic_with(&path, |w| write_bt_map(w, map))
                .map_err(|e| Failure::of_error(&e, &path)),
            Some("ktree") => ktree::io::ktree::write_map_ktree_file(&path, map)
                .map_err(|e| Failure::of_error(&e, &path)),
            _ => Err(Failure::Value(format!(
                "{}: a map is saved as .ot, .bt or .ktree",
                path.display()
            ))),
        })?)
    }

    /// Reads a 3-D map from OctoMap's `.ot` or `.bt` file or a `.ktree` map, with a sensor model given by
    /// probabilities as for the constructor (a `.bt` file's occupied voxels take the upper clamp, its free
    /// ones the lower). A ColorOcTree's colours are kept (`colours()`).
    #[staticmethod]
    #[pyo3(signature = (path, prob_hit = 0.7, prob_miss = 0.4, clamp_min = 0.1192, clamp_max = 0.971, occupancy = 0.5))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        prob_hit: f64,
        prob_miss: f64,
        clamp_min: f64,
        clamp_max: f64,
        occupancy: f64,
    ) -> PyResult<Self> {
        let model =
            SensorModel::from_probabilities(prob_hit, prob_miss, clamp_min, clamp_max, occupancy);
        model.check().map_err(Failure::Value)?;
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let (map, colours) = py.detach(|| {
            let bytes = std::fs::read(&path).map_err(|e| Failure::of_error(&e, &path))?;
            let name = path.display().to_string();
            match ext.as_deref() {
                Some("bt") => read_bt_map(&bytes, &name, model)
                    .map(|m| (m, None))
                    .map_err(|e| Failure::of_error(&e, &path)),
                Some("ktree") => ktree::io::ktree::read_map_ktree(&bytes, &name, model)
                    .map(|m| (m, None))
                    .map_err(|e| Failure::of_error(&e, &path)),
                _ => read_ot_map_with_colours(&bytes, &name, model)
                    .map_err(|e| Failure::of_error(&e, &path)),
            }
        })?;
        Ok(Self {
            map: AnyMap::D3(map),
            recorder: None,
            colours,
        })
    }

    /// The side of a voxel.
    #[getter]
    fn resolution(&self) -> f64 {
        with_map!(&self.map, m, K => m.grid().resolution())
    }

    /// The dimension (2 or 3).
    #[getter]
    fn dim(&self) -> usize {
        self.dim_of()
    }

    fn __repr__(&self) -> String {
        let (model, observed) =
            with_map!(&self.map, m, K => (*m.model(), m.log_odds().voxel_count()));
        // The probabilities as float32: what the model's float32 log-odds hold of the ones given.
        let p = |l: f32| probability(l) as f32;
        format!(
            "OccupancyMap(resolution={}, dim={}, prob_hit={}, prob_miss={}, clamp_min={}, clamp_max={}, \
             occupancy={}, observed={observed})",
            self.resolution(),
            self.dim_of(),
            p(model.hit),
            p(model.miss),
            p(model.clamp_min),
            p(model.clamp_max),
            p(model.occupied),
        )
    }
}

/// A 3-D map's history as one 4-D tree (`tree`): time is the fourth axis, one position a step (an
/// `insert`), and voxel (x, y, z, t) holds the state key (x, y, z) took at step t (`OccupancyMap.FREE` or
/// `OccupancyMap.OCCUPIED`) where it changed; empty where nothing changed.
#[pyclass(name = "MapHistory", module = "ktree", frozen)]
pub(crate) struct MapHistoryPy {
    history: MapHistory,
}

#[pymethods]
impl MapHistoryPy {
    /// The number of steps.
    #[getter]
    fn steps(&self) -> u32 {
        self.history.steps()
    }

    /// The history as a 4-D tree with uint8 values (level 16, at the map's keys and steps).
    #[getter]
    fn tree(&self) -> Tree {
        Tree::valued(AnyValuedTree::from(self.history.tree().clone()), 0.0)
    }

    /// The map's states after step `step`: a 3-D tree with uint8 values `FREE` and `OCCUPIED` (unknown
    /// voxels empty).
    fn at(&self, py: Python<'_>, step: u32) -> PyResult<Tree> {
        let labels = py
            .detach(|| self.history.at(step))
            .map_err(|e| Failure::Value(format!("at: {e}")))?;
        Ok(Tree::valued(AnyValuedTree::from(labels), 0.0))
    }

    /// The static map: the voxels occupied at some step and never observed free, as a 3-D tree.
    fn static_map(&self, py: Python<'_>) -> Tree {
        Tree::binary(AnyTree::from(py.detach(|| self.history.static_map())))
    }

    /// The voxels occupied at some step and observed free at another (moving objects and their
    /// trails), as a 3-D tree.
    fn moved(&self, py: Python<'_>) -> Tree {
        Tree::binary(AnyTree::from(py.detach(|| self.history.moved())))
    }

    /// Where and when voxels that are free at some step became occupied, as a 4-D tree: what moved, by
    /// one Boolean in 4-D.
    fn dynamic(&self, py: Python<'_>) -> Tree {
        Tree::binary(AnyTree::from(py.detach(|| self.history.dynamic())))
    }

    /// Writes the history as a `.ktree` file (the 4-D tree, uint8, with the map's resolution as its world
    /// frame and the number of steps; as `ktree map --history` writes), atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        Ok(py.detach(|| {
            ktree::io::ktree::write_history_ktree_file(&path, &self.history)
                .map_err(|e| Failure::of_error(&e, &path))
        })?)
    }

    /// Reads a history saved by `save` or written by `ktree map --history`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let history = py.detach(|| {
            let bytes = std::fs::read(&path).map_err(|e| Failure::of_error(&e, &path))?;
            ktree::io::ktree::read_history_ktree(&bytes, &path.display().to_string())
                .map_err(|e| Failure::of_error(&e, &path))
        })?;
        Ok(Self { history })
    }

    /// The side of the maps' voxels.
    #[getter]
    fn resolution(&self) -> f64 {
        self.history.grid().resolution()
    }

    fn __eq__(&self, other: PyRef<'_, Self>) -> bool {
        self.history == other.history
    }

    fn __repr__(&self) -> String {
        format!(
            "MapHistory(steps={}, nodes={})",
            self.history.steps(),
            self.history.tree().node_count()
        )
    }
}
