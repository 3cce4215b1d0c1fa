//! A tree back to rays: the runs of its full voxels along the last axis.
//!
//! The full leaves are visited slab by slab along the first axis (the most significant part of a column
//! key, so the slabs' columns follow one another in key order): each slab's runs — a run for every column
//! of every full leaf in it, a leaf's columns clipped to the slab — are sorted by column and `z`, and runs
//! that touch are joined. The runs of one slab are held at a time, never those of the whole tree: a full
//! leaf of side `s` gives `s^(K−1)` runs, and together the leaves give many times the maximal runs.

use crate::rays::RaySet;
use crate::tree::cursor::{walk, Visitor, Walk};
use crate::tree::{KTree, NodeRef, NodeState};

/// Slabs along the first axis (at most; one a column for small universes).
const SLABS: u64 = 64;

/// Collects `(column key, z1, z2)` for every column of every full leaf within `[x0, x1)` on axis 0.
struct SlabRuns<'a, const K: usize> {
    level: u32,
    x0: u64,
    x1: u64,
    out: &'a mut Vec<(u64, u32, u32)>,
}

impl<const K: usize> Visitor<K> for SlabRuns<'_, K> {
    const LEAVES: bool = false;

    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        let cell = node.cell();
        let side = cell.side();
        let origin = cell.origin;
        // With K = 1 the only axis is the runs' own: one slab, nothing to clip.
        let (lo, hi) = if K >= 2 {
            let x = u64::from(origin[0]);
            (x.max(self.x0), (x + side).min(self.x1))
        } else {
            (0, 1)
        };
        if lo >= hi {
            return Walk::Skip;
        }
        match node.state() {
            NodeState::Empty => Walk::Skip,
            NodeState::Partial => Walk::Descend,
            NodeState::Full => {
                let z = (origin[K - 1], origin[K - 1] + side as u32);
                // Every column of the cell within the slab: an odometer over the first K − 1 axes.
                let mut start = origin;
                if K >= 2 {
                    start[0] = lo as u32;
                }
                loop {
                    let key = start[..K - 1]
                        .iter()
                        .fold(0u64, |key, &c| (key << self.level) | u64::from(c));
                    self.out.push((key, z.0, z.1));
                    let mut axis = 0;
                    while axis + 1 < K {
                        start[axis] += 1;
                        let end = if axis == 0 {
                            hi as u32
                        } else {
                            origin[axis] + side as u32
                        };
                        if start[axis] < end {
                            break;
                        }
                        start[axis] = if axis == 0 { lo as u32 } else { origin[axis] };
                        axis += 1;
                    }
                    if axis + 1 >= K {
                        break;
                    }
                }
                Walk::Skip
            }
        }
    }
}

impl<const K: usize> KTree<K> {
    /// The runs along the last axis of a tree's full voxels: the ray set that stacks back to the tree.
    ///
    /// ```
    /// use ktree::{stacking::paper::stack, rays::ball_rays};
    /// let rays = ball_rays::<3>(5, [16, 16, 16], 11).unwrap();
    /// assert_eq!(stack(&rays).to_rays(), rays);
    /// ```
    ///
    /// # Performance
    /// One walk of the tree per slab of the first axis (see the module notes); memory the maximal runs
    /// and one slab's unjoined runs.
    pub fn to_rays(&self) -> RaySet<K> {
        let universe = self.universe();
        let side = universe.side();
        let slabs = if K >= 2 { side.min(SLABS) } else { 1 };
        let width = side / slabs;
        let (mut columns, mut runs) = (Vec::new(), Vec::<(u32, u32)>::new());
        let mut slab = Vec::new();
        for s in 0..slabs {
            slab.clear();
            let mut visitor = SlabRuns::<K> {
                level: self.level(),
                x0: s * width,
                x1: (s + 1) * width,
                out: &mut slab,
            };
            walk(self, &mut visitor);
            slab.sort_unstable();
            for &(key, z1, z2) in &slab {
                if let (Some(&last), Some(run)) = (columns.last(), runs.last_mut()) {
                    if last == key && z1 <= run.1 {
                        run.1 = run.1.max(z2);
                        continue;
                    }
                }
                columns.push(key);
                runs.push((z1, z2));
            }
        }
        RaySet::from_sorted_parts(universe, columns, runs, None)
    }
}

#[cfg(test)]
mod tests {
    use crate::rays::ball_rays;
    use crate::KTree;

    #[test]
    fn slabs_wider_than_a_column_give_the_stacked_rays() {
        // Sides 128 and 256: slabs of 2 and 4 columns, full leaves cut across slab boundaries.
        for (level, centre, diameter) in [(7, [100, 128, 60], 150), (8, [257, 250, 300], 400)] {
            let rays = ball_rays::<3>(level, centre, diameter).unwrap();
            assert_eq!(KTree::from_rays(&rays).to_rays(), rays);
        }
        let rays = ball_rays::<2>(9, [512, 512], 900).unwrap();
        assert_eq!(KTree::from_rays(&rays).to_rays(), rays);
    }
}
