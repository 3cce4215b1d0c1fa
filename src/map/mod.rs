//! Occupancy maps from range scans: every voxel unknown (never observed), free or occupied, from log-odds
//! updated by each scan's hits and misses — OctoMap's semantics ([`SensorModel`], [`MapGrid`],
//! [`key_ray`]), built on a valued tree ([`KTree<K, f32>`](crate::KTree) of log-odds; unknown voxels are
//! empty), so every operation of the crate applies to its parts.
//!
//! A scan's update ([`ScanUpdate`]) gathers the voxels its rays cross on all threads as bitmaps of blocks
//! of voxels, reads them back in Morton order and merges them into the map's tree in one pass from the
//! root down (the map's unobserved and uniform parts built as the keys come, without search). Rays may also be integrated one at
//! a time, as OctoMap's `insertRay` does ([`OccupancyMap::insert_ray`], [`OccupancyMap::insert_rays`]).
//!
//! ```
//! use ktree::map::{OccupancyMap, VoxelState};
//! // A quadtree map of 10 cm voxels; one scan of two points seen from the origin.
//! let mut map = OccupancyMap::<2>::new(0.1).unwrap();
//! map.insert(&[[1.05, 0.05], [0.05, 0.55]], [0.05, 0.05], None).unwrap();
//! assert_eq!(
//!     map.states(&[[1.05, 0.05], [0.55, 0.05], [-3.0, 2.0]]),
//!     [VoxelState::Occupied, VoxelState::Free, VoxelState::Unknown]
//! );
//! assert_eq!(map.occupied().voxel_count(), 2);
//! // The voxels the two rays cross before their ends: 10 along x, 5 along y, the sensor's shared.
//! assert_eq!(map.free().voxel_count(), 10 + 5 - 1);
//! ```

mod cast;
mod colours;
mod grid;
mod history;
mod leaves;
mod model;
mod plane;
// The vector instructions that step eight rays at a time are `unsafe` to call and to load and store.
#[allow(unsafe_code)]
mod ray_lanes;
mod rays;
mod traverse;
mod update;
mod view;
mod voxel_set;

pub use cast::CastEnd;
pub use grid::{MapGrid, CENTRE_KEY, MAP_LEVEL};
pub use history::{state_labels, HistoryRecorder, MapHistory, FREE, MAX_STEPS, OCCUPIED};
pub use leaves::{tree_from_leaves, Leaf};
pub use model::{log_odds, probability, SensorModel};
pub use plane::MapPlane;
pub use traverse::{clipped_end, key_ray, visit_key_ray, visit_morton_ray};
pub use update::{apply, ScanUpdate};
pub use view::MapView;

use crate::tree::storage::infallible;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::ValueState;
use crate::tree::TreeError;
use crate::KTree;

/// Checks rays before they change a map: every end (`end`, with `{i}` for its index) and the origin
/// (`start`) finite, the maximum range a distance.
fn check_rays<const K: usize>(
    ends: &[[f32; K]],
    origin: [f32; K],
    max_range: Option<f64>,
    end: &str,
    start: &str,
) -> Result<(), String> {
    if let Some(i) = ends.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        let end = end.replace("{i}", &i.to_string());
        return Err(format!("{end} has a coordinate that is not finite"));
    }
    if origin.iter().any(|c| !c.is_finite()) {
        return Err(format!("{start} has a coordinate that is not finite"));
    }
    if let Some(m) = max_range.filter(|m| m.is_nan() || *m < 0.0) {
        return Err(format!(
            "the maximum range {m} is not a distance (0 or more)"
        ));
    }
    Ok(())
}

/// What a map knows of a voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VoxelState {
    /// Never observed.
    Unknown,
    /// Observed, with log-odds below the occupancy threshold.
    Free,
    /// Observed, with log-odds at or above the occupancy threshold.
    Occupied,
}

