//! Ray casting: the first full voxel a ray enters ([`cast_ray`]), one ray or many on all threads
//! ([`cast_rays`]).
//!
//! A ray is `p(t) = origin + t · direction` for `0 ≤ t ≤ max_t`, in continuous coordinates where voxel
//! `v` is the half-open box `[v, v + 1)`. The cast is a front-to-back walk of the tree: a node's
//! children are visited in the order the ray crosses them (child code XOR the signs of the direction),
//! a subtree the ray misses or an empty cell costs one step whatever its size, and the first full leaf the
//! ray meets ends the walk. Every cast terminates: it is a walk of the tree's finite nodes.
//!
//! # Exactness and ties
//! Each cell's parameter interval is computed from its faces in `f64` as `(c − o) / d`; one face has one
//! value, so neighbouring cells share their boundary exactly, and the walk meets every cell the ray crosses
//! in order, never skipping one. Membership is half-open like the voxels: at a parameter `t` where the
//! ray lies exactly on a face, edge or corner shared by several cells, the point `p(t)` belongs to the cell
//! it is in under `[v, v + 1)`, and a cell the ray only touches at a point of its upper faces is not
//! entered. So where a ray passes exactly through an edge or a corner of several full voxels, the voxel
//! reported is the one the ray is inside just after that `t`. The only rounding is in comparing the
//! crossings of two different axes that are less than an ulp of `t` apart: such a near-tie may be decided
//! either way.

use rayon::prelude::*;
use thiserror::Error;

use crate::space::Cell;
use crate::tree::cursor::{try_walk, ChildOrder, Visitor, Walk};
use crate::tree::storage::TreeStorage;
use crate::tree::{NodeRef, NodeState};

/// Why a ray cannot be cast.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RayError {
    /// A coordinate of the origin or the direction is infinite or NaN: give finite numbers.
    #[error("the ray's {part} has {value} on axis {axis}: coordinates must be finite")]
    NotFinite {
        /// `"origin"` or `"direction"`.
        part: &'static str,
        /// The axis.
        axis: usize,
        /// The value given.
        value: f64,
    },
    /// `max_t` is NaN or negative: give a parameter `≥ 0` (`f64::INFINITY` for no limit).
    #[error("the ray's max_t is {value}: it must be >= 0 (inf for no limit)")]
    MaxT {
        /// The value given.
        value: f64,
    },
}

/// A ray to cast: a finite origin and direction and the largest parameter `max_t ≥ 0` (possibly
/// infinite), checked when made. The direction need not be normalised; `t` is in its units. A zero
/// direction is a point: it hits the voxel it is in.
///
/// ```
/// use ktree::query::RayCast;
/// assert!(RayCast::new([0.5, 0.5], [1.0, 0.0], f64::INFINITY).is_ok());
/// assert!(RayCast::new([0.5, f64::NAN], [1.0, 0.0], 1.0).is_err());
/// assert!(RayCast::new([0.5, 0.5], [1.0, 0.0], -1.0).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayCast<const K: usize> {
    origin: [f64; K],
    direction: [f64; K],
    max_t: f64,
}

impl<const K: usize> RayCast<K> {
    /// The ray from `origin` along `direction`, up to the parameter `max_t`.
    ///
    /// # Errors
    /// [`RayError::NotFinite`] for an infinite or NaN coordinate, [`RayError::MaxT`] for a NaN or
    /// negative `max_t`.
    pub fn new(origin: [f64; K], direction: [f64; K], max_t: f64) -> Result<Self, RayError> {
        for (part, v) in [("origin", &origin), ("direction", &direction)] {
            if let Some(axis) = v.iter().position(|x| !x.is_finite()) {
                return Err(RayError::NotFinite {
                    part,
                    axis,
                    value: v[axis],
                });
            }
        }
        if max_t.is_nan() || max_t < 0.0 {
            return Err(RayError::MaxT { value: max_t });
        }
        Ok(Self {
            origin,
            direction,
            max_t,
        })
    }

    /// The origin.
    pub fn origin(&self) -> [f64; K] {
        self.origin
    }

    /// The direction.
    pub fn direction(&self) -> [f64; K] {
        self.direction
    }

    /// The largest parameter.
    pub fn max_t(&self) -> f64 {
        self.max_t
    }

    /// The parameters at which the ray is in `cell` (within `[0, max_t]`): the entry `t` and the axis
    /// of the face entered (`None` when `p(t)` is in the cell at `t = 0`), or `None` if it never is.
    #[inline]
    fn entry(&self, cell: &Cell<K>) -> Option<(f64, Option<usize>)> {
        // (value, open) bounds; the lower one with the axis that gave it.
        let (mut low, mut low_open, mut low_axis) = (0.0f64, false, None);
        let (mut high, mut high_open) = (self.max_t, false);
        let side = cell.side() as f64;
        for a in 0..K {
            let (o, d) = (self.origin[a], self.direction[a]);
            let lo = f64::from(cell.origin[a]);
            let hi = lo + side;
            let (l, l_open, u, u_open) = if d > 0.0 {
                ((lo - o) / d, false, (hi - o) / d, true)
            } else if d < 0.0 {
                ((hi - o) / d, true, (lo - o) / d, false)
            } else if lo <= o && o < hi {
                continue;
            } else {
                return None;
            };
            if l > low || (l == low && l_open && !low_open) {
                (low, low_open, low_axis) = (l, l_open, Some(a));
            }
            if u < high || (u == high && u_open) {
                (high, high_open) = (u, u_open);
            }
        }
        let met = low < high || (low == high && !low_open && !high_open);
        met.then_some((low, low_axis))
    }

