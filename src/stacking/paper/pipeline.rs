//! Stacking as a pipeline of threads: Akman & Franklin's data-flow boxes (their Fig. 8), one thread per box.
//!
//! A producer cuts the rays into maximal rows; stage `D = 1 … K−1` runs in its own thread, combining and
//! splitting its lists ι(D, 0 … L) exactly as [`stack`](super::stack) does (the steps are shared) and
//! sending what it combines to stage `D + 1`; the calling thread collects the full leaves and assembles the
//! tree. Items travel in batches over bounded channels (`std::sync::mpsc::sync_channel`), so a fast stage
//! waits for a slow one instead of queueing without limit.
//!
//! A stage works on one *prefix group* at a time (the items that agree on the axes it does not combine
//! along or split), as the in-memory stacker does: rays arrive by column, so each stage's groups arrive one
//! after another, and a group is complete when the next one starts. The stages therefore overlap in time:
//! stage 1 stacks one slab while stage 2 collects what stage 1 finished before. Measured throughput against
//! the one-thread run: `results/akman-franklin/af9_pipeline.md`.

use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

use super::file_lists::for_each_row;
use super::lists::{pack_key, unpack_key, Cells, Stage};
use crate::rays::RaySet;
use crate::tree::KTree;

/// Items (origin, level) sent between stages at a time.
const BATCH: usize = 4096;
/// Batches a channel holds before its sender waits.
const CHANNEL_BATCHES: usize = 16;

type Batch<const K: usize> = Vec<([u32; K], u32)>;

/// Builds the minimal reduced k-tree of a ray set by stacking with one thread per stage (`K + 1` threads
/// with the producer and the caller's). The tree is the one [`stack`](super::stack) builds.
///
/// ```
/// use ktree::{rays::ball_rays, stacking};
/// let rays = ball_rays::<3>(5, [16, 16, 16], 12).unwrap();
/// assert_eq!(stacking::paper::stack_pipelined(&rays), stacking::paper::stack(&rays));
/// ```
pub fn stack_pipelined<const K: usize>(rays: &RaySet<K>) -> KTree<K> {
    let universe = rays.universe();
    let top = universe.level();
    std::thread::scope(|scope| {
        let (producer_tx, mut rx) = sync_channel::<Batch<K>>(CHANNEL_BATCHES);
        scope.spawn(move || {
            let mut batch = Vec::with_capacity(BATCH);
            for_each_row(rays, |origin, level| {
                batch.push((origin, level));
                if batch.len() == BATCH {
                    send(&producer_tx, &mut batch);
                }
            });
            send(&producer_tx, &mut batch);
        });
        for d in 1..K {
            let (tx, next_rx) = sync_channel::<Batch<K>>(CHANNEL_BATCHES);
            let stage_rx = std::mem::replace(&mut rx, next_rx);
            scope.spawn(move || run_stage::<K>(d, top, stage_rx, tx));
        }
        let mut cells = Cells::<K>::new(top);
        for batch in rx {
            for (origin, level) in batch {
                cells.push(origin, level);
            }
        }
        cells.into_tree(universe, Vec::new())
    })
}

/// Sends a batch on (if the receiver is gone, its thread panicked and the scope reports it).
fn send<const K: usize>(tx: &SyncSender<Batch<K>>, batch: &mut Batch<K>) {
    if !batch.is_empty() {
        let full = std::mem::replace(batch, Vec::with_capacity(BATCH));
        let _ = tx.send(full);
    }
}

/// Stage `d`: collects items by prefix group, combines or splits each complete group, sends the combined
/// items on.
fn run_stage<const K: usize>(d: usize, top: u32, rx: Receiver<Batch<K>>, tx: SyncSender<Batch<K>>) {
    let mut stage = Stage::new(K, d, top);
    let mut scratch = Vec::new();
    let mut out = Vec::with_capacity(BATCH);
    let local_mask = u64::MAX.checked_shr(64 - stage.local_bits).unwrap_or(0);
    for batch in rx {
        for (origin, level) in batch {
            let key = pack_key(top, stage.axis, origin);
            // For a 64-bit local key the prefix is empty (K·L = 64 happens only for K = 4, L = 16).
            let prefix = key.checked_shr(stage.local_bits).unwrap_or(0);
            if stage.prefix.is_some_and(|p| p != prefix) {
                flush_group(&mut stage, top, &mut scratch, &mut out, &tx);
            }
            stage.prefix = Some(prefix);
            stage.lists[level as usize].push(key & local_mask);
        }
    }
    flush_group(&mut stage, top, &mut scratch, &mut out, &tx);
    send(&tx, &mut out);
}

/// Combines or splits every level of the stage's current group, from the top level down.
fn flush_group<const K: usize>(
    stage: &mut Stage,
    top: u32,
    scratch: &mut Vec<u64>,
    out: &mut Batch<K>,
    tx: &SyncSender<Batch<K>>,
) {
    let Some(prefix) = stage.prefix.take() else {
        return;
    };
    let axis = stage.axis;
    let prefix_bits = prefix.checked_shl(stage.local_bits).unwrap_or(0);
    let mut list = Vec::new();
    for l in 0..=top as usize {
        std::mem::swap(&mut list, &mut stage.lists[l]);
        if list.is_empty() {
            continue;
        }
        stage.combine_level(l, &mut list, top, scratch, |key| {
            out.push((unpack_key(top, axis, prefix_bits | key), l as u32));
        });
        list.clear();
        if out.len() >= BATCH {
            send(tx, out);
        }
    }
}