/// An occupancy map of dimension `K` (2 or 3 for floor plans and rooms, any K the tree has): a grid, a
/// sensor model and the log-odds of the observed voxels.
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyMap<const K: usize> {
    grid: MapGrid,
    model: SensorModel,
    log_odds: KTree<K, f32>,
}

impl<const K: usize> OccupancyMap<K> {
    /// An empty map (every voxel unknown) of voxels of side `resolution`, OctoMap's default model.
    ///
    /// # Errors
    /// A message for a resolution that is not a positive number.
    pub fn new(resolution: f64) -> Result<Self, String> {
        Self::with_model(resolution, SensorModel::default())
    }

    /// An empty map with the sensor model `model`.
    ///
    /// # Errors
    /// A message for a resolution that is not a positive number or a model that cannot make a map
    /// ([`SensorModel::check`]).
    pub fn with_model(resolution: f64, model: SensorModel) -> Result<Self, String> {
        model.check()?;
        let grid = MapGrid::new(resolution)?;
        let unknown = build_top_down::<K, f32, (), TreeError>(
            MAP_LEVEL,
            (),
            |_, ()| Ok(Decision::Leaf(None)),
            |(), _| Ok(()),
        )
        .map_err(|e| e.to_string())?;
        Ok(Self {
            grid,
            model,
            log_odds: unknown,
        })
    }

    /// A map of these log-odds (unknown voxels empty), grid and model.
    ///
    /// # Errors
    /// A message if the tree's universe is not the map's ([`MAP_LEVEL`]) or the model cannot make a map.
    pub fn from_log_odds(
        grid: MapGrid,
        model: SensorModel,
        log_odds: KTree<K, f32>,
    ) -> Result<Self, String> {
        MapView::new(grid, model, &log_odds)?;
        Ok(Self {
            grid,
            model,
            log_odds,
        })
    }

    /// The map's grid.
    pub fn grid(&self) -> &MapGrid {
        &self.grid
    }

    /// The map's sensor model.
    pub fn model(&self) -> &SensorModel {
        &self.model
    }

    /// The log-odds of the observed voxels (unknown voxels are empty), at the map's keys.
    pub fn log_odds(&self) -> &KTree<K, f32> {
        &self.log_odds
    }

    /// Integrates one scan: `points` in world coordinates seen from `origin`, each ray cut at `max_range`
    /// if given (a point beyond it is no hit). Returns the scan's update (its voxels and the rays that left
    /// the map).
    ///
    /// # Errors
    /// A message for a coordinate that is not finite or a maximum range that is negative or not a number.
    pub fn insert(
        &mut self,
        points: &[[f32; K]],
        origin: [f32; K],
        max_range: Option<f64>,
    ) -> Result<ScanUpdate, String> {
        check_rays(
            points,
            origin,
            max_range,
            "point {i} of the scan",
            "the sensor origin",
        )?;
        let update = ScanUpdate::compute(&self.grid, points, origin, max_range);
        self.log_odds = apply(&self.log_odds, &update, &self.model);
        Ok(update)
    }

    /// The state of the voxels holding `points` (world coordinates; outside the map: unknown).
    pub fn states(&self, points: &[[f32; K]]) -> Vec<VoxelState> {
        infallible(self.view().states(points))
    }

    /// The state of a voxel of log-odds `l` (`None`: unknown).
    pub fn state_of(&self, l: Option<f32>) -> VoxelState {
        self.view().state_of(l)
    }

    /// The occupied voxels, as a binary tree at the map's keys.
    pub fn occupied(&self) -> KTree<K> {
        infallible(self.view().occupied())
    }

    /// The free voxels (observed, not occupied).
    pub fn free(&self) -> KTree<K> {
        infallible(self.view().free())
    }

