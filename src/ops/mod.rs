//! Meagher's octree-encoding operations for any `K` (Meagher 1982, claims M2–M6, M8–M10, M14): Booleans,
//! translation, scaling, rotations and reflections by reordering children, arbitrary affine maps by
//! overlays, interference detection, mass properties and the complexity metric.
//!
//! Every operation reads its trees through the one storage trait, [`TreeStorage`](crate::tree::TreeStorage)
//! — a [`KTree`](crate::KTree) in memory, whose reads cannot fail, or a `.ktree` file read in place
//! (`io::MappedTree`), whose every read is checked — and writes a new, *reduced* tree in one depth-first
//! pass that produces level order directly; none expands the object to voxels. The operations that make a
//! tree write it through a [`LevelSink`](crate::tree::sink::LevelSink) given by the caller (the `*_into`
//! forms: [`boolean_into`], [`translate_into`], [`transform_into`], …), so that the output may go to
//! files level by level as well as into memory (the plain forms return a `KTree`). Which ones are integer-only
//! (Meagher's M8) is said in [`affine`]'s docs: all but [`transform`] and [`transform_projective`], which
//! use `f64`; [`transform_fixed`] does the affine maps with integer additions and shifts.
//!
//! | operation | functions | method | cost |
//! |---|---|---|---|
//! | Booleans (M2) | [`boolean`], [`union`], [`intersection`], [`difference`], [`symmetric_difference`], [`complement`] | simultaneous depth-first traversal; complement on packed words | linear in the nodes reached |
//! | Booleans of files larger than memory | `io::boolean_files`, `io::complement_file` | [`boolean_into`] over memory maps, levels spilled and streamed to a `.ktree` | linear; memory bounded by the depth |
//! | translation (M3) | [`translate`], [`translate_fine`] | fixed overlay of `2^K` obels per target node | linear in the output nodes |
//! | scaling (M4) | [`grow`], [`zoom`] (by `2^n` through the root; [`grow_values`], [`zoom_values`] with values), [`scale`] (rational, overlays) | root levels; overlay engine | `O(n·2^K)` + copy; output-sensitive |
//! | rotations, reflections (M5) | [`rotate_axes`] with any [`AxisMap`] (`K!·2^K` of them) | child reordering | linear |
//! | arbitrary rotation, any affine map (M5, M6) | [`transform`] with an [`Affine`] | overlay engine, voxel-exact | output-sensitive |
//! | the same with integer additions and shifts only (M5, M8) | [`transform_fixed`] | overlay engine, fixed-point cell images updated incrementally | output-sensitive |
//! | perspective deformation (M6) | [`transform_projective`] with a [`Projective`] map, e.g. [`Projective::perspective`] | overlay engine, voxel-exact | output-sensitive |
//! | the same on a valued tree, each voxel keeping its value | [`rotate_values`], [`scale_values`], [`transform_values`], [`transform_projective_values`], `KTree::translate_values`; [`Geometry`] names each transform once for binary and valued trees | child reordering; the overlay engine over values ([`overlay::resample_values`]) | as above |
//! | interference (M14) | [`interferes`], [`overlap_cells`], [`first_contact`], [`min_separation`] | simultaneous traversal, early exit; branch and bound | at most linear |
//! | mass (M10) | [`mass_properties`], [`mass_progressive`] | exact integer moment sums; level-by-level bounds | linear; stops early |
//! | complexity (M9) | [`complexity`], [`over_translations`], [`over_placements`], [`over_maps`], [`normalise_to_origin`] | node counts | one operation per placement |
//!
//! ```
//! use ktree::{stacking::paper::stack, rays::ball_rays, ops};
//! let a = stack(&ball_rays::<3>(5, [24, 32, 32], 20).unwrap());
//! let b = stack(&ball_rays::<3>(5, [40, 32, 32], 20).unwrap());
//! let lens = ops::intersection(&a, &b).unwrap();
//! lens.assert_well_formed();
//! assert!(ops::interferes(&a, &b).unwrap());
//! assert_eq!(ops::mass_properties(&lens).unwrap().centroid[0], 16.0);
//! ```

pub mod affine;
mod any;
mod boolean;
mod complexity;
mod error;
mod fixed;
mod geometry;
mod interference;
mod mass;
mod operators;
mod output;
pub mod overlay;
mod perspective;
mod project;
mod rotate;
mod scale;
mod separation;
mod translate;
pub mod values;

pub use affine::{transform, transform_into, transform_values, Affine};
pub use boolean::{
    boolean, boolean_into, complement, complement_into, difference, intersection,
    symmetric_difference, union, BoolOp,
};
pub use complexity::{
    complexity, normalise_to_origin, over_maps, over_placements, over_translations, Normalised,
};
pub use error::OpsError;
pub use fixed::{transform_fixed, transform_fixed_into, FixedAffine};
pub use geometry::Geometry;
pub use interference::{collision, first_contact, interferes, overlap_cells, Collision};
pub use mass::{mass_progressive, mass_properties, LevelBounds, MassProperties, ProgressiveMass};
pub use perspective::{
    transform_projective, transform_projective_into, transform_projective_values, Projective,
};
pub use project::{extrude, project, slice, slice_values};
pub use rotate::{rotate_axes, rotate_axes_into, rotate_values, AxisMap};
pub use scale::{
    grow, grow_into, grow_values, scale, scale_into, scale_values, zoom, zoom_into, zoom_values,
};
pub use separation::min_separation;
pub use translate::{fine_shift, translate, translate_fine, translate_fine_into, translate_into};
