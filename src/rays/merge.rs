//! The one merge of two lists of runs along a line: the runs where a Boolean function of the two inputs'
//! memberships holds ([`merge_runs`]), given as a [`TruthTable`], and the stretches of constant membership
//! it is made of ([`stretches`]).
//!
//! The inputs are half-open runs `[z1, z2)` with `z1 < z2`, sorted, disjoint and not touching (as the runs
//! of one column of a [`RaySet`](super::RaySet)), of any integer type: `u32` in a universe, `i64` where
//! runs may reach outside it. The merge walks both lists' ends once, in order; a merged run's ends say
//! which input run end they come from ([`Cause`]), so that what rides on the inputs' ends (the normals of
//! a ray set) can ride on to the output.
//!
//! ```
//! use ktree::rays::{merge_runs, stretches, TruthTable};
//! let a = [(0u32, 5), (8, 10)];
//! let b = [(3u32, 9)];
//! let mut out = Vec::new();
//! merge_runs(a, b, TruthTable::SYMMETRIC_DIFFERENCE, 0..16, |z1, z2, _, _| out.push((z1, z2)));
//! assert_eq!(out, [(0, 3), (5, 8), (9, 10)]);
//! // A table that holds outside both inputs covers the rest of the span.
//! out.clear();
//! merge_runs(a, b, TruthTable::new(0b0001), 0..16, |z1, z2, _, _| out.push((z1, z2)));
//! assert_eq!(out, [(10, 16)]);
//! // The stretches between the inputs' ends, with the membership of each.
//! let s: Vec<_> = stretches(&a, &b).map(|s| (s.z1, s.z2, s.first, s.second)).collect();
//! assert_eq!(s, [(0, 3, true, false), (3, 5, true, true), (5, 8, false, true), (8, 9, true, true), (9, 10, true, false)]);
//! ```

use std::ops::Range;

/// A Boolean function of two memberships (in the first input, in the second) as its truth table: bit
/// `first + 2 · second` holds the result. The sixteen tables are every such function.
///
/// ```
/// use ktree::rays::TruthTable;
/// assert!(TruthTable::DIFFERENCE.apply(true, false) && !TruthTable::DIFFERENCE.apply(true, true));
/// assert_eq!(TruthTable::from_fn(|a, b| a || b), TruthTable::UNION);
/// assert_eq!(TruthTable::ALL.len(), 16);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TruthTable(u8);

impl TruthTable {
    /// `first ∪ second`.
    pub const UNION: Self = Self(0b1110);
    /// `first ∩ second`.
    pub const INTERSECTION: Self = Self(0b1000);
    /// `first ∖ second`.
    pub const DIFFERENCE: Self = Self(0b0010);
    /// `first △ second` (exclusive or).
    pub const SYMMETRIC_DIFFERENCE: Self = Self(0b0110);

    /// Every table, by bits.
    pub const ALL: [Self; 16] = {
        let mut all = [Self(0); 16];
        let mut i = 0;
        while i < 16 {
            all[i] = Self(i as u8);
            i += 1;
        }
        all
    };

    /// The table of bits `bits` (bit `first + 2 · second`; the bits above the fourth are ignored).
    pub const fn new(bits: u8) -> Self {
        Self(bits & 0xF)
    }

    /// The table of `f`.
    pub fn from_fn(f: impl Fn(bool, bool) -> bool) -> Self {
        let mut bits = 0;
        for i in 0..4u8 {
            bits |= u8::from(f(i & 1 == 1, i & 2 == 2)) << i;
        }
        Self(bits)
    }

    /// The table's bits.
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// Whether a voxel is in the result, given whether it is in the first input and in the second.
    #[inline(always)]
    pub const fn apply(self, first: bool, second: bool) -> bool {
        self.0 >> (first as u8 | (second as u8) << 1) & 1 == 1
    }
}