    /// Forgets the voxels whose centres lie farther than `radius` from `centre` (world coordinates): they
    /// become unknown, the others keep their log-odds. A map kept within a distance of the sensor this way
    /// on a long run holds the region around it, not the whole path (its memory bounded by the region).
    ///
    /// ```
    /// use ktree::map::{OccupancyMap, VoxelState};
    /// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    /// map.insert(&[[2.05, 0.05, 0.05], [-0.55, 0.05, 0.05]], [0.05; 3], None).unwrap();
    /// map.forget_outside([0.0; 3], 1.0).unwrap();
    /// let states = map.states(&[[2.05, 0.05, 0.05], [0.95, 0.05, 0.05], [-0.55, 0.05, 0.05]]);
    /// assert_eq!(states, [VoxelState::Unknown, VoxelState::Free, VoxelState::Occupied]);
    /// ```
    ///
    /// # Errors
    /// A message for a centre or radius that is not finite, or a negative radius.
    pub fn forget_outside(&mut self, centre: [f64; K], radius: f64) -> Result<(), String> {
        if centre.iter().any(|c| !c.is_finite()) {
            return Err("the centre has a coordinate that is not finite".to_string());
        }
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(format!("the radius {radius} is not a distance (0 or more)"));
        }
        let (grid, tree) = (self.grid, &self.log_odds);
        // The nearest and farthest squared distances from the centre to the voxel centres of a cell.
        let reach = |cell: &crate::space::Cell<K>| -> (f64, f64) {
            let (mut near, mut far) = (0.0, 0.0);
            for (a, &c) in centre.iter().enumerate() {
                let lo = grid.centre(cell.origin()[a]);
                let hi = lo + (cell.side() - 1) as f64 * grid.resolution();
                let gap = (lo - c).max(c - hi).max(0.0);
                let span = (c - lo).abs().max((hi - c).abs());
                near += gap * gap;
                far += span * span;
            }
            (near, far)
        };
        let r2 = radius * radius;
        // A cell is settled whole only clear of the sphere by more than rounding; a voxel exactly.
        let slack = |cell: &crate::space::Cell<K>| {
            if cell.side() == 1 {
                0.0
            } else {
                1e-9 * (r2 + 1.0)
            }
        };
        let kept = build_top_down::<K, f32, InputNode<f32>, TreeError>(
            MAP_LEVEL,
            infallible(InputNode::root(tree)),
            |cell, node| {
                let value = match node.state {
                    ValueState::Empty => return Ok(Decision::Leaf(None)),
                    ValueState::Full(v) => Some(v),
                    ValueState::Partial | ValueState::Mixed => None,
                };
                let ((near, far), slack) = (reach(cell), slack(cell));
                Ok(if near > r2 + slack {
                    Decision::Leaf(None)
                } else if far <= r2 - slack && value.is_some() {
                    Decision::Leaf(value)
                } else {
                    Decision::Split
                })
            },
            |node, code| Ok(infallible(node.child(tree, code))),
        );
        self.log_odds = kept.map_err(|e| e.to_string())?;
        Ok(())
    }

    /// This map with its observed voxels inside `voxels` made free (their log-odds the model's lower
    /// clamp): the map without what moved ([`MapHistory::moved`]), for instance.
    ///
    /// # Errors
    /// A message if `voxels` is not a tree of the map's level.
    pub fn cleared(&self, voxels: &KTree<K>) -> Result<Self, String> {
        if voxels.level() != MAP_LEVEL {
            return Err(format!(
                "a map's voxels are a tree of level {MAP_LEVEL}, not {}",
                voxels.level()
            ));
        }
        let floor = self.model.clamp_min;
        let free = self
            .log_odds
            .mask(voxels)
            .map_values(|_| Some(floor))
            .map_err(|e| e.to_string())?;
        let log_odds = self.log_odds.overlay(&free).map_err(|e| e.to_string())?;
        Ok(Self { log_odds, ..*self })
    }

    /// The unknown voxels (never observed).
    pub fn unknown(&self) -> KTree<K> {
        infallible(self.view().unknown())
    }
}
