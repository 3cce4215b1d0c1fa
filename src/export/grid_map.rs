//! A quadtree as the occupancy grid ROS's `map_server` reads: a PNG of the universe (pixel column `x`,
//! row `side − 1 − y`: the image's top is the largest `y`) in its three grey levels — occupied 0 (black),
//! free 254, unknown 205 — and a YAML file beside it naming the image, the resolution (the frame's voxel
//! size), the origin (the world position of voxel (0, 0)'s lower corner) and the thresholds `map_saver`
//! writes (`occupied_thresh: 0.65`, `free_thresh: 0.196`, `negate: 0`), so that `map_server` reads each
//! pixel back as what it was written as.
//!
//! ```
//! use ktree::export::grid_map::{write_grid_map, OCCUPIED, FREE};
//! use ktree::export::Frame;
//! use ktree::KTree;
//! let floor = KTree::<2>::from_dense(1, &[true, false, false, false]).unwrap(); // (0, 0) occupied
//! let dir = tempfile::tempdir().unwrap();
//! let png = dir.path().join("floor.png");
//! let frame = Frame { voxel_size: 0.05, origin: [-1.0, 2.0, 0.0] };
//! let yaml = write_grid_map(&png, &floor, None, &frame).unwrap();
//! let text = std::fs::read_to_string(&yaml).unwrap();
//! assert!(text.contains("image: floor.png") && text.contains("resolution: 0.05"));
//! assert!(text.contains("origin: [-1.0, 2.0, 0.0]"));
//! ```

use std::path::{Path, PathBuf};

use super::{ExportError, Frame};
use crate::tree::NodeState;
use crate::KTree;

/// The largest side of a map image (2^13 pixels, a level 13 universe).
pub const MAX_SIDE: u64 = 1 << 13;

/// The grey level of an occupied cell.
pub const OCCUPIED: u8 = 0;
/// The grey level of a free cell.
pub const FREE: u8 = 254;
/// The grey level of an unknown cell.
pub const UNKNOWN: u8 = 205;

/// Writes `occupied` as a map_server occupancy grid: the PNG at `png` and the YAML beside it (the same
/// name with `.yaml`), whose path is returned. Cells of `known` (when given) that are not occupied are
/// free and the rest unknown; without `known` every cell not occupied is free.
///
/// # Errors
/// [`ExportError::Usage`] for trees of different levels or a universe too large for an image;
/// [`ExportError::Write`] from the file system.
pub fn write_grid_map(
    png: &Path,
    occupied: &KTree<2>,
    known: Option<&KTree<2>>,
    frame: &Frame,
) -> Result<PathBuf, ExportError> {
    let usage = |message: String| ExportError::Usage {
        file: png.to_owned(),
        message,
    };
    if let Some(k) = known.filter(|k| k.level() != occupied.level()) {
        return Err(usage(format!(
            "the known cells' universe (level {}) is not the occupied cells' (level {})",
            k.level(),
            occupied.level()
        )));
    }
    let side = occupied.universe().side();
    if side > MAX_SIDE {
        return Err(usage(format!(
            "a universe of side {side} is larger than the {MAX_SIDE} pixels a side of a map image made \
             here: project a smaller region (crop the tree first)"
        )));
    }
    let width = side as u32;
    let n = side as usize;
    let mut grey = vec![if known.is_some() { UNKNOWN } else { FREE }; n * n];
    let mut paint = |tree: &KTree<2>, level: u8| {
        for (cell, state) in tree.leaves() {
            if state != NodeState::Full {
                continue;
            }
            let s = cell.side() as usize;
            let [x0, y0] = cell.origin.map(|c| c as usize);
            for y in y0..y0 + s {
                let row = n - 1 - y;
                grey[row * n + x0..row * n + x0 + s].fill(level);
            }
        }
    };
    if let Some(k) = known {
        paint(k, FREE);
    }
    paint(occupied, OCCUPIED);
    crate::display::png::write_grey_png(png, width, width, &grey)
        .map_err(|e| usage(e.to_string()))?;
    let yaml = png.with_extension("yaml");
    let name = png
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let text = format!(
        "image: {name}\nmode: trinary\nresolution: {:?}\norigin: [{:?}, {:?}, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        frame.voxel_size, frame.origin[0], frame.origin[1]
    );
    crate::fs::write_atomic(&yaml, text.as_bytes())?;
    Ok(yaml)
}
