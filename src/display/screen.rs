//! Where a cell falls on the screen of a camera: the pixels whose centres may see it, and the exact hit of
//! a pixel's ray with its box. Shared by the front-to-back renderer, the painter's order and the z-buffer.

use super::camera::{v3, Camera, Frame, PixelRays, Projection};
use super::error::{check_size, DisplayError};
use super::order::Viewer;
use crate::space::Cell;

/// Exact ray–box test. Returns `(t_near, t_far, axis entered)` when the ray's line passes through the open
/// box with a chord of positive length.
#[inline]
pub(super) fn slab(
    o: [f64; 3],
    d: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
) -> Option<(f64, f64, usize)> {
    let mut tn = f64::NEG_INFINITY;
    let mut tf = f64::INFINITY;
    let mut axis = 0;
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] <= lo[k] || o[k] >= hi[k] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[k];
        let (mut a, mut b) = ((lo[k] - o[k]) * inv, (hi[k] - o[k]) * inv);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        if a > tn {
            tn = a;
            axis = k;
        }
        if b < tf {
            tf = b;
        }
    }
    (tn < tf).then_some((tn, tf, axis))
}

/// The screen of a camera and an image size: pixel rectangles of cells and pixel rays.
pub(super) struct Screen {
    width: u32,
    height: u32,
    camera: Camera,
    rays: PixelRays,
    /// Orthographic: screen x = ax · p + bx, y = ay · p + by.
    ax: [f64; 3],
    bx: f64,
    ay: [f64; 3],
    by: f64,
    /// Half-extent of the screen rectangle of a unit cube.
    ex: f64,
    ey: f64,
    /// Perspective: the camera frame and the screen scale per unit of depth.
    frame: Frame,
    persp_sx: f64,
    persp_sy: f64,
}

/// An inclusive pixel rectangle.
#[derive(Clone, Copy)]
pub(super) struct Rect {
    pub(super) x0: u32,
    pub(super) x1: u32,
    pub(super) y0: u32,
    pub(super) y1: u32,
}

impl Screen {
    pub(super) fn new(camera: &Camera, width: u32, height: u32) -> Result<Self, DisplayError> {
        check_size(width, height)?;
        camera.check()?;
        let rays = camera.pixel_rays(width, height);
        // Orthographic affine map from world to screen, from two projections.
        let p0 = camera.project([0.0; 3], width, height);
        let (mut ax, mut ay) = ([0.0; 3], [0.0; 3]);
        let (mut bx, mut by) = (0.0, 0.0);
        if let (false, Some((x0, y0, _))) = (camera.is_perspective(), p0) {
            bx = x0;
            by = y0;
            for k in 0..3 {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                let (x, y, _) = camera.project(e, width, height).expect("orthographic");
                ax[k] = x - x0;
                ay[k] = y - y0;
            }
        }
        let ex = ax.iter().map(|a| a.abs()).sum::<f64>() / 2.0;
        let ey = ay.iter().map(|a| a.abs()).sum::<f64>() / 2.0;
        let frame = camera.frame();
        let (persp_sx, persp_sy) = match camera.projection {
            Projection::Perspective { fov_y_degrees } => {
                let half_h = (fov_y_degrees.to_radians() / 2.0).tan();
                let half_w = half_h * f64::from(width) / f64::from(height);
                (
                    f64::from(width) / (2.0 * half_w),
                    f64::from(height) / (2.0 * half_h),
                )
            }
            Projection::Orthographic { .. } => (0.0, 0.0),
        };
        Ok(Self {
            frame,
            persp_sx,
            persp_sy,
            width,
            height,
            camera: *camera,
            rays,
            ax,
            bx,
            ay,
            by,
            ex,
            ey,
        })
    }

    /// The pixels whose centres may see the cell, `None` if there are none.
    #[inline]
    pub(super) fn rect(&self, cell: &Cell<3>) -> Option<Rect> {
        let s = cell.side() as f64;
        let lo = cell.origin.map(f64::from);
        let (xmin, xmax, ymin, ymax) = if self.rays.perspective {
            let (mut xmin, mut xmax) = (f64::INFINITY, f64::NEG_INFINITY);
            let (mut ymin, mut ymax) = (f64::INFINITY, f64::NEG_INFINITY);
            for c in 0..8 {
                let p = [
                    lo[0] + if c & 1 == 0 { 0.0 } else { s },
                    lo[1] + if c & 2 == 0 { 0.0 } else { s },
                    lo[2] + if c & 4 == 0 { 0.0 } else { s },
                ];
                let v = v3::sub(p, self.camera.eye);
                let z = v3::dot(v, self.frame.f);
                let projected = (z > 1e-9).then(|| {
                    (
                        f64::from(self.width) / 2.0 + v3::dot(v, self.frame.r) / z * self.persp_sx,
                        f64::from(self.height) / 2.0 - v3::dot(v, self.frame.u) / z * self.persp_sy,
                    )
                });
                match projected {
                    Some((x, y)) => {
                        xmin = xmin.min(x);
                        xmax = xmax.max(x);
                        ymin = ymin.min(y);
                        ymax = ymax.max(y);
                    }
                    None => {
                        // A corner at or behind the eye plane: the cell may cover anything.
                        (xmin, xmax, ymin, ymax) =
                            (0.0, f64::from(self.width), 0.0, f64::from(self.height));
                        break;
                    }
                }
            }
            (xmin, xmax, ymin, ymax)
        } else {
            let h = s / 2.0;
            let c = [lo[0] + h, lo[1] + h, lo[2] + h];
            let cx = v3::dot(self.ax, c) + self.bx;
            let cy = v3::dot(self.ay, c) + self.by;
            (
                cx - self.ex * s,
                cx + self.ex * s,
                cy - self.ey * s,
                cy + self.ey * s,
            )
        };
        const MARGIN: f64 = 1e-7;
        let x0 = (xmin - 0.5 - MARGIN).ceil().max(0.0);
        let x1 = (xmax - 0.5 + MARGIN)
            .floor()
            .min(f64::from(self.width) - 1.0);
        let y0 = (ymin - 0.5 - MARGIN).ceil().max(0.0);
        let y1 = (ymax - 0.5 + MARGIN)
            .floor()
            .min(f64::from(self.height) - 1.0);
        (x0 <= x1 && y0 <= y1).then_some(Rect {
            x0: x0 as u32,
            x1: x1 as u32,
            y0: y0 as u32,
            y1: y1 as u32,
        })
    }

    /// The hit of pixel `(x, y)`'s ray with the box of `cell`: `(depth, axis entered, ray)`.
    #[inline]
    pub(super) fn hit(
        &self,
        x: u32,
        y: u32,
        lo: [f64; 3],
        hi: [f64; 3],
    ) -> Option<(f64, usize, [f64; 3], [f64; 3])> {
        let (o, d) = self.rays.ray(x, y);
        let (tn, _, axis) = slab(o, d, lo, hi)?;
        if self.rays.perspective && tn <= 0.0 {
            return None;
        }
        Some((tn, axis, o, d))
    }
}

/// Where a camera's viewer is, for ordering the walk.
pub(super) fn viewer(camera: &Camera) -> Viewer<3> {
    if camera.is_perspective() {
        Viewer::Eye(camera.eye)
    } else {
        Viewer::Direction(camera.frame().f)
    }
}

/// The box `[lo, hi)` of a cell.
pub(super) fn cell_box(cell: &Cell<3>) -> ([f64; 3], [f64; 3]) {
    let s = cell.side() as f64;
    let lo = cell.origin.map(f64::from);
    (lo, [lo[0] + s, lo[1] + s, lo[2] + s])
}
