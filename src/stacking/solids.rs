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

#[cfg(feature = "mesh")]
impl<V: crate::value::Value + TryFrom<u32>> KTree<3, V> {
    /// The tree of labels of several meshes placed together in a universe of level `level`: mesh `i` (in
    /// the order given) is label `i + 1`, the voxels of no mesh the background; where meshes overlap, the
    /// later mesh wins. One placement for all: [`Placement::Fit`](crate::solid::mesh::Placement::Fit)
    /// fits the union of their bounding boxes ([`MeshTransform::fit_all`](crate::solid::mesh::MeshTransform::fit_all)).
    /// Built from the runs of [`label_runs`](crate::solid::mesh::label_runs), so minimal; a mesh that is
    /// not closed is voxelized column by column as [`KTree::from_mesh`] does (check
    /// [`TriangleMesh::open_edges`](crate::solid::mesh::TriangleMesh::open_edges) first to refuse one).
    ///
    /// ```
    /// use ktree::solid::mesh::{Placement, TriangleMesh};
    /// use ktree::KTree;
    /// let tetrahedron = |at: f64| TriangleMesh::new(
    ///     vec![[at, 0.0, 0.0], [at + 1.0, 0.0, 0.0], [at, 1.0, 0.0], [at, 0.0, 1.0]],
    ///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    /// ).unwrap();
    /// let meshes = [tetrahedron(0.0), tetrahedron(2.0)];
    /// let tree = KTree::<3, u8>::from_label_meshes(&meshes, 5, Placement::Fit).unwrap();
    /// let labels: Vec<u8> = tree.value_stats().into_keys().collect();
    /// assert_eq!(labels, [1, 2]);
    /// tree.assert_well_formed();
    /// ```
    ///
    /// # Errors
    /// [`SolidError`]: a bad level, meshes that cannot be fitted or are too large for the universe, no
    /// mesh, or more meshes than `V` has labels.
    pub fn from_label_meshes(
        meshes: &[crate::solid::mesh::TriangleMesh],
        level: u32,
        placement: crate::solid::mesh::Placement,
    ) -> Result<Self, SolidError> {
        let transform = placement.transform_all(meshes, level)?;
        let labels = crate::solid::mesh::label_runs(meshes, level, &transform)?;
        Ok(Self::from_value_runs(&labels.runs))
    }
}
