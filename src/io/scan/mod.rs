//! Range scans in: each a [`Scan`], points in world coordinates and the sensor's origin, ready for
//! [`OccupancyMap::insert`](crate::map::OccupancyMap::insert).
//!
//! * [`graph`](read_scan_graph): OctoMap's scan graphs (`.graph`), scans in their sensor's frame with
//!   their poses, placed in the world as OctoMap's `insertPointCloud(const ScanNode&)` places them;
//! * [`log`](read_scan_log): OctoMap's scan log text (`.log`, `NODE x y z roll pitch yaw` and points);
//! * [`list`](read_scan_list): a text list of point files (PLY, PCD, XYZ, LAS/LAZ) with their poses or
//!   sensor origins, and the point files of a folder ([`read_scan_directory`]);
//! * [`Pose`]: OctoMap's 6-DoF pose, its arithmetic reproduced operation for operation in `f32`, so the
//!   world points are OctoMap's to the bit.
//!
//! ```
//! use ktree::io::read_scan_log;
//! use ktree::map::{OccupancyMap, VoxelState};
//! let log = b"NODE 0.05 0.05 0.05 0 0 0\n1 0 0\n";
//! let mut map = OccupancyMap::<3>::new(0.1).unwrap();
//! for node in read_scan_log(log, "a.log".as_ref()).unwrap() {
//!     let scan = node.to_scan();
//!     map.insert(&scan.points, scan.origin, None).unwrap();
//! }
//! assert_eq!(map.states(&[[1.05, 0.05, 0.05]]), [VoxelState::Occupied]);
//! ```

mod graph;
mod list;
mod log;
mod pose;

use std::path::Path;

pub use graph::{read_scan_graph, ScanNode};
pub use list::{read_scan_directory, read_scan_list};
pub use log::read_scan_log;
pub use pose::Pose;

use super::geometry_file::{extension, io_error, GeometryFileError};

/// One range scan: its points in world coordinates and where the sensor was.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scan {
    /// The points the rays ended at, in world coordinates.
    pub points: Vec<[f32; 3]>,
    /// The sensor's origin, where every ray starts, in world coordinates.
    pub origin: [f32; 3],
}

/// Reads the scans of a file, by its extension: `.graph` a scan graph ([`read_scan_graph`]), `.log` a
/// scan log ([`read_scan_log`]), anything else a scan list ([`read_scan_list`]). For a folder of point
/// files, whose sensor origin must be given, see [`read_scan_directory`].
///
/// # Errors
/// The reader's [`GeometryFileError`], naming the file and the byte offset or line.
pub fn read_scans(path: &Path) -> Result<Vec<Scan>, GeometryFileError> {
    let nodes = match extension(path).as_str() {
        "graph" => {
            let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
            read_scan_graph(&bytes, path)?
        }
        "log" => {
            let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
            read_scan_log(&bytes, path)?
        }
        _ => return read_scan_list(path),
    };
    Ok(nodes.iter().map(ScanNode::to_scan).collect())
}
