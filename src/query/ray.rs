//! Ray casting: the first full voxel a ray enters ([`cast_ray`]), one ray or many on all threads
//! ([`cast_rays`]).
//!
//! A ray is `p(t) = origin + t · direction` for `0 ≤ t ≤ max_t`, in continuous coordinates where voxel
//! `v` is the half-open box `[v, v + 1)`. The cast is a front-to-back walk of the tree: a node's
//! children are visited in the order the ray crosses them (child code XOR the signs of the direction),
//! a subtree the ray misses or an empty cell costs one step whatever its size, and the first full leaf the
//! ray meets ends the walk. Every cast terminates: it is a walk of the tree's finite nodes.
//!
//! A node costs `K` divisions, for its middle planes: a child's parameters along each axis are its
//! parent's or the middle plane's. Only the children between the middle planes the ray crosses before
//! and after them are tried (at most `K + 1` but at ties), and only those whose interval may be a single
//! point, or that are full, go through the exact test of open and closed faces below.
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
use crate::tree::storage::TreeStorage;
use crate::tree::NodeState;

/// Why a ray cannot be cast.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CastError {
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
    /// [`CastError::NotFinite`] for an infinite or NaN coordinate, [`CastError::MaxT`] for a NaN or
    /// negative `max_t`.
    pub fn new(origin: [f64; K], direction: [f64; K], max_t: f64) -> Result<Self, CastError> {
        for (part, v) in [("origin", &origin), ("direction", &direction)] {
            if let Some(axis) = v.iter().position(|x| !x.is_finite()) {
                return Err(CastError::NotFinite {
                    part,
                    axis,
                    value: v[axis],
                });
            }
        }
        if max_t.is_nan() || max_t < 0.0 {
            return Err(CastError::MaxT { value: max_t });
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

/// The parameters at which a ray crosses a cell's slab along each axis, in the ray's order: it enters
/// the slab of axis `a` at `near[a]` and leaves it at `far[a]`. An axis along which the ray does not move
/// has `(−∞, ∞)` (the ray is inside that slab, or the cell is never visited).
#[derive(Debug, Clone, Copy)]
struct Slabs<const K: usize> {
    near: [f64; K],
    far: [f64; K],
}

/// Where a ray is in a cell: from `t`, entering through a face of `axis` (`None`: in the cell at `t = 0`),
/// to `exit`.
#[derive(Debug, Clone, Copy)]
struct Entry {
    t: f64,
    exit: f64,
    axis: Option<usize>,
}

/// A front-to-back walk of one ray through a tree: the children of a partial node are tried in the order
/// the ray crosses them (child code XOR the signs of the direction), each child's slab parameters taken
/// from its parent's and the parent's middle planes, so that a node costs `K` divisions however many
/// children are tried.
struct Caster<'r, const K: usize, T> {
    tree: &'r T,
    ray: &'r RayCast<K>,
    /// Axes along which the ray moves down: their child bit is flipped in the ray's order, and a slab's
    /// entry is open (the upper face is not in the cell), its exit closed.
    down: usize,
    /// Axes along which the ray does not move.
    still: usize,
}

impl<const K: usize, T: TreeStorage<K>> Caster<'_, K, T> {
    /// Where the ray is in the cell whose slab parameters are `slabs`, within `[0, max_t]`: from the
    /// parameter of its entry, through the face of an axis (none when the ray is in the cell at `t = 0`),
    /// to that of its exit; `None` if it never is in the cell. A slab of an axis moving up is entered
    /// through its closed lower face and left through its open upper face; moving down, the reverse; a
    /// bound at an equal parameter that is open wins over a closed one, so that a cell the ray only
    /// touches at its open faces is not met.
    #[inline(always)]
    fn entry(&self, slabs: &Slabs<K>) -> Option<Entry> {
        // The interval [low, high] of the parameters in every slab and in [0, max_t]; an axis that does
        // not move has (−∞, ∞). A cell the ray misses is rejected on these two numbers.
        let (mut low, mut high) = (0.0f64, self.ray.max_t);
        for a in 0..K {
            if slabs.near[a] > low {
                low = slabs.near[a];
            }
            if slabs.far[a] < high {
                high = slabs.far[a];
            }
        }
        if low > high {
            return None;
        }
        // The bounds at `low` and `high`: open where an axis's open face gives them. The face entered is
        // the first axis giving `low` through an open face, else the first giving it at all (none when
        // `low` is 0 from a closed face: the ray starts in the cell).
        let (mut low_open, mut low_axis, mut high_open) = (false, None, false);
        for a in 0..K {
            let down = self.down >> a & 1 == 1;
            if slabs.near[a] == low && !low_open && (down || (low_axis.is_none() && low > 0.0)) {
                (low_open, low_axis) = (down, Some(a));
            }
            high_open |= slabs.far[a] == high && !down && self.still >> a & 1 == 0;
        }
        let met = low < high || (!low_open && !high_open);
        met.then_some(Entry {
            t: low,
            exit: high,
            axis: low_axis,
        })
    }

    /// The hit in the full leaf `cell`, entered at `t` through a face of `axis`.
    fn hit(&self, cell: &Cell<K>, t: f64, axis: Option<usize>) -> RayHit<K> {
        RayHit {
            voxel: self.ray.voxel_in(cell, t, axis),
            t,
            face: axis.map(|axis| Face {
                axis,
                sign: if self.down >> axis & 1 == 1 { 1 } else { -1 },
            }),
        }
    }

    /// The first full voxel the ray enters in the partial node `index` at `depth`, whose cell is `cell`,
    /// slab parameters `slabs` and parameters in the cell `within` (entry and exit).
    fn partial(
        &mut self,
        depth: usize,
        index: usize,
        cell: &Cell<K>,
        slabs: &Slabs<K>,
        within: (f64, f64),
    ) -> Result<Option<RayHit<K>>, T::Error> {
        let first = self.tree.first_child(depth, index)?;
        let codes = self.tree.block_codes(depth + 1, first)?;
        let half = (cell.side() / 2) as f64;
        let (o, d) = (self.ray.origin, self.ray.direction);
        let mut middle = [0.0; K];
        let mut fixed = 0usize;
        for a in 0..K {
            let plane = f64::from(cell.origin[a]) + half;
            if self.still >> a & 1 == 1 {
                fixed |= usize::from(o[a] >= plane) << a;
            } else {
                middle[a] = (plane - o[a]) / d[a];
            }
        }
        // The children worth trying, by their place `order` in the ray's order (the child code XOR the
        // axes moving down): not empty, on the ray's side of the still axes' middle planes, and with
        // room between the middle planes crossed before them and those crossed after, within the
        // parent's parameters. Every child the ray meets is one; ties make a few more, which the exact
        // test below rejects.
        let mut candidates = 0u32;
        let mut bounds = [(0.0f64, 0.0f64); 16];
        for (order, bound) in bounds.iter_mut().enumerate().take(1 << K) {
            let (mut low, mut high) = within;
            for (a, &m) in middle.iter().enumerate() {
                if self.still >> a & 1 == 0 {
                    if order >> a & 1 == 1 {
                        low = if m > low { m } else { low };
                    } else {
                        high = if m < high { m } else { high };
                    }
                }
            }
            *bound = (low, high);
            let code = order ^ self.down;
            let filled = NodeState::from_bits(codes >> (2 * code)) != NodeState::Empty;
            let aside = (order ^ fixed) & self.still != 0;
            candidates |= u32::from(low <= high && filled && !aside) << order;
        }
        while candidates != 0 {
            let order = candidates.trailing_zeros() as usize;
            candidates &= candidates - 1;
            let mut child = *slabs;
            for (a, &m) in middle.iter().enumerate() {
                if self.still >> a & 1 == 0 {
                    if order >> a & 1 == 1 {
                        child.near[a] = m;
                    } else {
                        child.far[a] = m;
                    }
                }
            }
            let code = order ^ self.down;
            let cell = cell.child(code);
            // A full child gets the exact test, which also gives the face entered. A partial child with
            // room between its entry and exit is met; where they are equal, the exact test decides. Its
            // bounds are those of `bounds`: maxima and minima of the same parameters.
            if NodeState::from_bits(codes >> (2 * code)) == NodeState::Full {
                if let Some(entry) = self.entry(&child) {
                    return Ok(Some(self.hit(&cell, entry.t, entry.axis)));
                }
                continue;
            }
            let (low, high) = bounds[order];
            if low == high && self.entry(&child).is_none() {
                continue;
            }
            if let Some(hit) = self.partial(depth + 1, first + code, &cell, &child, (low, high))? {
                return Ok(Some(hit));
            }
        }
        Ok(None)
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
    let (o, d) = (ray.origin, ray.direction);
    let down = (0..K).fold(0, |m, a| m | usize::from(d[a] < 0.0) << a);
    let still = (0..K).fold(0, |m, a| m | usize::from(d[a] == 0.0) << a);
    let root = tree.universe().root();
    let side = root.side() as f64;
    let mut slabs = Slabs {
        near: [f64::NEG_INFINITY; K],
        far: [f64::INFINITY; K],
    };
    for a in 0..K {
        let (lower, upper) = ((0.0 - o[a]) / d[a], (side - o[a]) / d[a]);
        if d[a] > 0.0 {
            (slabs.near[a], slabs.far[a]) = (lower, upper);
        } else if d[a] < 0.0 {
            (slabs.near[a], slabs.far[a]) = (upper, lower);
        } else if !(0.0 <= o[a] && o[a] < side) {
            return Ok(None);
        }
    }
    let mut caster = Caster {
        tree,
        ray,
        down,
        still,
    };
    let state = tree.root_state()?;
    if state == NodeState::Empty {
        return Ok(None);
    }
    let Some(entry) = caster.entry(&slabs) else {
        return Ok(None);
    };
    if state == NodeState::Full {
        return Ok(Some(caster.hit(&root, entry.t, entry.axis)));
    }
    caster.partial(0, 0, &root, &slabs, (entry.t, entry.exit))
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
{
    rays.par_iter()
        .with_min_len(256)
        .map(|ray| cast_ray(tree, ray))
        .collect()
}
