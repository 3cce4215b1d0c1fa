//! The first camera of a view page: orthographic, framing the page's boxes from the first view's direction
//! as `ktree render` frames an object (the same screen axes, the same 5 % margin). It is computed here and
//! given to the page, which shows, at whatever size its window has and whenever that size changes, the
//! smallest rectangle of the window's aspect that holds the boxes' projection with that margin.

use crate::display::camera::v3;
use crate::display::Camera;

use super::Lod;

/// The margin around the framed projection: 5 %, as [`Camera::framing`] leaves.
const MARGIN: f64 = 1.05;

/// An orthographic camera of the page: it looks along `forward` at `target`, with `right` and `up` the
/// screen's axes; `extent` is the half width and half height, on those axes, of the projection of the
/// page's boxes around `target`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PageCamera {
    /// The point looked at: the centre of the boxes' bounding box.
    pub(super) target: [f64; 3],
    /// The view direction, into the scene (unit).
    pub(super) forward: [f64; 3],
    /// Screen right (unit).
    pub(super) right: [f64; 3],
    /// Screen up (unit).
    pub(super) up: [f64; 3],
    /// Half width and half height of the boxes' projection around `target`.
    pub(super) extent: [f64; 2],
}

impl PageCamera {
    /// The camera framing the boxes of `lod` (of a tree of universe level `level`; for a 4-D tree, `time`
    /// is the axis not drawn) seen from `toward_eye`, a finite direction that is not zero.
    pub(super) fn framing<const K: usize>(
        lod: &Lod<K>,
        level: u32,
        time: Option<usize>,
        toward_eye: [f64; 3],
    ) -> Self {
        let boxes: Vec<([f64; 3], [f64; 3])> = boxes_3d(lod, time).collect();
        let (lo, hi) = if boxes.is_empty() {
            let side = (1u64 << level) as f64;
            let top = if K == 2 { 0.0 } else { side };
            ([0.0; 3], [side, side, top])
        } else {
            boxes.iter().fold(
                ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                |(lo, hi), (at, size)| {
                    (
                        std::array::from_fn(|a| lo[a].min(at[a])),
                        std::array::from_fn(|a| hi[a].max(at[a] + size[a])),
                    )
                },
            )
        };
        // Scaled so that its largest component is 1: any finite direction that is not zero normalises.
        let largest = toward_eye.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let toward = toward_eye.map(|x| x / largest);
        let camera = Camera::framing(lo, hi, toward, None, 1, 1)
            .expect("a direction of largest component 1 frames any box");
        let frame = camera.frame();
        let target = camera.target;
        let (mut ex, mut ey) = (0.0f64, 0.0f64);
        let whole = [(lo, v3::sub(hi, lo))];
        let corners_of = if boxes.is_empty() { &whole[..] } else { &boxes };
        for (at, size) in corners_of {
            for c in 0..8 {
                let corner: [f64; 3] =
                    std::array::from_fn(|a| at[a] + if c >> a & 1 == 1 { size[a] } else { 0.0 });
                let v = v3::sub(corner, target);
                ex = ex.max(v3::dot(v, frame.r).abs());
                ey = ey.max(v3::dot(v, frame.u).abs());
            }
        }
        Self {
            target,
            forward: frame.f,
            right: frame.r,
            up: frame.u,
            extent: [ex, ey],
        }
    }

    /// The camera as the page's header holds it.
    pub(super) fn json(&self) -> String {
        let v = |d: [f64; 3]| format!("[{},{},{}]", d[0], d[1], d[2]);
        format!(
            "{{\"target\":{},\"forward\":{},\"right\":{},\"up\":{},\"extent\":[{},{}],\"margin\":{MARGIN}}}",
            v(self.target),
            v(self.forward),
            v(self.right),
            v(self.up),
            self.extent[0],
            self.extent[1]
        )
    }
}

/// The boxes of `lod` in the page's 3-D space, as (lower corner, size): a quadtree's cells flat at
/// `z = 0`; a 4-D tree's cells without their time axis `time`.
fn boxes_3d<const K: usize>(
    lod: &Lod<K>,
    time: Option<usize>,
) -> impl Iterator<Item = ([f64; 3], [f64; 3])> + '_ {
    let spatial: Vec<usize> = (0..K).filter(|&a| Some(a) != time).take(3).collect();
    lod.full.iter().chain(&lod.coarse).map(move |cell| {
        let side = cell.side() as f64;
        let origin = cell.origin();
        let at = std::array::from_fn(|a| spatial.get(a).map_or(0.0, |&s| f64::from(origin[s])));
        let size = std::array::from_fn(|a| if a < spatial.len() { side } else { 0.0 });
        (at, size)
    })
}

#[cfg(test)]
mod tests {
    use super::super::select_boxes_of;
    use super::*;
    use crate::tree::NodeState;
    use crate::KTree;
    use proptest::prelude::*;

