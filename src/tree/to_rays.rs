//! A tree back to rays: the runs of its full voxels along the last axis.

use crate::rays::{Ray, RaySet};
use crate::tree::{KTree, NodeState};

impl<const K: usize> KTree<K> {
    /// The runs along the last axis of a tree's full voxels: the ray set that stacks back to the tree.
    ///
    /// ```
    /// use ktree::{stacking::paper::stack, rays::ball_rays};
    /// let rays = ball_rays::<3>(5, [16, 16, 16], 11).unwrap();
    /// assert_eq!(stack(&rays).to_rays(), rays);
    /// ```
    pub fn to_rays(&self) -> RaySet<K> {
        let tree = self;
        let mut rays = Vec::new();
        tree.for_each_leaf(|cell, state| {
            if state != NodeState::Full {
                return;
            }
            let side = cell.side() as u32;
            let origin = cell.origin;
            // Every column of the cell: an odometer over the first K − 1 axes.
            let mut start = origin;
            loop {
                rays.push(Ray::new(start, origin[K - 1] + side));
                let mut axis = 0;
                while axis + 1 < K {
                    start[axis] += 1;
                    if start[axis] < origin[axis] + side {
                        break;
                    }
                    start[axis] = origin[axis];
                    axis += 1;
                }
                if axis + 1 >= K {
                    break;
                }
            }
        });
        RaySet::from_rays(tree.level(), rays).expect("the cells of a tree lie in its universe")
    }
}
