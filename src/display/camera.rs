//! Cameras: orthographic and perspective, given by eye, target, up and either the image height in world
//! units or the vertical field of view; the default framing of an object; the rays through pixel centres.
//!
//! World coordinates are voxel coordinates: voxel `(x, y, z)` is the unit cube `[x, x+1) × …`. The image's
//! pixel `(px, py)` has its centre at `(px + ½, py + ½)`, `py` growing downwards; screen up is the camera's
//! up vector.
//!
//! ```
//! use ktree::display::{default_camera, ISO_TOWARD_EYE};
//! use ktree::{rays::ball_rays, stacking::paper::stack};
//! let ball = stack(&ball_rays::<3>(5, [32, 32, 32], 28).unwrap());
//! let camera = default_camera(&ball, ISO_TOWARD_EYE, None, 100, 100).unwrap();
//! assert!(!camera.is_perspective());
//! // The ball's centre projects to the middle of the image.
//! let (x, y, _depth) = camera.project([16.0, 16.0, 16.0], 100, 100).unwrap();
//! assert!((x - 50.0).abs() < 1.0 && (y - 50.0).abs() < 1.0);
//! ```

use super::error::{CameraProblem, DisplayError};
use crate::tree::cursor::TryLeaves;
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// 3-D vector helpers (private to the display module).
pub(crate) mod v3 {
    /// `a · b`.
    #[inline]
    pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    /// `a × b`.
    #[inline]
    pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
    /// `a + s·b`.
    #[inline]
    pub fn add_scaled(a: [f64; 3], s: f64, b: [f64; 3]) -> [f64; 3] {
        [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
    }
    /// `a − b`.
    #[inline]
    pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    /// `|a|`.
    #[inline]
    pub fn norm(a: [f64; 3]) -> f64 {
        dot(a, a).sqrt()
    }
    /// `a / |a|`, `None` for a zero or non-finite vector.
    pub fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
        let n = norm(a);
        (n.is_finite() && n > 1e-300).then(|| [a[0] / n, a[1] / n, a[2] / n])
    }
}

/// How the camera projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Parallel projection; `height` is the height of the image in world units (voxels).
    Orthographic {
        /// Image height in voxels.
        height: f64,
    },
    /// Perspective projection with this vertical field of view in degrees (0 < fov < 180).
    Perspective {
        /// Vertical field of view, degrees.
        fov_y_degrees: f64,
    },
}

/// A camera: where it is, what it looks at, which way is up, and how it projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The eye (for orthographic views, a point on the image plane's centre line).
    pub eye: [f64; 3],
    /// The point looked at (the image centre).
    pub target: [f64; 3],
    /// The up direction (need not be orthogonal to the view direction, but not parallel to it).
    pub up: [f64; 3],
    /// The projection.
    pub projection: Projection,
}

/// The default "isometric-ish" direction from the object towards the eye: front-right and above, slightly
/// off the exact isometric diagonal so that no lattice lines coincide in projection.
pub const ISO_TOWARD_EYE: [f64; 3] = [0.62, -1.0, 0.78];

/// The camera's orthonormal frame: forward `f` (into the scene), right `r`, up `u`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    pub f: [f64; 3],
    pub r: [f64; 3],
    pub u: [f64; 3],
}

/// The rays through the pixel centres of an image: `origin(px, py) + t · dir(px, py)`; `t` is the depth
/// along the camera's forward axis (both projections).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PixelRays {
    pub perspective: bool,
    /// Ray of pixel (0, 0): origin and direction.
    pub origin00: [f64; 3],
    pub dir00: [f64; 3],
    /// Change per pixel step right and down (of the origin for orthographic, of the direction for perspective).
    pub dx: [f64; 3],
    pub dy: [f64; 3],
}

