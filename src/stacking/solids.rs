//! Building a tree from a solid or a mesh in one call: the solid's rays are made slab by slab as the
//! [`Builder`] stacks the cells (never held whole), on the threads of the current rayon pool.

use super::Builder;
use crate::solid::{Sample, Solid, SolidError, SolidSource};
use crate::tree::KTree;

impl<const K: usize> KTree<K> {
    /// The tree of `solid` in a universe of level `level`, each voxel in when its `sample` point is.
    ///
    /// ```
    /// use ktree::solid::{Frame, Quadric, Rational, Sample, Solid};
    /// use ktree::KTree;
    /// let ball = Solid::Quadric(Quadric::<3>::ball([Rational::int(8); 3], Rational::int(6), Frame::Voxel).unwrap());
    /// let tree = KTree::from_solid(&ball, 4, Sample::Centre).unwrap();
    /// assert_eq!(tree, KTree::from_rays(&ball.to_rays(4, Sample::Centre, false).unwrap()));
    /// ```
    ///
    /// # Errors
    /// [`SolidError`]: a bad level, or a solid that cannot make its rays.
    pub fn from_solid(solid: &Solid<K>, level: u32, sample: Sample) -> Result<Self, SolidError> {
        let source = SolidSource::new(solid, level, sample)?;
        Builder::new(&source).build_on_current_pool()
    }
}

#[cfg(feature = "mesh")]
impl KTree<3> {
    /// The tree of a closed triangle mesh in a universe of level `level`, placed as `placement` says
    /// (the voxels whose centres lie inside the mesh).
    ///
    /// ```
    /// use ktree::solid::mesh::{Placement, TriangleMesh};
    /// use ktree::KTree;
    /// // A tetrahedron, fitted into a 32³ universe.
    /// let mesh = TriangleMesh::new(
    ///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    /// ).unwrap();
    /// let tree = KTree::from_mesh(&mesh, 5, Placement::Fit).unwrap();
    /// let volume = 30.0f64.powi(3) / 6.0; // the fitted tetrahedron's volume, in voxels
    /// assert!((tree.voxel_count() as f64 - volume).abs() < 0.1 * volume);
    /// ```
    ///
    /// # Errors
    /// [`SolidError`]: a bad level, a mesh that cannot be fitted, or one too large for the universe.
    pub fn from_mesh(
        mesh: &crate::solid::mesh::TriangleMesh,
        level: u32,
        placement: crate::solid::mesh::Placement,
    ) -> Result<Self, SolidError> {
        let transform = placement.transform(mesh, level)?;
        let source = crate::solid::mesh::MeshSource::new(mesh, level, &transform)?;
        match Builder::new(&source).build_on_current_pool() {
            Ok(tree) => Ok(tree),
            Err(never) => match never {},
        }
    }
}
