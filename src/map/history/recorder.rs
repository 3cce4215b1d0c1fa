//! Recording a map's history step by step, a chunk of steps at a time ([`HistoryRecorder`]).

use super::spans::{Span, Window, MIXED};
use super::{state_labels, MapHistory, MAP_LEVEL, MAX_STEPS};
use crate::map::grid::MapGrid;
use crate::map::OccupancyMap;
use crate::ops::difference;
use crate::tree::storage::infallible;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::ValueState;
use crate::tree::TreeError;
use crate::KTree;

/// Steps a history is built in at a time: a recorder keeps the full states of this many steps (and of
/// the step before them), and of every step only its states over cells of this side.
const CHUNK: u64 = 8;

/// Records a map's state after each step, to be made into a [`MapHistory`] — in memory bounded by a
/// few maps, not by the number of steps: the steps are built into the history 8 at a time (the 4-D
/// cells of a chunk's span of time, whose side in space is 8 voxels too; the recorder holds the states
/// of the chunk's steps and of the step before it), and of each step only its states over cells of that
/// side are kept, which is all the cells above the chunks are decided by.
/// [`finish`](Self::finish) gives the same tree as [`MapHistory::from_steps`] of every step's states.
#[derive(Debug, Clone)]
pub struct HistoryRecorder {
    grid: MapGrid,
    /// Each step's states over cells of side [`CHUNK`] ([`coarse_states`]).
    coarse: Vec<KTree<3, u8>>,
    /// The history of each whole chunk of steps, its cells of time side [`CHUNK`] and below.
    chunks: Vec<KTree<4, u8>>,
    /// The states of the step before the current chunk (none before the first).
    before: Option<KTree<3, u8>>,
    /// The states of the steps of the current chunk.
    current: Vec<KTree<3, u8>>,
}

impl HistoryRecorder {
    /// A recorder of maps of this grid, with no step yet.
    pub fn new(grid: MapGrid) -> Self {
        Self {
            grid,
            coarse: Vec::new(),
            chunks: Vec::new(),
            before: None,
            current: Vec::new(),
        }
    }

    /// Records the map's state as the next step.
    ///
    /// # Errors
    /// A message if the map's grid is not the recorder's, the history is full ([`MAX_STEPS`]), or a voxel
    /// observed in the step before is unknown in this map.
    pub fn record(&mut self, map: &OccupancyMap<3>) -> Result<(), String> {
        if *map.grid() != self.grid {
            return Err(format!(
                "a history of {} m voxels cannot record a map of {} m voxels",
                self.grid.resolution(),
                map.grid().resolution()
            ));
        }
        if self.coarse.len() == MAX_STEPS {
            return Err(format!("a history holds at most {MAX_STEPS} steps"));
        }
        let labels = state_labels(map);
        if let Some(last) = self.current.last().or(self.before.as_ref()) {
            if forgets(last, &labels) {
                return Err(format!("after step {}: {FORGOTTEN}", self.coarse.len() - 1));
            }
        }
        self.record_states(labels);
        Ok(())
    }

    /// Records a map's states ([`state_labels`]) as the next step (the number of steps and that no
    /// voxel is forgotten checked).
    fn record_states(&mut self, labels: KTree<3, u8>) {
        self.coarse.push(coarse_states(&labels));
        self.current.push(labels);
        if self.current.len() as u64 == CHUNK {
            let chunk = self.current_chunk();
            self.chunks.push(chunk);
            self.before = self.current.pop();
            self.current.clear();
        }
    }

    /// The history of the current chunk's steps (its cells of time side [`CHUNK`] and below).
    fn current_chunk(&self) -> KTree<4, u8> {
        Window {
            first: self.chunks.len() as u64 * CHUNK,
            before: self.before.as_ref(),
            steps: &self.current,
            side: CHUNK,
        }
        .tree()
    }

    /// The steps recorded so far.
    pub fn steps(&self) -> usize {
        self.coarse.len()
    }

    /// The bytes the recorder holds on the heap: the states of the current chunk's steps and of the
    /// step before them, every step's coarse states and the chunks' histories.
    pub fn heap_bytes(&self) -> usize {
        let trees = |t: &[KTree<3, u8>]| t.iter().map(KTree::heap_bytes).sum::<usize>();
        trees(&self.coarse)
            + trees(&self.current)
            + self.before.as_ref().map_or(0, KTree::heap_bytes)
            + self.chunks.iter().map(KTree::heap_bytes).sum::<usize>()
    }

