//! Scaling (§6 "Scaling", claim M4): by powers of two by adding or removing levels at the root (exact,
//! touching only the top of the tree), and by other rational factors with overlays.

use super::emit::LevelWriter;
use super::overlay::{resample, Preimage};
use super::OpsError;
use crate::space::{max_level, Universe};
use crate::tree::locate::locate;
use crate::tree::storage::infallible;
use crate::tree::{KTree, NodeState};

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
/// [`OpsError::BadPath`] for a child code `≥ 2^K`; [`OpsError::LevelTooLarge`] beyond [`max_level`].
pub fn grow<const K: usize>(tree: &KTree<K>, path: &[usize]) -> Result<KTree<K>, OpsError> {
    let n = path.len();
    let level = tree.level() + n as u32;
    if level > max_level(K) {
        return Err(OpsError::LevelTooLarge {
            k: K,
            level,
            max: max_level(K),
        });
    }
    check_path::<K>(path, level)?;
    let universe = Universe::<K>::new(level).map_err(|_| OpsError::LevelTooLarge {
        k: K,
        level,
        max: max_level(K),
    })?;
    if n == 0 {
        return Ok(tree.clone());
    }
    if tree.root_state() == NodeState::Empty {
        return Ok(KTree::empty(level).expect("level checked"));
    }
    let mut out = LevelWriter::new();
    out.push(0, NodeState::Partial);
    for (d, &code) in path.iter().enumerate() {
        for c in 0..1usize << K {
            out.push(
                d + 1,
                if c != code {
                    NodeState::Empty
                } else if d + 1 < n {
                    NodeState::Partial
                } else {
                    tree.root_state()
                },
            );
        }
    }
    // The old root is the only partial node at depth n, so every old level keeps its indices.
    out.copy_subtree(tree, 0, 0, n, false);
    Ok(KTree::from_levels(universe, out.finish()))
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
/// [`OpsError::BadPath`] for a code `≥ 2^K` or a path longer than the level.
pub fn zoom<const K: usize>(tree: &KTree<K>, path: &[usize]) -> Result<KTree<K>, OpsError> {
    check_path::<K>(path, tree.level())?;
    let level = tree.level() - path.len() as u32;
    let universe = Universe::<K>::new(level).expect("a smaller level is valid");
    // Descend to the path's cell.
    let target = path
        .iter()
        .fold(tree.universe().root(), |c, &code| c.child(code));
    let node = infallible(locate(tree, tree.root(), &target));
    if node.state != NodeState::Partial {
        return Ok(uniform(level, node.state));
    }
    // Copy the subtree, its root becoming the root.
    let mut out = LevelWriter::new();
    out.push(0, NodeState::Partial);
    out.copy_subtree(tree, node.cell.level as usize, node.index, 0, false);
    Ok(KTree::from_levels(universe, out.finish()))
}

fn uniform<const K: usize>(level: u32, state: NodeState) -> KTree<K> {
    if state == NodeState::Full {
        KTree::full(level).expect("valid level")
    } else {
        KTree::empty(level).expect("valid level")
    }
}

/// The preimage of a uniform scaling by `num / den` about the universe's origin corner.
struct Ratio<const K: usize> {
    num: i64,
    den: i64,
}

impl<const K: usize> Ratio<K> {
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
/// [`OpsError::BadScale`] unless `num` and `den` are both positive and at most 2^20.
pub fn scale<const K: usize>(tree: &KTree<K>, num: u32, den: u32) -> Result<KTree<K>, OpsError> {
    if num == 0 || den == 0 || num > 1 << 20 || den > 1 << 20 {
        return Err(OpsError::BadScale { num, den });
    }
    if num == den {
        return Ok(tree.clone());
    }
    Ok(resample(
        tree,
        &Ratio::<K> {
            num: num.into(),
            den: den.into(),
        },
    ))
}
