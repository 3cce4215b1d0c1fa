//! Where a mesh goes in the universe: a uniform scale and a translation, given or fitted.

use super::TriangleMesh;
use crate::solid::SolidError;
use crate::space::Universe;

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
        let (lo, hi) = mesh
            .bounds()
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
}
