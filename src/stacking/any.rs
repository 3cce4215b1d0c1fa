//! Building a tree from a ray set whose dimension is known only at run time.

use crate::rays::AnyRaySet;
use crate::tree::{AnyTree, KTree};

impl AnyRaySet {
    /// The tree of the rays, by the default build ([`KTree::from_rays`]).
    pub fn build(&self) -> AnyTree {
        match self {
            Self::K1(r) => AnyTree::K1(KTree::from_rays(r)),
            Self::K2(r) => AnyTree::K2(KTree::from_rays(r)),
            Self::K3(r) => AnyTree::K3(KTree::from_rays(r)),
            Self::K4(r) => AnyTree::K4(KTree::from_rays(r)),
        }
    }
}
