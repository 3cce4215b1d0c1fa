//! Exact sightlines for line drawings: the view direction as integers with a symbolic tilt, and the exact
//! part of a lattice segment that a cube hides.
//!
//! **The direction.** The view direction `d` (into the scene) is kept as integers `D` in units of 2⁻⁵⁰ of
//! its largest component (`D_k = round(2⁵⁰ · d_k / max|d|)`, so equal or opposite components stay equal or
//! opposite, and a diagonal stays exactly diagonal). Every visibility decision is exact integer arithmetic
//! on `D` and on the lattice coordinates.
//!
//! **The tie-break (simulation of simplicity).** Decisions are made for the direction
//! `d_ε = σ ⊙ (|D| + (ε, ε², ε⁴))` with an infinitesimal `ε > 0`, where `σ_k` is the sign of `d_k` (`+` when
//! `d_k = 0`). `d_ε` has no zero component and no rational ratio between two components, so no two lattice
//! lines project onto each other, no sightline runs inside a face plane and a sightline through a lattice
//! segment meets other lattice edges at isolated points only. A predicate that is a tie for `d` is decided
//! by the first non-zero coefficient of its polynomial in `ε`. The predicates are linear in the direction,
//! and the powers 1, 2, 4 of the three axes are distinct, so every predicate that is not identically zero
//! is decided. (Ends of hidden parts are compared at `ε = 0`: ends that tie there only decide whether a
//! single point is hidden.)
//!
//! **The hidden part.** A point `p` is hidden by a cube `C` when the line `p + t·d_ε` meets the open cube:
//! the open `t`-intervals of the three slabs of `C` intersect, i.e. for every ordered pair of axes `(i, j)`
//! the entry into slab `i` comes before the exit from slab `j`. Along a lattice segment the points hidden
//! by `C` are an open interval whose ends tend, as `ε → 0`, to exact rationals (or to ±∞); those limits are
//! what [`ExactView::hidden_part`] returns. Hidden parts that shrink to a point in the limit hide nothing,
//! and visible parts are kept only when their exact length is positive.

use std::cmp::Ordering;

use crate::space::Cell;

/// The resolution of the integer direction: components in units of 2⁻⁵⁰ of the largest one. Lattice
/// coordinates below 2²² keep every product of the predicates inside `i128`.
const DIRECTION_BITS: i32 = 50;

/// The power of `ε` tilting each axis: distinct and increasing with the axis.
const TILT_POWER: [u32; 3] = [1, 2, 4];

/// An exact number on a lattice line: a fraction `num / den` (`den > 0`) or an infinite end.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Exact {
    /// Below every number.
    NegInf,
    /// `num / den`, `den > 0`.
    Ratio(i128, i128),
    /// Above every number.
    PosInf,
}

impl Exact {
    pub(crate) fn int(n: u32) -> Self {
        Exact::Ratio(i128::from(n), 1)
    }

    fn neg(self) -> Self {
        match self {
            Exact::NegInf => Exact::PosInf,
            Exact::Ratio(n, d) => Exact::Ratio(-n, d),
            Exact::PosInf => Exact::NegInf,
        }
    }

    /// The nearest `f64` (exact for integers).
    pub(crate) fn to_f64(self) -> f64 {
        match self {
            Exact::NegInf => f64::NEG_INFINITY,
            Exact::Ratio(n, d) => {
                let (q, r) = (n.div_euclid(d), n.rem_euclid(d));
                q as f64 + r as f64 / d as f64
            }
            Exact::PosInf => f64::INFINITY,
        }
    }
}

impl PartialEq for Exact {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Exact {}

impl PartialOrd for Exact {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Exact {
    fn cmp(&self, other: &Self) -> Ordering {
        match (self, other) {
            (Exact::Ratio(a, b), Exact::Ratio(c, d)) => (a * d).cmp(&(c * b)),
            (Exact::NegInf, Exact::NegInf) | (Exact::PosInf, Exact::PosInf) => Ordering::Equal,
            (Exact::NegInf, _) | (_, Exact::PosInf) => Ordering::Less,
            (Exact::PosInf, _) | (_, Exact::NegInf) => Ordering::Greater,
        }
    }
}

/// The limit, as `ε → 0`, of the ratio `w_a / w_k` of two tilted magnitudes.
enum RatioLimit {
    /// `num / den` with `den > 0`.
    Finite(i128, i128),
    Infinite,
}

/// The view direction of a line drawing as used by its visibility decisions (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ExactView {
    /// `σ_k`: the direction into the scene points to increasing coordinates on axis `k`.
    increasing: [bool; 3],
    /// `|D_k|`.
    magnitude: [i64; 3],
}

impl ExactView {
    /// The exact view for the direction `d` into the scene (finite and non-zero).
    pub(crate) fn new(d: [f64; 3]) -> Self {
        let largest = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        debug_assert!(largest > 0.0 && largest.is_finite());
        let unit = f64::from(2u32).powi(DIRECTION_BITS);
        Self {
            increasing: d.map(|x| x >= 0.0),
            magnitude: d.map(|x| ((x.abs() / largest) * unit).round() as i64),
        }
    }

    /// The tilted direction's sign per axis (`+1` or `−1`, never 0), for the front-to-back order.
    pub(crate) fn signs(&self) -> [f64; 3] {
        self.increasing.map(|up| if up { 1.0 } else { -1.0 })
    }

    /// Whether the tilted direction into the scene points to increasing coordinates on `axis`.
    pub(crate) fn increasing(&self, axis: usize) -> bool {
        self.increasing[axis]
    }