/// Where an end of a merged run comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cause {
    /// The start (`exit` false) or the end of run `run` (its position in its list) of the first input.
    First {
        /// The run's position in its list.
        run: usize,
        /// Whether it is the run's end (else its start).
        exit: bool,
    },
    /// The start or the end of a run of the second input.
    Second {
        /// The run's position in its list.
        run: usize,
        /// Whether it is the run's end (else its start).
        exit: bool,
    },
    /// An end of the span: the table holds outside both inputs there.
    Span,
}

impl Cause {
    /// Whether the input's membership changes the other way than the merged run's at this end (a merged
    /// run starting where an input run ends, or ending where one starts): what is carried from that end
    /// is then turned around (a normal negated).
    ///
    /// ```
    /// use ktree::rays::Cause;
    /// let start_of_b = Cause::Second { run: 0, exit: false };
    /// assert!(start_of_b.reversed(true) && !start_of_b.reversed(false));
    /// ```
    pub fn reversed(self, at_exit: bool) -> bool {
        match self {
            Cause::First { exit, .. } | Cause::Second { exit, .. } => exit != at_exit,
            Cause::Span => false,
        }
    }
}

/// One input of a sweep: the run at hand, its position, and whether the sweep is past its start.
struct Cursor<Z, I> {
    runs: I,
    run: Option<(Z, Z)>,
    index: usize,
    inside: bool,
}

impl<Z: Copy + Ord, I: Iterator<Item = (Z, Z)>> Cursor<Z, I> {
    fn new(mut runs: I) -> Self {
        let run = runs.next();
        Self {
            runs,
            run,
            index: 0,
            inside: false,
        }
    }

    /// Where this input's membership changes next.
    #[inline(always)]
    fn next_end(&self) -> Option<Z> {
        self.run.map(|(z1, z2)| if self.inside { z2 } else { z1 })
    }

    /// Steps past the next end; returns it as (run, whether it is the run's end).
    #[inline(always)]
    fn step(&mut self) -> (usize, bool) {
        let end = (self.index, self.inside);
        if self.inside {
            self.run = self.runs.next();
            self.index += 1;
        }
        self.inside = !self.inside;
        end
    }

    /// Steps past every end at `z` (two when runs touch); the last one stepped past, if any.
    #[inline(always)]
    fn step_at(&mut self, z: Z) -> End {
        let mut last = None;
        while self.next_end() == Some(z) {
            last = Some(self.step());
        }
        last
    }
}

/// A run end an input stepped past: its run's position and whether it is the run's end.
type End = Option<(usize, bool)>;

/// The next place where either input's membership changes, stepped past: `(z, first's end, second's end)`.
#[inline(always)]
fn next_boundary<Z: Copy + Ord, A, B>(
    a: &mut Cursor<Z, A>,
    b: &mut Cursor<Z, B>,
) -> Option<(Z, End, End)>
where
    A: Iterator<Item = (Z, Z)>,
    B: Iterator<Item = (Z, Z)>,
{
    let z = match (a.next_end(), b.next_end()) {
        (None, None) => return None,
        (Some(x), None) => x,
        (None, Some(y)) => y,
        (Some(x), Some(y)) => x.min(y),
    };
    Some((z, a.step_at(z), b.step_at(z)))
}

/// The cause of a boundary: the first input's end when it has one there.
#[inline(always)]
fn cause_of(first: End, second: End) -> Cause {
    match (first, second) {
        (Some((run, exit)), _) => Cause::First { run, exit },
        (None, Some((run, exit))) => Cause::Second { run, exit },
        (None, None) => Cause::Span,
    }
}

