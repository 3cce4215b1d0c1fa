//! The overlay engine shared by scaling by other factors than powers of two and arbitrary affine maps
//! (Meagher §6: "overlays"; translation has its own fixed `2^K`-obel overlay in [`super::translate`]).
//!
//! The output tree is generated top-down. For each target cell the engine knows the source voxels the
//! cell's voxel centres map back to — a box given by the map ([`Preimage::cell_box`], conservative: it may
//! be larger, never smaller) — and carries down from the parent the *overlay*: the few source nodes that
//! meet the box, refined until they are no larger than the box. If every overlay obel meeting the box is
//! empty (or outside the universe — Meagher's void) the target is empty; if all are full it is full;
//! otherwise the target is partial and its `2^K` children are decided the same way, each refining its
//! parent's overlay. At the voxel level the decision is exact: the voxel's centre is mapped back
//! ([`Preimage::voxel`]) and the source voxel containing it looked up. So the output equals the brute-force
//! resampling of every voxel centre, while the work follows the output's nodes, not its voxels.
//!
//! Children are decided before they are appended, so the output is reduced. The source is read through
//! any [`TreeStorage`] and the output written through any [`LevelSink`] ([`resample_into`]).
//!
//! ```
//! use ktree::ops::overlay::{resample, Preimage};
//! use ktree::KTree;
//! /// Target voxel q comes from source voxel q − 1 along the one axis: a shift by one.
//! struct ShiftOne;
//! impl Preimage<1> for ShiftOne {
//!     fn voxel(&self, q: [u32; 1]) -> [i64; 1] {
//!         [i64::from(q[0]) - 1]
//!     }
//!     fn cell_box(&self, origin: [u32; 1], side: u64) -> [(i64, i64); 1] {
//!         let lo = i64::from(origin[0]) - 1;
//!         [(lo, lo + side as i64 - 1)]
//!     }
//! }
//! let a = KTree::<1>::from_dense(2, &[true, true, false, false]).unwrap();
//! assert_eq!(resample(&a, &ShiftOne).unwrap().to_dense().unwrap(), [false, true, true, false]);
//! ```

use std::rc::Rc;

use super::output::{collapse, leaf, Memory};
use super::values::Failure;
use crate::space::Cell;
use crate::tree::locate::PointCursor;
use crate::tree::sink::LevelSink;
use crate::tree::storage::TreeStorage;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::{ValueState, ValueStorage};
use crate::tree::{KTree, NodeRef, NodeState};
use crate::value::Value;

/// How target voxels map back into the source universe.
pub trait Preimage<const K: usize> {
    /// The source voxel whose cell contains the preimage of the centre of target voxel `q` (coordinates
    /// may lie outside the source universe: those voxels are empty).
    fn voxel(&self, q: [u32; K]) -> [i64; K];

    /// Inclusive bounds `(lo, hi)` per axis of source voxels containing the preimages of all voxel centres
    /// of the target cell at `origin` with side `side`. May be conservative (larger).
    fn cell_box(&self, origin: [u32; K], side: u64) -> [(i64, i64); K];
}

/// A preimage computed incrementally down the tree: each target cell carries a context derived from its
/// parent's (e.g. the fixed-point image of its first voxel centre, updated by additions and shifts).
pub trait IncrementalPreimage<const K: usize> {
    /// What a target cell carries.
    type Ctx: Copy;
    /// The root cell's context.
    fn root(&self) -> Self::Ctx;
    /// The context of child `code` of a cell of side `2^log_side` with context `ctx`.
    fn child(&self, ctx: &Self::Ctx, code: usize, log_side: u32) -> Self::Ctx;
    /// As [`Preimage::voxel`], for the voxel whose context is `ctx`.
    fn voxel(&self, ctx: &Self::Ctx, q: [u32; K]) -> [i64; K];
    /// As [`Preimage::cell_box`], for the cell whose context is `ctx`.
    fn cell_box(&self, ctx: &Self::Ctx, origin: [u32; K], side: u64) -> [(i64, i64); K];
}

/// Any [`Preimage`] as an [`IncrementalPreimage`] with no context.
struct Stateless<'a, P>(&'a P);

impl<const K: usize, P: Preimage<K>> IncrementalPreimage<K> for Stateless<'_, P> {
    type Ctx = ();
    fn root(&self) {}
    fn child(&self, _: &(), _: usize, _: u32) {}
    fn voxel(&self, _: &(), q: [u32; K]) -> [i64; K] {
        self.0.voxel(q)
    }
    fn cell_box(&self, _: &(), origin: [u32; K], side: u64) -> [(i64, i64); K] {
        self.0.cell_box(origin, side)
    }
}

