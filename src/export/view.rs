//! An interactive 3-D view of a tree in one self-contained HTML page: the boxes to draw chosen within a
//! budget ([`select_boxes`]), packed into a compact binary block (base64 in the page) and drawn by a small
//! WebGL2 program with instancing ([`view_page`], [`write_view`]).
//!
//! The page needs nothing from outside: its script, shaders and data are inline, and a
//! `Content-Security-Policy` of `default-src 'none'` forbids every request (a fetch would be a console
//! error). Octrees are drawn as shaded boxes, quadtrees as flat squares, 4-D trees as the 3-D slice at a
//! time chosen with a slider. The mouse orbits (left button), pans (right button or shift) and zooms
//! (wheel); sliders clip along each axis; a toggle colours by face normal or by depth in the tree, and a
//! tree with values by value, with a legend ([`view_values_page`]). The first camera is the one
//! `ktree render --camera NAME` takes (the same orthographic projection and framing): it is framed here,
//! on the boxes of the page, and given to the page in its header. At any window size, and again after
//! every change of size, the page shows the smallest rectangle of the window's shape that holds the boxes
//! with a 5 % margin (the wheel zooms from there). The URL hash sets the start: `#camera=NAME` another
//! camera, `colour=depth`, `colour=normal` or `colour=value`, `time=T` the slice of a
//! 4-D tree, `bare` no controls (the key `h` hides and shows them). `selftest`
//! drives every control after the first frame with DOM events (drags with both buttons, the wheel, a clip
//! slider, the camera and colour menus, the time slider) and records in the page's status, for each, whether
//! the view moved as it should and the frame changed: how the tests check the controls in a browser.
//!
//! The drawing is plain WebGL2 (about 200 lines in `view/page.html`, no library): one instanced unit cube,
//! clipping and colouring in the fragment shader, an orthographic matrix built from the same frame as
//! [`Camera::framing`](crate::display::Camera::framing). A 3-D library would add several hundred kilobytes
//! to every page and a module loader to make it work offline, for nothing the page needs.
//!
//! # Level of detail
//! [`select_boxes`] refines breadth first from the root: each partial node taken off the queue is replaced
//! by its partial children (queued) and its visible full children, as long as the number of boxes stays
//! within the budget. What is left in the queue is drawn as coarse boxes of the partial cells. A full leaf
//! is visible unless each of its faces (on the drawn axes) touches a full region of its own size — the
//! leaves buried inside full regions need no box. The selection works on any storage (a tree in memory, a
//! mapped file) and reads only the nodes it draws and their neighbours' paths.
//!
//! ```
//! use ktree::export::view::{select_boxes, view_page, ViewOptions};
//! use ktree::{rays::ball_rays, KTree};
//! let ball = KTree::from_rays(&ball_rays::<3>(5, [32, 32, 32], 40).unwrap());
//! let lod = select_boxes(&ball, 100, &[0, 1, 2]).unwrap();
//! assert!(lod.len() <= 100 && !lod.complete);
//! let page = view_page(&ball, &ViewOptions::default()).unwrap();
//! assert!(page.html.starts_with("<!doctype html>") && page.boxes > 0);
//! ```

mod camera;
mod lod;

use std::fmt::Write as _;
use std::path::Path;

use thiserror::Error;

use crate::display::palette::{ramp, value_colours, value_legend, Legend};
use crate::display::{View, NAMED_VIEWS};
use crate::fs::write_atomic;
use crate::space::Cell;
use crate::tree::cursor::TreeStorage;
use crate::tree::valued::LeavesOfValues;
use crate::value::Value;
use crate::KTree;
use camera::PageCamera;

pub use lod::{select_boxes, select_boxes_of, Lod};

/// The page template: markup, style and the WebGL2 program; the header and data are put in its slots.
const TEMPLATE: &str = include_str!("view/page.html");

/// The default box budget: about 0.8 MB of page (8 bytes of base64 a box for an octree).
pub const DEFAULT_BUDGET: usize = 100_000;

