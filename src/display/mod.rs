//! Display: hidden-surface images (Meagher's ordered traversal, M7) and line drawings with hidden lines
//! removed (Veenstra & Ahuja, V1–V8), plus pictures of quadtrees and 4-D trees.
//!
//! * [`order`]: front-to-back / back-to-front traversal for any view.
//! * [`camera`]: orthographic and perspective cameras, default framing.
//! * [`raster`] + [`coverage`]: the front-to-back renderer with a screen coverage mask; the painter's
//!   back-to-front order ([`render_back_to_front`]) and the brute-force z-buffer reference
//!   ([`render_zbuffer`]) beside it, over the same screen geometry and shading.
//! * [`neighbours`]: face neighbours in the compact tree, without pointers.
//! * [`lines`]: line drawings — visible edges with cracks, hidden lines and dots removed ([`hidden`] holds
//!   the paper's pairwise hidden-line step and a faster bucketed one).
//! * [`View`]: named views (`iso`, `top`, …, or `X,Y,Z`); [`render_png`]: an octree to a PNG in one call.
//! * [`svg`], [`png`]: writers; [`plane`]: 2-D quadtree images; [`slices`]: 4-D trees as strips of frames.
//!
//! ```
//! use ktree::display::{line_drawing, HiddenLineMethod, ISO_TOWARD_EYE};
//! use ktree::{rays::ball_rays, stacking::paper::stack};
//! let ball = stack(&ball_rays::<3>(4, [16, 16, 16], 20).unwrap());
//! let drawing = line_drawing(&ball, ISO_TOWARD_EYE, HiddenLineMethod::Bucketed).unwrap();
//! assert!(!drawing.lines.is_empty());
//! assert!(drawing.lines.iter().all(|edge| edge.u0 < edge.u1));
//! ```

pub mod camera;
pub mod coverage;
mod error;
pub mod hidden;
pub mod lines;
pub mod neighbours;
pub mod order;
mod painter;
pub mod palette;
pub mod plane;
pub mod png;
pub mod raster;
mod screen;
mod shading;
mod sightline;
pub mod slices;
pub mod svg;
mod view;
mod zbuffer;

pub use camera::{default_camera, object_bounds, Camera, Projection, ISO_TOWARD_EYE};
pub use coverage::Coverage;
pub use error::{check_size, CameraProblem, DisplayError, MAX_IMAGE_SIDE, MAX_PIXELS};
pub use hidden::HiddenLineMethod;
pub use lines::{line_drawing, line_drawing_with_progress, Edge3, LineDrawing, LineStats};
pub use order::{
    near_child, ordered_full_cells, try_ordered_full_cells, try_walk_ordered, walk_ordered, Order,
    Viewer, Walk,
};
pub use painter::render_back_to_front;
#[cfg(feature = "png")]
pub use raster::render_png;
pub use raster::{render, render_with_progress, Paint, RenderOptions, RenderStats, Rendered};
pub use view::{ParseViewError, View, NAMED_VIEWS};
pub use zbuffer::render_zbuffer;
