//! A map's history as one 4-D tree: time is the fourth axis, one position a step (a scan, or a bin of
//! scans). The tree records the **changes**: voxel `[x, y, z, t]` holds the state key `[x, y, z]` took at
//! step `t` ([`FREE`] or [`OCCUPIED`]) where it differs from the state before; an empty voxel records no
//! change (and a cell whose state holds over its whole span of steps may record it there). So what never
//! moves is recorded once, when it is first seen, and the history's size is about the static map's plus
//! the changes' — not the number of steps times the map, which a tree of every step's states would be
//! (its cells are cubes: a wall one voxel thick is a leaf a step).
//!
//! The 3-D map after any step is the last state recorded at or before it ([`MapHistory::at`]). What was
//! occupied at some time and observed free at another — a person walking through a room, a door that
//! opened — is separated from what never moved by one Boolean in 4-D: the recorded occupied voxels
//! intersected with (or taken from) the voxels ever free, held over all steps ([`MapHistory::dynamic`],
//! [`MapHistory::static_map`]).
//!
//! ```
//! use ktree::map::{HistoryRecorder, OccupancyMap, OCCUPIED};
//! let mut map = OccupancyMap::<3>::new(0.1).unwrap();
//! let mut history = HistoryRecorder::new(*map.grid());
//! // A wall at x = 1.05 seen from the origin; a person at x = 0.55 in the first scan only.
//! let wall = [1.05f32, 0.05, 0.05];
//! map.insert(&[[0.55, 0.05, 0.05]], [0.05; 3], None).unwrap();
//! history.record(&map).unwrap();
//! for _ in 0..4 {
//!     map.insert(&[wall], [0.05; 3], None).unwrap();
//!     history.record(&map).unwrap();
//! }
//! let history = history.finish();
//! let key = map.grid().keys([0.55f32, 0.05, 0.05]).unwrap();
//! // Occupied after the first scan, free after the wall had been seen through it three times.
//! assert_eq!(history.at(0).unwrap().value_at(key), Some(OCCUPIED));
//! assert_eq!(history.at(4).unwrap().value_at(key), Some(ktree::map::FREE));
//! // So the person is in the dynamic part, and the wall alone in the static map.
//! assert_eq!(history.moved().voxel_count(), 1);
//! assert!(history.static_map().contains(map.grid().keys(wall).unwrap()));
//! assert_eq!(history.static_map().voxel_count(), 1);
//! ```

mod recorder;
mod spans;

pub use recorder::HistoryRecorder;

use self::recorder::{forgets, FORGOTTEN};
use self::spans::Window;
use super::grid::{MapGrid, MAP_LEVEL};
use super::OccupancyMap;
use crate::ops::values::select_where;
use crate::ops::{difference, extrude, intersection, project};
use crate::tree::storage::infallible;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::ValueState;
use crate::tree::TreeError;
use crate::KTree;

/// The value of a voxel observed free at a time.
pub const FREE: u8 = 1;
/// The value of a voxel occupied at a time.
pub const OCCUPIED: u8 = 2;

/// The most steps a history holds: the side of the map's universe.
pub const MAX_STEPS: usize = 1 << MAP_LEVEL;

/// The states of a map's observed voxels as labels ([`FREE`], [`OCCUPIED`]; unknown voxels empty).
pub fn state_labels(map: &OccupancyMap<3>) -> KTree<3, u8> {
    let model = *map.model();
    let labels = map
        .log_odds()
        .map_values(|l| Some(if model.is_occupied(l) { OCCUPIED } else { FREE }));
    labels.unwrap_or_else(|e| unreachable!("labels are valid values: {e}"))
}

/// A value of `tree` other than [`FREE`] and [`OCCUPIED`], if it holds one.
fn other_state<const K: usize>(tree: &KTree<K, u8>) -> Option<u8> {
    tree.value_leaves()
        .filter_map(|(_, v)| v)
        .find(|&v| v != FREE && v != OCCUPIED)
}

