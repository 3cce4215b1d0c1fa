//! Boolean operations and translation on ray sets (Akman & Franklin's AF11: "on rays, Boolean operations are
//! 1-D"): each works column by column in one merge pass over both sorted sets.
//!
//! Normals: a result carries normals when every operand does; each end keeps the normal of the operand's run
//! end it comes from, negated where it comes from the subtracted set or a complement. Ends cut by the universe
//! (complement, translation) get `−z` at `z1` and `+z` at `z2`.

use super::{Normal, RaySet};
use thiserror::Error;

/// Errors of Boolean operations on ray sets.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum CsgError {
    /// The operands live in universes of different levels.
    #[error(
        "the ray sets have different levels ({0} and {1}); Boolean operations need one universe"
    )]
    LevelMismatch(u32, u32),
    /// The complement would have more than 2^32 columns.
    #[error("the complement of a level-{0} universe has too many columns")]
    TooManyColumns(u32),
}

/// The Boolean operation applied to the memberships `(in a, in b)`; `(false, false)` must give `false`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Union,
    Intersection,
    Difference,
}

impl Op {
    fn apply(self, a: bool, b: bool) -> bool {
        match self {
            Op::Union => a || b,
            Op::Intersection => a && b,
            Op::Difference => a && !b,
        }
    }
}

fn z_axis<const K: usize>(dir: f32) -> Normal<K> {
    let mut n = [0f32; K];
    n[K - 1] = dir;
    n
}

fn neg<const K: usize>(n: Normal<K>) -> Normal<K> {
    n.map(|x| -x)
}

struct Out<const K: usize> {
    columns: Vec<u64>,
    runs: Vec<(u32, u32)>,
    normals: Option<Vec<[Normal<K>; 2]>>,
}

impl<const K: usize> Out<K> {
    fn new(normals: bool) -> Self {
        Self {
            columns: Vec::new(),
            runs: Vec::new(),
            normals: normals.then(Vec::new),
        }
    }

    /// Appends the runs `range` of `set` as they are (with their normals, or zero normals if `set` has
    /// none).
    fn copy(&mut self, set: &RaySet<K>, range: std::ops::Range<usize>) {
        self.columns
            .extend_from_slice(&set.column_keys()[range.clone()]);
        self.runs.extend_from_slice(&set.runs()[range.clone()]);
        if let Some(ns) = self.normals.as_mut() {
            ns.extend(range.map(|i| set.normals(i).unwrap_or([[0.0; K]; 2])));
        }
    }

    fn push(&mut self, key: u64, z1: u32, z2: u32, n: [Normal<K>; 2]) {
        self.columns.push(key);
        self.runs.push((z1, z2));
        if let Some(ns) = self.normals.as_mut() {
            ns.push(n);
        }
    }
}

impl<const K: usize> RaySet<K> {
    /// The voxels in `self` or in `other`.
    ///
    /// ```
    /// use ktree::{Ray, RaySet};
    /// let a = RaySet::<2>::from_rays(3, [Ray::new([1, 0], 4)]).unwrap();
    /// let b = RaySet::<2>::from_rays(3, [Ray::new([1, 2], 6), Ray::new([5, 0], 1)]).unwrap();
    /// assert_eq!(a.union(&b).unwrap().voxel_count(), 7);
    /// assert_eq!(a.intersection(&b).unwrap().voxel_count(), 2);
    /// assert_eq!(a.difference(&b).unwrap().voxel_count(), 2);
    /// ```
    ///
    /// # Errors
    /// [`CsgError::LevelMismatch`] if the two sets live in universes of different levels.
    pub fn union(&self, other: &Self) -> Result<Self, CsgError> {
        self.merge(other, Op::Union)
    }

    /// The voxels in both `self` and `other`.
    ///
    /// # Errors
    /// As [`RaySet::union`].
    pub fn intersection(&self, other: &Self) -> Result<Self, CsgError> {
        self.merge(other, Op::Intersection)
    }

    /// The voxels in `self` but not in `other`.
    ///
    /// # Errors
    /// As [`RaySet::union`].
    pub fn difference(&self, other: &Self) -> Result<Self, CsgError> {
        self.merge(other, Op::Difference)
    }

