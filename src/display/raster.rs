//! Hidden-surface display (Meagher's M7): the octree is walked front to back in the order fixed by the
//! viewer's octant, each full leaf paints the pixels whose centre rays hit it, and a pixel is never painted
//! twice. The screen [`Coverage`] (one bit a pixel) prunes every subtree whose screen rectangle is already
//! covered, and the walk stops when the whole screen is.
//!
//! A pixel's ray is tested against the leaf's box exactly (slab test), so the result equals a z-buffer of
//! all full leaves ([`render_zbuffer`], the brute-force reference the tests compare against). Shading is by
//! face orientation (the face the ray enters), or — when the object's rays carry surface normals — by the
//! normal of the run the visible voxel belongs to, interpolated along the run.
//!
//! # Performance
//! A 1024×1024 image of a level-10 ball (about 7.5 million nodes) takes a fraction of a second on one core
//! (results/performance/display.md): most hidden subtrees are culled high up, and sub-pixel nodes cover at
//! most one pixel centre.
//!
//! ```
//! use ktree::display::{default_camera, render, render_zbuffer, RenderOptions, ISO_TOWARD_EYE};
//! use ktree::{rays::ball_rays, stacking::paper::stack};
//! let ball = stack(&ball_rays::<3>(4, [16, 16, 16], 24).unwrap());
//! let options = RenderOptions { width: 48, height: 48, ..Default::default() };
//! let camera = default_camera(&ball, ISO_TOWARD_EYE, None, 48, 48).unwrap();
//! let front_to_back = render(&ball, &camera, &options).unwrap();
//! let zbuffer = render_zbuffer(&ball, &camera, &options).unwrap();
//! // Front to back with a coverage mask paints exactly the pixels the brute-force reference paints.
//! assert_eq!(front_to_back.stats.painted, zbuffer.stats.painted);
//! assert!(front_to_back.stats.painted > 500);
//! ```

use super::camera::{v3, Camera, PixelRays};
use super::coverage::Coverage;
use super::error::{check_size, DisplayError};
use super::order::{walk_ordered, Order, ViewOrder, Viewer, Walk};
use crate::rays::RaySet;
use crate::space::Cell;
use crate::tree::cursor;
use crate::tree::storage::TreeStorage;
use crate::tree::{NodeRef, NodeState, Octree};

/// Everything a rendering can be asked for besides the tree and the camera, with defaults: a 512×512
/// image, face shading, no depth or cell images.
///
/// ```
/// use ktree::display::RenderOptions;
/// let options = RenderOptions { width: 64, height: 48, ..Default::default() };
/// assert!(options.normals.is_none() && !options.depth);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The object's base colour.
    pub colour: [u8; 3],
    /// The background colour.
    pub background: [u8; 3],
    /// Keep a depth image.
    pub depth: bool,
    /// Keep, for each pixel, the leaf cell seen there (for tests and picking; 24 bytes a pixel).
    pub cells: bool,
    /// The rays the tree was built from, if they carry surface normals: [`render`] then shades by them
    /// (elsewhere, and by default, shading is by face orientation).
    pub normals: Option<&'a RaySet<3>>,
}

impl Default for RenderOptions<'_> {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            colour: [222, 196, 150],
            background: [255, 255, 255],
            depth: false,
            cells: false,
            normals: None,
        }
    }
}

/// Counters of one rendering.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Nodes taken off the traversal stack.
    pub nodes_visited: u64,
    /// Non-empty nodes skipped because their screen rectangle was already covered.
    pub culled: u64,
    /// Full leaves that were rasterised.
    pub leaves_drawn: u64,
    /// Ray–box tests made.
    pub pixel_tests: u64,
    /// Pixels painted with the object.
    pub painted: u64,
}

/// A rendered image: RGB bytes row by row from the top, and optionally depth and visible cells.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 · width · height` bytes, row-major from the top-left.
    pub rgb: Vec<u8>,
    /// Depth along the camera's forward axis per pixel (`f32::INFINITY` for the background), if asked.
    pub depth: Option<Vec<f32>>,
    /// The leaf seen at each pixel, if asked.
    pub cells: Option<Vec<Option<Cell<3>>>>,
    /// Counters.
    pub stats: RenderStats,
}