/// A map's history: a 4-D tree at the map's keys with time (steps) along the fourth axis.
#[derive(Debug, Clone, PartialEq)]
pub struct MapHistory {
    grid: MapGrid,
    steps: u32,
    tree: KTree<4, u8>,
}

impl MapHistory {
    /// The history held by `tree` (a 4-D tree of the map's level whose values are [`FREE`] and
    /// [`OCCUPIED`]), of maps of this grid, with `steps` steps (`None`: up to the last change the tree
    /// records — the maps after it are all the same).
    ///
    /// # Errors
    /// A message if the tree's level is not [`MAP_LEVEL`], a voxel holds another value or a change lies
    /// after `steps`.
    pub fn from_tree(
        grid: MapGrid,
        tree: KTree<4, u8>,
        steps: Option<u32>,
    ) -> Result<Self, String> {
        if tree.level() != MAP_LEVEL {
            return Err(format!(
                "a map's history has level {MAP_LEVEL}, this tree {}",
                tree.level()
            ));
        }
        if let Some(v) = other_state(&tree) {
            return Err(format!(
                "a map's history holds {FREE} (free) and {OCCUPIED} (occupied), not {v}"
            ));
        }
        let recorded = tree
            .value_leaves()
            .filter(|(_, v)| v.is_some())
            .map(|(cell, _)| u64::from(cell.origin[3]) + cell.side())
            .max()
            .unwrap_or(0);
        let steps = match steps {
            None => recorded as u32,
            Some(s) if u64::from(s) >= recorded && s as usize <= MAX_STEPS => s,
            Some(s) if s as usize > MAX_STEPS => {
                return Err(format!(
                    "a history holds at most {MAX_STEPS} steps, not {s}"
                ))
            }
            Some(s) => {
                return Err(format!(
                    "the history records changes up to step {}, after its {s} steps",
                    recorded - 1
                ))
            }
        };
        Ok(Self { grid, steps, tree })
    }

    /// The history of maps of this grid whose states after each step are `steps` (as [`state_labels`]
    /// gives them), built at once ([`HistoryRecorder`] builds the same tree step by step, holding fewer
    /// of them).
    ///
    /// # Errors
    /// A message for more than [`MAX_STEPS`] steps, a tree of another level than [`MAP_LEVEL`], a
    /// value other than [`FREE`] and [`OCCUPIED`], or a voxel known at a step and unknown at a later one.
    pub fn from_steps(grid: MapGrid, steps: &[KTree<3, u8>]) -> Result<Self, String> {
        if steps.len() > MAX_STEPS {
            return Err(format!("a history holds at most {MAX_STEPS} steps"));
        }
        for (t, s) in steps.iter().enumerate() {
            if s.level() != MAP_LEVEL {
                return Err(format!(
                    "step {t}: a map's states have level {MAP_LEVEL}, not {}",
                    s.level()
                ));
            }
            if let Some(v) = other_state(s) {
                return Err(format!(
                    "step {t}: a map's states are {FREE} (free) and {OCCUPIED} (occupied), not {v}"
                ));
            }
            if t > 0 && forgets(&steps[t - 1], s) {
                return Err(format!("step {t}: {FORGOTTEN}"));
            }
        }
        let window = Window {
            first: 0,
            before: None,
            steps,
            side: 1 << MAP_LEVEL,
        };
        Ok(Self {
            grid,
            steps: steps.len() as u32,
            tree: window.tree(),
        })
    }

    /// The maps' grid.
    pub fn grid(&self) -> &MapGrid {
        &self.grid
    }

    /// The number of steps.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// The 4-D tree: voxel `[x, y, z, t]` holds the state key `[x, y, z]` took at step `t`, or is empty
    /// where that state did not change.
    pub fn tree(&self) -> &KTree<4, u8> {
        &self.tree
    }

