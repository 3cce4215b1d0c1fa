//! Ray sets whose dimension is known only at run time (read from a ray file): [`AnyRaySet`].

use super::RaySet;

/// A [`RaySet`] of any supported dimension, as read from a ray file whose header names `K`.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyRaySet {
    /// Rays of a bintree universe.
    K1(RaySet<1>),
    /// Rays of a quadtree universe.
    K2(RaySet<2>),
    /// Rays of an octree universe.
    K3(RaySet<3>),
    /// Rays of a 4-D universe.
    K4(RaySet<4>),
}

impl AnyRaySet {
    /// The dimension `K`.
    pub fn k(&self) -> usize {
        match self {
            Self::K1(_) => 1,
            Self::K2(_) => 2,
            Self::K3(_) => 3,
            Self::K4(_) => 4,
        }
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        with_dim!(self, AnyRaySet, r => r.level())
    }

    /// The number of runs.
    pub fn len(&self) -> usize {
        with_dim!(self, AnyRaySet, r => r.len())
    }

    /// Whether there is no run.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

crate::dim::from_typed!(RaySet, AnyRaySet);
