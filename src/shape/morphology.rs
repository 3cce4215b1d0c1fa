//! Dilation, erosion, opening and closing by a ball, box or cross of any real radius.
//!
//! # Method
//! Per-column run extension over the element's `(K − 1)`-D slice: the element is cut into columns — for
//! each column offset `c` a run `[−h(c), h(c)]` along the last axis — and the dilation is the union over
//! `c` of the object's runs moved by `c` and grown by `h(c)` at both ends; the erosion is the
//! intersection over `c` of the runs moved by `−c` and shrunk by `h(c)` (a column outside the universe
//! has no run, so what would reach outside is eroded: scipy's `border_value=0`; this is the complement
//! of the dilation of the complement with the outside empty). The cost is one merge pass over the runs
//! for each column offset, `O(r^(K−1) · runs)`, independent of `r` along the last axis and never
//! `r` unit steps over voxels. The box and the cross are cheaper still as Minkowski sums of small slices
//! (segments by doubling, `O(K log r)` passes; unit crosses, `O(K r)` passes), taken where that makes
//! fewer passes; the ball, which is no such sum, takes its own slice. No dense array and no distance field is made, and memory stays
//! proportional to the runs. (A distance transform would cost a pass per voxel of the universe.)
//!
//! The closing is the erosion of the dilation computed in an unbounded space (signed coordinates, no
//! universe), so the universe's faces cut neither; the result is then clipped to the universe. It equals
//! scipy's `binary_closing` on an array padded by more than the radius on every side, then cropped.
use super::distance::{ball_by_distance_fits, dilate_ball_by_distance, erode_ball_by_distance};
use super::element::{check_radius, plan, Slice};
use super::input::runs;
use super::runs::Runs;
use super::{Element, ShapeError};
use crate::tree::storage::TreeStorage;
use crate::KTree;

/// Up to this many column offsets, a slice's dilation (erosion) merges (intersects) all its moved copies
/// in one pass; beyond, it takes them one at a time (each output column would look at too many copies).
/// Measured on the L = 10 ball and armadillo, one thread: the unit cross (5 offsets) and the ball of r = 2
/// (13) 1.25–1.6× faster in one pass; the ball of r = 4 (49 offsets) and r = 8 (197) 1.4–1.6× slower.
const MERGED_AT_ONCE: usize = 16;

/// Sets `out` to the dilation of `runs` by one slice of an element; `spare` is a second buffer.
fn dilate_runs<const K: usize>(
    runs: &Runs<K>,
    element: &Slice<K>,
    out: &mut Runs<K>,
    spare: &mut Runs<K>,
) {
    if element.len() <= MERGED_AT_ONCE {
        runs.union_of_moved_into(element, out);
        return;
    }
    out.clear();
    for &(c, h) in element {
        out.combine_into(runs.moved(c, h), true, spare);
        std::mem::swap(out, spare);
    }
}

/// Sets `out` to the erosion of `runs` by one slice of an element; `spare` is a second buffer.
fn erode_runs<const K: usize>(
    runs: &Runs<K>,
    element: &Slice<K>,
    out: &mut Runs<K>,
    spare: &mut Runs<K>,
) {
    if element.len() <= MERGED_AT_ONCE {
        let reflected: Slice<K> = element.iter().map(|&(c, h)| (c.map(|x| -x), h)).collect();
        runs.intersection_of_moved_into(&reflected, out);
        return;
    }
    out.clear();
    let Some((&(c, h), rest)) = element.split_first() else {
        return;
    };
    runs.moved(c.map(|x| -x), -h).copy_into(out);
    for &(c, h) in rest {
        if out.is_empty() {
            return;
        }
        out.combine_into(runs.moved(c.map(|x| -x), -h), false, spare);
        std::mem::swap(out, spare);
    }
}

/// Applies `step` with each slice in turn, three buffers in all, reused from step to step.
fn all_steps<const K: usize>(
    runs: Runs<K>,
    steps: &[Slice<K>],
    step: fn(&Runs<K>, &Slice<K>, &mut Runs<K>, &mut Runs<K>),
) -> Runs<K> {
    let (mut acc, mut out, mut spare) = (runs, Runs::default(), Runs::default());
    for slice in steps {
        step(&acc, slice, &mut out, &mut spare);
        std::mem::swap(&mut acc, &mut out);
    }
    acc
}

fn dilate_all<const K: usize>(runs: Runs<K>, steps: &[Slice<K>]) -> Runs<K> {
    all_steps(runs, steps, dilate_runs)
}

fn erode_all<const K: usize>(runs: Runs<K>, steps: &[Slice<K>]) -> Runs<K> {
    all_steps(runs, steps, erode_runs)
}