impl PixelRays {
    /// The ray through the centre of pixel `(px, py)`.
    #[inline]
    pub fn ray(&self, px: u32, py: u32) -> ([f64; 3], [f64; 3]) {
        let (x, y) = (f64::from(px), f64::from(py));
        let step = [
            x * self.dx[0] + y * self.dy[0],
            x * self.dx[1] + y * self.dy[1],
            x * self.dx[2] + y * self.dy[2],
        ];
        if self.perspective {
            (self.origin00, v3::add_scaled(self.dir00, 1.0, step))
        } else {
            (v3::add_scaled(self.origin00, 1.0, step), self.dir00)
        }
    }
}

impl Camera {
    /// Checks the camera.
    ///
    /// # Errors
    /// [`DisplayError::BadCamera`] if a value is not finite, eye = target, up ∥ view direction, the height
    /// is not positive or the field of view is outside (0°, 180°).
    pub fn check(&self) -> Result<(), DisplayError> {
        let bad = |p: CameraProblem| Err(DisplayError::BadCamera(p));
        if self
            .eye
            .iter()
            .chain(&self.target)
            .chain(&self.up)
            .any(|v| !v.is_finite())
        {
            return bad(CameraProblem::NotFinite);
        }
        match self.projection {
            Projection::Orthographic { height } if !(height.is_finite() && height > 0.0) => {
                return bad(CameraProblem::BadHeight)
            }
            Projection::Perspective { fov_y_degrees: f }
                if !(f.is_finite() && f > 0.0 && f < 180.0) =>
            {
                return bad(CameraProblem::BadFieldOfView)
            }
            _ => {}
        }
        let Some(f) = v3::normalize(v3::sub(self.target, self.eye)) else {
            return bad(CameraProblem::EyeAtTarget);
        };
        let Some(up) = v3::normalize(self.up) else {
            return bad(CameraProblem::ZeroUp);
        };
        if v3::norm(v3::cross(f, up)) < 1e-9 {
            return bad(CameraProblem::UpAlongView);
        }
        Ok(())
    }

    /// The orthonormal frame. The camera must have passed [`Camera::check`].
    pub(crate) fn frame(&self) -> Frame {
        let f = v3::normalize(v3::sub(self.target, self.eye)).expect("checked camera");
        let r = v3::normalize(v3::cross(f, self.up)).expect("checked camera");
        let u = v3::cross(r, f);
        Frame { f, r, u }
    }

    /// The forward direction (unit).
    ///
    /// # Errors
    /// As [`Camera::check`].
    pub fn forward(&self) -> Result<[f64; 3], DisplayError> {
        self.check()?;
        Ok(self.frame().f)
    }

    /// Whether the camera is a perspective one.
    pub fn is_perspective(&self) -> bool {
        matches!(self.projection, Projection::Perspective { .. })
    }

    /// The visible extent of the image plane: (half width, half height) per unit of depth for perspective,
    /// in world units for orthographic.
    fn half_extent(&self, width: u32, height: u32) -> (f64, f64) {
        let aspect = f64::from(width) / f64::from(height);
        let half_h = match self.projection {
            Projection::Orthographic { height } => height / 2.0,
            Projection::Perspective { fov_y_degrees } => (fov_y_degrees.to_radians() / 2.0).tan(),
        };
        (half_h * aspect, half_h)
    }

    /// The pixel-centre rays of a `width × height` image. The camera must have passed [`Camera::check`].
    pub(crate) fn pixel_rays(&self, width: u32, height: u32) -> PixelRays {
        let Frame { f, r, u } = self.frame();
        let (hw, hh) = self.half_extent(width, height);
        let sx = 2.0 * hw / f64::from(width);
        let sy = 2.0 * hh / f64::from(height);
        let dx = [r[0] * sx, r[1] * sx, r[2] * sx];
        let dy = [-u[0] * sy, -u[1] * sy, -u[2] * sy];
        // Offset of pixel (0, 0)'s centre from the image centre.
        let ox = -hw + sx / 2.0;
        let oy = hh - sy / 2.0;
        let centre_offset = v3::add_scaled([r[0] * ox, r[1] * ox, r[2] * ox], oy, u);
        if self.is_perspective() {
            PixelRays {
                perspective: true,
                origin00: self.eye,
                dir00: v3::add_scaled(f, 1.0, centre_offset),
                dx,
                dy,
            }
        } else {
            PixelRays {
                perspective: false,
                origin00: v3::add_scaled(self.eye, 1.0, centre_offset),
                dir00: f,
                dx,
                dy,
            }
        }
    }