/// A source node of an overlay.
#[derive(Clone, Copy)]
struct Entry<const K: usize> {
    index: usize,
    cell: Cell<K>,
    state: NodeState,
}

struct Engine<'a, const K: usize, T, P, S> {
    src: &'a T,
    /// The source's root, whose identity the nodes handed to the point cursor carry.
    root: NodeRef<K>,
    map: &'a P,
    side: i64,
    out: S,
    overlay: Vec<Entry<K>>,
}

fn meets<const K: usize>(cell: &Cell<K>, bx: &[(i64, i64); K]) -> bool {
    let side = cell.side() as i64;
    (0..K).all(|i| {
        let o = i64::from(cell.origin[i]);
        o <= bx[i].1 && o + side > bx[i].0
    })
}

impl<const K: usize, T, P, S> Engine<'_, K, T, P, S>
where
    T: TreeStorage<K>,
    P: IncrementalPreimage<K>,
    S: LevelSink,
{
    /// Adds `e` (meeting `bx`) to the overlay, partial nodes refined to nodes no larger than `extent`;
    /// leaves set `seen` (`[empty, full]`); returns the number of partial nodes added.
    fn refine(
        &mut self,
        e: Entry<K>,
        bx: &[(i64, i64); K],
        extent: i64,
        seen: &mut [bool; 2],
    ) -> Result<usize, T::Error> {
        match e.state {
            NodeState::Empty => {
                seen[0] = true;
                self.overlay.push(e);
                Ok(0)
            }
            NodeState::Full => {
                seen[1] = true;
                self.overlay.push(e);
                Ok(0)
            }
            NodeState::Partial => {
                if (e.cell.side() as i64) <= extent {
                    self.overlay.push(e);
                    return Ok(1);
                }
                let mut partial = 0;
                let depth = e.cell.level as usize;
                let first = self.src.first_child(depth, e.index)?;
                let codes = self.src.block_codes(depth + 1, first)?;
                for c in 0..1usize << K {
                    let cell = e.cell.child(c);
                    if meets(&cell, bx) {
                        let child = Entry {
                            index: first + c,
                            cell,
                            state: NodeState::from_bits(codes >> (2 * c)),
                        };
                        partial += self.refine(child, bx, extent, seen)?;
                    }
                }
                Ok(partial)
            }
        }
    }

    /// Whether source voxel `p` is full, starting from the overlay entry (in `near`) that holds it — a
    /// few levels above the voxel — rather than from the root.
    fn lookup(&self, p: [i64; K], near: std::ops::Range<usize>) -> Result<bool, T::Error> {
        if p.iter().any(|&c| c < 0 || c >= self.side) {
            return Ok(false);
        }
        let p = p.map(|c| c as u32);
        let start = match near.map(|k| self.overlay[k]).find(|e| e.cell.contains(p)) {
            Some(e) if e.state != NodeState::Partial => return Ok(e.state == NodeState::Full),
            Some(e) => NodeRef {
                index: e.index,
                cell: e.cell,
                state: e.state,
                tree: self.root.tree,
            },
            None => self.root,
        };
        Ok(PointCursor::at(self.src, start)?.state(p)? == NodeState::Full)
    }

    /// Decides target cell `cell` given its parent's overlay `parent` (a range of `self.overlay`).
    fn node<E: From<T::Error> + From<S::Error>>(
        &mut self,
        cell: Cell<K>,
        ctx: P::Ctx,
        parent: std::ops::Range<usize>,
    ) -> Result<NodeState, E> {
        if cell.log_side == 0 {
            return Ok(leaf(
                self.lookup(self.map.voxel(&ctx, cell.origin), parent)?,
            ));
        }
        let mut bx = self.map.cell_box(&ctx, cell.origin, cell.side());
        let mut seen = [false; 2];
        for b in bx.iter_mut() {
            if b.0 < 0 || b.1 >= self.side {
                seen[0] = true; // part of the preimage is in the void
            }
            b.0 = b.0.max(0);
            b.1 = b.1.min(self.side - 1);
            if b.0 > b.1 {
                return Ok(NodeState::Empty);
            }
        }
        let extent = bx.iter().map(|b| b.1 - b.0 + 1).max().unwrap_or(1);
        let start = self.overlay.len();
        let mut partial = 0;
        for k in parent {
            let e = self.overlay[k];
            if meets(&e.cell, &bx) {
                partial += self.refine(e, &bx, extent, &mut seen)?;
            }
        }
        let end = self.overlay.len();
        if partial == 0 {
            match seen {
                [_, false] => return Ok(NodeState::Empty),
                [false, true] => return Ok(NodeState::Full),
                _ => {}
            }
        }
        let mut kids = [NodeState::Empty; 16];
        for (c, kid) in kids.iter_mut().enumerate().take(1 << K) {
            let child_ctx = self.map.child(&ctx, c, cell.log_side);
            *kid = self.node::<E>(cell.child(c), child_ctx, start..end)?;
        }
        self.overlay.truncate(start);
        let kids = &kids[..1 << K];
        Ok(match collapse(kids) {
            Some(s) => s,
            None => {
                self.out.push_block(cell.level as usize + 1, kids)?;
                NodeState::Partial
            }
        })
    }
}