    /// The voxel of the full leaf `cell` that the ray is in just after entering it at `t` through a face
    /// of `axis` (or at `t = 0` when `axis` is `None`).
    fn voxel_in(&self, cell: &Cell<K>, t: f64, axis: Option<usize>) -> [u32; K] {
        std::array::from_fn(|a| {
            let lo = f64::from(cell.origin[a]);
            let last = lo + (cell.side() - 1) as f64;
            let (o, d) = (self.origin[a], self.direction[a]);
            let v = match axis {
                Some(e) if e == a => {
                    if d > 0.0 {
                        lo
                    } else {
                        last
                    }
                }
                Some(_) if d > 0.0 => (o + t * d).floor(),
                Some(_) if d < 0.0 => (o + t * d).ceil() - 1.0,
                _ => o.floor(),
            };
            v.clamp(lo, last) as u32
        })
    }
}

/// The face through which a ray enters a voxel: its axis and the sign of its outward normal (`-1`: the
/// face at `voxel[axis]`, entered moving up the axis; `+1`: the face at `voxel[axis] + 1`, entered moving
/// down).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Face {
    /// The axis normal to the face.
    pub axis: usize,
    /// The sign of the face's outward normal: `-1` or `+1`.
    pub sign: i8,
}

/// Where a ray first enters a full voxel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit<const K: usize> {
    /// The voxel.
    pub voxel: [u32; K],
    /// The parameter at which the ray enters it (`0` when the origin is inside it).
    pub t: f64,
    /// The face entered; `None` when the origin is inside the voxel.
    pub face: Option<Face>,
}

/// Walks front to back and stops at the first full leaf the ray is in.
struct Caster<'r, const K: usize> {
    ray: &'r RayCast<K>,
    mask: usize,
    hit: Option<RayHit<K>>,
}

impl<const K: usize> Visitor<K> for Caster<'_, K> {
    const LEAVES: bool = false;

    #[inline]
    fn visit(&mut self, node: &NodeRef<K>) -> Walk {
        if node.state() == NodeState::Empty {
            return Walk::Skip;
        }
        let cell = node.cell();
        let Some((t, axis)) = self.ray.entry(&cell) else {
            return Walk::Skip;
        };
        if node.state() == NodeState::Partial {
            return Walk::Descend;
        }
        self.hit = Some(RayHit {
            voxel: self.ray.voxel_in(&cell, t, axis),
            t,
            face: axis.map(|axis| Face {
                axis,
                sign: if self.ray.direction[axis] > 0.0 {
                    -1
                } else {
                    1
                },
            }),
        });
        Walk::Stop
    }

    #[inline]
    fn child_order(&self, _node: &NodeRef<K>) -> ChildOrder {
        ChildOrder::xor::<K>(self.mask)
    }
}

/// The first full voxel `ray` enters at a parameter `0 ≤ t ≤ ray.max_t()`, with `t` and the face entered
/// (the origin inside a full voxel: that voxel, `t = 0`, no face); `None` when the ray leaves the universe
/// or passes `max_t` first. Rays starting outside the universe enter it first. Ties: see the
/// [module docs](self).
///
/// ```
/// use ktree::query::{cast_ray, Face, RayCast};
/// use ktree::KTree;
/// let tree = KTree::<1>::from_dense(3, &[false, false, false, false, false, true, false, false]).unwrap();
/// let hit = cast_ray(&tree, &RayCast::new([-2.0], [2.0], f64::INFINITY).unwrap()).unwrap().unwrap();
/// assert_eq!((hit.voxel, hit.t, hit.face), ([5], 3.5, Some(Face { axis: 0, sign: -1 })));
/// assert_eq!(cast_ray(&tree, &RayCast::new([-2.0], [2.0], 3.0).unwrap()), Ok(None));
/// assert_eq!(cast_ray(&tree, &RayCast::new([4.5], [-1.0], 9.0).unwrap()), Ok(None));
/// ```
///
/// # Errors
/// The storage's read error.
pub fn cast_ray<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    ray: &RayCast<K>,
) -> Result<Option<RayHit<K>>, T::Error> {
    let mask = (0..K).fold(0, |m, a| m | usize::from(ray.direction[a] < 0.0) << a);
    let mut caster = Caster {
        ray,
        mask,
        hit: None,
    };
    try_walk(tree, &mut caster)?;
    Ok(caster.hit)
}

/// [`cast_ray`] for each ray, on all threads, in the order given.
///
/// # Errors
/// The storage's first read error.
pub fn cast_rays<const K: usize, T>(
    tree: &T,
    rays: &[RayCast<K>],
) -> Result<Vec<Option<RayHit<K>>>, T::Error>
where
    T: TreeStorage<K> + Sync,
    T::Error: Send,
{
    rays.par_iter()
        .with_min_len(256)
        .map(|ray| cast_ray(tree, ray))
        .collect()
}
