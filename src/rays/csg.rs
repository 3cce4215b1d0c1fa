//! Boolean operations and translation on ray sets (Akman & Franklin's AF11: "on rays, Boolean operations are
//! 1-D"): each works column by column, the columns of both sets side by side ([`join_columns`]), each
//! column's runs through the one merge of runs ([`merge_runs`]) with the operation's truth table.
//!
//! Normals: a result carries normals when every operand does; each end keeps the normal of the operand's run
//! end it comes from, negated where it comes from the subtracted set or a complement. Ends cut by the universe
//! (complement, translation) get `−z` at `z1` and `+z` at `z2`.

use std::ops::Range;

use super::merge::{merge_runs, Cause, TruthTable};
use super::{join_columns, Normal, RaySet};
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

    /// Appends the runs of column `key` where `table` holds of the runs `ra` of `a` and `rb` of `b` (none
    /// when `b` is `None`), in a line of `side` voxels. Each end carries the normal of the input run end
    /// it comes from, negated where that input's membership changes the other way (a run of the
    /// subtracted set, a complement); the universe's ends carry `∓z`.
    fn merge(
        &mut self,
        key: u64,
        a: &RaySet<K>,
        ra: Range<usize>,
        b: Option<(&RaySet<K>, Range<usize>)>,
        table: TruthTable,
        side: u32,
    ) {
        let (b, rb) = match b {
            Some((b, rb)) => (b, rb),
            None => (a, 0..0),
        };
        let normal = |cause: Cause, at_exit: bool| {
            let n = match cause {
                Cause::First { run, exit } => {
                    a.normals(ra.start + run).map(|n| n[usize::from(exit)])
                }
                Cause::Second { run, exit } => {
                    b.normals(rb.start + run).map(|n| n[usize::from(exit)])
                }
                Cause::Span => Some(z_axis::<K>(if at_exit { 1.0 } else { -1.0 })),
            };
            let n = n.unwrap_or([0.0; K]);
            if cause.reversed(at_exit) {
                neg(n)
            } else {
                n
            }
        };
        let (runs_a, runs_b) = (&a.runs()[ra.clone()], &b.runs()[rb.clone()]);
        merge_runs(
            runs_a.iter().copied(),
            runs_b.iter().copied(),
            table,
            0..side,
            |z1, z2, start, end| self.push(key, z1, z2, [normal(start, false), normal(end, true)]),
        );
    }
}

/// The complement's table: inside where the one input is not.
const NOT_FIRST: TruthTable = TruthTable::new(0b0101);

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
        self.merge(other, TruthTable::UNION)
    }

    /// The voxels in both `self` and `other`.
    ///
    /// # Errors
    /// As [`RaySet::union`].
    pub fn intersection(&self, other: &Self) -> Result<Self, CsgError> {
        self.merge(other, TruthTable::INTERSECTION)
    }

    /// The voxels in `self` but not in `other`.
    ///
    /// # Errors
    /// As [`RaySet::union`].
    pub fn difference(&self, other: &Self) -> Result<Self, CsgError> {
        self.merge(other, TruthTable::DIFFERENCE)
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
        let mut i = 0;
        for key in 0..columns {
            let end = i + keys[i..].iter().take_while(|&&k| k == key).count();
            out.merge(key, self, i..end, None, NOT_FIRST, side);
            i = end;
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
        let keys = self.keys();
        let mut out = Out::<K>::new(self.has_normals());
        for (key, range) in self.column_groups() {
            let Some(new_key) = keys.moved(key, offset) else {
                continue;
            };
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

    fn merge(&self, other: &Self, table: TruthTable) -> Result<Self, CsgError> {
        if self.level() != other.level() {
            return Err(CsgError::LevelMismatch(self.level(), other.level()));
        }
        let normals = self.has_normals() && other.has_normals();
        let mut out = Out::<K>::new(normals);
        let side = self.universe().side() as u32;
        for (key, ra, rb) in join_columns(self.column_keys(), other.column_keys(), 0) {
            if rb.is_empty() && table.apply(true, false) {
                // A column of `self` only: its runs are kept whole (or dropped whole).
                out.copy(self, ra);
            } else if ra.is_empty() && table.apply(false, true) {
                out.copy(other, rb);
            } else if !ra.is_empty() && !rb.is_empty() {
                out.merge(key, self, ra, Some((other, rb)), table, side);
            }
        }
        Ok(RaySet::from_sorted_parts(
            self.universe(),
            out.columns,
            out.runs,
            out.normals,
        ))
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
        for op in [
            TruthTable::UNION,
            TruthTable::INTERSECTION,
            TruthTable::DIFFERENCE,
        ] {
            for (x, y) in [(&a, &b), (&b, &a)] {
                let merged = x.merge(y, op).unwrap();
                let mut swept = Out::<2>::new(true);
                let side = x.universe().side() as u32;
                let (kx, ky) = (x.column_keys(), y.column_keys());
                let mut keys: Vec<u64> = kx.iter().chain(ky).copied().collect();
                keys.sort_unstable();
                keys.dedup();
                for key in keys {
                    let rx = kx.partition_point(|&k| k < key)..kx.partition_point(|&k| k <= key);
                    let ry = ky.partition_point(|&k| k < key)..ky.partition_point(|&k| k <= key);
                    swept.merge(key, x, rx, Some((y, ry)), op, side);
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