/// The number of column offsets of a ball's slice, `(2⌊r⌋ + 1)^(K−1)`, from which [`dilate`] and
/// [`erode`] take the distance transform ([`dilate_ball_by_distance`]) instead of the run
/// extension, whose cost grows with that number while the transform's grows only with the blocks' margin.
/// Measured on the L = 9 ball (radius 256) and armadillo, dilation, one thread, one run each, load 1.4–1.7:
///
/// | r | ball: runs | transform | armadillo: runs | transform |
/// |---|---:|---:|---:|---:|
/// | 24 | 4.1 s | 8.6 s | 2.5 s | 4.3 s |
/// | 32 | 6.2 s | 12.3 s | 4.3 s | 6.3 s |
/// | 48 | 19.0 s | 15.4 s | 14.2 s | 11.5 s |
///
/// so the switch is at r = 40 in 3-D, 81² offsets. The run extension also peaks lower (27 MiB against 56 MiB
/// at r = 32, 30 against 222 MiB at r = 48: the transform holds a block grown by r on each side). Other K
/// take the same count of offsets (not measured); in 1-D the ball is one run and the runs always win.
pub const BALL_BY_DISTANCE_FROM: u128 = 81 * 81;

/// Whether a dilation or erosion by `element` of radius `r` takes the distance transform.
fn by_distance<const K: usize>(r: f64, element: Element) -> bool {
    let offsets = (2 * r.floor().min(1e9) as u128 + 1).saturating_pow(K as u32 - 1);
    K >= 2 && element == Element::Ball && offsets >= BALL_BY_DISTANCE_FROM
}

/// Reads the runs of `tree`, applies `f` with the element's slices, and stacks the result.
fn morph<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    r: f64,
    element: Element,
    f: impl FnOnce(Runs<K>, &[Slice<K>]) -> Runs<K>,
    bound: i64,
) -> Result<KTree<K>, ShapeError> {
    check_radius(r)?;
    let steps = plan::<K>(element, r, bound)?;
    let runs = Runs::from_rays(&runs(tree)?);
    Ok(KTree::from_rays(&f(runs, &steps).to_rays(tree.universe())))
}

/// The voxels within the element of radius `r` of a full voxel of `tree` (in memory or a file read in
/// place), clipped to the universe (scipy's `binary_dilation` with that structure).
///
/// ```
/// use ktree::{shape::{dilate, Element}, KTree, Ray, RaySet};
/// let dot = KTree::from_rays(&RaySet::<2>::from_rays(3, [Ray::new([4, 4], 5)]).unwrap());
/// assert_eq!(dilate(&dot, 1.0, Element::Ball).unwrap().voxel_count(), 5);
/// assert_eq!(dilate(&dot, 1.0, Element::Box).unwrap().voxel_count(), 9);
/// assert_eq!(dilate(&dot, 2.0, Element::Cross).unwrap().voxel_count(), 13);
/// ```
///
/// # Performance
/// One merge pass over the runs per column offset of the element (see [`crate::shape`]'s morphology
/// notes); a ball of many offsets through the distance transform instead ([`BALL_BY_DISTANCE_FROM`]).
///
/// # Errors
/// [`ShapeError::BadRadius`] for a negative or non-finite `r`; [`ShapeError::RadiusTooLarge`] if the
/// element has more than 2^24 column offsets inside the universe's reach; [`ShapeError::Storage`] for a
/// read error.
pub fn dilate<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    r: f64,
    element: Element,
) -> Result<KTree<K>, ShapeError> {
    if by_distance::<K>(r, element) && ball_by_distance_fits(tree, r) {
        return dilate_ball_by_distance(tree, r);
    }
    let bound = tree.universe().side() as i64;
    morph(tree, r, element, dilate_all, bound)
}

/// The voxels of `tree` whose whole element of radius `r` lies in the object, outside the universe
/// counting as empty (scipy's `binary_erosion(..., border_value=0)`).
///
/// ```
/// use ktree::{shape::{erode, Element}, KTree};
/// let full = KTree::<2>::full(3).unwrap();
/// assert_eq!(erode(&full, 1.0, Element::Box).unwrap().voxel_count(), 36); // the 6 × 6 inside
/// ```
///
/// # Errors
/// As [`dilate`].
pub fn erode<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    r: f64,
    element: Element,
) -> Result<KTree<K>, ShapeError> {
    check_radius(r)?;
    let side = tree.universe().side();
    // The element reaches ⌊r⌋ along every axis: wider than the universe, nothing survives.
    if 2.0 * r.floor() + 1.0 > side as f64 {
        return Ok(KTree::empty(tree.level()).expect("the tree's level"));
    }
    if by_distance::<K>(r, element) && ball_by_distance_fits(tree, r) {
        return erode_ball_by_distance(tree, r);
    }
    morph(tree, r, element, erode_all, side as i64)
}

