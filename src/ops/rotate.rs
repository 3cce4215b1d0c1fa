//! Rotations by quarter turns and reflections of the whole universe — the hyperoctahedral group of
//! `K!·2^K` elements — by reordering children (Meagher §6 "Rotation", claim M5). Integer-only; the cost is
//! one visit per node and the output has exactly the input's node counts per level.
//!
//! An element is an [`AxisMap`]: output axis `i` takes input axis `perm[i]`, mirrored if `flip[i]`. On
//! voxels: `p'[i] = p[perm[i]]`, or `U − 1 − p[perm[i]]` when flipped — a rotation or reflection about the
//! universe's centre. On a tree it is a fixed permutation of the `2^K` child codes applied at every node.

use super::output::Memory;
use super::values::Failure;
use super::OpsError;
use crate::tree::sink::LevelSink;
use crate::tree::storage::TreeStorage;
use crate::tree::top_down::{build_top_down, Decision, InputNode};
use crate::tree::valued::{ValueState, ValueStorage};
use crate::tree::{KTree, NodeState};

/// An element of the hyperoctahedral group in `K` dimensions: a signed permutation of the axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AxisMap<const K: usize> {
    perm: [usize; K],
    flip: [bool; K],
}

impl<const K: usize> AxisMap<K> {
    /// The identity.
    pub fn identity() -> Self {
        Self {
            perm: std::array::from_fn(|i| i),
            flip: [false; K],
        }
    }

    /// The map with output axis `i` taken from input axis `perm[i]`, mirrored when `flip[i]`.
    ///
    /// # Errors
    /// [`OpsError::NotAPermutation`] if `perm` is not a permutation of `0 … K−1`.
    pub fn new(perm: [usize; K], flip: [bool; K]) -> Result<Self, OpsError> {
        let mut seen = [false; K];
        for &p in &perm {
            if p >= K || seen[p] {
                return Err(OpsError::NotAPermutation {
                    perm: perm.to_vec(),
                });
            }
            seen[p] = true;
        }
        Ok(Self { perm, flip })
    }

    /// The reflection across the mid-plane perpendicular to `axis`.
    ///
    /// # Errors
    /// [`OpsError::BadAxis`] if `axis ≥ K`.
    pub fn reflection(axis: usize) -> Result<Self, OpsError> {
        if axis >= K {
            return Err(OpsError::BadAxis { axis, k: K });
        }
        let mut m = Self::identity();
        m.flip[axis] = true;
        Ok(m)
    }

    /// The quarter turn about the universe's centre in the plane of axes `from` and `to`, turning the
    /// positive `from` direction into the positive `to` direction (for `from = 0, to = 1` in 3-D: +90° about z).
    ///
    /// # Errors
    /// [`OpsError::BadAxisPair`] if an axis is `≥ K` or `from == to`.
    pub fn quarter_turn(from: usize, to: usize) -> Result<Self, OpsError> {
        if from >= K || to >= K || from == to {
            return Err(OpsError::BadAxisPair { from, to, k: K });
        }
        // (x_from, x_to) → (−x_to, x_from) about the centre: out[to] = in[from], out[from] = U−1−in[to].
        let mut m = Self::identity();
        m.perm[to] = from;
        m.perm[from] = to;
        m.flip[from] = true;
        Ok(m)
    }

    /// Output axis `i` takes input axis `perm()[i]`.
    pub fn perm(&self) -> [usize; K] {
        self.perm
    }

    /// Whether output axis `i` is mirrored.
    pub fn flip(&self) -> [bool; K] {
        self.flip
    }

    /// Applies the map to a voxel of a universe of side `side`.
    pub fn map_point(&self, p: [u32; K], side: u32) -> [u32; K] {
        std::array::from_fn(|i| {
            let v = p[self.perm[i]];
            if self.flip[i] {
                side - 1 - v
            } else {
                v
            }
        })
    }

    /// `self ∘ other`: first `other`, then `self`.
    pub fn compose(&self, other: &Self) -> Self {
        // out[i] = f_i(mid[perm[i]]), mid[j] = g_j(in[other.perm[j]]).
        Self {
            perm: std::array::from_fn(|i| other.perm[self.perm[i]]),
            flip: std::array::from_fn(|i| self.flip[i] != other.flip[self.perm[i]]),
        }
    }

    /// The inverse element.
    pub fn inverse(&self) -> Self {
        let mut perm = [0; K];
        let mut flip = [false; K];
        for i in 0..K {
            perm[self.perm[i]] = i;
            flip[self.perm[i]] = self.flip[i];
        }
        Self { perm, flip }
    }

    /// Whether the map is a proper rotation (determinant +1) rather than a reflection.
    pub fn is_rotation(&self) -> bool {
        let mut inversions = 0;
        for i in 0..K {
            for j in i + 1..K {
                if self.perm[i] > self.perm[j] {
                    inversions += 1;
                }
            }
        }
        let flips = self.flip.iter().filter(|&&f| f).count();
        (inversions + flips) % 2 == 0
    }

    /// All `K!·2^K` elements of the group.
    pub fn all() -> Vec<Self> {
        let mut perms = Vec::new();
        permutations::<K>(&mut [0; K], 0, &mut [false; K], &mut perms);
        let mut out = Vec::new();
        for perm in perms {
            for bits in 0..1usize << K {
                out.push(Self {
                    perm,
                    flip: std::array::from_fn(|i| bits >> i & 1 == 1),
                });
            }
        }
        out
    }

