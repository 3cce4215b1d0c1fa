//! Building a tree from a ray set whose dimension is known only at run time.

use crate::rays::AnyRaySet;
use crate::tree::AnyTree;

impl AnyRaySet {
    /// Builds the tree by stacking.
    pub fn stack(&self) -> AnyTree {
        match self {
            Self::K1(r) => AnyTree::K1(crate::stacking::stack(r)),
            Self::K2(r) => AnyTree::K2(crate::stacking::stack(r)),
            Self::K3(r) => AnyTree::K3(crate::stacking::stack(r)),
            Self::K4(r) => AnyTree::K4(crate::stacking::stack(r)),
        }
    }
}
