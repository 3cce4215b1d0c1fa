//! A map's history kept as a `.ktree` file: a version 3 file of the history's 4-D tree of states
//! ([`MapHistory::tree`]: `uint8`, K = 4, level 16), the maps' grid as its world frame (as a map file keeps
//! it) and its number of steps as the note [`STEPS_NOTE`] — what `ktree map --history` writes.
//!
//! ```
//! use ktree::io::ktree::{read_history_ktree, write_history_ktree_file};
//! use ktree::map::{HistoryRecorder, OccupancyMap};
//! let mut map = OccupancyMap::<3>::new(0.1).unwrap();
//! let mut recorder = HistoryRecorder::new(*map.grid());
//! for _ in 0..3 {
//!     map.insert(&[[1.05, 0.05, 0.05]], [0.05; 3], None).unwrap();
//!     recorder.record(&map).unwrap();
//! }
//! let history = recorder.finish();
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("history.ktree");
//! write_history_ktree_file(&path, &history).unwrap();
//! let back = read_history_ktree(&std::fs::read(&path).unwrap(), "history.ktree").unwrap();
//! // Every step kept, though nothing changed after the first.
//! assert_eq!((back.steps(), back.grid().resolution()), (3, 0.1));
//! assert_eq!(back, history);
//! ```

use std::path::Path;

use super::notes::Notes;
use super::v3::{read_valued_ktree_noted, write_valued_ktree_file_noted};
use super::{KtreeFileError, KtreeFileErrorKind};
use crate::fs::FileOpError;
use crate::map::{MapGrid, MapHistory};

/// The note holding a history's number of steps.
pub const STEPS_NOTE: &str = "steps";

/// The error for a file that holds a tree but not a map's history.
fn not_a_history(file: &str, why: String) -> KtreeFileError {
    KtreeFileError::at_byte(
        file.to_string(),
        0,
        KtreeFileErrorKind::Header(format!(
            "not a map's history ({why}; a .ktree history keeps uint8 states in a level-16 4-D tree, the \
             map's resolution and OctoMap's origin as its world frame, and its steps as the note \
             \"{STEPS_NOTE}\")"
        )),
    )
}

/// Writes `history` as a `.ktree` file (through a temporary file renamed into place).
///
/// # Errors
/// The file system's, naming the file.
pub fn write_history_ktree_file(path: &Path, history: &MapHistory) -> Result<(), FileOpError> {
    let notes = Notes::from([(STEPS_NOTE.to_string(), history.steps().to_string())]);
    let frame = history.grid().world_frame();
    write_valued_ktree_file_noted(path, history.tree(), Some(&frame), &notes)
}

/// Reads a map's history kept as a `.ktree` file's bytes. A file without the steps note (written before
/// it was kept) has the steps up to its last change.
///
/// # Errors
/// The file's errors ([`KtreeFileError`]), or [`KtreeFileErrorKind::Header`] for a tree that is not a
/// history (no map's frame, a steps note that is not a number, another universe or values).
pub fn read_history_ktree(bytes: &[u8], file: &str) -> Result<MapHistory, KtreeFileError> {
    let (tree, frame, notes) = read_valued_ktree_noted::<4, u8>(bytes, file)?;
    let grid = frame
        .as_ref()
        .and_then(MapGrid::from_world_frame)
        .ok_or_else(|| not_a_history(file, format!("its world frame is {frame:?}")))?;
    let steps = match notes.get(STEPS_NOTE) {
        None => None,
        Some(text) => Some(text.parse::<u32>().map_err(|_| {
            not_a_history(file, format!("its steps note {text:?} is not a number"))
        })?),
    };
    MapHistory::from_tree(grid, tree, steps).map_err(|why| not_a_history(file, why))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ktree::v3::write_valued_ktree_noted;
    use crate::map::{HistoryRecorder, OccupancyMap};

    #[test]
    fn histories_read_back_and_other_trees_are_refused() {
        let mut map = OccupancyMap::<3>::new(0.25).unwrap();
        let mut recorder = HistoryRecorder::new(*map.grid());
        for end in [
            [1.1f32, 0.1, 0.1],
            [0.6, 0.1, 0.1],
            [1.1, 0.1, 0.1],
            [1.1, 0.1, 0.1],
        ] {
            map.insert(&[end], [0.1; 3], None).unwrap();
            recorder.record(&map).unwrap();
        }
        let history = recorder.finish();
        let frame = history.grid().world_frame();
        let write = |notes: &[(&str, &str)], frame| {
            let notes: Notes = notes
                .iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect();
            let mut bytes = Vec::new();
            write_valued_ktree_noted(&mut bytes, history.tree(), frame, &notes).unwrap();
            bytes
        };
        let steps = history.steps().to_string();
        let back = read_history_ktree(&write(&[("steps", &steps)], Some(&frame)), "h").unwrap();
        assert_eq!(back, history);
        // The file written, read in place: the same notes.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.ktree");
        write_history_ktree_file(&path, &history).unwrap();
        let mapped = crate::io::ktree::v3::MappedValuedTree::<4, u8>::open(&path).unwrap();
        assert_eq!(mapped.notes().get(STEPS_NOTE), Some(&steps));
        assert_eq!(mapped.frame(), Some(frame));
        // Without the note: the steps up to the last change.
        let old = read_history_ktree(&write(&[], Some(&frame)), "h").unwrap();
        assert_eq!(old.tree(), history.tree());
        assert!(old.steps() <= history.steps());
        for (notes, frame, why) in [
            (vec![("steps", "many")], Some(&frame), "not a number"),
            (vec![("steps", "1")], Some(&frame), "after its 1 steps"),
            (vec![("steps", &*steps)], None, "world frame is None"),
        ] {
            let e = read_history_ktree(&write(&notes, frame), "h.ktree")
                .unwrap_err()
                .to_string();
            assert!(e.contains(why) && e.contains("h.ktree"), "{e}");
        }
    }
}
