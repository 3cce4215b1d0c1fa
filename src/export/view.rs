//! An interactive 3-D view of a tree in one self-contained HTML page: the boxes to draw chosen within a
//! budget ([`select_boxes`]), packed into a compact binary block (base64 in the page) and drawn by a small
//! WebGL2 program with instancing ([`view_page`], [`write_view`]).
//!
//! The page needs nothing from outside: its script, shaders and data are inline, and a
//! `Content-Security-Policy` of `default-src 'none'` forbids every request (a fetch would be a console
//! error). Octrees are drawn as shaded boxes, quadtrees as flat squares, 4-D trees as the 3-D slice at a
//! time chosen with a slider. The mouse orbits (left button), pans (right button or shift) and zooms
//! (wheel); sliders clip along each axis; a toggle colours by face normal or by depth in the tree. The
//! first camera is the one `ktree render --camera NAME` takes (the same orthographic projection and
//! framing). The URL hash sets the start: `#camera=NAME` another camera, `colour=depth` or `colour=normal`,
//! `time=T` the slice of a 4-D tree, `bare` no controls (the key `h` hides and shows them). `selftest`
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
//! leaves buried inside full regions need no box. Each refinement is a one-level [`cursor`](crate::tree::cursor) walk and each
//! neighbour question a [`cursor`](crate::tree::cursor) walk towards one cell, so the selection works on any storage (a tree in
//! memory, a mapped file) and reads only the nodes it draws and their neighbours' paths.
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

use std::convert::Infallible;
use std::fmt::Write as _;
use std::path::Path;

use thiserror::Error;

use crate::display::{View, NAMED_VIEWS};
use crate::fs::write_atomic;
use crate::space::Cell;
use crate::tree::cursor::{try_walk, try_walk_from, ChildOrder, TreeStorage, Visitor, Walk};
use crate::tree::{NodeRef, NodeState};

/// The page template: markup, style and the WebGL2 program; the header and data are put in its slots.
const TEMPLATE: &str = include_str!("view/page.html");

/// The default box budget: about 0.8 MB of page (8 bytes of base64 a box for an octree).
pub const DEFAULT_BUDGET: usize = 100_000;

/// The boxes of a view: visible full leaves and the coarse partial cells left unrefined.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lod<const K: usize> {
    /// Full leaves with at least one face open on the drawn axes.
    pub full: Vec<Cell<K>>,
    /// Partial cells drawn whole because the budget ran out before they were refined.
    pub coarse: Vec<Cell<K>>,
    /// Whether every partial node was refined (`coarse` is then empty and `full` holds every visible leaf).
    pub complete: bool,
}

impl<const K: usize> Lod<K> {
    /// The number of boxes.
    pub fn len(&self) -> usize {
        self.full.len() + self.coarse.len()
    }

    /// Whether there is no box (an empty tree).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

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
pub enum ViewError {
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
    #[error("{0}")]
    Read(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// Writing the page failed (the message names the file).
    #[error("{0}")]
    Write(#[source] std::io::Error),
}

/// Whether every voxel of the aligned cell `region` that touches its face on `axis` (`upper`: the face at
/// `origin + side`) is full: a walk that takes one child at a time down to `region`, then only the
/// children on that face, stopping at the first empty node.
fn face_all_full<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    region: &Cell<K>,
    axis: usize,
    upper: bool,
) -> Result<bool, T::Error> {
    struct Face<const K: usize> {
        region: Cell<K>,
        face: ChildOrder,
        all_full: bool,
    }
    impl<const K: usize> Visitor<K> for Face<K> {
        const ORIGINS: bool = false;
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            if node.state() == NodeState::Empty {
                self.all_full = false;
                return Walk::Stop;
            }
            Walk::Descend
        }
        fn child_order(&self, node: &NodeRef<K>) -> ChildOrder {
            if node.cell().level() >= self.region.level() {
                return self.face;
            }
            let bit = node.cell().log_side() - 1;
            let code = (0..K).fold(0, |code, a| {
                code | ((self.region.origin()[a] >> bit & 1) as usize) << a
            });
            ChildOrder::one(code)
        }
    }
    let mut face = Face {
        region: *region,
        face: ChildOrder::half::<K>(axis, upper),
        all_full: true,
    };
    try_walk(tree, &mut face)?;
    Ok(face.all_full)
}

/// The children of a partial node, in code order: a walk of one level below it.
fn children<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    node: NodeRef<K>,
) -> Result<Vec<NodeRef<K>>, T::Error> {
    struct OneLevel<const K: usize> {
        top: u32,
        seen: Vec<NodeRef<K>>,
    }
    impl<const K: usize> Visitor<K> for OneLevel<K> {
        const LEAVES: bool = false;
        fn visit(&mut self, node: &NodeRef<K>) -> Walk {
            if node.cell().level() == self.top {
                return Walk::Descend;
            }
            self.seen.push(*node);
            Walk::Skip
        }
    }
    let mut one = OneLevel {
        top: node.cell().level(),
        seen: Vec::with_capacity(1 << K),
    };
    try_walk_from(tree, node, &mut one)?;
    Ok(one.seen)
}