/// Resamples `src` through `map` into a tree of the same universe: target voxel `q` is full iff the source
/// voxel `map.voxel(q)` is inside the universe and full. The output is reduced.
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn resample<const K: usize, T: TreeStorage<K>, P: Preimage<K>>(
    src: &T,
    map: &P,
) -> Result<KTree<K>, T::Error> {
    resample_into(src, map, Memory::new(src.universe()))
}

/// [`resample`] written to `sink`.
///
/// # Errors
/// The first read error of `src` or write error of `sink`.
pub fn resample_into<const K: usize, T, P, S, E>(src: &T, map: &P, sink: S) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    P: Preimage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    resample_incremental_into(src, &Stateless(map), sink)
}

/// Like [`resample`], for a map evaluated incrementally from cell to child.
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn resample_incremental<const K: usize, T: TreeStorage<K>, P: IncrementalPreimage<K>>(
    src: &T,
    map: &P,
) -> Result<KTree<K>, T::Error> {
    resample_incremental_into(src, map, Memory::new(src.universe()))
}

/// [`resample_incremental`] written to `sink`.
///
/// # Errors
/// The first read error of `src` or write error of `sink`.
pub fn resample_incremental_into<const K: usize, T, P, S, E>(
    src: &T,
    map: &P,
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    P: IncrementalPreimage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    let universe = src.universe();
    let root = src.root()?;
    let mut engine = Engine {
        src,
        root,
        map,
        side: universe.side() as i64,
        out: sink,
        overlay: vec![Entry {
            index: 0,
            cell: universe.root(),
            state: root.state,
        }],
    };
    let root_ctx = map.root();
    let state = engine.node::<E>(universe.root(), root_ctx, 0..1)?;
    Ok(engine.out.finish(state)?)
}

/// A source node of a valued overlay: its cell and where it stands in the source.
#[derive(Clone, Copy)]
struct ValueEntry<const K: usize, V> {
    cell: Cell<K>,
    node: InputNode<V>,
}

/// A target cell of a valued resampling: the source nodes meeting its preimage box (refined until no
/// larger than the box, as the binary engine's overlay) and what the cell is.
struct ValueOverlay<const K: usize, V> {
    cell: Cell<K>,
    entries: Vec<ValueEntry<K, V>>,
    decision: Decision<V>,
}

/// What the leaves of an overlay hold so far: nothing seen, one state (`None`: empty) or more than one.
enum Seen<V> {
    Nothing,
    One(Option<V>),
    Several,
}

impl<V: Value> Seen<V> {
    fn add(&mut self, value: Option<V>) {
        *self = match std::mem::replace(self, Seen::Several) {
            Seen::Nothing => Seen::One(value),
            Seen::One(v) if same(v, value) => Seen::One(v),
            _ => Seen::Several,
        }
    }
}

fn same<V: Value>(a: Option<V>, b: Option<V>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.same(b),
        _ => false,
    }
}

