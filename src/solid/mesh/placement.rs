//! Where a mesh goes in the universe: a uniform scale and a translation, given or fitted.

use super::TriangleMesh;
use crate::solid::SolidError;
use crate::space::{Universe, WorldFrame};

/// Where a mesh goes in the universe: voxel coordinate = `scale · v + translate`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshTransform {
    /// Uniform scale.
    pub scale: f64,
    /// Translation, in voxels.
    pub translate: [f64; 3],
}

impl MeshTransform {
    /// Parses `s,tx,ty,tz`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for anything else.
    pub fn parse(text: &str) -> Result<Self, SolidError> {
        let v: Vec<f64> = text
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                SolidError::BadParameter(format!("transform '{text}': expected s,tx,ty,tz"))
            })?;
        if v.len() != 4 || !v.iter().all(|x| x.is_finite()) || v[0] == 0.0 {
            return Err(SolidError::BadParameter(format!(
                "transform '{text}': expected four finite numbers s,tx,ty,tz with s ≠ 0"
            )));
        }
        Ok(Self {
            scale: v[0],
            translate: [v[1], v[2], v[3]],
        })
    }

    /// Uniform scale and centring of `mesh` into a universe of level `level`, one voxel of margin each side.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level; [`SolidError::BadParameter`] for an empty or flat mesh.
    pub fn fit(mesh: &TriangleMesh, level: u32) -> Result<Self, SolidError> {
        Self::fit_all(std::slice::from_ref(mesh), level)
    }

    /// Uniform scale and centring of the union of the bounding boxes of `meshes` into a universe of level
    /// `level`, one voxel of margin each side: the one placement [`MeshTransform::fit`] gives a mesh that
    /// holds them all.
    ///
    /// ```
    /// use ktree::solid::mesh::{MeshTransform, TriangleMesh};
    /// let tetrahedron = |at: f64| TriangleMesh::new(
    ///     vec![[at, 0.0, 0.0], [at + 1.0, 0.0, 0.0], [at, 1.0, 0.0], [at, 0.0, 1.0]],
    ///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    /// ).unwrap();
    /// let both = MeshTransform::fit_all(&[tetrahedron(0.0), tetrahedron(3.0)], 5).unwrap();
    /// assert_eq!(both.scale, 30.0 / 4.0); // the union is 4 wide
    /// assert_eq!(MeshTransform::fit(&tetrahedron(0.0), 5).unwrap().scale, 30.0);
    /// ```
    ///
    /// # Errors
    /// As [`MeshTransform::fit`]; no mesh is an empty union.
    pub fn fit_all(meshes: &[TriangleMesh], level: u32) -> Result<Self, SolidError> {
        let (lo, hi) = meshes
            .iter()
            .filter_map(TriangleMesh::bounds)
            .reduce(|(lo, hi), (l, h)| {
                (
                    std::array::from_fn(|a| lo[a].min(l[a])),
                    std::array::from_fn(|a| hi[a].max(h[a])),
                )
            })
            .ok_or_else(|| SolidError::BadParameter("the mesh has no vertex".into()))?;
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        let side = Universe::<3>::new(level)?.side() as f64;
        if extent.is_nan() || extent <= 0.0 || side <= 2.0 {
            return Err(SolidError::BadParameter(
                "cannot fit: the mesh has no extent or the universe is smaller than 4 voxels"
                    .into(),
            ));
        }
        let scale = (side - 2.0) / extent;
        let translate = std::array::from_fn(|a| side / 2.0 - scale * (lo[a] + hi[a]) / 2.0);
        Ok(Self { scale, translate })
    }

    /// `s,tx,ty,tz` (what [`MeshTransform::parse`] reads).
    pub fn to_arg(&self) -> String {
        format!(
            "{},{},{},{}",
            self.scale, self.translate[0], self.translate[1], self.translate[2]
        )
    }

    /// Where the voxels are in the mesh's units, when the scale is positive: voxels of side `1 / scale`,
    /// the corner of voxel 0 at `−translate / scale` (`None` for a mirroring, negative scale).
    ///
    /// ```
    /// use ktree::solid::mesh::MeshTransform;
    /// let t = MeshTransform { scale: 4.0, translate: [2.0, 0.0, -8.0] };
    /// let frame = t.world_frame().unwrap();
    /// assert_eq!((frame.voxel_size, frame.origin), (0.25, [-0.5, 0.0, 2.0]));
    /// assert_eq!(frame.corner_of([2, 0, 8]), [0.0, 0.0, 4.0]); // where s·v + t = (2, 0, 8)
    /// ```
    pub fn world_frame(&self) -> Option<WorldFrame> {
        (self.scale > 0.0).then(|| WorldFrame {
            voxel_size: 1.0 / self.scale,
            origin: self.translate.map(|t| -t / self.scale),
        })
    }

    /// The voxel coordinates of `v`.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| self.scale * v[a] + self.translate[a])
    }
}

/// Where a mesh goes in the universe, for [`KTree::from_mesh`](crate::KTree::from_mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// Scaled uniformly and centred into the universe with one voxel of margin each side
    /// ([`MeshTransform::fit`]).
    Fit,
    /// Voxel coordinate = `scale · v + translate`.
    Transform(MeshTransform),
}

impl Placement {
    /// The transform this placement gives `mesh` in a universe of level `level`.
    ///
    /// # Errors
    /// As [`MeshTransform::fit`].
    pub fn transform(&self, mesh: &TriangleMesh, level: u32) -> Result<MeshTransform, SolidError> {
        match self {
            Self::Fit => MeshTransform::fit(mesh, level),
            Self::Transform(t) => Ok(*t),
        }
    }

    /// The one transform this placement gives all of `meshes` together (fitted: their union,
    /// [`MeshTransform::fit_all`]).
    ///
    /// # Errors
    /// As [`MeshTransform::fit_all`].
    pub fn transform_all(
        &self,
        meshes: &[TriangleMesh],
        level: u32,
    ) -> Result<MeshTransform, SolidError> {
        match self {
            Self::Fit => MeshTransform::fit_all(meshes, level),
            Self::Transform(t) => Ok(*t),
        }
    }
}