    /// The half width and half height of the image plane the page shows for `camera` in a window of
    /// `aspect` (width / height) before any zoom, as the page's `camHeight` computes it: the smallest
    /// rectangle of that aspect holding the extent with the margin.
    fn half_view(camera: &PageCamera, aspect: f64) -> [f64; 2] {
        let height = (2.0 * camera.extent[1])
            .max(2.0 * camera.extent[0] / aspect)
            .max(1.0)
            * MARGIN;
        [height / 2.0 * aspect, height / 2.0]
    }

    /// Every corner of every full voxel of `tree` (a 4-D tree's without its time axis), projected on the
    /// camera's screen axes around its target, lies within the camera's extent; and within the view the
    /// page shows at common window shapes, the margin inside.
    fn frames_every_voxel<const K: usize>(
        tree: &KTree<K>,
        budget: usize,
        time: Option<usize>,
        toward: [f64; 3],
    ) -> Result<(), TestCaseError> {
        let axes: Vec<usize> = match K {
            2 => Vec::new(),
            _ => (0..K).filter(|&a| Some(a) != time).collect(),
        };
        let lod = select_boxes_of(tree, budget, &axes);
        let camera = PageCamera::framing(&lod, tree.level(), time, toward);
        let spatial: Vec<usize> = (0..K).filter(|&a| Some(a) != time).take(3).collect();
        let (mut px, mut py) = (0.0f64, 0.0f64);
        for (cell, state) in tree.leaves() {
            if state != NodeState::Full {
                continue;
            }
            let side = cell.side() as f64;
            for c in 0..8 {
                let corner: [f64; 3] = std::array::from_fn(|a| match spatial.get(a) {
                    Some(&s) => {
                        f64::from(cell.origin()[s]) + if c >> a & 1 == 1 { side } else { 0.0 }
                    }
                    None => 0.0,
                });
                let v = v3::sub(corner, camera.target);
                px = px.max(v3::dot(v, camera.right).abs());
                py = py.max(v3::dot(v, camera.up).abs());
            }
        }
        let slack = 1e-9 * (1u64 << tree.level()) as f64;
        prop_assert!(px <= camera.extent[0] + slack, "{px} > {:?}", camera.extent);
        prop_assert!(py <= camera.extent[1] + slack, "{py} > {:?}", camera.extent);
        for aspect in [
            1024.0 / 768.0,
            320.0 / 240.0,
            768.0 / 1024.0,
            1920.0 / 1080.0,
            1.0,
        ] {
            let [hw, hh] = half_view(&camera, aspect);
            prop_assert!(px * MARGIN <= hw + slack && py * MARGIN <= hh + slack);
            prop_assert!((hw / hh - aspect).abs() < 1e-9);
        }
        prop_assert!(v3::dot(camera.forward, toward) < 0.0);
        prop_assert!(v3::dot(camera.right, camera.up).abs() < 1e-9);
        Ok(())
    }

    fn direction() -> impl Strategy<Value = [f64; 3]> {
        prop::array::uniform3(-2.0f64..2.0)
            .prop_filter("not zero", |d| d.iter().any(|x| x.abs() > 1e-3))
    }

    fn dense(k: u32, level: u32) -> impl Strategy<Value = Vec<bool>> {
        prop::collection::vec(prop::bool::weighted(0.3), 1usize << (k * level))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn the_first_camera_frames_every_voxel_k2(
            d in dense(2, 4), budget in 1usize..80, toward in direction(),
        ) {
            frames_every_voxel(&KTree::<2>::from_dense(4, &d).unwrap(), budget, None, toward)?;
        }
        #[test]
        fn the_first_camera_frames_every_voxel_k3(
            d in dense(3, 3), budget in 1usize..300, toward in direction(),
        ) {
            frames_every_voxel(&KTree::<3>::from_dense(3, &d).unwrap(), budget, None, toward)?;
        }
        #[test]
        fn the_first_camera_frames_every_voxel_k4(
            d in dense(4, 2), budget in 1usize..300, time in 0usize..4, toward in direction(),
        ) {
            frames_every_voxel(&KTree::<4>::from_dense(2, &d).unwrap(), budget, Some(time), toward)?;
        }
    }

    #[test]
    fn an_empty_tree_frames_its_universe() {
        let empty = KTree::<3>::empty(4).unwrap();
        let lod = select_boxes_of(&empty, 10, &[0, 1, 2]);
        let camera = PageCamera::framing(&lod, 4, None, [0.0, 0.0, 1.0]);
        assert_eq!(camera.target, [8.0, 8.0, 8.0]);
        assert_eq!(camera.extent, [8.0, 8.0]);
        // A direction too small to normalise as it is still frames.
        let tiny = PageCamera::framing(&lod, 4, None, [0.0, 0.0, 1e-320]);
        assert_eq!(tiny, camera);
    }
}
