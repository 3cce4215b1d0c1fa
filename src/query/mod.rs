//! Questions asked of a map, for every `K` and on every storage (a tree in memory, a `.ktree` file read
//! through its map): batch point queries and a cached cursor ([`points`]), bounding boxes, counts and
//! crops of boxes ([`boxes`]), dense windows ([`dense`]), ray casting ([`ray`]) and the nearest full voxel ([`nearest`](mod@nearest)).
//!
//! Conventions: voxel `v` is the box `[v, v + 1)` in continuous coordinates and the universe is
//! `[0, U)^K`; points outside the universe are outside the object (a query answers, it does not fail).
//! Boxes are `(lo, hi)` with `hi` exclusive. Distances are Euclidean, in voxel units, between voxel
//! centres (as scipy's `distance_transform_edt` measures them).
//!
//! Every query is a provided method of [`Query`], implemented for every
//! [`TreeStorage`]: a tree in memory and a `.ktree` file mapped in
//! place (`io::MappedTree`) answer the same calls, each a walk of [`cursor`](crate::tree::cursor) or the
//! one point descent of [`locate`](crate::tree::locate); the batch forms run on the threads of the
//! current rayon pool. [`KTree`] also has each as a method that cannot fail.
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

mod box_table;
pub mod boxes;
pub mod dense;
pub mod nearest;
pub mod points;
pub mod ray;
pub mod stats;
pub mod values;

pub use boxes::{bounding_box, count, crop, VoxelBox};
pub use dense::{dense_window, dense_window_into, window_voxels, DenseError, DenseOrder};
pub use nearest::{distance, nearest, nearest_many, nearest_many_signed, nearest_signed, Nearest};
pub use points::{contains, contains_many, contains_many_signed, PointCursor};
pub use ray::{cast_ray, cast_rays, CastError, Face, RayCast, RayHit};
pub use stats::{stats, TreeStats};
pub use values::{first_values, values_at, values_at_into};

use crate::tree::storage::{infallible, TreeStorage};
use crate::KTree;

/// The questions asked of a map, provided for every storage of a tree: [`KTree`] in memory (whose
/// reads cannot fail: its own methods of the same names drop the `Result`) and a `.ktree` file read in
/// place (`io::MappedTree`), whose reads fail with an error naming the file and byte when the file
/// changed after it was opened. One primitive is required (the storage's reads); every query is
/// provided on it, as parry's `PointQuery` provides its queries on one projection.
///
/// ```
/// use ktree::query::Query;
/// use ktree::KTree;
/// fn inside_share<T: Query<2>>(tree: &T) -> Result<f64, T::Error> {
///     let inside = tree.contains_many(&[[0, 0], [1, 1], [2, 2], [3, 3]])?;
///     Ok(inside.iter().filter(|&&b| b).count() as f64 / 4.0)
/// }
/// let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i < 8).collect::<Vec<_>>()).unwrap();
/// assert_eq!(inside_share(&tree), Ok(0.5));
/// ```
pub trait Query<const K: usize>: TreeStorage<K> + Sync + Sized {
    /// Whether voxel `point` is inside the object ([`contains()`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn contains(&self, point: [u32; K]) -> Result<bool, Self::Error> {
        contains(self, point)
    }

    /// Whether each voxel of `points` is inside the object, in the order given, on all threads
    /// ([`contains_many()`]).
    ///
    /// # Errors
    /// The storage's first read error.
    fn contains_many(&self, points: &[[u32; K]]) -> Result<Vec<bool>, Self::Error> {
        contains_many(self, points)
    }

    /// A cursor for coherent point queries ([`PointCursor`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn cursor(&self) -> Result<PointCursor<'_, K, Self>, Self::Error> {
        PointCursor::new(self)
    }

    /// The bounding box of the full voxels, `(lo, hi)` with `hi` exclusive; `None` when empty
    /// ([`bounding_box()`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn bounding_box(&self) -> Result<Option<VoxelBox<K>>, Self::Error> {
        bounding_box(self)
    }

    /// The number of full voxels in the box `[lo, hi)` ([`count()`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn count(&self, lo: [u32; K], hi: [u32; K]) -> Result<u128, Self::Error> {
        count(self, lo, hi)
    }

    /// The object cut to the box `[lo, hi)`, in memory ([`crop()`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn crop(&self, lo: [u32; K], hi: [u32; K]) -> Result<KTree<K>, Self::Error> {
        crop(self, lo, hi)
    }

    /// The voxels of the box `[lo, hi)` (anywhere: outside the universe is empty) as a dense array in
    /// `order` ([`dense_window()`]).
    ///
    /// # Errors
    /// [`DenseError::TooLarge`] past the dense limit, [`DenseError::Storage`] for a read error.
    fn dense_window(
        &self,
        lo: [i64; K],
        hi: [i64; K],
        order: DenseOrder,
    ) -> Result<Vec<bool>, DenseError> {
        dense_window(self, lo, hi, order)
    }

    /// The first full voxel `ray` enters ([`cast_ray()`]; ties as [`ray`] says).
    ///
    /// # Errors
    /// The storage's read error.
    fn cast_ray(&self, ray: &RayCast<K>) -> Result<Option<RayHit<K>>, Self::Error> {
        cast_ray(self, ray)
    }

    /// [`Query::cast_ray`] for each ray, on all threads ([`cast_rays()`]).
    ///
    /// # Errors
    /// The storage's first read error.
    fn cast_rays(&self, rays: &[RayCast<K>]) -> Result<Vec<Option<RayHit<K>>>, Self::Error> {
        cast_rays(self, rays)
    }

    /// A nearest full voxel to voxel `point` and its squared distance; `None` when empty ([`nearest()`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn nearest(&self, point: [u32; K]) -> Result<Option<Nearest<K>>, Self::Error> {
        nearest(self, point)
    }

    /// [`Query::nearest`] for each point, on all threads ([`nearest_many()`]).
    ///
    /// # Errors
    /// The storage's first read error.
    fn nearest_many(&self, points: &[[u32; K]]) -> Result<Vec<Option<Nearest<K>>>, Self::Error> {
        nearest_many(self, points)
    }

    /// The distance from voxel `point` to the nearest full voxel: `0` inside, infinite when empty
    /// ([`distance()`]).
    ///
    /// # Errors
    /// The storage's read error.
    fn distance(&self, point: [u32; K]) -> Result<f64, Self::Error> {
        distance(self, point)
    }
}

impl<const K: usize, T: TreeStorage<K> + Sync> Query<K> for T {}

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
    /// [`CastError`] for an infinite or NaN coordinate or a NaN or negative `max_t`.
    pub fn cast_ray(
        &self,
        origin: [f64; K],
        direction: [f64; K],
        max_t: f64,
    ) -> Result<Option<RayHit<K>>, CastError> {
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