/// The dilation of the erosion of `tree` (scipy's `binary_opening` with `border_value=0` semantics).
///
/// ```
/// use ktree::{shape::{opening, Element}, KTree, Ray, RaySet};
/// // A 4 × 4 square with a one-voxel spur: the opening by a 3 × 3 box removes the spur.
/// let mut rays: Vec<_> = (2..6).map(|x| Ray::new([x, 2], 6)).collect();
/// rays.push(Ray::new([6, 3], 4));
/// let tree = KTree::from_rays(&RaySet::<2>::from_rays(3, rays).unwrap());
/// assert_eq!(opening(&tree, 1.0, Element::Box).unwrap().voxel_count(), 16);
/// ```
///
/// # Errors
/// As [`dilate`].
pub fn opening<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    r: f64,
    element: Element,
) -> Result<KTree<K>, ShapeError> {
    dilate(&erode(tree, r, element)?, r, element)
}

/// The erosion of the dilation of `tree`, both in an unbounded space so the universe's faces cut
/// neither, then clipped to the universe (scipy's `binary_closing` on an array padded by more than `r`,
/// cropped).
///
/// ```
/// use ktree::{shape::{closing, Element}, KTree, Ray, RaySet};
/// // Two runs with a one-voxel gap: the closing fills it.
/// let rays = RaySet::<1>::from_rays(3, [Ray::new([0], 3), Ray::new([4], 8)]).unwrap();
/// let closed = closing(&KTree::from_rays(&rays), 1.0, Element::Ball).unwrap();
/// assert_eq!(closed.voxel_count(), 8);
/// ```
///
/// # Errors
/// As [`dilate`] (with the element's full reach counted, not cut at the universe), and
/// [`ShapeError::ClosingTooWide`] for a radius over four times the universe's side.
pub fn closing<const K: usize, T: TreeStorage<K> + Sync>(
    tree: &T,
    r: f64,
    element: Element,
) -> Result<KTree<K>, ShapeError> {
    check_radius(r)?;
    let side = tree.universe().side();
    if r.floor() > 4.0 * side as f64 {
        return Err(ShapeError::ClosingTooWide { radius: r, side });
    }
    morph(
        tree,
        r,
        element,
        |runs, steps| erode_all(dilate_all(runs, steps), steps),
        i64::MAX / 4,
    )
}

impl<const K: usize> KTree<K> {
    /// The voxels within the element of radius `r` of a full voxel, clipped to the universe (scipy's
    /// `binary_dilation` with that structure; [`dilate()`]).
    ///
    /// ```
    /// use ktree::{shape::Element, KTree, Ray, RaySet};
    /// let dot = KTree::from_rays(&RaySet::<2>::from_rays(3, [Ray::new([4, 4], 5)]).unwrap());
    /// assert_eq!(dot.dilate(1.0, Element::Ball).unwrap().voxel_count(), 5);
    /// ```
    ///
    /// # Errors
    /// As [`dilate()`].
    pub fn dilate(&self, r: f64, element: Element) -> Result<KTree<K>, ShapeError> {
        dilate(self, r, element)
    }

    /// The voxels whose whole element of radius `r` lies in the object, outside the universe counting as
    /// empty (scipy's `binary_erosion(..., border_value=0)`; [`erode()`]).
    ///
    /// ```
    /// use ktree::{shape::Element, KTree};
    /// let full = KTree::<2>::full(3).unwrap();
    /// assert_eq!(full.erode(1.0, Element::Box).unwrap().voxel_count(), 36);
    /// ```
    ///
    /// # Errors
    /// As [`dilate()`].
    pub fn erode(&self, r: f64, element: Element) -> Result<KTree<K>, ShapeError> {
        erode(self, r, element)
    }

    /// The dilation of the erosion ([`opening()`]).
    ///
    /// # Errors
    /// As [`dilate()`].
    pub fn opening(&self, r: f64, element: Element) -> Result<KTree<K>, ShapeError> {
        opening(self, r, element)
    }

    /// The erosion of the dilation, in an unbounded space, clipped to the universe ([`closing()`]).
    ///
    /// # Errors
    /// As [`closing()`].
    pub fn closing(&self, r: f64, element: Element) -> Result<KTree<K>, ShapeError> {
        closing(self, r, element)
    }
}
