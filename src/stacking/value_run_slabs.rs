//! Valued runs built out of core: the tree of a [`ValueRuns`] built slab by slab along the last axis, the
//! cells of depth `m` of each slab built apart from the pieces of the runs inside them (as
//! [`KTree::from_value_runs`](crate::KTree::from_value_runs) builds its cells) and the levels below each
//! cell with children spilled as they are built ([`ValuePart`]): the runs are held, the tree never whole.
//! A slab's cells are found in one pass over the runs, so a build reads the runs `2^m` times (a pass for
//! a batch of slabs would read them less often, but hold a piece of every long run for each slab of the
//! batch: more memory than the tree held whole, measured).

use std::convert::Infallible;
use std::ops::Range;

use rayon::prelude::*;

use super::out_of_core::{BuildError, PieceStore};
use super::value_parts::{stack_cells, ValuePart};
use super::value_slabs::{spread_across, MAX_CELL_BITS};
use super::value_spill::{ValueSlabsReport, ValuedLevelSink};
use super::values::subtree;
use crate::rays::source::default_split_depth;
use crate::rays::{ColumnKeys, ValueRun, ValueRuns};
use crate::space::morton_decode;
use crate::tree::top_down::Subtree;
use crate::value::Value;

impl<const K: usize, V: Value + Send + Sync> ValueRuns<K, V> {
    /// The depth of the cells an out-of-core build of these runs builds apart by default: cells of about
    /// 2^18 voxels, as the builders on threads cut them (at most about 16 million cells).
    pub fn default_cell_depth(&self) -> u32 {
        let level = self.universe().level();
        default_split_depth(K, level).min(MAX_CELL_BITS / K as u32)
    }

    /// `cell_depth` clamped to the level and to about 16 million cells.
    pub(crate) fn clamped_cell_depth(&self, cell_depth: u32) -> u32 {
        cell_depth
            .min(self.universe().level())
            .min(MAX_CELL_BITS / K as u32)
    }

    /// Builds the part of the tree in the slabs `slabs` of its cells of depth `cell_depth` (clamped to
    /// the level and to about 16 million cells; the slabs clamped to the `2^m` along the last axis), the
    /// levels below each cell with children spilled to `store` — one part of a build across processes
    /// ([`ValuePart::add_part`], [`ValuePart::write_into`]).
    ///
    /// # Errors
    /// [`BuildError::Files`]: the store's error.
    pub fn stack_part<P: PieceStore>(
        &self,
        cell_depth: u32,
        slabs: Range<u32>,
        store: P,
    ) -> Result<ValuePart<K, V, P::Stored>, BuildError<Infallible, P::Error>> {
        let level = self.universe().level();
        let m = self.clamped_cell_depth(cell_depth);
        let keys = ColumnKeys::<K>::new(level);
        let mut buckets = Vec::new();
        stack_cells(level, m, slabs, store, |b| {
            Ok(self.slab_cells(&keys, m, b, &mut buckets))
        })
    }

    /// Builds the tree of the runs into `sink` level by level from the root down, its cells of depth
    /// `cell_depth` built slab by slab and their subtrees spilled to `store` ([`stack_part`](Self::stack_part)
    /// of every slab, written): the levels `sink` receives are those of
    /// [`KTree::from_value_runs`](crate::KTree::from_value_runs).
    ///
    /// # Errors
    /// [`BuildError::Files`]: the store's or the output's error.
    pub fn build_into<P, O>(
        &self,
        cell_depth: u32,
        store: P,
        sink: O,
    ) -> Result<(O::Output, ValueSlabsReport), BuildError<Infallible, P::Error>>
    where
        P: PieceStore,
        O: ValuedLevelSink<Error = P::Error>,
    {
        self.stack_part(cell_depth, 0..u32::MAX, store)?
            .write_into(sink, |_, _: &mut [u64]| {
                unreachable!("a build in one part receives nothing")
            })
    }

    /// The cells of depth `m` of slab `b` (in the Morton order of their coordinates along the other
    /// axes), each built from the pieces of the runs inside it; `None` if no run enters the slab.
    /// `buckets` is scratch space.
    fn slab_cells(
        &self,
        keys: &ColumnKeys<K>,
        m: u32,
        b: u32,
        buckets: &mut Vec<Vec<ValueRun<V>>>,
    ) -> Option<Vec<Subtree<V>>> {
        let universe = self.universe();
        let s = universe.level() - m;
        let (z0, z1) = (u64::from(b) << s, u64::from(b + 1) << s);
        let across = 1usize << (m as usize * (K - 1));
        buckets.resize_with(across, Vec::new);
        buckets.iter_mut().for_each(Vec::clear);
        let mut entered = false;
        for run in self.runs() {
            if u64::from(run.z1) >= z1 || u64::from(run.z2) <= z0 {
                continue;
            }
            // The cell's place among the slab's cells, its coordinates in lexicographic order (axis 0
            // most significant, as the runs' columns are sorted).
            let column = keys.unpack(run.column);
            let i = column[..K - 1]
                .iter()
                .fold(0usize, |i, &c| (i << m) | (c >> s) as usize);
            buckets[i].push(ValueRun {
                z1: run.z1.max(z0 as u32),
                z2: (u64::from(run.z2).min(z1)) as u32,
                ..*run
            });
            entered = true;
        }
        if !entered {
            return None;
        }
        let buckets = &*buckets;
        let cells = (0..across)
            .into_par_iter()
            .map(|i| {
                // Cell `i` in Morton order, and its bucket.
                let mut origin = [0u32; K];
                let mut bucket = 0usize;
                if K > 1 {
                    let coords = morton_decode::<K>(spread_across::<K>(i as u64));
                    for (o, c) in origin[..K - 1].iter_mut().zip(coords) {
                        *o = c << s;
                        bucket = (bucket << m) | c as usize;
                    }
                }
                let pieces = &buckets[bucket];
                origin[K - 1] = b << s;
                let cell = universe
                    .cell(origin, m)
                    .expect("a cell of the slab lies in the universe");
                subtree(keys, cell, pieces, 0)
            })
            .collect();
        Some(cells)
    }
}
