//! Scaling (§6 "Scaling", claim M4): by powers of two by adding or removing levels at the root (exact,
//! touching only the top of the tree), and by other rational factors with overlays. Each reads any
//! [`TreeStorage`] and writes through any [`LevelSink`] (the `*_into` forms).

use super::output::{copy_into, Memory};
use super::overlay::{resample_into, resample_values, Preimage};
use super::OpsError;
use crate::space::{max_level, Cell, Universe};
use crate::tree::cursor::Walk;
use crate::tree::locate::locate;
use crate::tree::sink::{copy_subtree_to, LevelSink};
use crate::tree::storage::TreeStorage;
use crate::tree::valued::{
    try_walk_values, ValueAssembler, ValueNode, ValueState, ValueStorage, ValueVisitor,
};
use crate::tree::{KTree, NodeState};
use crate::value::Value;

fn check_path<const K: usize>(path: &[usize], level: u32) -> Result<(), OpsError> {
    if path.len() > level as usize || path.iter().any(|&c| c >= 1 << K) {
        return Err(OpsError::BadPath {
            path: path.to_vec(),
            k: K,
            level,
            fanout: 1 << K,
        });
    }
    Ok(())
}

/// The universe of level `level` for the result of [`grow`], or why there is none.
fn grown<const K: usize>(level: u32, path: &[usize]) -> Result<Universe<K>, OpsError> {
    let level = level + path.len() as u32;
    let too_large = || OpsError::LevelTooLarge {
        k: K,
        level,
        max: max_level(K),
    };
    if level > max_level(K) {
        return Err(too_large());
    }
    check_path::<K>(path, level)?;
    Universe::<K>::new(level).map_err(|_| too_large())
}

/// Halves the object `path.len()` times by adding that many levels at the root: the result lives in a
/// universe of level `L + n` and the old universe becomes the cell reached from the new root by the child
/// codes `path` (Meagher: "the new root points to one branch node, the old root, and 2^N − 1 empty terminal
/// nodes"). Voxels keep their size, so relative to the new universe the object is scaled by `2^−n`. The
/// old levels are reused unchanged: cost `O(n·2^K)` plus one copy of the tree.
///
/// ```
/// use ktree::{KTree, ops::grow};
/// let a = KTree::<2>::full(1).unwrap();
/// let g = grow(&a, &[3]).unwrap(); // into the upper-right quadrant
/// assert_eq!(g.level(), 2);
/// assert!(g.contains([3, 3]) && !g.contains([0, 0]));
/// ```
///
/// # Errors
/// [`OpsError::BadPath`] for a child code `≥ 2^K`; [`OpsError::LevelTooLarge`] beyond [`max_level`];
/// [`OpsError::Storage`] if a read of `tree` fails.
pub fn grow<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    path: &[usize],
) -> Result<KTree<K>, OpsError> {
    let universe = grown::<K>(tree.level(), path)?;
    grow_checked::<K, _, _, T::Error>(tree, path, Memory::new(universe)).map_err(OpsError::storage)
}

/// [`grow`] written to `sink`, a sink for a tree of level `L + path.len()`.
///
/// # Errors
/// As [`grow`], and the sink's write error.
pub fn grow_into<const K: usize, T, S, E>(tree: &T, path: &[usize], sink: S) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<OpsError> + From<T::Error> + From<S::Error>,
{
    grown::<K>(tree.level(), path)?;
    grow_checked(tree, path, sink)
}

/// [`grow_into`] for a path already checked.
fn grow_checked<const K: usize, T, S, E>(
    tree: &T,
    path: &[usize],
    mut sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    let n = path.len();
    if n == 0 {
        return copy_into(tree, sink);
    }
    let root = tree.root_state()?;
    if root == NodeState::Empty {
        return Ok(sink.finish(NodeState::Empty)?);
    }
    let mut kids = [NodeState::Empty; 16];
    for (d, &code) in path.iter().enumerate() {
        kids[..1 << K].fill(NodeState::Empty);
        kids[code] = if d + 1 < n { NodeState::Partial } else { root };
        sink.push_block(d + 1, &kids[..1 << K])?;
    }
    // The old root is the only partial node at depth n, so every old level keeps its indices.
    if root == NodeState::Partial {
        copy_subtree_to::<K, _, _, E>(&mut sink, tree, 0, 0, n, false)?;
    }
    Ok(sink.finish(NodeState::Partial)?)
}

/// Doubles the object `path.len()` times by removing levels at the root: the cell reached by the child
/// codes `path` becomes the whole universe (of level `L − n`). Everything outside that cell is dropped.
/// Cost: linear in the nodes of the kept subtree.
///
/// ```
/// use ktree::{KTree, ops::{grow, zoom}};
/// let a = KTree::<3>::from_dense(1, &[true, false, false, true, false, true, true, false]).unwrap();
/// assert_eq!(zoom(&grow(&a, &[5, 2]).unwrap(), &[5, 2]).unwrap(), a);
/// ```
///
/// # Errors
/// [`OpsError::BadPath`] for a code `≥ 2^K` or a path longer than the level; [`OpsError::Storage`] if a
/// read of `tree` fails.
pub fn zoom<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    path: &[usize],
) -> Result<KTree<K>, OpsError> {
    let universe = zoomed::<K>(tree.level(), path)?;
    zoom_checked::<K, _, _, T::Error>(tree, path, Memory::new(universe)).map_err(OpsError::storage)
}

