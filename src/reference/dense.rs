//! Reference builder: a dense bottom-up pyramid. Level `L` is the voxel array; each coarser level holds, per
//! cell, empty / full / partial from its `2^K` children. Simple enough to trust; `O(U^K)` time and memory, so
//! only for small universes (tests).
//!
//! ```
//! use ktree::{reference::DensePyramid, NodeState};
//! // A 4-voxel bintree universe with voxels 0 and 1 full.
//! let p = DensePyramid::<1>::from_dense(2, &[true, true, false, false]).unwrap();
//! assert_eq!(p.state(0, [0]), NodeState::Partial); // the root
//! assert_eq!(p.state(1, [0]), NodeState::Full); // its lower half
//! assert_eq!(p.to_tree().voxel_count(), 2);
//! ```

use crate::rays::RaySet;
use crate::space::{SpaceError, Universe, DENSE_LIMIT};
use crate::tree::{KTree, NodeState, TreeAssembler};

/// A dense pyramid of node states, one array per level, axis 0 fastest within a level.
#[derive(Debug, Clone)]
pub struct DensePyramid<const K: usize> {
    universe: Universe<K>,
    /// `levels[d]` has `(2^d)^K` states.
    levels: Vec<Vec<NodeState>>,
}

impl<const K: usize> DensePyramid<K> {
    /// The pyramid of a dense boolean array (axis 0 fastest, see [`Universe::dense_index`]).
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`]; [`SpaceError::TooLargeForDense`] if `dense` does not have `U^K`
    /// entries or the universe exceeds [`DENSE_LIMIT`].
    pub fn from_dense(level: u32, dense: &[bool]) -> Result<Self, SpaceError> {
        let universe = Universe::<K>::new(level)?;
        let len = universe.dense_len(DENSE_LIMIT)?;
        if dense.len() != len {
            return Err(SpaceError::TooLargeForDense {
                voxels: dense.len() as u128,
                limit: len as u128,
            });
        }
        let bottom: Vec<NodeState> = dense
            .iter()
            .map(|&b| if b { NodeState::Full } else { NodeState::Empty })
            .collect();
        let mut levels = vec![bottom];
        for depth in (0..level).rev() {
            let fine = levels.last().expect("at least the voxel level");
            let fine_u = Universe::<K>::new(depth + 1)?;
            let coarse_u = Universe::<K>::new(depth)?;
            let mut coarse = Vec::with_capacity(fine.len() >> K);
            for i in 0..fine.len() >> K {
                let p = coarse_u.dense_point(i);
                let mut child_states = (0..1usize << K).map(|code| {
                    let mut q = p;
                    for (axis, c) in q.iter_mut().enumerate() {
                        *c = 2 * *c + (code >> axis & 1) as u32;
                    }
                    fine[fine_u.dense_index(q)]
                });
                let first = child_states.next().expect("2^K >= 2 children");
                let uniform = first != NodeState::Partial && child_states.all(|s| s == first);
                coarse.push(if uniform { first } else { NodeState::Partial });
            }
            levels.push(coarse);
        }
        levels.reverse();
        Ok(Self { universe, levels })
    }

    /// The pyramid of a ray set, through a dense array.
    ///
    /// # Errors
    /// As [`DensePyramid::from_dense`].
    pub fn from_rays(rays: &RaySet<K>) -> Result<Self, SpaceError> {
        let u = rays.universe();
        let mut dense = vec![false; u.dense_len(DENSE_LIMIT)?];
        for ray in rays.iter() {
            let mut p = ray.start;
            for z in ray.z1()..ray.z2 {
                p[K - 1] = z;
                dense[u.dense_index(p)] = true;
            }
        }
        Self::from_dense(u.level(), &dense)
    }

    /// The state of the cell at `depth` whose origin, divided by the cell side, is `point`.
    pub fn state(&self, depth: u32, point: [u32; K]) -> NodeState {
        let u = Universe::<K>::new(depth).expect("depth <= level");
        self.levels[depth as usize][u.dense_index(point)]
    }

    /// The reduced `KTree` of the pyramid, by a depth-first walk from the root.
    pub fn to_tree(&self) -> KTree<K> {
        let mut out =
            TreeAssembler::<K>::new(self.universe.level()).expect("level already checked");
        self.walk(&mut out, 0, [0; K]);
        out.finish()
    }

    fn walk(&self, out: &mut TreeAssembler<K>, depth: u32, point: [u32; K]) {
        let state = self.state(depth, point);
        out.push(depth as usize, state);
        if state == NodeState::Partial {
            for code in 0..1usize << K {
                let mut q = point;
                for (axis, c) in q.iter_mut().enumerate() {
                    *c = 2 * *c + (code >> axis & 1) as u32;
                }
                self.walk(out, depth + 1, q);
            }
        }
    }
}

impl<const K: usize> KTree<K> {
    /// The tree of a dense boolean array (axis 0 fastest, see [`Universe::dense_index`]), reduced.
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`]; [`SpaceError::TooLargeForDense`] if `dense.len() != U^K` or the
    /// universe exceeds [`DENSE_LIMIT`](crate::space::DENSE_LIMIT).
    pub fn from_dense(level: u32, dense: &[bool]) -> Result<Self, SpaceError> {
        DensePyramid::<K>::from_dense(level, dense).map(|p| p.to_tree())
    }
}
