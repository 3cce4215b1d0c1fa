//! A small universe's tree through a bitmap pyramid: the voxels set run by run (a run is a range of bits
//! of its column), each coarser level found by merging `2^K` cells with word-wide AND and OR, and the tree
//! written top down, level by level, reading the children of each partial node from the pyramid (the two
//! children along the last axis from one word of each column) as one word of 2-bit codes.
//!
//! For the cache-sized cells of a partitioned build (about 2^18 voxels: 32 KiB of bits) this does a few
//! word operations per 64 voxels plus a few per output node, where stacking sorts and merges lists of
//! rows; it gives the same minimal reduced tree, node for node.

use crate::rays::RaySet;
use crate::tree::LevelWriter;
use crate::tree::{KTree, NodeState};

/// One level of the pyramid: for each column (the `K − 1` first coordinates, axis 0 most significant)
/// `words` words of bits along the last axis; `full` where every voxel of the cell is set, `any` where
/// some is.
struct Level {
    log_side: u32,
    words: usize,
    full: Vec<u64>,
    any: Vec<u64>,
}

impl Level {
    fn new<const K: usize>(log_side: u32) -> Self {
        let columns = 1usize << (log_side as usize * (K - 1));
        let words = (1usize << log_side).div_ceil(64);
        Self {
            log_side,
            words,
            full: vec![0; columns * words],
            any: vec![0; columns * words],
        }
    }

    /// The state of the cell at `coords` (the last coordinate along the words).
    #[inline]
    fn state<const K: usize>(&self, coords: &[u32; K]) -> NodeState {
        let column = coords[..K - 1]
            .iter()
            .fold(0usize, |c, &x| (c << self.log_side) | x as usize);
        let z = coords[K - 1] as usize;
        let at = column * self.words + z / 64;
        let bit = 1u64 << (z % 64);
        if self.full[at] & bit != 0 {
            NodeState::Full
        } else if self.any[at] & bit != 0 {
            NodeState::Partial
        } else {
            NodeState::Empty
        }
    }
}

/// The bits at even positions of `x`, packed into the low 32 bits.
#[inline]
fn even_bits(mut x: u64) -> u64 {
    x &= 0x5555_5555_5555_5555;
    x = (x | (x >> 1)) & 0x3333_3333_3333_3333;
    x = (x | (x >> 2)) & 0x0F0F_0F0F_0F0F_0F0F;
    x = (x | (x >> 4)) & 0x00FF_00FF_00FF_00FF;
    x = (x | (x >> 8)) & 0x0000_FFFF_0000_FFFF;
    (x | (x >> 16)) & 0x0000_0000_FFFF_FFFF
}

/// The level above `fine`: a cell is full where its `2^K` children all are, partly set where any is.
fn coarsen<const K: usize>(fine: &Level) -> Level {
    let mut coarse = Level::new::<K>(fine.log_side - 1);
    let columns = 1usize << (coarse.log_side as usize * (K - 1));
    let side = 1usize << coarse.log_side;
    for column in 0..columns {
        // The 2^(K−1) finer columns under this one.
        let mut xs = [0usize; 3];
        let mut rest = column;
        for x in xs[..K - 1].iter_mut().rev() {
            *x = rest & (side - 1);
            rest >>= coarse.log_side;
        }
        let mut fine_columns = [0usize; 8];
        for (b, slot) in fine_columns.iter_mut().enumerate().take(1 << (K - 1)) {
            *slot = xs[..K - 1].iter().enumerate().fold(0, |c, (a, &x)| {
                (c << fine.log_side) | (2 * x + ((b >> a) & 1))
            });
        }
        for k in 0..coarse.words {
            // Coarse word k holds fine bits 128k .. 128k + 128: fine words 2k and 2k + 1 (or the one word).
            let mut halves = [0u64; 2];
            let mut any_halves = [0u64; 2];
            for h in 0..2 {
                let w = 2 * k + h;
                if w >= fine.words {
                    break;
                }
                let (mut all, mut some) = (u64::MAX, 0u64);
                for &c in &fine_columns[..1 << (K - 1)] {
                    all &= fine.full[c * fine.words + w];
                    some |= fine.any[c * fine.words + w];
                }
                halves[h] = even_bits(all & (all >> 1));
                any_halves[h] = even_bits(some | (some >> 1));
            }
            coarse.full[column * coarse.words + k] = halves[0] | (halves[1] << 32);
            coarse.any[column * coarse.words + k] = any_halves[0] | (any_halves[1] << 32);
        }
    }
    coarse
}

/// Universes of at most this many voxels (2^22: two bitmaps of 512 KiB) go through the bitmap pyramid.
pub(crate) const MAX_BITMAP_VOXELS: u64 = 1 << 22;