/// [`zoom`] written to `sink`, a sink for a tree of level `L − path.len()`.
///
/// # Errors
/// As [`zoom`], and the sink's write error.
pub fn zoom_into<const K: usize, T, S, E>(tree: &T, path: &[usize], sink: S) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<OpsError> + From<T::Error> + From<S::Error>,
{
    zoomed::<K>(tree.level(), path)?;
    zoom_checked(tree, path, sink)
}

/// The universe of the result of [`zoom`], or why the path is refused.
fn zoomed<const K: usize>(level: u32, path: &[usize]) -> Result<Universe<K>, OpsError> {
    check_path::<K>(path, level)?;
    Ok(Universe::<K>::new(level - path.len() as u32).expect("a smaller level is valid"))
}

/// [`zoom_into`] for a path already checked.
fn zoom_checked<const K: usize, T, S, E>(
    tree: &T,
    path: &[usize],
    mut sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    // Descend to the path's cell.
    let target = path
        .iter()
        .fold(tree.universe().root(), |c, &code| c.child(code));
    let node = locate(tree, tree.root()?, &target)?;
    if node.state != NodeState::Partial {
        return Ok(sink.finish(node.state)?);
    }
    // Copy the subtree, its root becoming the root.
    copy_subtree_to::<K, _, _, E>(
        &mut sink,
        tree,
        node.cell.level as usize,
        node.index,
        0,
        false,
    )?;
    Ok(sink.finish(NodeState::Partial)?)
}

/// [`grow`] of a tree with values: the old universe becomes the cell of the new one reached by `path`,
/// each voxel keeping its value. The old nodes are copied unchanged, `n` levels deeper.
///
/// ```
/// use ktree::{KTree, ops::{grow_values, zoom_values}};
/// let a = KTree::<2, u8>::from_dense_values(1, &[Some(1), None, Some(2), Some(2)]).unwrap();
/// let g = grow_values(&a, &[3]).unwrap(); // into the upper-right quadrant
/// assert_eq!((g.level(), g.value_at([2, 2]), g.value_at([3, 3])), (2, Some(1), Some(2)));
/// assert_eq!(zoom_values(&g, &[3]).unwrap(), a);
/// ```
///
/// # Errors
/// As [`grow`].
pub fn grow_values<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    path: &[usize],
) -> Result<KTree<K, T::Value>, OpsError> {
    let universe = grown::<K>(tree.level(), path)?;
    let mut out = assembler::<K, T::Value>(universe)?;
    let root = tree.root().map_err(OpsError::storage)?;
    if path.is_empty() || root.state == ValueState::Empty {
        // Nothing moves, or nothing to place: the whole universe is the old root's subtree or empty.
        if path.is_empty() {
            copy_values_below(tree, &[], 0, &mut out)?;
        } else {
            out.push(0, ValueState::Empty);
        }
        return Ok(out.finish());
    }
    // The new levels: one node with children a level down to the old root, its siblings empty.
    fn place<const K: usize, T: ValueStorage<K>>(
        tree: &T,
        path: &[usize],
        depth: usize,
        out: &mut ValueAssembler<K, T::Value>,
    ) -> Result<(), OpsError> {
        out.push(depth, ValueState::Partial);
        for code in 0..1 << K {
            match path.get(depth) {
                Some(&c) if c == code && depth + 1 < path.len() => {
                    place(tree, path, depth + 1, out)?
                }
                Some(&c) if c == code => copy_values_below(tree, &[], depth + 1, out)?,
                _ => out.push(depth + 1, ValueState::Empty),
            }
        }
        Ok(())
    }
    place(tree, path, 0, &mut out)?;
    Ok(out.finish())
}

/// [`zoom`] of a tree with values: the cell reached by `path` becomes the universe, each voxel keeping its
/// value; everything outside the cell is dropped. See [`grow_values`].
///
/// # Errors
/// As [`zoom`].
pub fn zoom_values<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    path: &[usize],
) -> Result<KTree<K, T::Value>, OpsError> {
    let universe = zoomed::<K>(tree.level(), path)?;
    let mut out = assembler::<K, T::Value>(universe)?;
    copy_values_below(tree, path, 0, &mut out)?;
    Ok(out.finish())
}

/// An empty assembler for a tree of `universe` (a level [`grown`] or [`zoomed`] checked).
fn assembler<const K: usize, V: Value>(
    universe: Universe<K>,
) -> Result<ValueAssembler<K, V>, OpsError> {
    let level = universe.level();
    ValueAssembler::new(level).map_err(|_| OpsError::LevelTooLarge {
        k: K,
        level,
        max: max_level(K),
    })
}