    /// Projects a world point to continuous screen coordinates `(x, y, depth)` (pixel `(i, j)` covers
    /// `[i, i+1) × [j, j+1)`); `None` for a perspective point at or behind the eye plane.
    /// The camera must have passed [`Camera::check`].
    pub fn project(&self, point: [f64; 3], width: u32, height: u32) -> Option<(f64, f64, f64)> {
        let Frame { f, r, u } = self.frame();
        let (hw, hh) = self.half_extent(width, height);
        let v = v3::sub(point, self.eye);
        let z = v3::dot(v, f);
        let (mut x, mut y) = (v3::dot(v, r), v3::dot(v, u));
        if self.is_perspective() {
            if z <= 1e-9 {
                return None;
            }
            x /= z;
            y /= z;
        }
        Some((
            (x / hw + 1.0) / 2.0 * f64::from(width),
            (1.0 - y / hh) / 2.0 * f64::from(height),
            z,
        ))
    }

    /// A camera that frames the box `[lo, hi]` seen from direction `toward_eye` (from the object towards
    /// the eye), with `z` up (or `y` up when looking along `z`), leaving a 5 % margin.
    /// `fov_y_degrees = None` gives an orthographic camera.
    ///
    /// # Errors
    /// [`DisplayError::BadDirection`] for a zero or non-finite direction; [`DisplayError::BadCamera`] for a
    /// bad field of view.
    pub fn framing(
        lo: [f64; 3],
        hi: [f64; 3],
        toward_eye: [f64; 3],
        fov_y_degrees: Option<f64>,
        width: u32,
        height: u32,
    ) -> Result<Camera, DisplayError> {
        let dir = v3::normalize(toward_eye)
            .ok_or_else(|| DisplayError::BadDirection(toward_eye.to_vec()))?;
        let centre = [
            (lo[0] + hi[0]) / 2.0,
            (lo[1] + hi[1]) / 2.0,
            (lo[2] + hi[2]) / 2.0,
        ];
        let radius = (v3::norm(v3::sub(hi, lo)) / 2.0).max(0.5);
        let up = if dir[0].abs() < 1e-6 && dir[1].abs() < 1e-6 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let aspect = f64::from(width) / f64::from(height);
        let mut camera = match fov_y_degrees {
            None => Camera {
                eye: v3::add_scaled(centre, 4.0 * radius, dir),
                target: centre,
                up,
                projection: Projection::Orthographic { height: 1.0 },
            },
            Some(fov) => {
                let half_v = fov.to_radians() / 2.0;
                let half = half_v.min((half_v.tan() * aspect).atan());
                let distance = radius / half.sin() * 1.05;
                Camera {
                    eye: v3::add_scaled(centre, distance, dir),
                    target: centre,
                    up,
                    projection: Projection::Perspective { fov_y_degrees: fov },
                }
            }
        };
        camera.check()?;
        if !camera.is_perspective() {
            // Fit the projected box corners.
            let Frame { r, u, .. } = camera.frame();
            let (mut ex, mut ey) = (0.0f64, 0.0f64);
            for c in 0..8 {
                let p = [
                    if c & 1 == 0 { lo[0] } else { hi[0] },
                    if c & 2 == 0 { lo[1] } else { hi[1] },
                    if c & 4 == 0 { lo[2] } else { hi[2] },
                ];
                let v = v3::sub(p, centre);
                ex = ex.max(v3::dot(v, r).abs());
                ey = ey.max(v3::dot(v, u).abs());
            }
            let height = (2.0 * ey).max(2.0 * ex / aspect).max(1.0) * 1.05;
            camera.projection = Projection::Orthographic { height };
        }
        Ok(camera)
    }
}