    /// The voxels of the universe not in `self`.
    ///
    /// # Errors
    /// [`CsgError::TooManyColumns`] if the universe has more than 2^32 columns.
    pub fn complement(&self) -> Result<Self, CsgError> {
        let level = self.level();
        let columns = 1u64 << (level as usize * (K - 1));
        if columns > 1 << 32 {
            return Err(CsgError::TooManyColumns(level));
        }
        let side = self.universe().side() as u32;
        let mut out = Out::<K>::new(self.has_normals());
        let keys = self.column_keys();
        let runs = self.runs();
        let mut i = 0;
        for key in 0..columns {
            let mut z = 0u32;
            let mut n1 = z_axis::<K>(-1.0);
            while i < keys.len() && keys[i] == key {
                let (z1, z2) = runs[i];
                let ns = self.normals(i).unwrap_or([[0.0; K]; 2]);
                if z1 > z {
                    out.push(key, z, z1, [n1, neg(ns[0])]);
                }
                z = z2;
                n1 = neg(ns[1]);
                i += 1;
            }
            if z < side {
                out.push(key, z, side, [n1, z_axis::<K>(1.0)]);
            }
        }
        Ok(RaySet::from_sorted_parts(
            self.universe(),
            out.columns,
            out.runs,
            out.normals,
        ))
    }

    /// The set moved by `offset` voxels (any sign, per axis); what leaves the universe is cut off.
    ///
    /// ```
    /// use ktree::{Ray, RaySet};
    /// let a = RaySet::<2>::from_rays(3, [Ray::new([1, 0], 4), Ray::new([7, 2], 3)]).unwrap();
    /// let moved = a.translated([2, 6]);
    /// assert_eq!(moved.iter().collect::<Vec<_>>(), [Ray::new([3, 6], 8)]);
    /// ```
    pub fn translated(&self, offset: [i64; K]) -> Self {
        let side = self.universe().side() as i64;
        let level = self.level();
        let mut out = Out::<K>::new(self.has_normals());
        for (key, range) in self.column_groups() {
            let col = self.column_of_key(key);
            let mut new_key = 0u64;
            let mut inside = true;
            for a in 0..K - 1 {
                let c = i64::from(col[a]).saturating_add(offset[a]);
                inside &= (0..side).contains(&c);
                new_key = (new_key << level) | (c.max(0) as u64);
            }
            if !inside {
                continue;
            }
            for i in range {
                let (z1, z2) = self.runs()[i];
                let (a, b) = (
                    i64::from(z1).saturating_add(offset[K - 1]),
                    i64::from(z2).saturating_add(offset[K - 1]),
                );
                let (c1, c2) = (a.max(0), b.min(side));
                if c1 >= c2 {
                    continue;
                }
                let mut n = self.normals(i).unwrap_or([[0.0; K]; 2]);
                if c1 != a {
                    n[0] = z_axis::<K>(-1.0);
                }
                if c2 != b {
                    n[1] = z_axis::<K>(1.0);
                }
                out.push(new_key, c1 as u32, c2 as u32, n);
            }
        }
        RaySet::from_sorted_parts(self.universe(), out.columns, out.runs, out.normals)
    }

    fn merge(&self, other: &Self, op: Op) -> Result<Self, CsgError> {
        if self.level() != other.level() {
            return Err(CsgError::LevelMismatch(self.level(), other.level()));
        }
        let normals = self.has_normals() && other.has_normals();
        let mut out = Out::<K>::new(normals);
        let (ka, kb) = (self.column_keys(), other.column_keys());
        let (mut i, mut j) = (0, 0);
        while i < ka.len() || j < kb.len() {
            let key = match (ka.get(i), kb.get(j)) {
                (Some(&a), Some(&b)) => a.min(b),
                (Some(&a), None) => a,
                (None, Some(&b)) => b,
                (None, None) => unreachable!(),
            };
            let i_end = i + ka[i..].iter().take_while(|&&k| k == key).count();
            let j_end = j + kb[j..].iter().take_while(|&&k| k == key).count();
            if j == j_end {
                // A column of `self` only: its runs are kept whole or dropped whole.
                if op.apply(true, false) {
                    out.copy(self, i..i_end);
                }
            } else if i == i_end {
                if op.apply(false, true) {
                    out.copy(other, j..j_end);
                }
            } else {
                merge_column(self, i..i_end, other, j..j_end, key, op, &mut out);
            }
            i = i_end;
            j = j_end;
        }
        Ok(RaySet::from_sorted_parts(
            self.universe(),
            out.columns,
            out.runs,
            out.normals,
        ))
    }
}