/// Appends to `out`, depth first, the subtree of `tree` at the cell reached by `path` (or the leaf
/// above it that covers it), its root at depth `to`.
fn copy_values_below<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    path: &[usize],
    to: usize,
    out: &mut ValueAssembler<K, T::Value>,
) -> Result<(), OpsError> {
    struct Copy<'a, const K: usize, V> {
        /// The cell whose subtree is copied.
        target: Cell<K>,
        to: usize,
        out: &'a mut ValueAssembler<K, V>,
    }
    impl<const K: usize, V: Value> ValueVisitor<K, V> for Copy<'_, K, V> {
        fn visit(&mut self, node: &ValueNode<K, V>) -> Walk {
            let (depth, n) = (node.cell.level(), self.target.level());
            if depth <= n && !node.cell.contains(self.target.origin()) {
                return Walk::Skip; // beside the path to the cell
            }
            if depth < n {
                // Above the cell: a leaf covers the whole cell.
                if !node.state.has_children() {
                    self.out.push(self.to, node.state);
                }
            } else {
                self.out.push((depth - n) as usize + self.to, node.state);
            }
            Walk::Descend
        }
    }
    let target = path
        .iter()
        .fold(tree.universe().root(), |c, &code| c.child(code));
    let mut copy = Copy { target, to, out };
    try_walk_values(tree, &mut copy).map_err(OpsError::storage)?;
    Ok(())
}

/// The preimage of a uniform scaling by `num / den` about the universe's origin corner.
struct Ratio<const K: usize> {
    num: i64,
    den: i64,
}

impl<const K: usize> Ratio<K> {
    /// The factor `num / den`.
    fn new(num: u32, den: u32) -> Result<Self, OpsError> {
        if num == 0 || den == 0 || num > 1 << 20 || den > 1 << 20 {
            return Err(OpsError::BadScale { num, den });
        }
        Ok(Self {
            num: num.into(),
            den: den.into(),
        })
    }

    /// Source voxel of target coordinate `q`: the centre `q + ½` divided by the factor, floored:
    /// `floor((2q + 1)·den / (2·num))` — integer arithmetic.
    fn back(&self, q: i64) -> i64 {
        ((2 * q + 1) * self.den).div_euclid(2 * self.num)
    }
}

impl<const K: usize> Preimage<K> for Ratio<K> {
    fn voxel(&self, q: [u32; K]) -> [i64; K] {
        q.map(|c| self.back(i64::from(c)))
    }

    fn cell_box(&self, origin: [u32; K], side: u64) -> [(i64, i64); K] {
        origin.map(|o| {
            let o = i64::from(o);
            (self.back(o), self.back(o + side as i64 - 1))
        })
    }
}

/// Scales the object by the rational factor `num / den` about the universe's origin corner, in the same
/// universe, with overlays: target voxel `q` is full iff the source voxel containing `(q + ½)·den/num` is.
/// Integer-only. Parts scaled beyond the universe are cut off.
///
/// ```
/// use ktree::{KTree, ops::scale};
/// let a = KTree::<1>::from_dense(3, &[true, true, false, true, false, false, false, false]).unwrap();
/// let s = scale(&a, 2, 1).unwrap();
/// assert_eq!(s.to_dense().unwrap(), [true, true, true, true, false, false, true, true]);
/// ```
///
/// # Errors
/// [`OpsError::BadScale`] unless `num` and `den` are both positive and at most 2^20;
/// [`OpsError::Storage`] if a read of `tree` fails.
pub fn scale<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    num: u32,
    den: u32,
) -> Result<KTree<K>, OpsError> {
    let ratio = Ratio::<K>::new(num, den)?;
    scale_checked::<K, _, _, T::Error>(tree, ratio, Memory::new(tree.universe()))
        .map_err(OpsError::storage)
}

/// [`scale`] of a valued tree: target voxel `q` takes the value of the source voxel containing
/// `(q + ½)·den/num`.
///
/// ```
/// use ktree::{KTree, ops::scale_values};
/// let a = KTree::<1, u8>::from_dense_values(2, &[Some(3), Some(5), None, None]).unwrap();
/// assert_eq!(scale_values(&a, 2, 1).unwrap().to_dense_values().unwrap(), [Some(3), Some(3), Some(5), Some(5)]);
/// ```
///
/// # Errors
/// As [`scale`].
pub fn scale_values<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    num: u32,
    den: u32,
) -> Result<KTree<K, T::Value>, OpsError> {
    let ratio = Ratio::<K>::new(num, den)?;
    resample_values(tree, &ratio).map_err(OpsError::storage)
}

/// [`scale`] written to `sink`.
///
/// # Errors
/// As [`scale`], and the sink's write error.
pub fn scale_into<const K: usize, T, S, E>(
    tree: &T,
    num: u32,
    den: u32,
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<OpsError> + From<T::Error> + From<S::Error>,
{
    scale_checked(tree, Ratio::<K>::new(num, den)?, sink)
}

/// [`scale_into`] for a checked factor.
fn scale_checked<const K: usize, T, S, E>(
    tree: &T,
    ratio: Ratio<K>,
    sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    if ratio.num == ratio.den {
        return copy_into(tree, sink);
    }
    resample_into(tree, &ratio, sink)
}
