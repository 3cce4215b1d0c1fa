//! Structuring elements (scipy's definitions) and their slices across the columns.
use std::fmt;
use std::str::FromStr;

use super::ShapeError;

/// Most column offsets an element may have (each is one pass over the runs).
const MAX_OFFSETS: u128 = 1 << 24;

/// A structuring element of radius `r`: the offsets `d ∈ Z^K` with `|d|² ≤ r²` (ball), `max |d_i| ≤ r`
/// (box) or `Σ |d_i| ≤ r` (cross).
///
/// ```
/// use ktree::shape::Element;
/// assert_eq!("cross".parse::<Element>().unwrap(), Element::Cross);
/// assert_eq!(Element::Box.to_string(), "box");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Element {
    /// `|d|² ≤ r²`.
    #[default]
    Ball,
    /// `max |d_i| ≤ r`.
    Box,
    /// `Σ |d_i| ≤ r`.
    Cross,
}

impl Element {
    /// The three elements.
    pub const ALL: [Element; 3] = [Element::Ball, Element::Box, Element::Cross];

    /// Whether the offset `d` lies in the element of radius `r` (the definition, for any `r ≥ 0`).
    ///
    /// ```
    /// use ktree::shape::Element;
    /// assert!(Element::Ball.contains([1, 1], 1.5) && !Element::Cross.contains([1, 1], 1.5));
    /// ```
    pub fn contains<const K: usize>(self, d: [i64; K], r: f64) -> bool {
        match self {
            Element::Ball => (d.iter().map(|&x| (x * x) as f64).sum::<f64>()) <= r * r,
            Element::Box => d.iter().all(|&x| (x.unsigned_abs() as f64) <= r),
            Element::Cross => (d.iter().map(|&x| x.unsigned_abs()).sum::<u64>() as f64) <= r,
        }
    }
}

impl fmt::Display for Element {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Element::Ball => "ball",
            Element::Box => "box",
            Element::Cross => "cross",
        })
    }
}

impl FromStr for Element {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "ball" => Ok(Element::Ball),
            "box" => Ok(Element::Box),
            "cross" => Ok(Element::Cross),
            _ => Err(format!("unknown shape {s:?} (ball, box or cross)")),
        }
    }
}

/// Checks a radius: finite and ≥ 0.
pub(crate) fn check_radius(r: f64) -> Result<(), ShapeError> {
    if r.is_finite() && r >= 0.0 {
        Ok(())
    } else {
        Err(ShapeError::BadRadius(r))
    }
}

/// The element cut into columns: for each column offset `c` (the first `K − 1` coordinates; the last is 0)
/// the half-length `h ≥ 0` of its run `[−h, h]` along the last axis. Column offsets are limited to
/// `|c_i| ≤ bound`, half-lengths to `bound` (offsets beyond do not matter in a universe of side `bound`).
pub(crate) fn slice<const K: usize>(
    element: Element,
    r: f64,
    bound: i64,
) -> Result<Vec<([i64; K], i64)>, ShapeError> {
    check_radius(r)?;
    let e = (r.floor().min(bound as f64)) as i64; // the reach along any one axis
    let width = (2 * e + 1) as u128;
    let offsets = width.saturating_pow(K as u32 - 1);
    if offsets > MAX_OFFSETS {
        return Err(ShapeError::RadiusTooLarge {
            radius: r,
            offsets,
            limit: MAX_OFFSETS,
        });
    }
    // |d|² ≤ r² ⟺ |d|² ≤ ⌊r²⌋ for integers; ⌊r²⌋ exactly as the f64 product rounds (as `contains`).
    let r2 = (r * r).floor().min(1e30) as u128;
    let rf = r.floor() as i128;
    let mut out = Vec::new();
    let mut c = [-e; K];
    c[K - 1] = 0;
    loop {
        let h: Option<i64> = match element {
            Element::Ball => {
                let n: u128 = c[..K - 1].iter().map(|&x| (x * x) as u128).sum();
                (n <= r2).then(|| isqrt(r2 - n).min(bound as u128) as i64)
            }
            Element::Box => Some(e),
            Element::Cross => {
                let n: i128 = c[..K - 1].iter().map(|&x| i128::from(x.abs())).sum();
                (n <= rf).then(|| (rf - n).min(i128::from(bound)) as i64)
            }
        };
        if let Some(h) = h {
            out.push((c, h));
        }
        // Odometer over the first K − 1 axes.
        let mut axis = 0;
        while axis + 1 < K {
            c[axis] += 1;
            if c[axis] <= e {
                break;
            }
            c[axis] = -e;
            axis += 1;
        }
        if axis + 1 >= K {
            break;
        }
    }
    // The centre column first: erosion intersects with it first, the largest set.
    out.sort_by_key(|(c, _)| c.iter().map(|x| x.unsigned_abs()).sum::<u64>());
    Ok(out)
}

/// One element slice (see [`slice`]).
pub(crate) type Slice<const K: usize> = Vec<([i64; K], i64)>;

