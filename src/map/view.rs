//! A map's questions over its log-odds in any [`ValueStorage`]: in memory ([`OccupancyMap::view`]) or
//! read in place from a file (`io::MappedMap`), with one code for both.
//!
//! ```
//! use ktree::map::{MapView, OccupancyMap, VoxelState};
//! let mut map = OccupancyMap::<3>::new(0.1).unwrap();
//! map.insert(&[[1.05, 0.05, 0.05]], [0.05, 0.05, 0.05], None).unwrap();
//! let view = MapView::new(*map.grid(), *map.model(), map.log_odds()).unwrap();
//! assert_eq!(view.states(&[[1.05, 0.05, 0.05], [0.55, 0.05, 0.05]]).unwrap(), [VoxelState::Occupied, VoxelState::Free]);
//! assert_eq!(view.occupied().unwrap(), map.occupied());
//! ```

use super::{MapGrid, OccupancyMap, SensorModel, VoxelState, MAP_LEVEL};
use crate::ops::values::select_where;
use crate::query::values_at;
use crate::tree::ValueStorage;
use crate::KTree;

/// A map — its grid, its sensor model and its log-odds in a storage `S` (unknown voxels empty) — that
/// answers questions and changes nothing.
#[derive(Debug)]
pub struct MapView<'a, const K: usize, S> {
    grid: MapGrid,
    model: SensorModel,
    log_odds: &'a S,
}

impl<const K: usize, S> Clone for MapView<'_, K, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<const K: usize, S> Copy for MapView<'_, K, S> {}

impl<'a, const K: usize, S: ValueStorage<K, Value = f32>> MapView<'a, K, S> {
    /// The map of these log-odds, grid and model.
    ///
    /// # Errors
    /// A message if the storage's universe is not a map's ([`MAP_LEVEL`]) or the model cannot make a map.
    pub fn new(grid: MapGrid, model: SensorModel, log_odds: &'a S) -> Result<Self, String> {
        model.check()?;
        let level = log_odds.universe().level();
        if level != MAP_LEVEL {
            return Err(format!(
                "a map's tree has level {MAP_LEVEL}, this one {level}"
            ));
        }
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

    /// The log-odds of the observed voxels, at the map's keys.
    pub fn log_odds(&self) -> &'a S {
        self.log_odds
    }

    /// The state of a voxel of log-odds `l` (`None`: unknown).
    pub fn state_of(&self, l: Option<f32>) -> VoxelState {
        match l {
            None => VoxelState::Unknown,
            Some(l) if self.model.is_occupied(l) => VoxelState::Occupied,
            Some(_) => VoxelState::Free,
        }
    }

    /// The state of the voxels holding `points` (world coordinates; outside the map: unknown), on the
    /// threads of the current rayon pool.
    ///
    /// # Errors
    /// The storage's first read error.
    pub fn states(&self, points: &[[f32; K]]) -> Result<Vec<VoxelState>, S::Error>
    where
        S: Sync,
        S::Error: Send,
    {
        let keys: Vec<[u32; K]> = points
            .iter()
            .map(|&p| self.grid.keys(p).unwrap_or([u32::MAX; K]))
            .collect();
        Ok(values_at(self.log_odds, &keys)?
            .into_iter()
            .map(|v| self.state_of(v))
            .collect())
    }

    /// The occupied voxels, as a binary tree at the map's keys.
    ///
    /// # Errors
    /// The storage's first read error.
    pub fn occupied(&self) -> Result<KTree<K>, S::Error> {
        let model = self.model;
        select_where(self.log_odds, move |l| model.is_occupied(l))
    }

    /// The free voxels (observed, not occupied).
    ///
    /// # Errors
    /// The storage's first read error.
    pub fn free(&self) -> Result<KTree<K>, S::Error> {
        let model = self.model;
        select_where(self.log_odds, move |l| !model.is_occupied(l))
    }

    /// The unknown voxels (never observed).
    ///
    /// # Errors
    /// The storage's first read error.
    pub fn unknown(&self) -> Result<KTree<K>, S::Error> {
        Ok(!&select_where(self.log_odds, |_| true)?)
    }
}

impl<const K: usize> OccupancyMap<K> {
    /// The map as a [`MapView`] of its tree in memory.
    pub fn view(&self) -> MapView<'_, K, KTree<K, f32>> {
        MapView {
            grid: *self.grid(),
            model: *self.model(),
            log_odds: self.log_odds(),
        }
    }
}