/// Calls `emit(z1, z2, start, end)` for each run, in order, where `table` holds of the memberships of
/// `first` and `second`: sorted, disjoint, not touching, each end with the input run end it comes from
/// (the first input's when both have an end there). `span` is the line's extent: where the table holds
/// outside both inputs (`table.apply(false, false)`), the output covers the rest of the span; the inputs
/// must lie inside it. A union ([`TruthTable::UNION`]) also takes inputs whose own runs overlap or touch
/// (sorted by their starts, as runs grown at both ends are): its output is the union of all of them.
///
/// # Performance
/// One pass over both inputs' ends, `O(runs)`; unions and intersections take a pass over the runs (the
/// same result, a third fewer comparisons).
///
/// # Example
/// ```
/// use ktree::rays::{merge_runs, Cause, TruthTable};
/// let mut out = Vec::new();
/// merge_runs([(2i64, 6)], [(4i64, 9)], TruthTable::DIFFERENCE, i64::MIN..i64::MAX, |z1, z2, start, end| {
///     out.push((z1, z2, start, end))
/// });
/// assert_eq!(out, [(2, 4, Cause::First { run: 0, exit: false }, Cause::Second { run: 0, exit: false })]);
/// ```
#[inline]
pub fn merge_runs<Z, A, B>(
    first: A,
    second: B,
    table: TruthTable,
    span: Range<Z>,
    emit: impl FnMut(Z, Z, Cause, Cause),
) where
    Z: Copy + Ord,
    A: IntoIterator<Item = (Z, Z)>,
    B: IntoIterator<Item = (Z, Z)>,
{
    let (first, second) = (first.into_iter(), second.into_iter());
    match table {
        TruthTable::INTERSECTION => intersect(first, second, emit),
        TruthTable::UNION => unite(first, second, emit),
        _ => sweep(first, second, table, span, emit),
    }
}

/// [`merge_runs`] for any table: a sweep over both inputs' ends.
fn sweep<Z, A, B>(
    first: A,
    second: B,
    table: TruthTable,
    span: Range<Z>,
    mut emit: impl FnMut(Z, Z, Cause, Cause),
) where
    Z: Copy + Ord,
    A: Iterator<Item = (Z, Z)>,
    B: Iterator<Item = (Z, Z)>,
{
    let (mut a, mut b) = (Cursor::new(first), Cursor::new(second));
    let mut open = table
        .apply(false, false)
        .then_some((span.start, Cause::Span));
    while let Some((z, end_a, end_b)) = next_boundary(&mut a, &mut b) {
        if table.apply(a.inside, b.inside) == open.is_some() {
            continue;
        }
        let cause = cause_of(end_a, end_b);
        match open.take() {
            None => open = Some((z, cause)),
            Some((z1, start)) => {
                if z1 < z {
                    emit(z1, z, start, cause);
                }
            }
        }
    }
    if let Some((z1, start)) = open {
        if z1 < span.end {
            emit(z1, span.end, start, Cause::Span);
        }
    }
}

/// [`merge_runs`] for [`TruthTable::INTERSECTION`]: the overlaps of the runs, each pair met once.
#[inline]
fn intersect<Z, A, B>(mut first: A, mut second: B, mut emit: impl FnMut(Z, Z, Cause, Cause))
where
    Z: Copy + Ord,
    A: Iterator<Item = (Z, Z)>,
    B: Iterator<Item = (Z, Z)>,
{
    let (Some(mut p), Some(mut q)) = (first.next(), second.next()) else {
        return;
    };
    let (mut i, mut j) = (0, 0);
    loop {
        let (lo, hi) = (p.0.max(q.0), p.1.min(q.1));
        if lo < hi {
            let start = if p.0 >= q.0 {
                Cause::First {
                    run: i,
                    exit: false,
                }
            } else {
                Cause::Second {
                    run: j,
                    exit: false,
                }
            };
            let end = if p.1 <= q.1 {
                Cause::First { run: i, exit: true }
            } else {
                Cause::Second { run: j, exit: true }
            };
            emit(lo, hi, start, end);
        }
        if p.1 < q.1 {
            let Some(next) = first.next() else {
                return;
            };
            p = next;
            i += 1;
        } else {
            let Some(next) = second.next() else {
                return;
            };
            q = next;
            j += 1;
        }
    }
}