/// What the page shows and how.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewOptions {
    /// The most boxes in the page (at least 1).
    pub budget: usize,
    /// The first camera (`None`: `iso` for octrees and 4-D trees, `top` for quadtrees).
    pub camera: Option<View>,
    /// 4-D trees: the axis the slider moves along (time); the other three are drawn.
    pub time_axis: usize,
    /// The page's title (the file's name).
    pub title: String,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self {
            budget: DEFAULT_BUDGET,
            camera: None,
            time_axis: 3,
            title: "ktree".into(),
        }
    }
}

/// A page made by [`view_page`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Page {
    /// The HTML.
    pub html: String,
    /// Boxes in the page.
    pub boxes: usize,
    /// Of which coarse partial cells.
    pub coarse: usize,
    /// Whether the tree is shown to the voxel (no coarse box).
    pub complete: bool,
}

/// Why a view could not be made.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ViewPageError {
    /// Bintrees have no 3-D view.
    #[error("a bintree (K = 1) has no 3-D view; view needs K = 2, 3 or 4")]
    Bintree,
    /// The budget is zero.
    #[error("the box budget must be at least 1")]
    ZeroBudget,
    /// The time axis is not an axis of the tree.
    #[error("time axis {axis} is not an axis of a K = {k} tree (0..{k})")]
    BadTimeAxis {
        /// The axis asked for.
        axis: usize,
        /// The tree's dimension.
        k: usize,
    },
    /// Reading the tree failed.
    #[error(transparent)]
    Read(Box<dyn std::error::Error + Send + Sync>),
    /// Writing the page failed (the message names the file).
    #[error(transparent)]
    Write(#[from] crate::fs::FileOpError),
}