    /// The history of the steps recorded: one 4-D tree of their changes, the same as
    /// [`MapHistory::from_steps`] of every step's states.
    pub fn finish(&self) -> MapHistory {
        let count = self.coarse.len() as u64;
        let last = (!self.current.is_empty()).then(|| self.current_chunk());
        let chunks: Vec<&KTree<4, u8>> = self.chunks.iter().chain(&last).collect();
        MapHistory {
            grid: self.grid,
            steps: count as u32,
            tree: chunked_tree(&self.coarse, &chunks),
        }
    }
}

/// Why a map's states cannot follow another's in a history.
pub(super) const FORGOTTEN: &str =
    "a voxel observed before is unknown (a history records maps that forget nothing)";

/// Whether a voxel known in `before` is unknown in `after`.
pub(super) fn forgets(before: &KTree<3, u8>, after: &KTree<3, u8>) -> bool {
    let lost = difference(&before.shape(), &after.shape())
        .unwrap_or_else(|e| unreachable!("two maps' states have one level: {e}"));
    lost.voxel_count() > 0
}

/// A step's states over the cells of side [`CHUNK`]: a tree of level [`MAP_LEVEL`] less that side's, a
/// voxel of it the state all over the cell ([`MIXED`] where the states in it are not all one).
fn coarse_states(labels: &KTree<3, u8>) -> KTree<3, u8> {
    let level = MAP_LEVEL - CHUNK.trailing_zeros();
    let built = build_top_down::<3, u8, InputNode<u8>, TreeError>(
        level,
        infallible(InputNode::root(labels)),
        |cell, node| {
            Ok(match node.state {
                ValueState::Empty => Decision::Leaf(None),
                ValueState::Full(v) => Decision::Leaf(Some(v)),
                _ if cell.side() == 1 => Decision::Leaf(Some(MIXED)),
                _ => Decision::Split,
            })
        },
        |node, code| Ok(infallible(node.child(labels, code))),
    );
    built.unwrap_or_else(|e| unreachable!("coarse states are a valid tree: {e}"))
}

/// A cell of the history assembled from chunks: above the chunks, a span over the steps' coarse states
/// with the nodes of the chunks' trees it holds; at and below a chunk's side, a node of that chunk's tree.
#[derive(Clone)]
enum Part {
    Above(Span, Vec<InputNode<u8>>),
    Chunk(usize, InputNode<u8>),
}