/// The element as a Minkowski sum of slices, applied one after the other (dilation by `A ⊕ B` is dilation
/// by `A` then by `B`; erosion likewise), chosen to make the fewest passes over the runs: the element's
/// own slice, or for the box a run along the last axis and on each other axis `{−m, 0, m}` for
/// `m = 1, 2, 4, …` and a rest (segments by doubling: `O(K log r)` passes), or for the cross `⌊r⌋` unit
/// crosses (`O(K r)` passes instead of `O(r^(K−1))`).
pub(crate) fn plan<const K: usize>(
    element: Element,
    r: f64,
    bound: i64,
) -> Result<Vec<Slice<K>>, ShapeError> {
    check_radius(r)?;
    let e = (r.floor().min(bound as f64)) as i64;
    let direct = ((2 * e + 1) as u128).saturating_pow(K as u32 - 1);
    let zero = [0i64; K];
    let unit = |axis: usize, m: i64| {
        let mut c = zero;
        c[axis] = m;
        c
    };
    match element {
        Element::Box if e > 0 => {
            let (mut steps, mut m, mut reach) = (vec![vec![(zero, e)]], 1i64, 0i64);
            let mut segments = Vec::new();
            while reach + m <= e {
                segments.push(m);
                reach += m;
                m *= 2;
            }
            if reach < e {
                segments.push(e - reach);
            }
            for axis in 0..K - 1 {
                for &m in &segments {
                    steps.push(vec![(zero, 0), (unit(axis, m), 0), (unit(axis, -m), 0)]);
                }
            }
            if (steps.len() as u128) * 3 < direct {
                return Ok(steps);
            }
        }
        Element::Cross if e > 0 => {
            // Σ |d_i| reaches past one side on one axis: K sides together bound it.
            let n = r.floor().min(K as f64 * bound as f64) as i64;
            let e = n;
            let passes = (e as u128) * (2 * K as u128 - 1);
            if passes < direct && passes <= MAX_OFFSETS {
                let mut step = vec![(zero, 1)];
                for axis in 0..K - 1 {
                    step.push((unit(axis, 1), 0));
                    step.push((unit(axis, -1), 0));
                }
                return Ok(vec![step; e as usize]);
            }
        }
        _ => {}
    }
    Ok(vec![slice::<K>(element, r, bound)?])
}

/// `⌊√n⌋` exactly.
fn isqrt(n: u128) -> u128 {
    let mut x = (n as f64).sqrt() as u128;
    while x * x > n {
        x -= 1;
    }
    while (x + 1) * (x + 1) <= n {
        x += 1;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_agree_with_the_definition() {
        for element in Element::ALL {
            for r in [0.0, 0.5, 1.0, 1.5, 2.0, 2.3, 3.0] {
                let s = slice::<3>(element, r, 100).unwrap();
                let mut from_slice: Vec<[i64; 3]> = s
                    .iter()
                    .flat_map(|&(c, h)| (-h..=h).map(move |z| [c[0], c[1], z]))
                    .collect();
                from_slice.sort();
                let mut direct = Vec::new();
                for x in -4..=4 {
                    for y in -4..=4 {
                        for z in -4..=4 {
                            if element.contains([x, y, z], r) {
                                direct.push([x, y, z]);
                            }
                        }
                    }
                }
                assert_eq!(from_slice, direct, "{element} r = {r}");
            }
        }
    }

    #[test]
    fn plans_sum_to_the_element() {
        for element in Element::ALL {
            for r in [0.0, 1.0, 2.5, 3.0, 5.0, 7.9] {
                let mut reach: std::collections::BTreeSet<[i64; 3]> = [[0, 0, 0]].into();
                for step in plan::<3>(element, r, 100).unwrap() {
                    let offsets: Vec<[i64; 3]> = step
                        .iter()
                        .flat_map(|&(c, h)| (-h..=h).map(move |z| [c[0], c[1], z]))
                        .collect();
                    reach = reach
                        .iter()
                        .flat_map(|a| {
                            offsets
                                .iter()
                                .map(move |b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]])
                        })
                        .collect();
                }
                let e = r.floor() as i64;
                let mut direct = std::collections::BTreeSet::new();
                for x in -e..=e {
                    for y in -e..=e {
                        for z in -e..=e {
                            if element.contains([x, y, z], r) {
                                direct.insert([x, y, z]);
                            }
                        }
                    }
                }
                assert_eq!(reach, direct, "{element} r = {r}");
            }
        }
    }

    #[test]
    fn bad_radii_are_errors() {
        assert!(matches!(
            slice::<2>(Element::Ball, -1.0, 8),
            Err(ShapeError::BadRadius(_))
        ));
        assert!(slice::<2>(Element::Ball, f64::NAN, 8).is_err());
        assert!(matches!(
            slice::<4>(Element::Box, 1e9, 1 << 20),
            Err(ShapeError::RadiusTooLarge { .. })
        ));
    }
}
