//! Meagher's octree-encoding operations for any `K` (Meagher 1982, claims M2–M6, M8–M10, M14): Booleans,
//! translation, scaling, rotations and reflections by reordering children, arbitrary affine maps by
//! overlays, interference detection, mass properties and the complexity metric.
//!
//! Every operation reads [`KTree`](crate::KTree)s and writes a new, *reduced* tree in one depth-first pass
//! that produces level order directly; none expands the object to voxels. Which ones are integer-only
//! (Meagher's M8) is said in [`affine`]'s docs: all but [`transform`] and [`transform_projective`], which
//! use `f64`; [`transform_fixed`] does the affine maps with integer additions and shifts.
//!
//! | operation | functions | method | cost |
//! |---|---|---|---|
//! | Booleans (M2) | [`boolean`], [`union`], [`intersection`], [`difference`], [`symmetric_difference`], [`complement`] | simultaneous depth-first traversal; complement on packed words | linear in the nodes reached |
//! | Booleans of files larger than memory | [`boolean_files`], [`complement_file`] | the same traversal over memory maps, levels spilled and streamed to a `.ktree` | linear; memory bounded by the depth |
//! | translation (M3) | [`translate`], [`translate_fine`] | fixed overlay of `2^K` obels per target node | linear in the output nodes |
//! | scaling (M4) | [`grow`], [`zoom`] (by `2^n` through the root), [`scale`] (rational, overlays) | root levels; overlay engine | `O(n·2^K)` + copy; output-sensitive |
//! | rotations, reflections (M5) | [`rotate_axes`] with any [`AxisMap`] (`K!·2^K` of them) | child reordering | linear |
//! | arbitrary rotation, any affine map (M5, M6) | [`transform`] with an [`Affine`] | overlay engine, voxel-exact | output-sensitive |
//! | the same with integer additions and shifts only (M5, M8) | [`transform_fixed`] | overlay engine, fixed-point cell images updated incrementally | output-sensitive |
//! | perspective deformation (M6) | [`transform_projective`] with a [`Projective`] map, e.g. [`Projective::perspective`] | overlay engine, voxel-exact | output-sensitive |
//! | interference (M14) | [`interferes`], [`overlap_cells`], [`first_contact`], [`min_separation`] | simultaneous traversal, early exit; branch and bound | at most linear |
//! | mass (M10) | [`mass_properties`], [`mass_of_leaves`], [`mass_progressive`] | exact integer moment sums; level-by-level bounds | linear; stops early |
//! | complexity (M9) | [`complexity`], [`over_translations`], [`over_placements`], [`over_maps`], [`bounding_box`], [`normalise_to_origin`] | node counts | one operation per placement |
//!
//! ```
//! use ktree::{stacking::paper::stack, rays::ball_rays, ops};
//! let a = stack(&ball_rays::<3>(5, [24, 32, 32], 20).unwrap());
//! let b = stack(&ball_rays::<3>(5, [40, 32, 32], 20).unwrap());
//! let lens = ops::intersection(&a, &b).unwrap();
//! lens.assert_well_formed();
//! assert!(ops::interferes(&a, &b).unwrap());
//! assert_eq!(ops::mass_properties(&lens).centroid[0], 16.0);
//! ```

pub mod affine;
mod any;
mod boolean;
mod boolean_files;
mod complexity;
mod emit;
mod error;
mod fixed;
mod interference;
mod mass;
pub mod overlay;
mod perspective;
mod rotate;
mod scale;
mod separation;
mod translate;
pub mod values;

pub use affine::{transform, Affine};
pub use boolean::{
    boolean, complement, difference, intersection, symmetric_difference, union, BoolOp,
};
pub use boolean_files::{
    boolean_files, boolean_views, complement_file, BooleanFileError, BooleanFileReport,
    ViewOperation,
};
pub use complexity::{
    bounding_box, complexity, normalise_to_origin, over_maps, over_placements, over_translations,
    Normalised,
};
pub use error::OpsError;
pub use fixed::{transform_fixed, FixedAffine};
pub use interference::{collision, first_contact, interferes, overlap_cells, Collision};
pub use mass::{
    mass_of_leaves, mass_progressive, mass_properties, LevelBounds, MassProperties, ProgressiveMass,
};
pub use perspective::{transform_projective, Projective};
pub use rotate::{rotate_axes, AxisMap};
pub use scale::{grow, scale, zoom};
pub use separation::min_separation;
pub use translate::{fine_shift, translate, translate_fine};
