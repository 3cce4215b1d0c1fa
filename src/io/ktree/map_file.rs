//! Occupancy maps kept as `.ktree` files: a version 3 file of `f32` log-odds in a map's universe (K = 3,
//! level 16; unknown voxels empty) whose world frame is the map's grid (voxels of its resolution, key 0 at
//! its corner) — what `ktree map --out map.ktree` writes. Read whole ([`read_map_ktree`]) or in place
//! ([`MappedMap`]: its states and ray casts read the file's pages they need, so a map larger than memory
//! answers them).
//!
//! ```
//! use ktree::io::ktree::{read_map_ktree, write_map_ktree_file, MappedMap};
//! use ktree::map::{OccupancyMap, SensorModel, VoxelState};
//! let mut map = OccupancyMap::<3>::new(0.1).unwrap();
//! map.insert(&[[1.05, 0.05, 0.05]], [0.05, 0.05, 0.05], None).unwrap();
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("map.ktree");
//! write_map_ktree_file(&path, &map).unwrap();
//! let mapped = MappedMap::open(&path, SensorModel::default()).unwrap();
//! let points = [[1.05, 0.05, 0.05], [0.55, 0.05, 0.05], [0.05, 1.05, 0.05]];
//! assert_eq!(mapped.view().states(&points).unwrap(), [VoxelState::Occupied, VoxelState::Free, VoxelState::Unknown]);
//! let bytes = std::fs::read(&path).unwrap();
//! assert_eq!(read_map_ktree(&bytes, "map.ktree", SensorModel::default()).unwrap(), map);
//! ```

use std::path::Path;

use super::v3::{read_valued_ktree_framed, write_valued_ktree_file_framed};
use super::v3_mapped::MappedValuedTree;
use super::{KtreeFileError, KtreeFileErrorKind};
use crate::fs::FileOpError;
use crate::map::{MapGrid, MapView, OccupancyMap, SensorModel};
use crate::space::WorldFrame;

/// The error for a file that holds a tree but not a map.
fn not_a_map(file: &str, why: String) -> KtreeFileError {
    KtreeFileError::at_byte(
        file.to_string(),
        0,
        KtreeFileErrorKind::Header(format!(
            "not an occupancy map ({why}; a .ktree map keeps float32 log-odds in a level-16 octree and its \
             resolution and OctoMap's origin as its world frame)"
        )),
    )
}

/// The grid of a map file's frame.
fn grid_of(frame: Option<WorldFrame>, file: &str) -> Result<MapGrid, KtreeFileError> {
    let frame = frame.ok_or_else(|| not_a_map(file, "no world frame".into()))?;
    MapGrid::from_world_frame(&frame).ok_or_else(|| {
        not_a_map(
            file,
            format!(
                "its frame, voxels of {} from {:?}, is not a map's",
                frame.voxel_size, frame.origin
            ),
        )
    })
}

/// Reads a map kept as a `.ktree` file's bytes, with the sensor model `model` (the file keeps log-odds,
/// not the model that made them).
///
/// # Errors
/// The file's errors ([`KtreeFileError`]), or [`KtreeFileErrorKind::Header`] for a tree that is not a
/// map's (another universe, no frame or another one).
pub fn read_map_ktree(
    bytes: &[u8],
    file: &str,
    model: SensorModel,
) -> Result<OccupancyMap<3>, KtreeFileError> {
    let (log_odds, frame) = read_valued_ktree_framed::<3, f32>(bytes, file)?;
    let grid = grid_of(frame, file)?;
    OccupancyMap::from_log_odds(grid, model, log_odds).map_err(|why| not_a_map(file, why))
}

/// Writes `map` as a `.ktree` file (through a temporary file renamed into place).
///
/// # Errors
/// The file system's, naming the file.
pub fn write_map_ktree_file(path: &Path, map: &OccupancyMap<3>) -> Result<(), FileOpError> {
    write_valued_ktree_file_framed(path, map.log_odds(), Some(&map.grid().world_frame()))
}

/// A map kept as a `.ktree` file, read in place: its log-odds a [`MappedValuedTree`] over the file's memory
/// map, its questions those of a [`MapView`] ([`MappedMap::view`]), each read checked.
#[derive(Debug, Clone)]
pub struct MappedMap {
    grid: MapGrid,
    model: SensorModel,
    log_odds: MappedValuedTree<3, f32>,
}

impl MappedMap {
    /// Opens, checks and maps the map file `path`, with the sensor model `model`.
    ///
    /// # Errors
    /// As [`MappedValuedTree::open`], or [`KtreeFileErrorKind::Header`] for a tree that is not a map's.
    pub fn open(path: &Path, model: SensorModel) -> Result<Self, KtreeFileError> {
        let log_odds = MappedValuedTree::<3, f32>::open(path)?;
        let file = path.display().to_string();
        let grid = grid_of(log_odds.frame(), &file)?;
        MapView::new(grid, model, &log_odds).map_err(|why| not_a_map(&file, why))?;
        Ok(Self {
            grid,
            model,
            log_odds,
        })
    }

    /// The map's questions (states at points, ray casts, its occupied, free and unknown parts).
    pub fn view(&self) -> MapView<'_, 3, MappedValuedTree<3, f32>> {
        MapView::new(self.grid, self.model, &self.log_odds)
            .expect("checked when the file was opened")
    }
}
