//! The memory accounting of an out-of-core build: what each run, stacked cell and buffer is counted as.

/// Bytes accounted for each run of a slab being stacked: the runs and their copies while they are cut
/// into cells, and the subtrees made from them until they are spilled.
pub(crate) const RUN_BYTES: u64 = 64;
/// Bytes accounted for each stacked cell, besides 8 per level of its subtree (its place in the index and
/// in the order the levels are written in).
pub(crate) const SUBTREE_BYTES: u64 = 24;
/// Bytes accounted for each I/O buffer: one per level of the [`PieceStore`](super::PieceStore), one for
/// the output, one for reading back (the spill files and the `.ktree` writer of `io` buffer this much).
pub(crate) const BUFFER_BYTES: u64 = 1 << 16;

/// A byte count with its size in MiB or GiB, for messages.
pub(crate) fn bytes_text(bytes: u64) -> String {
    const MIB: f64 = 1024.0 * 1024.0;
    let b = bytes as f64;
    if b >= 1024.0 * MIB {
        format!("{bytes} bytes ({:.2} GiB)", b / (1024.0 * MIB))
    } else {
        format!("{bytes} bytes ({:.1} MiB)", b / MIB)
    }
}

/// The memory accounting of a build.
pub(super) struct Budget {
    pub(super) max: u64,
    /// Levels of a subtree below its root.
    pub(super) t: u64,
    pub(super) peak: u64,
}

impl Budget {
    /// The memory held between slabs: cells, index, buffers.
    pub(super) fn fixed(&self, cell_bytes: u64, subtrees: usize) -> u64 {
        cell_bytes
            + subtrees as u64 * (SUBTREE_BYTES + 8 * (self.t + 1))
            + (self.t + 2) * BUFFER_BYTES
    }
}