/// Whether the full child `code` of a partial node (its siblings `kids`, in code order) has a face on one
/// of `axes` that touches a voxel that is not full (the universe's boundary is open).
fn visible<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    kids: &[NodeRef<K>],
    code: usize,
    axes: &[usize],
) -> Result<bool, T::Error> {
    if axes.is_empty() {
        return Ok(true);
    }
    let cell = kids[code].cell();
    let side = cell.side();
    let universe = tree.universe().side();
    // Faces inside the parent first: their neighbours are siblings; a full or empty one is answered
    // without a walk.
    for &a in axes {
        let sibling = kids[code ^ (1 << a)];
        let open = match sibling.state() {
            NodeState::Full => false,
            NodeState::Empty => true,
            NodeState::Partial => !face_all_full(tree, &sibling.cell(), a, code >> a & 1 == 1)?,
        };
        if open {
            return Ok(true);
        }
    }
    for &a in axes {
        let upper = code >> a & 1 == 1;
        let o = u64::from(cell.origin()[a]);
        let across = if upper {
            o + side
        } else {
            o.wrapping_sub(side)
        };
        if across >= universe {
            return Ok(true);
        }
        let mut origin = cell.origin();
        origin[a] = across as u32;
        let neighbour = Cell {
            origin,
            level: cell.level(),
            log_side: cell.log_side(),
        };
        if !face_all_full(tree, &neighbour, a, !upper)? {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The boxes to draw of `tree` within `budget`: breadth-first refinement from the root while the number
/// of boxes (visible full leaves plus the partial cells not yet refined) stays within the budget. A full
/// leaf is kept when one of its faces on `axes` touches a voxel that is not full or the universe's
/// boundary (`axes` empty: every full leaf is kept).
///
/// # Errors
/// The storage's read error.
///
/// # Performance
/// `O(B · K · L)` node reads for `B` boxes, plus for a buried leaf the nodes along its faces: each face
/// question is a walk of `L` steps to the cell across, then down that cell's face until an empty node.
pub fn select_boxes<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    budget: usize,
    axes: &[usize],
) -> Result<Lod<K>, T::Error> {
    let root = tree.root()?;
    let mut full = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    match root.state() {
        NodeState::Full if budget > 0 => full.push(root.cell()),
        NodeState::Partial if budget > 0 => queue.push_back(root),
        _ => {}
    }
    let mut complete = root.state() != NodeState::Partial;
    let mut boxes = full.len() + queue.len();
    while let Some(node) = queue.pop_front() {
        let kids = children(tree, node)?;
        let mut keep = Vec::new();
        let mut partial = 0;
        for (code, kid) in kids.iter().enumerate() {
            match kid.state() {
                NodeState::Partial => partial += 1,
                NodeState::Full if visible(tree, &kids, code, axes)? => keep.push(kid.cell()),
                _ => {}
            }
        }
        if boxes - 1 + keep.len() + partial > budget {
            queue.push_front(node);
            break;
        }
        boxes = boxes - 1 + keep.len() + partial;
        full.extend(keep);
        queue.extend(kids.into_iter().filter(|k| k.state() == NodeState::Partial));
        complete = queue.is_empty();
    }
    let coarse = queue.into_iter().map(|n| n.cell()).collect();
    Ok(Lod {
        full,
        coarse,
        complete,
    })
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
/// units of the cell's side, little-endian, 2 bytes each for depths up to 16, else 4. Returns the
/// groups' JSON and the bytes.
fn pack<const K: usize>(lod: &Lod<K>, level: u32) -> (String, Vec<u8>) {
    let mut groups = String::from("[");
    let mut bytes = Vec::new();
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
            }
        }
    }
    groups.push(']');
    (groups, bytes)
}