    /// For each output child code, the source child code it comes from.
    fn child_table(&self) -> [usize; 16] {
        let mut table = [0usize; 16];
        for (out_code, src) in table.iter_mut().enumerate().take(1 << K) {
            let mut code = 0;
            for i in 0..K {
                let bit = (out_code >> i & 1 == 1) != self.flip[i];
                if bit {
                    code |= 1 << self.perm[i];
                }
            }
            *src = code;
        }
        table
    }
}

fn permutations<const K: usize>(
    cur: &mut [usize; K],
    at: usize,
    used: &mut [bool; K],
    out: &mut Vec<[usize; K]>,
) {
    if at == K {
        out.push(*cur);
        return;
    }
    for v in 0..K {
        if !used[v] {
            used[v] = true;
            cur[at] = v;
            permutations(cur, at + 1, used, out);
            used[v] = false;
        }
    }
}

/// Rotates or reflects the whole object about the universe's centre by an element of the hyperoctahedral
/// group, by reordering children. Linear in the nodes; the output has the input's counts per level.
///
/// ```
/// use ktree::{KTree, ops::{rotate_axes, AxisMap}};
/// // 2×2 quadtree with the voxel (1, 0) set; a quarter turn x → y moves it to (1, 1).
/// let a = KTree::<2>::from_dense(1, &[false, true, false, false]).unwrap();
/// let r = rotate_axes(&a, &AxisMap::quarter_turn(0, 1).unwrap()).unwrap();
/// assert!(r.contains([1, 1]));
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn rotate_axes<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    map: &AxisMap<K>,
) -> Result<KTree<K>, T::Error> {
    rotate_axes_into(tree, map, Memory::new(tree.universe()))
}

/// [`rotate_axes`] of a valued tree: each voxel keeps its value. The output has the input's node counts
/// per level.
///
/// ```
/// use ktree::{KTree, ops::{rotate_values, AxisMap}};
/// // Voxel (1, 0) holds 7; a quarter turn x → y moves it to (1, 1).
/// let a = KTree::<2, u8>::from_dense_values(1, &[Some(2), Some(7), None, None]).unwrap();
/// let r = rotate_values(&a, &AxisMap::quarter_turn(0, 1).unwrap()).unwrap();
/// assert_eq!(r.to_dense_values().unwrap(), [None, Some(2), None, Some(7)]);
/// ```
///
/// # Errors
/// The storage's read error (none for a [`KTree`]).
pub fn rotate_values<const K: usize, T: ValueStorage<K>>(
    tree: &T,
    map: &AxisMap<K>,
) -> Result<KTree<K, T::Value>, T::Error> {
    let table = map.child_table();
    build_top_down::<K, T::Value, _, Failure<T::Error>>(
        tree.level(),
        InputNode::root(tree)?,
        |_, node| {
            Ok(match node.state {
                ValueState::Empty => Decision::Leaf(None),
                ValueState::Full(v) => Decision::Leaf(Some(v)),
                ValueState::Partial | ValueState::Mixed => Decision::Split,
            })
        },
        |node, code| node.child(tree, table[code]).map_err(Failure::Read),
    )
    .map_err(Failure::into_read)
}

/// [`rotate_axes`] written to `sink`. The output is walked depth first in its own child order, so its
/// blocks reach each level in level order and the memory held is a stack of `2^K` nodes per level.
///
/// # Errors
/// The first read error of `tree` or write error of `sink`.
pub fn rotate_axes_into<const K: usize, T, S, E>(
    tree: &T,
    map: &AxisMap<K>,
    mut sink: S,
) -> Result<S::Output, E>
where
    T: TreeStorage<K>,
    S: LevelSink,
    E: From<T::Error> + From<S::Error>,
{
    let table = map.child_table();
    let fanout = 1usize << K;
    let root = tree.root_state()?;
    // The source nodes `(depth, index)` of output partial nodes still to expand, the next on top. Each
    // one's children are an aligned block of `2^K` states, permuted by the table into one word.
    let mut stack: Vec<(usize, usize)> = Vec::with_capacity(fanout * tree.depth_count());
    if root == NodeState::Partial {
        stack.push((0, 0));
    }
    while let Some((depth, index)) = stack.pop() {
        let first = tree.first_child(depth, index)?;
        let block = tree.block_codes(depth + 1, first)?;
        // The permuted block in one word; bit `code` of `partial` set for each partial output child.
        let (mut word, mut partial) = (0u64, 0u32);
        for (code, &src) in table[..fanout].iter().enumerate() {
            let state = (block >> (2 * src) & 3).min(NodeState::Partial as u32);
            word |= u64::from(state) << (2 * code);
            partial |= (state >> 1) << code;
        }
        sink.append(depth + 1, word, fanout)?;
        // The partial children, last to first in output order: the first comes off the stack first.
        while partial != 0 {
            let code = (u32::BITS - 1 - partial.leading_zeros()) as usize;
            stack.push((depth + 1, first + table[code]));
            partial &= !(1 << code);
        }
    }
    Ok(sink.finish(root)?)
}