/// Standard base64 with padding (RFC 4648 §4).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for j in 0..4 {
            if j <= chunk.len() {
                out.push(char::from(ALPHABET[(n >> (18 - 6 * j) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Escapes text for HTML.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The boxes packed in groups of one kind (0 full, 1 coarse) and depth: per box its `K` coordinates in
/// units of the cell's side, little-endian, 2 bytes each for depths up to 16, else 4; then, with `colour`,
/// 3 bytes R, G, B per box in the same order (coarse boxes grey). Returns the groups' JSON and the bytes.
fn pack<const K: usize>(
    lod: &Lod<K>,
    level: u32,
    colour: Option<&BoxColour<'_, K>>,
) -> (String, Vec<u8>) {
    let mut groups = String::from("[");
    let mut bytes = Vec::new();
    let mut colours = Vec::new();
    for (kind, cells) in [(0, &lod.full), (1, &lod.coarse)] {
        for depth in 0..=level {
            let at: Vec<&Cell<K>> = cells.iter().filter(|c| c.level() == depth).collect();
            if at.is_empty() {
                continue;
            }
            let width = if depth <= 16 { 2 } else { 4 };
            if groups.len() > 1 {
                groups.push(',');
            }
            let _ = write!(
                groups,
                "{{\"kind\":{kind},\"depth\":{depth},\"count\":{},\"width\":{width}}}",
                at.len()
            );
            for c in at {
                for o in c.origin() {
                    let unit = o >> c.log_side();
                    if width == 2 {
                        bytes.extend_from_slice(&(unit as u16).to_le_bytes());
                    } else {
                        bytes.extend_from_slice(&unit.to_le_bytes());
                    }
                }
                if let Some(colour) = colour {
                    colours.extend(if kind == 0 { colour(c) } else { COARSE });
                }
            }
        }
    }
    groups.push(']');
    bytes.extend(colours);
    (groups, bytes)
}

/// The colour of a full box.
type BoxColour<'a, const K: usize> = dyn Fn(&Cell<K>) -> [u8; 3] + 'a;

/// The colour of a coarse box of a tree with values (its voxels' values differ).
const COARSE: [u8; 3] = [160, 160, 160];

/// The colours of a tree with values on its page: each full box's colour, and the header's `values`
/// entry (value type and legend).
struct PageValues<'a, const K: usize> {
    colour: &'a BoxColour<'a, K>,
    json: String,
}

/// The page showing `tree` (see the [module docs](self)).
///
/// # Errors
/// [`ViewPageError::Bintree`] for K = 1, [`ViewPageError::ZeroBudget`], [`ViewPageError::BadTimeAxis`] for a 4-D
/// tree, [`ViewPageError::Read`] from the storage.
pub fn view_page<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    options: &ViewOptions,
) -> Result<Page, ViewPageError> {
    page(tree, options, None)
}

/// The page showing a tree with values: its boxes coloured by value as `ktree render` colours them
/// ([`value_colours`]; the colour menu's `by value`, the first colouring, `#colour=value` in the URL),
/// with a legend ([`value_legend`]: the labels and their colours, the ramp from the smallest to the
/// largest float, or a note that colours are drawn as stored). Each box is a leaf of one value
/// ([`LeavesOfValues`]); the boxes the budget leaves coarse are grey.
///
/// ```
/// use ktree::export::view::{view_values_page, ViewOptions};
/// use ktree::KTree;
/// let t = KTree::<2, u8>::from_dense_values(1, &[Some(3), None, Some(5), Some(5)]).unwrap();
/// let page = view_values_page(&t, &ViewOptions::default()).unwrap();
/// assert_eq!(page.boxes, 3);
/// assert!(page.html.contains("\"legend\":{\"kind\":\"labels\""));
/// ```
///
/// # Errors
/// As [`view_page`].
pub fn view_values_page<const K: usize, V: Value>(
    tree: &KTree<K, V>,
    options: &ViewOptions,
) -> Result<Page, ViewPageError> {
    let of_value = value_colours(tree);
    let colour = |cell: &Cell<K>| tree.value_at(cell.origin()).map_or(COARSE, &of_value);
    let number = |v: V| {
        let x: f64 = v.text().parse().unwrap_or(f64::NAN);
        if x.is_finite() {
            x.to_string()
        } else {
            "null".into()
        }
    };
    let rgb = |c: [u8; 3]| format!("[{},{},{}]", c[0], c[1], c[2]);
    let legend = match value_legend(tree) {
        Legend::Labels { entries, more } => {
            let entries: Vec<String> = entries
                .iter()
                .map(|(v, c, n)| format!("[{},{},{n}]", number(*v), rgb(*c)))
                .collect();
            format!(
                "{{\"kind\":\"labels\",\"entries\":[{}],\"more\":{more}}}",
                entries.join(",")
            )
        }
        Legend::Ramp { range } => {
            let stops: Vec<String> = (0..=4).map(|i| rgb(ramp(f64::from(i) / 4.0))).collect();
            let (lo, hi) = range.map_or(("null".into(), "null".into()), |(lo, hi)| {
                (number(lo), number(hi))
            });
            format!(
                "{{\"kind\":\"ramp\",\"min\":{lo},\"max\":{hi},\"stops\":[{}]}}",
                stops.join(",")
            )
        }
        Legend::AsStored => "{\"kind\":\"stored\"}".into(),
    };
    let dtype = V::DTYPE.map_or("none", |d| d.name());
    let values = PageValues {
        colour: &colour,
        json: format!("{{\"dtype\":\"{dtype}\",\"legend\":{legend}}}"),
    };
    page(&LeavesOfValues(tree), options, Some(values))
}

/// The page of `tree`, its boxes coloured by `values` if given.
fn page<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    options: &ViewOptions,
    values: Option<PageValues<'_, K>>,
) -> Result<Page, ViewPageError> {
    if K == 1 {
        return Err(ViewPageError::Bintree);
    }
    if options.budget == 0 {
        return Err(ViewPageError::ZeroBudget);
    }
    let time = if K == 4 {
        if options.time_axis >= K {
            return Err(ViewPageError::BadTimeAxis {
                axis: options.time_axis,
                k: K,
            });
        }
        Some(options.time_axis)
    } else {
        None
    };
    // Quadtrees are seen from above: every full leaf shows. 4-D trees are seen a slice at a time.
    let axes: Vec<usize> = match K {
        2 => Vec::new(),
        _ => (0..K).filter(|&a| Some(a) != time).collect(),
    };
    let level = tree.level();
    let lod =
        select_boxes(tree, options.budget, &axes).map_err(|e| ViewPageError::Read(Box::new(e)))?;
    let (groups, bytes) = pack(&lod, level, values.as_ref().map(|v| v.colour));
    let camera = options.camera.unwrap_or_else(|| {
        if K == 2 { "top" } else { "iso" }
            .parse()
            .expect("a named view")
    });
    let v = |d: [f64; 3]| format!("[{},{},{}]", d[0], d[1], d[2]);
    let views: Vec<String> = NAMED_VIEWS
        .iter()
        .map(|(name, d)| format!("\"{name}\":{}", v(*d)))
        .collect();
    let header = format!(
        "{{\"k\":{K},\"level\":{level},\"time_axis\":{},\"budget\":{},\"complete\":{},\"full\":{},\"coarse\":{},\"camera\":{},\"frame\":{},\"views\":{{{}}},\"values\":{},\"groups\":{groups}}}",
        time.map_or("null".into(), |t| t.to_string()),
        options.budget,
        lod.complete,
        lod.full.len(),
        lod.coarse.len(),
        v(camera.toward_eye()),
        PageCamera::framing(&lod, level, time, camera.toward_eye()).json(),
        views.join(","),
        values.as_ref().map_or("null", |v| v.json.as_str()),
    );
    let html = TEMPLATE
        .replace("{{TITLE}}", &escape(&options.title))
        .replace("{{HEADER}}", &header)
        .replace("{{DATA}}", &base64(&bytes));
    Ok(Page {
        html,
        boxes: lod.len(),
        coarse: lod.coarse.len(),
        complete: lod.complete,
    })
}

/// Writes [`view_page`] of `tree` to `path` atomically.
///
/// # Errors
/// As [`view_page`]; [`ViewPageError::Write`] from the file system.
pub fn write_view<const K: usize, T: TreeStorage<K>>(
    path: &Path,
    tree: &T,
    options: &ViewOptions,
) -> Result<Page, ViewPageError> {
    let page = view_page(tree, options)?;
    write_atomic(path, page.html.as_bytes()).map_err(ViewPageError::Write)?;
    Ok(page)
}

/// Writes [`view_values_page`] of `tree` to `path` atomically.
///
/// # Errors
/// As [`view_values_page`]; [`ViewPageError::Write`] from the file system.
pub fn write_values_view<const K: usize, V: Value>(
    path: &Path,
    tree: &KTree<K, V>,
    options: &ViewOptions,
) -> Result<Page, ViewPageError> {
    let page = view_values_page(tree, options)?;
    write_atomic(path, page.html.as_bytes()).map_err(ViewPageError::Write)?;
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, coded) in cases {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn the_page_holds_the_boxes_and_requests_nothing() {
        let ball = KTree::from_rays(&crate::rays::ball_rays::<3>(5, [32, 32, 32], 40).unwrap());
        for budget in [1, 10, 1000, 100_000] {
            let page = view_page(
                &ball,
                &ViewOptions {
                    budget,
                    ..Default::default()
                },
            )
            .unwrap();
            assert!(page.boxes <= budget && page.boxes > 0);
            assert!(!page.html.contains("http://") && !page.html.contains("https://"));
            assert!(page.html.contains("default-src 'none'"));
        }
        let bin = KTree::<1>::full(2).unwrap();
        assert!(matches!(
            view_page(&bin, &ViewOptions::default()),
            Err(ViewPageError::Bintree)
        ));
        let t4 = KTree::<4>::full(2).unwrap();
        let bad = ViewOptions {
            time_axis: 4,
            ..Default::default()
        };
        assert!(matches!(
            view_page(&t4, &bad),
            Err(ViewPageError::BadTimeAxis { axis: 4, k: 4 })
        ));
    }
}