impl<const K: usize, V: Value> ValueOverlay<K, V> {
    /// The overlay of target `cell` from its parent's `entries` (for the root, the source's root).
    fn of<T: ValueStorage<K, Value = V>, P: Preimage<K>>(
        src: &T,
        map: &P,
        cell: Cell<K>,
        parent: &[ValueEntry<K, V>],
    ) -> Result<Self, T::Error> {
        let side = src.universe().side() as i64;
        let leaf = |decision| {
            Ok(Self {
                cell,
                entries: Vec::new(),
                decision,
            })
        };
        if cell.log_side == 0 {
            let p = map.voxel(cell.origin);
            if p.iter().any(|&c| c < 0 || c >= side) {
                return leaf(Decision::Leaf(None));
            }
            let p = p.map(|c| c as u32);
            let start = match parent.iter().find(|e| e.cell.contains(p)) {
                Some(e) => *e,
                None => ValueEntry {
                    cell: src.universe().root(),
                    node: InputNode::root(src)?,
                },
            };
            return leaf(Decision::Leaf(value_of(src, start, p)?));
        }
        let mut bx = map.cell_box(cell.origin, cell.side());
        let mut seen = Seen::Nothing;
        for b in bx.iter_mut() {
            if b.0 < 0 || b.1 >= side {
                seen.add(None); // part of the preimage is in the void
            }
            b.0 = b.0.max(0);
            b.1 = b.1.min(side - 1);
            if b.0 > b.1 {
                return leaf(Decision::Leaf(None));
            }
        }
        let extent = bx.iter().map(|b| b.1 - b.0 + 1).max().unwrap_or(1);
        let mut entries = Vec::new();
        let mut partial = false;
        let mut stack: Vec<ValueEntry<K, V>> = parent
            .iter()
            .filter(|e| meets(&e.cell, &bx))
            .copied()
            .collect();
        while let Some(e) = stack.pop() {
            match e.node.state {
                ValueState::Empty => seen.add(None),
                ValueState::Full(v) => seen.add(Some(v)),
                ValueState::Partial | ValueState::Mixed if e.cell.side() as i64 <= extent => {
                    partial = true;
                }
                ValueState::Partial | ValueState::Mixed => {
                    for code in 0..1usize << K {
                        let child = e.cell.child(code);
                        if meets(&child, &bx) {
                            stack.push(ValueEntry {
                                cell: child,
                                node: e.node.child(src, code)?,
                            });
                        }
                    }
                    continue;
                }
            }
            entries.push(e);
        }
        let decision = match seen {
            Seen::One(value) if !partial => Decision::Leaf(value),
            Seen::Nothing if !partial => Decision::Leaf(None),
            _ => Decision::Split,
        };
        Ok(Self {
            cell,
            entries,
            decision,
        })
    }
}

/// The value of source voxel `p`, looked up from `start`, a node whose cell holds it.
fn value_of<const K: usize, T: ValueStorage<K>>(
    src: &T,
    start: ValueEntry<K, T::Value>,
    p: [u32; K],
) -> Result<Option<T::Value>, T::Error> {
    let ValueEntry { mut cell, mut node } = start;
    while node.state.has_children() {
        let half = 1u32 << (cell.log_side - 1);
        let code = (0..K).fold(0, |code, a| {
            code | usize::from(p[a] - cell.origin[a] >= half) << a
        });
        node = node.child(src, code)?;
        cell = cell.child(code);
    }
    Ok(match node.state {
        ValueState::Full(v) => Some(v),
        _ => None,
    })
}

/// [`resample`] of a valued tree: target voxel `q` takes the value of source voxel `map.voxel(q)`
/// (empty outside the universe). A target cell whose preimage box meets source leaves of one value (or
/// only empty ones) is a leaf; the output is minimal.
///
/// ```
/// use ktree::ops::overlay::{resample_values, Preimage};
/// use ktree::KTree;
/// /// Target voxel q comes from source voxel q − 1 along the one axis: a shift by one.
/// struct ShiftOne;
/// impl Preimage<1> for ShiftOne {
///     fn voxel(&self, q: [u32; 1]) -> [i64; 1] {
///         [i64::from(q[0]) - 1]
///     }
///     fn cell_box(&self, origin: [u32; 1], side: u64) -> [(i64, i64); 1] {
///         let lo = i64::from(origin[0]) - 1;
///         [(lo, lo + side as i64 - 1)]
///     }
/// }
/// let a = KTree::<1, u8>::from_dense_values(2, &[Some(4), Some(7), None, None]).unwrap();
/// let shifted = resample_values(&a, &ShiftOne).unwrap();
/// assert_eq!(shifted.to_dense_values().unwrap(), [None, Some(4), Some(7), None]);
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn resample_values<const K: usize, T: ValueStorage<K>, P: Preimage<K>>(
    src: &T,
    map: &P,
) -> Result<KTree<K, T::Value>, T::Error> {
    let universe = src.universe();
    let root = ValueEntry {
        cell: universe.root(),
        node: InputNode::root(src)?,
    };
    let overlay = ValueOverlay::of(src, map, universe.root(), &[root])?;
    build_top_down::<K, T::Value, _, Failure<T::Error>>(
        universe.level(),
        Rc::new(overlay),
        |_, overlay| Ok(overlay.decision),
        |overlay, code| {
            let cell = overlay.cell.child(code);
            ValueOverlay::of(src, map, cell, &overlay.entries)
                .map(Rc::new)
                .map_err(Failure::Read)
        },
    )
    .map_err(Failure::into_read)
}