/// A box `[lo, hi]` in continuous voxel coordinates.
pub type Bounds<const K: usize> = ([f64; K], [f64; K]);

/// The bounding box `[lo, hi]` (in voxel coordinates) of the full cells of a tree, `None` for an empty
/// object: [`query::bounding_box`](crate::query::bounding_box) in continuous coordinates.
///
/// # Errors
/// The storage's read error.
pub fn object_bounds<const K: usize, T: TreeStorage<K>>(
    tree: &T,
) -> Result<Option<Bounds<K>>, T::Error> {
    Ok(crate::query::bounding_box(tree)?.map(|(lo, hi)| (lo.map(f64::from), hi.map(f64::from))))
}

/// The default camera for a tree: [`ISO_TOWARD_EYE`] framing the object (the whole universe if it is
/// empty), orthographic unless a field of view is given.
///
/// # Errors
/// As [`Camera::framing`]; [`DisplayError::Storage`] if a read of the tree fails.
pub fn default_camera<T: TreeStorage<3>>(
    tree: &T,
    toward_eye: [f64; 3],
    fov_y_degrees: Option<f64>,
    width: u32,
    height: u32,
) -> Result<Camera, DisplayError> {
    let side = tree.universe().side() as f64;
    let (lo, hi) = object_bounds(tree)
        .map_err(|e| DisplayError::Storage(e.into()))?
        .unwrap_or(([0.0; 3], [side; 3]));
    let mut camera = Camera::framing(lo, hi, toward_eye, fov_y_degrees, width, height)?;
    // Tighter: fit the projected corners of the full leaves rather than the bounding box (or sphere).
    let Frame { f, r, u } = camera.frame();
    let toward = [-f[0], -f[1], -f[2]];
    let aspect = f64::from(width) / f64::from(height);
    let (mut ex, mut ey, mut distance) = (0.0f64, 0.0f64, 0.0f64);
    let (tan_v, tan_h) = match camera.projection {
        Projection::Perspective { fov_y_degrees } => {
            let t = (fov_y_degrees.to_radians() / 2.0).tan();
            (t, t * aspect)
        }
        Projection::Orthographic { .. } => (1.0, 1.0),
    };
    for leaf in TryLeaves::new(tree) {
        let (cell, state) = leaf.map_err(|e| DisplayError::Storage(e.into()))?;
        if state != NodeState::Full {
            continue;
        }
        let s = cell.side() as f64;
        let o = cell.origin.map(f64::from);
        for c in 0..8 {
            let p = [
                o[0] + if c & 1 == 0 { 0.0 } else { s },
                o[1] + if c & 2 == 0 { 0.0 } else { s },
                o[2] + if c & 4 == 0 { 0.0 } else { s },
            ];
            let v = v3::sub(p, camera.target);
            let (x, y) = (v3::dot(v, r).abs(), v3::dot(v, u).abs());
            ex = ex.max(x);
            ey = ey.max(y);
            let along = v3::dot(v, toward);
            distance = distance.max(along + x / tan_h).max(along + y / tan_v);
        }
    }
    match camera.projection {
        Projection::Orthographic { height: box_height } => {
            let fitted = (2.0 * ey).max(2.0 * ex / aspect).max(1.0) * 1.05;
            camera.projection = Projection::Orthographic {
                height: fitted.min(box_height),
            };
        }
        Projection::Perspective { .. } => {
            // Keep the eye where it was if that is already closer; never inside the object's box.
            let current = v3::norm(v3::sub(camera.eye, camera.target));
            let radius = v3::norm(v3::sub(hi, lo)) / 2.0;
            let fitted = (distance * 1.05).max(radius * 1.05).max(1.0);
            if fitted < current {
                camera.eye = v3::add_scaled(camera.target, fitted, toward);
            }
        }
    }
    Ok(camera)
}
