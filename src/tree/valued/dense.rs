//! Dense arrays of values and the tree: the voxels of a cell, and the reference builder (a dense pyramid).

use crate::space::{Cell, SpaceError, Universe, DENSE_LIMIT};
use crate::tree::ktree::KTree;
use crate::tree::TreeError;
use crate::value::Value;

use super::{combine, ValueAssembler, ValueState};

/// Calls `f` with the dense index of every voxel of `cell`.
pub(crate) fn for_each_voxel<const K: usize>(
    universe: &Universe<K>,
    cell: &Cell<K>,
    mut f: impl FnMut(usize),
) {
    let side = cell.side() as u32;
    let mut offset = [0u32; K];
    loop {
        let p: [u32; K] = std::array::from_fn(|a| cell.origin[a] + offset[a]);
        f(universe.dense_index(p));
        let mut axis = 0;
        loop {
            if axis == K {
                return;
            }
            offset[axis] += 1;
            if offset[axis] < side {
                break;
            }
            offset[axis] = 0;
            axis += 1;
        }
    }
}

/// The reference builder of a valued tree: a dense bottom-up pyramid of node states, then a depth-first
/// walk from the root. Simple enough to trust; `O(U^K)`.
pub(crate) fn reference_pyramid<const K: usize, V: Value>(
    level: u32,
    dense: &[Option<V>],
) -> Result<KTree<K, V>, TreeError> {
    let universe = Universe::<K>::new(level)?;
    let len = universe.dense_len(DENSE_LIMIT)?;
    if dense.len() != len {
        return Err(TreeError::Space(SpaceError::TooLargeForDense {
            voxels: dense.len() as u128,
            limit: len as u128,
        }));
    }
    if let Some(e) = dense.iter().flatten().find_map(|v| v.check().err()) {
        return Err(TreeError::Value(e));
    }
    let bottom: Vec<ValueState<V>> = dense
        .iter()
        .map(|v| v.map_or(ValueState::Empty, ValueState::Full))
        .collect();
    let mut pyramid = vec![bottom];
    for depth in (0..level).rev() {
        let fine = pyramid.last().expect("the voxel level");
        let (fine_u, coarse_u) = (Universe::<K>::new(depth + 1)?, Universe::<K>::new(depth)?);
        let coarse = (0..fine.len() >> K)
            .map(|i| {
                let p = coarse_u.dense_point(i);
                let kids: Vec<ValueState<V>> = (0..1usize << K)
                    .map(|code| {
                        let q = std::array::from_fn(|a| 2 * p[a] + (code >> a & 1) as u32);
                        fine[fine_u.dense_index(q)]
                    })
                    .collect();
                combine(&kids)
            })
            .collect();
        pyramid.push(coarse);
    }
    pyramid.reverse();
    let mut out = ValueAssembler::<K, V>::new(level)?;
    let mut stack = vec![(0u32, [0u32; K])];
    while let Some((depth, p)) = stack.pop() {
        let u = Universe::<K>::new(depth)?;
        let state = pyramid[depth as usize][u.dense_index(p)];
        out.push(depth as usize, state);
        if state.has_children() {
            for code in (0..1usize << K).rev() {
                stack.push((
                    depth + 1,
                    std::array::from_fn(|a| 2 * p[a] + (code >> a & 1) as u32),
                ));
            }
        }
    }
    Ok(out.finish())
}