/// The tree of `rays`, equal node for node to [`stack`](super::paper::stack): built through a bitmap pyramid of
/// its universe when that has at most [`MAX_BITMAP_VOXELS`] voxels (memory: two bits a voxel and a third
/// more for the coarser levels — the cells of a partitioned build), stacked otherwise.
pub(crate) fn stack_bitmap<const K: usize>(rays: &RaySet<K>) -> KTree<K> {
    let level = rays.level();
    if K as u64 * u64::from(level) > u64::from(MAX_BITMAP_VOXELS.trailing_zeros()) {
        return super::paper::stack(rays);
    }
    let mut voxels = Level::new::<K>(level);
    for (&column, &(z1, z2)) in rays.column_keys().iter().zip(rays.runs()) {
        let base = column as usize * voxels.words;
        let (z1, z2) = (z1 as usize, z2 as usize);
        for w in z1 / 64..z2.div_ceil(64) {
            let lo = z1.max(64 * w) - 64 * w;
            let hi = z2.min(64 * w + 64) - 64 * w;
            let bits = if hi - lo == 64 {
                u64::MAX
            } else {
                ((1u64 << (hi - lo)) - 1) << lo
            };
            voxels.full[base + w] |= bits;
        }
    }
    voxels.any.clone_from(&voxels.full);
    // pyramid[d]: the level at depth d (side 2^d).
    let mut pyramid = vec![voxels];
    while pyramid[pyramid.len() - 1].log_side > 0 {
        let next = coarsen::<K>(&pyramid[pyramid.len() - 1]);
        pyramid.push(next);
    }
    pyramid.reverse();
    let mut out = LevelWriter::new();
    let root = pyramid[0].state::<K>(&[0; K]);
    out.push(0, root);
    let mut partial: Vec<[u32; K]> = if root == NodeState::Partial {
        vec![[0; K]]
    } else {
        Vec::new()
    };
    for depth in 0..level as usize {
        let below = &pyramid[depth + 1];
        let half = 1usize << (K - 1);
        // The word offset, from the first, of each of the 2^(K−1) columns of a node's children (bit a of
        // b: the child's half on axis a).
        let offsets: [usize; 8] = std::array::from_fn(|b| {
            (0..K - 1)
                .map(|a| ((b >> a) & 1) << (below.log_side as usize * (K - 2 - a)))
                .sum::<usize>()
                * below.words
        });
        let mut next = Vec::with_capacity(partial.len() * 4);
        for coords in &partial {
            let column = coords[..K - 1]
                .iter()
                .fold(0usize, |c, &x| (c << below.log_side) | (2 * x as usize));
            let z = 2 * coords[K - 1] as usize;
            let first = column * below.words + z / 64;
            let shift = z % 64;
            // The children's 2-bit codes in child-code order (code b + 2^(K−1)·zb for the child in column
            // b at the lower (zb = 0) or upper z), both z of a column read from one word.
            let mut codes = 0u64;
            for (b, offset) in offsets[..half].iter().enumerate() {
                let full = (below.full[first + offset] >> shift) & 3;
                let partly = (below.any[first + offset] >> shift) & 3 & !full;
                for zb in 0..2 {
                    let code = ((full >> zb) & 1) | (((partly >> zb) & 1) << 1);
                    codes |= code << (2 * (b + zb * half));
                }
            }
            let mut partial_codes = codes & 0xAAAA_AAAA;
            while partial_codes != 0 {
                let code = partial_codes.trailing_zeros() as usize / 2;
                partial_codes &= partial_codes - 1;
                next.push(std::array::from_fn(|a| {
                    2 * coords[a] + ((code >> a) & 1) as u32
                }));
            }
            out.append_word(depth + 1, codes, 1 << K);
        }
        partial = next;
    }
    KTree::from_levels(rays.universe(), out.finish())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::{ball_rays, Ray};
    use crate::stacking::paper::stack;

    #[test]
    fn even_bits_packs_every_other_bit() {
        assert_eq!(even_bits(0b0101), 0b11);
        assert_eq!(even_bits(0b1010), 0);
        assert_eq!(even_bits(u64::MAX), u64::from(u32::MAX));
    }

    fn check<const K: usize>(level: u32) {
        let u = 1i64 << level;
        for r in [1, u / 3, u / 2, u, 2 * u] {
            let ball = ball_rays::<K>(level, [u - 1; K], r).unwrap();
            assert_eq!(
                stack_bitmap(&ball),
                stack(&ball),
                "K = {K}, L = {level}, r = {r}"
            );
        }
        let empty = RaySet::<K>::from_rays(level, []).unwrap();
        assert_eq!(stack_bitmap(&empty), stack(&empty));
        let one = RaySet::<K>::from_rays(level, [Ray::new([0; K], 1)]).unwrap();
        assert_eq!(stack_bitmap(&one), stack(&one));
    }

    #[test]
    fn equals_stacking_in_every_dimension_and_word_layout() {
        for level in [0, 1, 3, 6, 7, 8] {
            check::<1>(level);
            check::<2>(level);
        }
        for level in [0, 1, 2, 5, 7] {
            check::<3>(level);
        }
        for level in [0, 1, 3, 4] {
            check::<4>(level);
        }
    }
}