/// [`merge_runs`] for [`TruthTable::UNION`]: the runs taken by their starts, joined where they overlap or
/// touch (so an input's own runs may overlap).
#[inline]
fn unite<Z, A, B>(mut first: A, mut second: B, mut emit: impl FnMut(Z, Z, Cause, Cause))
where
    Z: Copy + Ord,
    A: Iterator<Item = (Z, Z)>,
    B: Iterator<Item = (Z, Z)>,
{
    let (mut x, mut y) = (first.next(), second.next());
    let (mut i, mut j) = (0, 0);
    // The run being joined: its ends and their causes.
    let mut open: Option<(Z, Z, Cause, Cause)> = None;
    loop {
        // The next run by its start, the first input's on a tie.
        let (run, is_first, index) = match (x, y) {
            (Some(p), Some(q)) if p.0 <= q.0 => (p, true, i),
            (Some(p), None) => (p, true, i),
            (_, Some(q)) => (q, false, j),
            (None, None) => break,
        };
        if is_first {
            x = first.next();
            i += 1;
        } else {
            y = second.next();
            j += 1;
        }
        let cause = |exit| {
            if is_first {
                Cause::First { run: index, exit }
            } else {
                Cause::Second { run: index, exit }
            }
        };
        match &mut open {
            Some(o) if run.0 <= o.1 => {
                // On a tie of the ends, the first input's end is the cause (as the sweep has it).
                if run.1 > o.1 || (run.1 == o.1 && is_first) {
                    o.1 = run.1;
                    o.3 = cause(true);
                }
            }
            _ => {
                if let Some((z1, z2, s, e)) = open {
                    emit(z1, z2, s, e);
                }
                open = Some((run.0, run.1, cause(false), cause(true)));
            }
        }
    }
    if let Some((z1, z2, s, e)) = open {
        emit(z1, z2, s, e);
    }
}

/// The union of runs sorted by their starts that may overlap or touch (runs grown at both ends, say), as
/// sorted, disjoint, non-touching runs: what [`merge_runs`] takes. Empty runs (`z2 ≤ z1`) are dropped.
///
/// ```
/// use ktree::rays::joined;
/// let runs: Vec<_> = joined([(0, 4), (2, 5), (5, 6), (7, 7), (8, 9)]).collect();
/// assert_eq!(runs, [(0, 6), (8, 9)]);
/// ```
pub fn joined<Z: Copy + Ord, I: IntoIterator<Item = (Z, Z)>>(runs: I) -> Joined<Z, I::IntoIter> {
    Joined {
        runs: runs.into_iter(),
        pending: None,
    }
}

/// The iterator of [`joined`].
#[derive(Debug, Clone)]
pub struct Joined<Z, I> {
    runs: I,
    /// The first run of the next joined run, read already.
    pending: Option<(Z, Z)>,
}

impl<Z: Copy + Ord, I: Iterator<Item = (Z, Z)>> Iterator for Joined<Z, I> {
    type Item = (Z, Z);

    #[inline]
    fn next(&mut self) -> Option<(Z, Z)> {
        let mut open = match self.pending.take() {
            Some(run) => run,
            None => self.runs.by_ref().find(|r| r.0 < r.1)?,
        };
        loop {
            match self.runs.next() {
                None => return Some(open),
                Some((z1, z2)) if z1 >= z2 => {}
                Some(run) if run.0 <= open.1 => open.1 = open.1.max(run.1),
                Some(run) => {
                    self.pending = Some(run);
                    return Some(open);
                }
            }
        }
    }
}

/// One stretch of [`stretches`]: `[z1, z2)` and whether it is in the first input and in the second.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Stretch<Z> {
    /// Where the stretch starts.
    pub z1: Z,
    /// Where it ends (exclusive).
    pub z2: Z,
    /// Whether it is in the first input.
    pub first: bool,
    /// Whether it is in the second input.
    pub second: bool,
}

