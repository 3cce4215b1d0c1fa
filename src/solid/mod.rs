//! Solids to rays: analytic quadrics (and boxes), triangle meshes and scalar volumes become [`RaySet`]s
//! exactly, touching only the columns that meet the solid.
//!
//! * [`Quadric`]: `Vᵀ Ξ V ≤ 0` with named constructors (ball, ellipsoid, paraboloid, cylinder, cone,
//!   half-space) and [`BoxSolid`]; exact integer inside tests at voxel centres (or corners).
//! * [`mesh`]: triangle meshes, inside by the winding number along each column.
//! * [`cloud`]: point clouds, the voxels holding points.
//!
//! Meshes and clouds are read from their files by [`crate::io`] (`read_mesh`, `read_cloud`).
//! * [`volume`]: dense 3-D scalar volumes (raw + JSON sidecar, NIfTI) by threshold or label.
//! * [`volume_file`]: a volume file read plane by plane, and a tree of its labels built slab by slab.
//!
//! Boolean operations and translation on the resulting rays are in [`crate::rays`] (`union`, …).
//!
//! ```
//! use ktree::solid::{BoxSolid, Frame, Sample};
//! use ktree::stacking::paper::stack;
//! // The box [0, 4] × [0, 2] in voxel units: the voxel centres inside are x in 0..4, y in 0..2.
//! let b = BoxSolid::<2>::new([0.into(), 0.into()], [4.into(), 2.into()], Frame::Voxel).unwrap();
//! let rays = b.to_rays(3, Sample::Centre, false).unwrap();
//! assert_eq!(rays.voxel_count(), 8);
//! assert_eq!(stack(&rays).node_count(), 9); // two levels of quadrants: 1 + 4 + 4
//! ```

mod boxsolid;
#[cfg(feature = "cloud")]
pub mod cloud;
mod error;
#[cfg(feature = "mesh")]
pub mod mesh;
mod named;
mod quadric;
mod rational;
#[cfg(feature = "volume")]
pub mod volume;
#[cfg(feature = "volume")]
pub mod volume_file;
#[cfg(feature = "volume")]
mod volume_format;

pub use boxsolid::BoxSolid;
pub use error::SolidError;
pub use quadric::{Frame, Quadric, Sample};
pub use rational::Rational;

use std::borrow::Cow;
use std::ops::Range;

use crate::rays::RaySet;
use crate::rays::{RaySource, SlabRuns};
use crate::space::Universe;

/// The most runs a quadric or a box generates (about 1.5 GiB of rays); beyond it the generator stops with
/// [`SolidError::TooManyRays`] instead of exhausting memory.
pub const MAX_RAYS: usize = 1 << 27;

/// Any analytic solid: a quadric or a box.
#[allow(clippy::large_enum_variant)] // a handful of solids at a time
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Solid<const K: usize> {
    /// `Vᵀ Ξ V ≤ 0`.
    Quadric(Quadric<K>),
    /// An axis-aligned box.
    Box(BoxSolid<K>),
}

impl<const K: usize> Solid<K> {
    /// The solid's voxels as rays (see [`Quadric::to_rays`]).
    ///
    /// # Errors
    /// As [`Quadric::to_rays`].
    pub fn to_rays(
        &self,
        level: u32,
        sample: Sample,
        normals: bool,
    ) -> Result<RaySet<K>, SolidError> {
        match self {
            Solid::Quadric(q) => q.to_rays(level, sample, normals),
            Solid::Box(b) => b.to_rays(level, sample, normals),
        }
    }

    /// The rays of the columns whose axis-0 coordinate lies in `x` (see [`Quadric::slab_rays`]).
    ///
    /// # Errors
    /// As [`Quadric::to_rays`].
    pub fn slab_rays(
        &self,
        level: u32,
        sample: Sample,
        x: Range<u32>,
    ) -> Result<RaySet<K>, SolidError> {
        match self {
            Solid::Quadric(q) => q.slab_rays(level, sample, x),
            Solid::Box(b) => b.slab_rays(level, sample, x),
        }
    }

    /// Whether one voxel is inside (the brute-force reference).
    pub fn contains(&self, level: u32, sample: Sample, point: [u32; K]) -> bool {
        match self {
            Solid::Quadric(q) => q.contains(level, sample, point),
            Solid::Box(b) => b.contains(level, sample, point),
        }
    }
}

/// A solid in a universe, producing its rays slab by slab for
/// [`Builder::build`](crate::stacking::Builder::build): no whole ray set is held and no cap on the number of
/// rays applies.
///
/// ```
/// use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
/// use ktree::stacking::{paper::stack, Builder};
/// let ball = Solid::Quadric(Quadric::<3>::ball([Rational::int(16); 3], Rational::int(11), Frame::Voxel).unwrap());
/// let source = SolidSource::new(&ball, 5, Sample::Centre).unwrap();
/// let tree = Builder::new(&source).split_depth(2).build().unwrap();
/// assert_eq!(tree, stack(&ball.to_rays(5, Sample::Centre, false).unwrap()));
/// ```
#[derive(Debug, Clone)]
pub struct SolidSource<'a, const K: usize> {
    solid: &'a Solid<K>,
    universe: Universe<K>,
    sample: Sample,
}

impl<'a, const K: usize> SolidSource<'a, K> {
    /// The solid's rays in a universe of level `level`.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level.
    pub fn new(solid: &'a Solid<K>, level: u32, sample: Sample) -> Result<Self, SolidError> {
        Ok(Self {
            solid,
            universe: Universe::new(level)?,
            sample,
        })
    }
}

impl<const K: usize> RaySource<K> for SolidSource<'_, K> {
    type Error = SolidError;

    fn universe(&self) -> Universe<K> {
        self.universe
    }

    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, SolidError> {
        let (keys, runs) = self
            .solid
            .slab_rays(self.universe.level(), self.sample, x)?
            .into_parts();
        Ok(SlabRuns {
            keys: Cow::Owned(keys),
            runs: Cow::Owned(runs),
        })
    }
}