impl Rendered {
    /// The depth image as grey levels (near = white, far = dark, background black), if depth was kept.
    pub fn depth_grey(&self) -> Option<Vec<u8>> {
        let depth = self.depth.as_ref()?;
        let finite = depth.iter().copied().filter(|d| d.is_finite());
        let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), d| {
            (a.min(d), b.max(d))
        });
        let span = (hi - lo).max(1e-6);
        Some(
            depth
                .iter()
                .map(|&d| {
                    if d.is_finite() {
                        (255.0 - 200.0 * (d - lo) / span).round() as u8
                    } else {
                        0
                    }
                })
                .collect(),
        )
    }
}

/// Exact ray–box test. Returns `(t_near, t_far, axis entered)` when the ray's line passes through the open
/// box with a chord of positive length.
#[inline]
pub(crate) fn slab(
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

/// Screen-space geometry shared by the renderer and the z-buffer reference.
struct Screen {
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
    frame: super::camera::Frame,
    persp_sx: f64,
    persp_sy: f64,
}

/// An inclusive pixel rectangle.
#[derive(Clone, Copy)]
struct Rect {
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
}

impl Screen {
    fn new(camera: &Camera, width: u32, height: u32) -> Result<Self, DisplayError> {
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
            super::camera::Projection::Perspective { fov_y_degrees } => {
                let half_h = (fov_y_degrees.to_radians() / 2.0).tan();
                let half_w = half_h * f64::from(width) / f64::from(height);
                (
                    f64::from(width) / (2.0 * half_w),
                    f64::from(height) / (2.0 * half_h),
                )
            }
            super::camera::Projection::Orthographic { .. } => (0.0, 0.0),
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
    fn rect(&self, cell: &Cell<3>) -> Option<Rect> {
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
    fn hit(
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
fn viewer(camera: &Camera) -> Viewer<3> {
    if camera.is_perspective() {
        Viewer::Eye(camera.eye)
    } else {
        Viewer::Direction(camera.frame().f)
    }
}

fn cell_box(cell: &Cell<3>) -> ([f64; 3], [f64; 3]) {
    let s = cell.side() as f64;
    let lo = cell.origin.map(f64::from);
    (lo, [lo[0] + s, lo[1] + s, lo[2] + s])
}

/// The light direction (towards the light) for a camera: above and to the left of the eye.
fn light_for(camera: &Camera) -> [f64; 3] {
    let f = camera.frame();
    let back = [-f.f[0], -f.f[1], -f.f[2]];
    let l = v3::add_scaled(v3::add_scaled(back, 0.6, f.u), -0.25, f.r);
    v3::normalize(l).expect("non-zero light")
}

/// Lambert shading with ambient light.
#[inline]
fn shade(normal: [f64; 3], light: [f64; 3], base: [u8; 3]) -> [u8; 3] {
    let k = 0.2 + 0.8 * v3::dot(normal, light).max(0.0);
    base.map(|c| (f64::from(c) * k).round().clamp(0.0, 255.0) as u8)
}

/// The shaded colour of each of the six axis-aligned faces, computed once an image: a face is lit the same
/// wherever it is seen, and a pixel's colour is then a lookup.
struct FaceColours([[u8; 3]; 6]);

impl FaceColours {
    fn new(light: [f64; 3], base: [u8; 3]) -> Self {
        Self(std::array::from_fn(|i| {
            let mut normal = [0.0; 3];
            normal[i / 2] = if i % 2 == 1 { -1.0 } else { 1.0 };
            shade(normal, light, base)
        }))
    }

    /// The colour of the face on `axis` that a ray along `dir` enters (the face looks against the ray).
    #[inline]
    fn entered(&self, axis: usize, dir: [f64; 3]) -> [u8; 3] {
        self.0[2 * axis + usize::from(dir[axis] > 0.0)]
    }
}

/// Looks up the surface normal of the voxel `v` seen through a face on `axis` from the rays' normals:
/// the run's end normal for a face across the run, else the end normals interpolated along the run.
fn ray_normal(rays: &RaySet<3>, v: [u32; 3], axis: usize, dir: [f64; 3]) -> Option<[f64; 3]> {
    let key = rays.column_key(v);
    let keys = rays.column_keys();
    let start = keys.partition_point(|&k| k < key);
    let end = keys.partition_point(|&k| k <= key);
    let runs = &rays.runs()[start..end];
    let j = runs.partition_point(|&(_, z2)| z2 <= v[2]);
    let &(z1, z2) = runs.get(j)?;
    if z1 > v[2] {
        return None;
    }
    let [n1, n2] = rays.normals(start + j)?;
    let (n1, n2) = (n1.map(f64::from), n2.map(f64::from));
    let n = if axis == 2 {
        if dir[2] > 0.0 {
            n1
        } else {
            n2
        }
    } else {
        let t = (f64::from(v[2]) + 0.5 - f64::from(z1)) / f64::from(z2 - z1);
        [
            n1[0] + t * (n2[0] - n1[0]),
            n1[1] + t * (n2[1] - n1[1]),
            n1[2] + t * (n2[2] - n1[2]),
        ]
    };
    let n = v3::normalize(n)?;
    (v3::norm(n) > 0.5).then_some(n)
}

/// Renders the object in `tree` as seen by `camera`, front to back with early termination.
///
/// Shading follows the surface normals of `options.normals` where the rays carry them (and the visible
/// voxel is found in them), else the face orientation.
///
/// ```
/// use ktree::display::{default_camera, render, RenderOptions, ISO_TOWARD_EYE};
/// use ktree::{stacking::paper::stack, rays::ball_rays};
/// let tree = stack(&ball_rays::<3>(5, [32, 32, 32], 28).unwrap());
/// let options = RenderOptions { width: 64, height: 64, ..Default::default() };
/// let camera = default_camera(&tree, ISO_TOWARD_EYE, None, 64, 64).unwrap();
/// let image = render(&tree, &camera, &options).unwrap();
/// assert!(image.stats.painted > 1000); // the ball fills much of the frame
/// ```
///
/// # Errors
/// [`DisplayError::BadSize`] or [`DisplayError::BadCamera`]; [`DisplayError::Storage`] if a read of the
/// tree fails.
pub fn render<T: TreeStorage<3>>(
    tree: &T,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Rendered, DisplayError> {
    front_to_back(tree, camera, options, None)
}

/// As [`render`], calling `progress` now and then with (pixels covered, pixels in all).
///
/// # Errors
/// As [`render`].
pub fn render_with_progress<T: TreeStorage<3>>(
    tree: &T,
    camera: &Camera,
    options: &RenderOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Rendered, DisplayError> {
    front_to_back(tree, camera, options, Some(progress))
}

/// Renders the object in `tree` seen from `view` (orthographic, framed by [`default_camera`](super::default_camera)),
/// `width × height` pixels, and writes it to `path` as a PNG (atomically); returns what was drawn.
///
/// ```
/// use ktree::{display::{render_png, View}, rays::ball_rays, KTree};
/// let ball = KTree::from_rays(&ball_rays::<3>(5, [32, 32, 32], 28).unwrap());
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("ball.png");
/// let stats = render_png(&ball, View::default(), 64, 48, &path).unwrap();
/// assert!(stats.painted > 500);
/// assert_eq!(&std::fs::read(&path).unwrap()[1..4], b"PNG");
/// ```
///
/// # Errors
/// [`DisplayError::BadSize`], [`DisplayError::BadCamera`], or the PNG's encoding and writing errors.
#[cfg(feature = "png")]
pub fn render_png<T: TreeStorage<3>>(
    tree: &T,
    view: super::View,
    width: u32,
    height: u32,
    path: &std::path::Path,
) -> Result<RenderStats, DisplayError> {
    let camera = super::default_camera(tree, view.toward_eye(), None, width, height)?;
    let options = RenderOptions {
        width,
        height,
        ..Default::default()
    };
    let image = render(tree, &camera, &options)?;
    super::png::write_rgb_png(path, width, height, &image.rgb)?;
    Ok(image.stats)
}

fn front_to_back<T: TreeStorage<3>>(
    tree: &T,
    camera: &Camera,
    options: &RenderOptions,
    mut progress: Option<&mut dyn FnMut(u64, u64)>,
) -> Result<Rendered, DisplayError> {
    let screen = Screen::new(camera, options.width, options.height)?;
    let (w, h) = (options.width, options.height);
    let pixels = w as usize * h as usize;
    let mut rgb = Vec::with_capacity(pixels * 3);
    for _ in 0..pixels {
        rgb.extend_from_slice(&options.background);
    }
    let mut depth = options.depth.then(|| vec![f32::INFINITY; pixels]);
    let mut cells = options.cells.then(|| vec![None; pixels]);
    let normals = options
        .normals
        .filter(|r| r.has_normals() && r.level() == tree.level());
    let light = light_for(camera);
    let faces = FaceColours::new(light, options.colour);
    let mut cov = Coverage::new(w, h);
    let mut stats = RenderStats::default();
    let total = cov.uncovered();
    let visit = |node: &NodeRef<3>| {
        stats.nodes_visited += 1;
        if stats.nodes_visited % (1 << 16) == 0 {
            if let Some(p) = progress.as_mut() {
                p(total - cov.uncovered(), total);
            }
        }
        let (cell, state) = (node.cell, node.state);
        if state == NodeState::Empty {
            return Walk::Skip;
        }
        let Some(r) = screen.rect(&cell) else {
            return Walk::Skip;
        };
        if cov.rect_covered(r.x0, r.x1, r.y0, r.y1) {
            stats.culled += 1;
            return Walk::Skip;
        }
        if state == NodeState::Partial {
            return Walk::Descend;
        }
        // A full leaf: paint the uncovered pixels its box is hit at.
        stats.leaves_drawn += 1;
        let (lo, hi) = cell_box(&cell);
        for y in r.y0..=r.y1 {
            let row = y as usize * w as usize;
            let mut tests = 0u64;
            let painted = cov.cover_where(y, r.x0, r.x1, |x| {
                tests += 1;
                let Some((t, axis, o, d)) = screen.hit(x, y, lo, hi) else {
                    return false;
                };
                let c = normals
                    .and_then(|rays| {
                        // The voxel of the cell just behind the hit point.
                        let p = v3::add_scaled(o, t, d);
                        let mut v = [0u32; 3];
                        for k in 0..3 {
                            let c = if k == axis {
                                if d[k] > 0.0 {
                                    lo[k]
                                } else {
                                    hi[k] - 1.0
                                }
                            } else {
                                p[k].floor().clamp(lo[k], hi[k] - 1.0)
                            };
                            v[k] = c as u32;
                        }
                        ray_normal(rays, v, axis, d)
                    })
                    .map_or_else(
                        || faces.entered(axis, d),
                        |normal| shade(normal, light, options.colour),
                    );
                rgb[3 * (row + x as usize)..3 * (row + x as usize) + 3].copy_from_slice(&c);
                if let Some(dep) = depth.as_mut() {
                    dep[row + x as usize] = t as f32;
                }
                if let Some(cs) = cells.as_mut() {
                    cs[row + x as usize] = Some(cell);
                }
                true
            });
            stats.pixel_tests += tests;
            stats.painted += u64::from(painted);
        }
        if cov.uncovered() == 0 {
            Walk::Stop
        } else {
            Walk::Skip
        }
    };
    cursor::try_walk(
        tree,
        &mut ViewOrder::new(viewer(camera), Order::FrontToBack, visit),
    )
    .map_err(|e| DisplayError::Storage(e.into()))?;
    if let Some(p) = progress.as_mut() {
        p(total - cov.uncovered(), total);
    }
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        depth,
        cells,
        stats,
    })
}

/// Meagher's other order (M7): the painter's algorithm. Leaves are visited back to front and every hit
/// pixel is painted, later leaves overwriting earlier ones; no depth is compared and nothing is culled,
/// so it costs a visit of every full leaf. Same picture as [`render`] (face shading; `options.normals` is
/// not used).
///
/// # Errors
/// As [`render`].
pub fn render_back_to_front(
    tree: &Octree,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Rendered, DisplayError> {
    let screen = Screen::new(camera, options.width, options.height)?;
    let (w, h) = (options.width, options.height);
    let pixels = w as usize * h as usize;
    let mut rgb = Vec::with_capacity(pixels * 3);
    for _ in 0..pixels {
        rgb.extend_from_slice(&options.background);
    }
    let mut depth = options.depth.then(|| vec![f32::INFINITY; pixels]);
    let mut cells = options.cells.then(|| vec![None; pixels]);
    let mut hit_any = vec![false; pixels];
    let faces = FaceColours::new(light_for(camera), options.colour);
    let mut stats = RenderStats::default();
    walk_ordered(tree, viewer(camera), Order::BackToFront, |node| {
        stats.nodes_visited += 1;
        if node.state != NodeState::Full {
            return Walk::Descend;
        }
        let Some(r) = screen.rect(&node.cell) else {
            return Walk::Descend;
        };
        stats.leaves_drawn += 1;
        let (lo, hi) = cell_box(&node.cell);
        for y in r.y0..=r.y1 {
            for x in r.x0..=r.x1 {
                stats.pixel_tests += 1;
                if let Some((t, axis, _, d)) = screen.hit(x, y, lo, hi) {
                    let i = y as usize * w as usize + x as usize;
                    rgb[3 * i..3 * i + 3].copy_from_slice(&faces.entered(axis, d));
                    hit_any[i] = true;
                    if let Some(dep) = depth.as_mut() {
                        dep[i] = t as f32;
                    }
                    if let Some(cs) = cells.as_mut() {
                        cs[i] = Some(node.cell);
                    }
                }
            }
        }
        Walk::Descend
    });
    stats.painted = hit_any.iter().filter(|&&b| b).count() as u64;
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        depth,
        cells,
        stats,
    })
}

/// The brute-force reference: a z-buffer over *all* full leaves in Morton order, keeping for each pixel the
/// leaf with the smallest entry depth (ties: the first). Shading is by face orientation (`options.normals` is
/// not used). `O(leaves · pixels
/// per leaf)`; for tests and small trees.
///
/// # Errors
/// As [`render`].
pub fn render_zbuffer(
    tree: &Octree,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Rendered, DisplayError> {
    let screen = Screen::new(camera, options.width, options.height)?;
    let (w, h) = (options.width, options.height);
    let pixels = w as usize * h as usize;
    let mut rgb = Vec::with_capacity(pixels * 3);
    for _ in 0..pixels {
        rgb.extend_from_slice(&options.background);
    }
    let mut depth = vec![f64::INFINITY; pixels];
    let mut cells = vec![None; pixels];
    let light = light_for(camera);
    let mut stats = RenderStats::default();
    tree.for_each_leaf(|cell, state| {
        stats.nodes_visited += 1;
        if state != NodeState::Full {
            return;
        }
        // The reference's own rectangle: all 8 corners through the public projection (independent of
        // the renderer's incremental one); a corner behind the eye means the whole screen.
        let Some(r) = reference_rect(camera, &cell, w, h) else {
            return;
        };
        stats.leaves_drawn += 1;
        let (lo, hi) = cell_box(&cell);
        for y in r.y0..=r.y1 {
            for x in r.x0..=r.x1 {
                stats.pixel_tests += 1;
                if let Some((t, axis, _, d)) = screen.hit(x, y, lo, hi) {
                    let i = y as usize * w as usize + x as usize;
                    if t < depth[i] {
                        depth[i] = t;
                        cells[i] = Some(cell);
                        let mut n = [0.0; 3];
                        n[axis] = if d[axis] > 0.0 { -1.0 } else { 1.0 };
                        rgb[3 * i..3 * i + 3].copy_from_slice(&shade(n, light, options.colour));
                    }
                }
            }
        }
    });
    stats.painted = cells.iter().filter(|c| c.is_some()).count() as u64;
    Ok(Rendered {
        width: w,
        height: h,
        rgb,
        depth: Some(depth.iter().map(|&d| d as f32).collect()),
        cells: Some(cells),
        stats,
    })
}

/// The pixels whose centres may see `cell`, from its 8 corners projected by [`Camera::project`].
fn reference_rect(camera: &Camera, cell: &Cell<3>, w: u32, h: u32) -> Option<Rect> {
    let (lo, hi) = cell_box(cell);
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for c in 0..8 {
        let p = [
            if c & 1 == 0 { lo[0] } else { hi[0] },
            if c & 2 == 0 { lo[1] } else { hi[1] },
            if c & 4 == 0 { lo[2] } else { hi[2] },
        ];
        match camera.project(p, w, h) {
            Some((x, y, _)) => {
                xmin = xmin.min(x);
                xmax = xmax.max(x);
                ymin = ymin.min(y);
                ymax = ymax.max(y);
            }
            None => {
                return Some(Rect {
                    x0: 0,
                    x1: w - 1,
                    y0: 0,
                    y1: h - 1,
                })
            }
        }
    }
    let x0 = (xmin - 0.5 - 1e-6).ceil().max(0.0);
    let x1 = (xmax - 0.5 + 1e-6).floor().min(f64::from(w) - 1.0);
    let y0 = (ymin - 0.5 - 1e-6).ceil().max(0.0);
    let y1 = (ymax - 0.5 + 1e-6).floor().min(f64::from(h) - 1.0);
    (x0 <= x1 && y0 <= y1).then_some(Rect {
        x0: x0 as u32,
        x1: x1 as u32,
        y0: y0 as u32,
        y1: y1 as u32,
    })
}