/// The stretches from the first end of either input to the last, in order, each as long as neither
/// input's membership changes: the pieces [`merge_runs`] keeps or drops by its table (the inputs as
/// there: sorted, disjoint, not touching).
pub fn stretches<'a, Z: Copy + Ord>(first: &'a [(Z, Z)], second: &'a [(Z, Z)]) -> Stretches<'a, Z> {
    let (mut a, mut b) = (
        Cursor::new(first.iter().copied()),
        Cursor::new(second.iter().copied()),
    );
    let at = next_boundary(&mut a, &mut b).map(|(z, _, _)| z);
    Stretches { a, b, at }
}

/// The iterator of [`stretches`].
pub struct Stretches<'a, Z> {
    a: Cursor<Z, std::iter::Copied<std::slice::Iter<'a, (Z, Z)>>>,
    b: Cursor<Z, std::iter::Copied<std::slice::Iter<'a, (Z, Z)>>>,
    /// Where the next stretch starts (`None` when done).
    at: Option<Z>,
}

impl<Z: Copy + Ord> Iterator for Stretches<'_, Z> {
    type Item = Stretch<Z>;

    fn next(&mut self) -> Option<Stretch<Z>> {
        let z1 = self.at?;
        let (first, second) = (self.a.inside, self.b.inside);
        loop {
            let Some((z2, _, _)) = next_boundary(&mut self.a, &mut self.b) else {
                self.at = None;
                return None;
            };
            if (self.a.inside, self.b.inside) != (first, second) {
                self.at = Some(z2);
                return Some(Stretch {
                    z1,
                    z2,
                    first,
                    second,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Lcg;

    /// Random sorted, disjoint, non-touching runs in `0..60`.
    fn runs(lcg: &mut Lcg) -> Vec<(u32, u32)> {
        let mut next = |n: u64| lcg.below(n);
        let mut out = Vec::new();
        let mut z = next(4) as u32;
        while z < 56 && next(8) != 0 {
            let end = z + 1 + next(6) as u32;
            out.push((z, end));
            z = end + 1 + next(5) as u32;
        }
        out
    }

    /// The fast unions and intersections give what the sweep gives, ends' causes included.
    #[test]
    fn fast_tables_are_the_sweep() {
        let mut lcg = Lcg(5);
        for _ in 0..2000 {
            let (a, b) = (runs(&mut lcg), runs(&mut lcg));
            for table in [TruthTable::UNION, TruthTable::INTERSECTION] {
                let (mut fast, mut swept) = (Vec::new(), Vec::new());
                merge_runs(
                    a.iter().copied(),
                    b.iter().copied(),
                    table,
                    0..64,
                    |p, q, s, e| fast.push((p, q, s, e)),
                );
                sweep(
                    a.iter().copied(),
                    b.iter().copied(),
                    table,
                    0..64,
                    |p, q, s, e| swept.push((p, q, s, e)),
                );
                assert_eq!(fast, swept, "{a:?} {b:?} {table:?}");
            }
        }
    }

    #[test]
    fn stretches_cover_both_inputs() {
        let mut lcg = Lcg(9);
        for _ in 0..500 {
            let (a, b) = (runs(&mut lcg), runs(&mut lcg));
            let inside = |runs: &[(u32, u32)], z: u32| runs.iter().any(|r| r.0 <= z && z < r.1);
            let mut at = None;
            for s in stretches(&a, &b) {
                assert!(s.z1 < s.z2);
                assert!(at.is_none_or(|z| z == s.z1), "contiguous");
                for z in s.z1..s.z2 {
                    assert_eq!((inside(&a, z), inside(&b, z)), (s.first, s.second));
                }
                at = Some(s.z2);
            }
            let first = a.iter().chain(&b).map(|r| r.0).min();
            let last = a.iter().chain(&b).map(|r| r.1).max();
            if first.is_some() {
                assert_eq!(at, last);
                assert_eq!(stretches(&a, &b).next().map(|s| s.z1), first);
            }
        }
    }
}