/// The history of steps whose coarse states are `coarse` and whose chunks' trees are `chunks` (the
/// last one holding the steps after the last whole chunk): the cells above the chunks decided from the
/// coarse states as [`Span::decide`] decides them, the cells of each chunk copied from its tree.
fn chunked_tree(coarse: &[KTree<3, u8>], chunks: &[&KTree<4, u8>]) -> KTree<4, u8> {
    let count = coarse.len() as u64;
    let root = Part::Above(
        Span {
            first: 0,
            side: 1 << MAP_LEVEL,
            before: None,
            nodes: coarse
                .iter()
                .map(|t| infallible(InputNode::root(t)))
                .collect(),
        },
        chunks
            .iter()
            .map(|t| infallible(InputNode::root(*t)))
            .collect(),
    );
    let built = build_top_down::<4, u8, Part, TreeError>(
        MAP_LEVEL,
        root,
        |_, part| {
            Ok(match part {
                Part::Above(span, _) => span.decide(count),
                Part::Chunk(_, node) => match node.state {
                    ValueState::Empty => Decision::Leaf(None),
                    ValueState::Full(v) => Decision::Leaf(Some(v)),
                    ValueState::Partial | ValueState::Mixed => Decision::Split,
                },
            })
        },
        |part, code| {
            Ok(match part {
                Part::Chunk(k, node) => Part::Chunk(*k, infallible(node.child(chunks[*k], code))),
                Part::Above(span, held) => {
                    let half = span.side / 2;
                    let first = span.first + if code >> 3 & 1 == 1 { half } else { 0 };
                    // The chunks the child's span holds, among those the parent's holds.
                    let k0 = (span.first / CHUNK) as usize;
                    let (lo, hi) = ((first / CHUNK) as usize, ((first + half) / CHUNK) as usize);
                    let nodes = (lo..hi.min(chunks.len()))
                        .map(|k| infallible(held[k - k0].child(chunks[k], code)))
                        .collect::<Vec<_>>();
                    if half == CHUNK {
                        match nodes.into_iter().next() {
                            Some(node) => Part::Chunk(lo, node),
                            // After the last step: nothing recorded.
                            None => Part::Above(
                                Span {
                                    first,
                                    side: half,
                                    before: None,
                                    nodes: Vec::new(),
                                },
                                Vec::new(),
                            ),
                        }
                    } else {
                        Part::Above(span.child(code, count, |t| &coarse[t as usize]), nodes)
                    }
                }
            })
        },
    );
    built.unwrap_or_else(|e| unreachable!("a history of label trees is a valid tree: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::history::{FREE, OCCUPIED};

    /// A hash of a voxel and a number.
    fn hash(p: [u32; 3], n: u64) -> u64 {
        let mut h = u64::from(p[0]) << 42 ^ u64::from(p[1]) << 21 ^ u64::from(p[2]) ^ n << 56;
        for _ in 0..3 {
            h = (h ^ h >> 31).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
        h ^ h >> 29
    }

    /// The states at step `t` of a 32-voxel cube near the map's centre: its lower half in `z` free
    /// throughout, its upper half a noise of unknown voxels becoming free or occupied, each changing now
    /// and then (every voxel's time and period its own), so that every cell of side 8 there is mixed.
    fn noisy_states(t: u64, seed: u64) -> KTree<3, u8> {
        let lo = 1u32 << (MAP_LEVEL - 1);
        let state = |p: [u32; 3]| -> Option<u8> {
            if p.iter().any(|&c| c < lo || c >= lo + 32) {
                return None;
            }
            if p[2] < lo + 16 {
                return Some(FREE);
            }
            // Unknown until first seen (some before the first step, some never), then changing.
            if t < hash(p, seed) % 48 {
                return None;
            }
            let period = 3 + hash(p, seed + 1) % 29;
            let epoch = (t + hash(p, seed + 2) % period) / period;
            Some(if hash(p, seed + 3 + epoch).is_multiple_of(2) {
                FREE
            } else {
                OCCUPIED
            })
        };
        let built = build_top_down::<3, u8, (), TreeError>(
            MAP_LEVEL,
            (),
            |cell, ()| {
                let (o, side) = (cell.origin(), cell.side() as u32);
                let outside = (0..3).any(|a| o[a] + side <= lo || o[a] >= lo + 32);
                Ok(if outside {
                    Decision::Leaf(None)
                } else if side == 1 {
                    Decision::Leaf(state(o))
                } else {
                    Decision::Split
                })
            },
            |(), _| Ok(()),
        );
        built.unwrap()
    }

    /// Recorded in chunks, the history of states that are mixed at every cell of a chunk's side (the
    /// coarse states' [`MIXED`] cells), with a region that never changes, is the history built at once —
    /// for every number of steps up to five chunks.
    #[test]
    fn a_history_recorded_in_chunks_is_the_history_built_at_once() {
        let grid = MapGrid::new(0.1).unwrap();
        for seed in [1u64, 7] {
            let steps: Vec<KTree<3, u8>> = (0..5 * CHUNK).map(|t| noisy_states(t, seed)).collect();
            let mut recorder = HistoryRecorder::new(grid);
            for (t, s) in steps.iter().enumerate() {
                recorder.record_states(s.clone());
                let at_once = MapHistory::from_steps(grid, &steps[..=t]).unwrap();
                assert_eq!(recorder.finish(), at_once, "seed {seed}, {} steps", t + 1);
            }
            let history = recorder.finish();
            assert_eq!(history.at(33).unwrap(), steps[33]);
        }
        // A voxel known, then unknown: refused.
        let steps = [noisy_states(40, 1), noisy_states(2, 1)];
        let e = MapHistory::from_steps(grid, &steps).unwrap_err();
        assert!(
            e.contains("step 1: a voxel observed before is unknown"),
            "{e}"
        );
    }
}
