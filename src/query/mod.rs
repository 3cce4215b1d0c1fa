//! Questions asked of a map, for every `K` and on every storage (a tree in memory, a `.ktree` file read
//! through its map): batch point queries and a cached cursor ([`points`]), bounding boxes, counts and
//! crops of boxes ([`boxes`]), ray casting ([`ray`]) and the nearest full voxel ([`nearest`](mod@nearest)).
//!
//! Conventions: voxel `v` is the box `[v, v + 1)` in continuous coordinates and the universe is
//! `[0, U)^K`; points outside the universe are outside the object (a query answers, it does not fail).
//! Boxes are `(lo, hi)` with `hi` exclusive. Distances are Euclidean, in voxel units, between voxel
//! centres (as scipy's `distance_transform_edt` measures them).
//!
//! Every query is generic over [`TreeStorage`](crate::tree::storage::TreeStorage) and runs as one walk
//! of [`cursor`](crate::tree::cursor); the batch forms run on the threads of the current rayon pool.
//!
//! ```
//! use ktree::KTree;
//! let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i == 5 || i == 6).collect::<Vec<_>>()).unwrap();
//! assert_eq!(tree.contains_many(&[[1, 1], [2, 1], [3, 3]]), [true, true, false]);
//! assert_eq!(tree.bounding_box(), Some(([1, 1], [3, 2])));
//! assert_eq!(tree.count([2, 0], [4, 4]), 1);
//! let hit = tree.cast_ray([0.5, 1.5], [1.0, 0.0], f64::INFINITY).unwrap().unwrap();
//! assert_eq!((hit.voxel, hit.t), ([1, 1], 0.5));
//! assert_eq!(tree.nearest([3, 3]).unwrap().voxel, [2, 1]);
//! ```

pub mod boxes;
pub mod nearest;
pub mod points;
pub mod ray;

pub use boxes::{bounding_box, count, crop, VoxelBox};
pub use nearest::{distance, nearest, nearest_many, nearest_many_signed, nearest_signed, Nearest};
pub use points::{contains, contains_many, PointCursor};
pub use ray::{cast_ray, cast_rays, Face, RayCast, RayError, RayHit};

use crate::tree::storage::infallible;
use crate::KTree;

/// The queries of this module as methods of a tree in memory.
impl<const K: usize> KTree<K> {
    /// Whether each voxel of `points` is inside the object, in the order given, answered on all threads
    /// ([`contains_many`]). Points outside the universe are `false`.
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(1, &[false, true]).unwrap();
    /// assert_eq!(tree.contains_many(&[[1], [0], [2]]), [true, false, false]);
    /// ```
    pub fn contains_many(&self, points: &[[u32; K]]) -> Vec<bool> {
        infallible(contains_many(self, points))
    }

    /// A cursor for coherent point queries ([`PointCursor`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(1, &[false, true]).unwrap();
    /// let mut cursor = tree.cursor();
    /// assert_eq!(cursor.contains([1]), Ok(true));
    /// ```
    pub fn cursor(&self) -> PointCursor<'_, K, KTree<K>> {
        infallible(PointCursor::new(self))
    }

    /// The bounding box of the full voxels, `(lo, hi)` with `hi` exclusive; `None` when empty
    /// ([`bounding_box`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
    /// assert_eq!(tree.bounding_box(), Some(([1], [3])));
    /// ```
    pub fn bounding_box(&self) -> Option<VoxelBox<K>> {
        infallible(bounding_box(self))
    }

    /// The number of full voxels in the box `[lo, hi)` ([`count`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
    /// assert_eq!(tree.count([2], [4]), 1);
    /// ```
    pub fn count(&self, lo: [u32; K], hi: [u32; K]) -> u128 {
        infallible(count(self, lo, hi))
    }

    /// The object cut to the box `[lo, hi)` ([`crop`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(2, &[false, true, true, false]).unwrap();
    /// assert_eq!(tree.crop([2], [4]).voxel_count(), 1);
    /// ```
    pub fn crop(&self, lo: [u32; K], hi: [u32; K]) -> KTree<K> {
        infallible(crop(self, lo, hi))
    }

    /// The first full voxel the ray `origin + t · direction` enters at `0 ≤ t ≤ max_t` ([`cast_ray`];
    /// ties as its module says).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(2, &[false, false, true, false]).unwrap();
    /// assert_eq!(tree.cast_ray([0.0], [1.0], 10.0).unwrap().unwrap().t, 2.0);
    /// assert!(tree.cast_ray([f64::NAN], [1.0], 10.0).is_err());
    /// ```
    ///
    /// # Errors
    /// [`RayError`] for an infinite or NaN coordinate or a NaN or negative `max_t`.
    pub fn cast_ray(
        &self,
        origin: [f64; K],
        direction: [f64; K],
        max_t: f64,
    ) -> Result<Option<RayHit<K>>, RayError> {
        let ray = RayCast::new(origin, direction, max_t)?;
        Ok(infallible(cast_ray(self, &ray)))
    }

    /// [`KTree::cast_ray`] for each ray, on all threads ([`cast_rays`]).
    pub fn cast_rays(&self, rays: &[RayCast<K>]) -> Vec<Option<RayHit<K>>> {
        infallible(cast_rays(self, rays))
    }

    /// A nearest full voxel to voxel `point` and its squared distance; `None` when empty ([`nearest()`];
    /// ties: the smallest Morton key).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(2, &[false, false, true, false]).unwrap();
    /// assert_eq!(tree.nearest([0]).unwrap().voxel, [2]);
    /// ```
    pub fn nearest(&self, point: [u32; K]) -> Option<Nearest<K>> {
        infallible(nearest(self, point))
    }

    /// [`KTree::nearest`] for each point, on all threads ([`nearest_many`]).
    pub fn nearest_many(&self, points: &[[u32; K]]) -> Vec<Option<Nearest<K>>> {
        infallible(nearest_many(self, points))
    }

    /// The distance from voxel `point` to the nearest full voxel: `0` inside, infinite when empty
    /// ([`distance`]).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::<1>::from_dense(2, &[false, false, true, false]).unwrap();
    /// assert_eq!(tree.distance([0]), 2.0);
    /// ```
    pub fn distance(&self, point: [u32; K]) -> f64 {
        infallible(distance(self, point))
    }
}