/// Sweeps the run ends of one column of `a` and `b` in order and emits the runs where `op` holds.
fn merge_column<const K: usize>(
    a: &RaySet<K>,
    ra: std::ops::Range<usize>,
    b: &RaySet<K>,
    rb: std::ops::Range<usize>,
    key: u64,
    op: Op,
    out: &mut Out<K>,
) {
    let (runs_a, runs_b) = (&a.runs()[ra.clone()], &b.runs()[rb.clone()]);
    // Each operand's state changes at its run ends; walk both lists of ends together.
    let (mut ia, mut ib) = (0usize, 0usize); // index of the next end: run = idx / 2, end = idx % 2
    let (mut in_a, mut in_b) = (false, false);
    let mut open: Option<(u32, Normal<K>)> = None;
    let end_of = |runs: &[(u32, u32)], idx: usize| {
        let r = runs[idx / 2];
        if idx.is_multiple_of(2) {
            r.0
        } else {
            r.1
        }
    };
    loop {
        let za = (ia < 2 * runs_a.len()).then(|| end_of(runs_a, ia));
        let zb = (ib < 2 * runs_b.len()).then(|| end_of(runs_b, ib));
        let z = match (za, zb) {
            (None, None) => break,
            (Some(x), None) => x,
            (None, Some(y)) => y,
            (Some(x), Some(y)) => x.min(y),
        };
        // Apply every change at z, remembering the normal of the last end applied from each side.
        let mut normal_a = None;
        let mut normal_b = None;
        while ia < 2 * runs_a.len() && end_of(runs_a, ia) == z {
            in_a = ia % 2 == 0;
            normal_a = a.normals(ra.start + ia / 2).map(|n| n[ia % 2]);
            ia += 1;
        }
        while ib < 2 * runs_b.len() && end_of(runs_b, ib) == z {
            in_b = ib % 2 == 0;
            normal_b = b.normals(rb.start + ib / 2).map(|n| n[ib % 2]);
            ib += 1;
        }
        let now = op.apply(in_a, in_b);
        let from_b = |n: Normal<K>| {
            if op == Op::Difference {
                neg(n)
            } else {
                n
            }
        };
        let normal = normal_a.or(normal_b.map(from_b)).unwrap_or([0.0; K]);
        match (open, now) {
            (None, true) => open = Some((z, normal)),
            (Some((z1, n1)), false) => {
                out.push(key, z1, z, [n1, normal]);
                open = None;
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ray;

    /// Columns held by one operand only are copied whole; the copy equals what the run-end sweep gives,
    /// normals included.
    #[test]
    fn one_sided_columns_copy_what_the_sweep_gives() {
        let n = |x: f32| [x, 1.0 - x];
        let a = RaySet::<2>::from_rays_with_normals(
            4,
            [
                (Ray::new([1, 0], 3), [n(0.1), n(0.2)]),
                (Ray::new([1, 5], 7), [n(0.3), n(0.4)]),
                (Ray::new([2, 4], 5), [n(0.5), n(0.6)]),
            ],
        )
        .unwrap();
        let b = RaySet::<2>::from_rays_with_normals(
            4,
            [
                (Ray::new([1, 2], 6), [n(0.7), n(0.8)]),
                (Ray::new([3, 2], 6), [n(0.9), n(1.0)]),
            ],
        )
        .unwrap();
        for op in [Op::Union, Op::Intersection, Op::Difference] {
            for (x, y) in [(&a, &b), (&b, &a)] {
                let merged = x.merge(y, op).unwrap();
                let mut swept = Out::<2>::new(true);
                let (kx, ky) = (x.column_keys(), y.column_keys());
                let mut keys: Vec<u64> = kx.iter().chain(ky).copied().collect();
                keys.sort_unstable();
                keys.dedup();
                for key in keys {
                    let rx = kx.partition_point(|&k| k < key)..kx.partition_point(|&k| k <= key);
                    let ry = ky.partition_point(|&k| k < key)..ky.partition_point(|&k| k <= key);
                    merge_column(x, rx, y, ry, key, op, &mut swept);
                }
                assert_eq!(merged.column_keys(), swept.columns, "{op:?}");
                assert_eq!(merged.runs(), swept.runs, "{op:?}");
                let normals: Vec<_> = (0..merged.len())
                    .map(|i| merged.normals(i).unwrap())
                    .collect();
                assert_eq!(Some(normals), swept.normals, "{op:?}");
            }
        }
    }
}