/// The page showing `tree` (see the [module docs](self)).
///
/// # Errors
/// [`ViewError::Bintree`] for K = 1, [`ViewError::ZeroBudget`], [`ViewError::BadTimeAxis`] for a 4-D
/// tree, [`ViewError::Read`] from the storage.
pub fn view_page<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    options: &ViewOptions,
) -> Result<Page, ViewError> {
    if K == 1 {
        return Err(ViewError::Bintree);
    }
    if options.budget == 0 {
        return Err(ViewError::ZeroBudget);
    }
    let time = if K == 4 {
        if options.time_axis >= K {
            return Err(ViewError::BadTimeAxis {
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
        select_boxes(tree, options.budget, &axes).map_err(|e| ViewError::Read(Box::new(e)))?;
    let (groups, bytes) = pack(&lod, level);
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
        "{{\"k\":{K},\"level\":{level},\"time_axis\":{},\"budget\":{},\"complete\":{},\"full\":{},\"coarse\":{},\"camera\":{},\"views\":{{{}}},\"groups\":{groups}}}",
        time.map_or("null".into(), |t| t.to_string()),
        options.budget,
        lod.complete,
        lod.full.len(),
        lod.coarse.len(),
        v(camera.toward_eye()),
        views.join(","),
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
/// As [`view_page`]; [`ViewError::Write`] from the file system.
pub fn write_view<const K: usize, T: TreeStorage<K>>(
    path: &Path,
    tree: &T,
    options: &ViewOptions,
) -> Result<Page, ViewError> {
    let page = view_page(tree, options)?;
    write_atomic(path, page.html.as_bytes()).map_err(ViewError::Write)?;
    Ok(page)
}

/// [`select_boxes`] over a tree whose reads cannot fail.
pub fn select_boxes_of<const K: usize, T: TreeStorage<K, Error = Infallible>>(
    tree: &T,
    budget: usize,
    axes: &[usize],
) -> Lod<K> {
    match select_boxes(tree, budget, axes) {
        Ok(lod) => lod,
        Err(never) => match never {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::DensePyramid;
    use crate::KTree;
    use proptest::prelude::*;

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

    /// The brute-force reference: every full leaf with a voxel whose neighbour across a face on `axes`
    /// is outside the universe or not full (from the dense array), in no particular order.
    fn visible_leaves<const K: usize>(tree: &KTree<K>, axes: &[usize]) -> Vec<Cell<K>> {
        let u = tree.universe();
        let side = u.side() as i64;
        let dense = tree.to_dense().unwrap();
        let n = dense.len();
        let full = |p: [i64; K]| {
            p.iter().all(|&c| (0..side).contains(&c)) && dense[u.dense_index(p.map(|c| c as u32))]
        };
        let mut out = Vec::new();
        for (cell, state) in tree.leaves() {
            if state != NodeState::Full {
                continue;
            }
            let s = cell.side() as i64;
            let o = cell.origin().map(i64::from);
            let open = axes.is_empty()
                || (0..n).any(|i| {
                    let p = u.dense_point(i).map(i64::from);
                    if !(0..K).all(|a| (o[a]..o[a] + s).contains(&p[a])) {
                        return false;
                    }
                    axes.iter().any(|&a| {
                        [-1, 1].iter().any(|&d| {
                            let mut q = p;
                            q[a] += d;
                            !(o[a]..o[a] + s).contains(&q[a]) && !full(q)
                        })
                    })
                });
            if open {
                out.push(cell);
            }
        }
        out
    }

    fn check<const K: usize>(dense: &[bool], level: u32, budget: usize, axes: &[usize]) {
        let tree = KTree::<K>::from_dense(level, dense).unwrap();
        let lod = select_boxes_of(&tree, budget, axes);
        let reference = visible_leaves(&tree, axes);
        let key = |c: &Cell<K>| (c.level(), c.morton());
        assert!(
            lod.len() <= budget,
            "{} boxes for a budget of {budget}",
            lod.len()
        );
        // Every box holds part of the object; the full ones are visible leaves of the tree.
        let mut leaves: Vec<_> = reference.iter().map(key).collect();
        leaves.sort_unstable();
        for c in &lod.full {
            assert!(
                leaves.binary_search(&key(c)).is_ok(),
                "{c:?} is not a visible full leaf"
            );
        }
        let pyramid = DensePyramid::<K>::from_dense(level, dense).unwrap();
        for c in &lod.coarse {
            let unit = c.origin().map(|o| o >> c.log_side());
            assert_eq!(pyramid.state(c.level(), unit), NodeState::Partial, "{c:?}");
        }
        // Every visible leaf is drawn: itself, or inside a coarse box.
        for c in &reference {
            let drawn = lod.full.iter().any(|f| key(f) == key(c))
                || lod
                    .coarse
                    .iter()
                    .any(|p| p.level() < c.level() && p.contains(c.origin()));
            assert!(drawn, "visible leaf {c:?} is not drawn");
        }
        if lod.complete {
            assert!(lod.coarse.is_empty());
            assert_eq!(lod.full.len(), reference.len());
        }
        // A budget as large as the reference's count is always enough to finish.
        let enough = reference.len()
            + tree
                .counts_per_level()
                .iter()
                .map(|c| c.partial as usize)
                .sum::<usize>();
        let all = select_boxes_of(&tree, enough.max(1), axes);
        assert!(all.complete);
        assert_eq!(all.full.len(), reference.len());
    }

    fn dense_strategy(k: usize, level: u32) -> impl Strategy<Value = Vec<bool>> {
        let n = 1usize << (k as u32 * level);
        (
            prop::collection::vec(any::<bool>(), n),
            0.0f64..1.0,
            any::<u64>(),
        )
            .prop_map(move |(bits, p, seed)| {
                // Blobs: a random field thresholded after smoothing by its neighbours in code order.
                let mut out = bits.clone();
                let mut s = seed | 1;
                for (i, b) in out.iter_mut().enumerate() {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    let keep = (s % 1000) as f64 / 1000.0 < p;
                    *b = if keep { bits[i] } else { bits[i / 8 * 8] };
                }
                out
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn lod_k1(dense in dense_strategy(1, 5), budget in 1usize..40) {
            check::<1>(&dense, 5, budget, &[0]);
        }
        #[test]
        fn lod_k2(dense in dense_strategy(2, 3), budget in 1usize..60, cull in any::<bool>()) {
            check::<2>(&dense, 3, budget, if cull { &[0, 1] } else { &[] });
        }
        #[test]
        fn lod_k3(dense in dense_strategy(3, 3), budget in 1usize..200) {
            check::<3>(&dense, 3, budget, &[0, 1, 2]);
        }
        #[test]
        fn lod_k4(dense in dense_strategy(4, 2), budget in 1usize..200, time in 0usize..4) {
            let axes: Vec<usize> = (0..4).filter(|&a| a != time).collect();
            check::<4>(&dense, 2, budget, &axes);
        }
    }

    #[test]
    fn full_and_empty_universes() {
        let full = KTree::<3>::full(3).unwrap();
        let lod = select_boxes_of(&full, 1, &[0, 1, 2]);
        assert_eq!(
            (lod.full.len(), lod.coarse.len(), lod.complete),
            (1, 0, true)
        );
        let empty = KTree::<3>::empty(3).unwrap();
        assert!(select_boxes_of(&empty, 5, &[0, 1, 2]).is_empty());
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
            Err(ViewError::Bintree)
        ));
        let t4 = KTree::<4>::full(2).unwrap();
        let bad = ViewOptions {
            time_axis: 4,
            ..Default::default()
        };
        assert!(matches!(
            view_page(&t4, &bad),
            Err(ViewError::BadTimeAxis { axis: 4, k: 4 })
        ));
    }
}