    /// The limit of `w_a / w_k` (`a ≠ k`).
    fn ratio_limit(&self, a: usize, k: usize) -> RatioLimit {
        let (ma, mk) = (self.magnitude[a], self.magnitude[k]);
        if mk != 0 {
            RatioLimit::Finite(i128::from(ma), i128::from(mk))
        } else if ma != 0 || TILT_POWER[a] < TILT_POWER[k] {
            RatioLimit::Infinite
        } else {
            RatioLimit::Finite(0, 1)
        }
    }

    /// The limit of `c + m · w_a / w_k`.
    fn bound(&self, c: i64, m: i64, a: usize, k: usize) -> Exact {
        let (c, m) = (i128::from(c), i128::from(m));
        match self.ratio_limit(a, k) {
            RatioLimit::Finite(num, den) => Exact::Ratio(c * den + m * num, den),
            RatioLimit::Infinite => match m.cmp(&0) {
                Ordering::Less => Exact::NegInf,
                Ordering::Equal => Exact::Ratio(c, 1),
                Ordering::Greater => Exact::PosInf,
            },
        }
    }

    /// The part `(lo, hi)` of the lattice segment along `axis` at `fixed` (the other two axes, lower
    /// first) from `u0` to `u1` that `cube` hides in the limit of the tilted view: the points whose line
    /// along `d_ε` meets the open cube. `None` when that part is empty or shrinks to a point.
    #[inline]
    pub(crate) fn hidden_part(
        &self,
        axis: usize,
        fixed: [u32; 2],
        (u0, u1): (u32, u32),
        cube: &Cell<3>,
    ) -> Option<(Exact, Exact)> {
        let a = axis;
        let [b, c] = super::lines::other_axes(a);
        let s = cube.side() as i64;
        // Reflect every axis so that the tilted direction is positive on it: the cube becomes
        // [o'_k, o'_k + s], the point p'.
        let reflected_origin = |k: usize| {
            let o = i64::from(cube.origin[k]);
            if self.increasing[k] {
                o
            } else {
                -(o + s)
            }
        };
        let reflected = |k: usize, x: u32| {
            let x = i64::from(x);
            if self.increasing[k] {
                x
            } else {
                -x
            }
        };
        // Entry offsets e_k = o'_k − p'_k (the exits are e_k + s) on the two axes across the segment.
        let entry = [
            reflected_origin(b) - reflected(b, fixed[0]),
            reflected_origin(c) - reflected(c, fixed[1]),
        ];
        let exit = entry.map(|e| e + s);
        // Across the segment: entering slab i before leaving slab j, e_i·w_j < x_j·w_i, both ways. Most
        // cubes fail here, so this test is kept small and inlined.
        if !self.negative(entry[0], c, -exit[1], b) || !self.negative(entry[1], b, -exit[0], c) {
            return None;
        }
        self.hidden_along([a, b, c], reflected_origin(a), s, entry, (u0, u1))
    }

    /// Whether `p · w_i + q · w_j < 0` for the tilted magnitudes `w_k = |D_k| + ε^{p_k}` (`i ≠ j`): decided
    /// at `ε = 0` when not zero there, else by the first non-zero coefficient in axis order.
    #[inline]
    fn negative(&self, p: i64, i: usize, q: i64, j: usize) -> bool {
        let at_zero = i128::from(p) * i128::from(self.magnitude[i])
            + i128::from(q) * i128::from(self.magnitude[j]);
        if at_zero != 0 {
            return at_zero < 0;
        }
        // The first non-zero coefficient in axis order decides (TILT_POWER increases with the axis).
        let (first, second) = if i < j { (p, q) } else { (q, p) };
        if first != 0 {
            first < 0
        } else {
            second < 0
        }
    }

    /// The part of the segment along axis `a` (from `u0` to `u1`) hidden by a cube of side `s` whose
    /// reflected origin on `a` is `oa`, for a segment whose sightlines cross the cube's slabs on the other
    /// two axes `b`, `c` (`entry`: the entry offsets on those axes).
    fn hidden_along(
        &self,
        [a, b, c]: [usize; 3],
        oa: i64,
        s: i64,
        entry: [i64; 2],
        (u0, u1): (u32, u32),
    ) -> Option<(Exact, Exact)> {
        let exit = entry.map(|e| e + s);
        // Along the segment, in the reflected coordinate v = ±u: entering slab a before leaving slab j
        // gives v > o'_a − x_j·w_a/w_j; entering slab i before leaving slab a gives
        // v < o'_a + s − e_i·w_a/w_i.
        let mut lo = Exact::NegInf;
        let mut hi = Exact::PosInf;
        for (k, (e, x)) in [(b, (entry[0], exit[0])), (c, (entry[1], exit[1]))] {
            lo = lo.max(self.bound(oa, -x, a, k));
            hi = hi.min(self.bound(oa + s, -e, a, k));
        }
        if !self.increasing[a] {
            (lo, hi) = (hi.neg(), lo.neg());
        }
        let lo = lo.max(Exact::int(u0));
        let hi = hi.min(Exact::int(u1));
        (lo < hi).then_some((lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cube of side 2 at `origin` in an 8³ universe.
    fn cube(origin: [u32; 3]) -> Cell<3> {
        Cell::new(crate::space::Universe::new(3).unwrap(), origin, 2).unwrap()
    }

    #[test]
    fn an_axis_view_is_tilted_symbolically() {
        // Looking down −z: a cube directly below the segment hides it wholly, one beside it does not.
        let view = ExactView::new([0.0, 0.0, -1.0]);
        assert_eq!(view.signs(), [1.0, 1.0, -1.0]);
        let below = cube([2, 0, 0]);
        let hidden = view.hidden_part(0, [1, 4], (0, 8), &below);
        assert_eq!(hidden, Some((Exact::int(2), Exact::int(4))));
        let beside = cube([2, 2, 0]);
        assert_eq!(view.hidden_part(0, [1, 4], (0, 8), &beside), None);
    }
}