    /// The map's states after step `step`, as labels ([`FREE`], [`OCCUPIED`]): at each voxel the last
    /// state recorded at or before that time.
    ///
    /// # Errors
    /// A message for a step the history does not hold.
    pub fn at(&self, step: u32) -> Result<KTree<3, u8>, String> {
        if step >= self.steps {
            return Err(format!(
                "step {step} is not in a history of {} steps",
                self.steps
            ));
        }
        // Top down over the 3-D cells, each with the history's nodes over it whose spans start at or
        // before `step`, in time order; a cell is decided once all of them are leaves: by the last
        // recorded label (an empty node records no change).
        let tree = &self.tree;
        let step = u64::from(step);
        let root = vec![(0u64, 1u64 << MAP_LEVEL, infallible(InputNode::root(tree)))];
        let built = build_top_down::<3, u8, Vec<(u64, u64, InputNode<u8>)>, TreeError>(
            MAP_LEVEL,
            root,
            |_, nodes| {
                if nodes.iter().any(|(_, _, n)| n.state.has_children()) {
                    return Ok(Decision::Split);
                }
                let last = nodes.iter().rev().find_map(|(_, _, n)| match n.state {
                    ValueState::Full(v) => Some(v),
                    _ => None,
                });
                Ok(Decision::Leaf(last))
            },
            |nodes, code| {
                let mut out = Vec::with_capacity(nodes.len() + 1);
                for &(first, side, node) in nodes {
                    if !node.state.has_children() {
                        out.push((first, side, node));
                        continue;
                    }
                    let half = side / 2;
                    out.push((first, half, infallible(node.child(tree, code))));
                    if first + half <= step {
                        out.push((first + half, half, infallible(node.child(tree, code | 8))));
                    }
                }
                Ok(out)
            },
        );
        Ok(built.unwrap_or_else(|e| unreachable!("a slice of a history is a valid tree: {e}")))
    }

    /// Where and when voxels became occupied, as a 4-D tree.
    pub fn occupied(&self) -> KTree<4> {
        infallible(select_where(&self.tree, |v| v == OCCUPIED))
    }

    /// Where and when voxels became free, as a 4-D tree.
    pub fn free(&self) -> KTree<4> {
        infallible(select_where(&self.tree, |v| v == FREE))
    }

    /// The voxels free at some time, held over every step.
    fn ever_free(&self) -> KTree<4> {
        let all = 0..self.steps;
        let ever: KTree<3> = project(&self.free(), 3, all.clone())
            .unwrap_or_else(|e| unreachable!("a history projects along time: {e}"));
        extrude(&ever, 3, all).unwrap_or_else(|e| unreachable!("a map extrudes in time: {e}"))
    }

    /// What moved: where and when voxels became occupied that are observed free at some time (a moving
    /// object arriving), as a 4-D tree.
    pub fn dynamic(&self) -> KTree<4> {
        intersection(&self.occupied(), &self.ever_free())
            .unwrap_or_else(|e| unreachable!("two trees of one level intersect: {e}"))
    }

    /// Where and when voxels became occupied that are never observed free: the recorded occupied voxels
    /// with [`MapHistory::dynamic`] taken away, as a 4-D tree.
    pub fn static_history(&self) -> KTree<4> {
        difference(&self.occupied(), &self.ever_free())
            .unwrap_or_else(|e| unreachable!("two trees of one level subtract: {e}"))
    }

    /// The static map: the voxels occupied at some time and never observed free.
    pub fn static_map(&self) -> KTree<3> {
        project(&self.static_history(), 3, 0..self.steps)
            .unwrap_or_else(|e| unreachable!("a history projects along time: {e}"))
    }

    /// The voxels occupied at some time and observed free at another: where something moved.
    pub fn moved(&self) -> KTree<3> {
        project(&self.dynamic(), 3, 0..self.steps)
            .unwrap_or_else(|e| unreachable!("a history projects along time: {e}"))
    }
}
