//! Where runs come from: [`RaySource`], anything that produces the runs of a slab of columns on demand
//! — a whole [`RaySet`], a solid, a mesh or a volume generating its rays slab by slab, a ray file read
//! slab by slab — and [`SlabRuns`], one slab's runs. Every builder consumes runs through it; the
//! producers live with what they produce from (`solid/`, `io/`), and none of them knows the builder.

use std::borrow::Cow;
use std::convert::Infallible;
use std::ops::Range;

use super::RaySet;
use crate::space::Universe;

/// The runs of one slab of columns: the column keys (as [`RaySet::column_key`], non-decreasing) and the
/// `(z1, z2)` runs, sorted as in a [`RaySet`].
#[derive(Debug, Clone)]
pub struct SlabRuns<'a> {
    /// One column key per run.
    pub keys: Cow<'a, [u64]>,
    /// One `(z1, z2)` per run.
    pub runs: Cow<'a, [(u32, u32)]>,
}

/// Anything that can produce the runs of a slab of columns on demand (from any thread).
pub trait RaySource<const K: usize>: Sync {
    /// Why producing runs can fail.
    type Error: Send;

    /// The universe of the runs.
    fn universe(&self) -> Universe<K>;

    /// The runs of the columns whose axis-0 coordinate lies in `x` (for `K = 1`, of the one column), in
    /// [`RaySet`] order.
    ///
    /// # Errors
    /// As the source defines.
    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, Self::Error>;

    /// The slabs of width `2^(L − m)` (numbered along axis 0) that may hold runs, in increasing order; by
    /// default all `2^m` of them.
    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        (0..1u32 << m).collect()
    }
}

impl<const K: usize> RaySource<K> for RaySet<K> {
    type Error = Infallible;

    fn universe(&self) -> Universe<K> {
        RaySet::universe(self)
    }

    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        if K == 1 {
            return vec![0];
        }
        let keys = self.column_keys();
        let shift = K.saturating_sub(2) as u32 * self.level() + (self.level() - m);
        let mut slabs = Vec::new();
        let mut at = 0;
        while at < keys.len() {
            let slab = keys[at] >> shift;
            slabs.push(slab as u32);
            at += keys[at..].partition_point(|&k| k >> shift == slab);
        }
        slabs
    }

    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, Infallible> {
        let r = self.slab_range(x);
        Ok(SlabRuns {
            keys: Cow::Borrowed(&self.column_keys()[r.clone()]),
            runs: Cow::Borrowed(&self.runs()[r]),
        })
    }
}

/// The split depth builders use when none is given: cells of about 2^18 voxels (side 64 for octrees),
/// whose stacking lists fit in cache. Sources that index their input by slab (a mesh's triangles) expect
/// slabs of this depth.
pub fn default_split_depth(k: usize, level: u32) -> u32 {
    let subtree_level = 18u32.div_ceil(k as u32);
    level.saturating_sub(subtree_level)
}
