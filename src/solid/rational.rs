//! Exact rational parameters for solids: a decimal typed by a user (`0.35`, `-2`, `1/3`, `2.5e-1`) is kept as
//! the exact fraction it denotes, so that the inside test of a solid is exact.

use std::fmt;
use std::str::FromStr;

use super::SolidError;

/// A fraction `num / den` with `den > 0`, in lowest terms.
///
/// ```
/// use ktree::solid::Rational;
/// let r: Rational = "0.35".parse().unwrap();
/// assert_eq!((r.num(), r.den()), (7, 20));
/// assert_eq!("-3/6".parse::<Rational>().unwrap(), Rational::new(-1, 2).unwrap());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rational {
    num: i64,
    den: i64,
}

fn gcd(mut a: i128, mut b: i128) -> i128 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Rational {
    /// `num / den` reduced; `None` if `den` is 0 or the reduced fraction does not fit in `i64`.
    pub fn new(num: i64, den: i64) -> Option<Self> {
        Self::from_i128(i128::from(num), i128::from(den))
    }

    fn from_i128(num: i128, den: i128) -> Option<Self> {
        if den == 0 {
            return None;
        }
        let g = gcd(num, den).max(1);
        let s = if den < 0 { -1 } else { 1 };
        Some(Self {
            num: i64::try_from(s * num / g).ok()?,
            den: i64::try_from(s * den / g).ok()?,
        })
    }

    /// The integer `n`.
    pub fn int(n: i64) -> Self {
        Self { num: n, den: 1 }
    }

    /// The numerator.
    pub fn num(&self) -> i64 {
        self.num
    }

    /// The (positive) denominator.
    pub fn den(&self) -> i64 {
        self.den
    }

    /// The nearest `f64`.
    pub fn to_f64(&self) -> f64 {
        self.num as f64 / self.den as f64
    }
}

impl From<i64> for Rational {
    fn from(n: i64) -> Self {
        Self::int(n)
    }
}

impl fmt::Display for Rational {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

impl FromStr for Rational {
    type Err = SolidError;

    fn from_str(text: &str) -> Result<Self, SolidError> {
        let bad = |why| SolidError::BadNumber {
            text: text.to_string(),
            why,
        };
        let t = text.trim();
        if let Some((n, d)) = t.split_once('/') {
            let n: Rational = n.parse().map_err(|_| bad("bad numerator"))?;
            let d: Rational = d.parse().map_err(|_| bad("bad denominator"))?;
            if d.num == 0 {
                return Err(bad("zero denominator"));
            }
            return Self::from_i128(
                i128::from(n.num) * i128::from(d.den),
                i128::from(n.den) * i128::from(d.num),
            )
            .ok_or_else(|| bad("too large"));
        }
        let (mantissa, exp) = match t.find(['e', 'E']) {
            Some(i) => (
                &t[..i],
                t[i + 1..].parse::<i32>().map_err(|_| bad("bad exponent"))?,
            ),
            None => (t, 0),
        };
        let (neg, digits) = match mantissa.strip_prefix('-') {
            Some(rest) => (true, rest),
            None => (false, mantissa.strip_prefix('+').unwrap_or(mantissa)),
        };
        let (int_part, frac_part) = digits.split_once('.').unwrap_or((digits, ""));
        if int_part.is_empty() && frac_part.is_empty()
            || !int_part
                .bytes()
                .chain(frac_part.bytes())
                .all(|b| b.is_ascii_digit())
        {
            return Err(bad("expected a decimal number or a fraction a/b"));
        }
        let mut num: i128 = 0;
        for b in int_part.bytes().chain(frac_part.bytes()) {
            num = num
                .checked_mul(10)
                .and_then(|n| n.checked_add(i128::from(b - b'0')))
                .ok_or_else(|| bad("too many digits"))?;
        }
        let scale = exp - frac_part.len() as i32;
        if scale.unsigned_abs() > 30 {
            return Err(bad("exponent out of range"));
        }
        let p = 10i128.pow(scale.unsigned_abs());
        let (mut n, d) = if scale >= 0 {
            (num.checked_mul(p).ok_or_else(|| bad("too large"))?, 1)
        } else {
            (num, p)
        };
        if neg {
            n = -n;
        }
        Self::from_i128(n, d).ok_or_else(|| bad("too large or too precise"))
    }
}

/// Puts rationals on a common denominator: returns `D` and the numerators over `D`.
pub(crate) fn common_denominator(values: &[Rational]) -> Result<(i128, Vec<i128>), SolidError> {
    let mut d: i128 = 1;
    for v in values {
        let den = i128::from(v.den);
        d = d
            .checked_mul(den / gcd(d, den))
            .filter(|d| *d < 1 << 62)
            .ok_or_else(|| SolidError::BadParameter("denominators too large".into()))?;
    }
    let nums = values
        .iter()
        .map(|v| i128::from(v.num) * (d / i128::from(v.den)))
        .collect();
    Ok((d, nums))
}

pub(crate) fn gcd_i128(a: i128, b: i128) -> i128 {
    gcd(a, b)
}
