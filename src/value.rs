//! What a voxel holds: nothing (a binary tree's `()`), or a value of one type — labels (`u8`, `u16`,
//! `u32`), quantized log-odds (`i8`), densities, log-odds or distances (`f32`), colours ([`Rgb`]).
//!
//! A valued tree keeps, beside its 2-bit node codes, the value of each full node (a node all of whose
//! voxels hold one equal value), in level order; a node whose voxels all hold values, not all equal, has
//! the code `11` (*mixed*) and children. Two values are the same when their bits are: `0.0` and `-0.0` are
//! two values, and NaN is refused ([`Value::check`]).
//!
//! ```
//! use ktree::tree::value::{Dtype, Value};
//! assert_eq!(<u16 as Value>::DTYPE, Some(Dtype::U16));
//! assert_eq!(<() as Value>::DTYPE, None);
//! assert!(1.5f32.check().is_ok() && f32::NAN.check().is_err());
//! assert!(!0.0f32.same(-0.0)); // bit-equal, not IEEE-equal
//! assert_eq!(Dtype::parse("rgb8"), Some(Dtype::Rgb));
//! ```

use std::fmt::Debug;
use std::hash::Hash;

/// A colour: red, green, blue.
pub type Rgb = [u8; 3];

/// The mean colour, channel by channel, rounded to the nearest (halves up).
///
/// ```
/// assert_eq!(ktree::value::mean_colour(&[[0, 10, 255], [1, 20, 255]]), [1, 15, 255]);
/// ```
pub fn mean_colour(colours: &[Rgb]) -> Rgb {
    let n = colours.len().max(1) as u64;
    std::array::from_fn(|c| {
        let sum: u64 = colours.iter().map(|p| u64::from(p[c])).sum();
        ((2 * sum + n) / (2 * n)) as u8
    })
}

/// The run-time name of a value type, where the dimension is run-time too (files, the command line,
/// Python).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Dtype {
    /// `u8` labels.
    U8,
    /// `u16` labels.
    U16,
    /// `u32` labels.
    U32,
    /// `i8`, quantized log-odds.
    I8,
    /// `f32`: densities, log-odds, distances.
    F32,
    /// [`Rgb`] colours.
    Rgb,
}

impl Dtype {
    /// Every value type.
    pub const ALL: [Dtype; 6] = [
        Dtype::U8,
        Dtype::U16,
        Dtype::U32,
        Dtype::I8,
        Dtype::F32,
        Dtype::Rgb,
    ];

    /// The name numpy gives it (`uint8`, `uint16`, `uint32`, `int8`, `float32`), `rgb8` for colours.
    pub fn name(self) -> &'static str {
        match self {
            Dtype::U8 => "uint8",
            Dtype::U16 => "uint16",
            Dtype::U32 => "uint32",
            Dtype::I8 => "int8",
            Dtype::F32 => "float32",
            Dtype::Rgb => "rgb8",
        }
    }

    /// The type of a name of [`Dtype::name`] (also `u8`, `u16`, `u32`, `i8`, `f32`, `rgb`).
    pub fn parse(name: &str) -> Option<Dtype> {
        Some(match name {
            "uint8" | "u8" => Dtype::U8,
            "uint16" | "u16" => Dtype::U16,
            "uint32" | "u32" => Dtype::U32,
            "int8" | "i8" => Dtype::I8,
            "float32" | "f32" => Dtype::F32,
            "rgb8" | "rgb" => Dtype::Rgb,
            _ => return None,
        })
    }

    /// The code stored in files (1 … 6; 0 is a tree without values).
    pub fn code(self) -> u8 {
        match self {
            Dtype::U8 => 1,
            Dtype::U16 => 2,
            Dtype::U32 => 3,
            Dtype::I8 => 4,
            Dtype::F32 => 5,
            Dtype::Rgb => 6,
        }
    }

    /// The type of a file's code ([`Dtype::code`]).
    pub fn from_code(code: u8) -> Option<Dtype> {
        Dtype::ALL.into_iter().find(|d| d.code() == code)
    }

    /// Bytes a value.
    pub fn bytes(self) -> usize {
        match self {
            Dtype::U8 | Dtype::I8 => 1,
            Dtype::U16 => 2,
            Dtype::U32 | Dtype::F32 => 4,
            Dtype::Rgb => 3,
        }
    }
}

impl std::fmt::Display for Dtype {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A value that is not allowed in a tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ValueError {
    /// A NaN: it equals no value, not even itself, so no node could be full of it.
    #[error("NaN is not a value a voxel can hold (use the background, or another value, for missing data)")]
    NaN,
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for () {}
    impl Sealed for u8 {}
    impl Sealed for u16 {}
    impl Sealed for u32 {}
    impl Sealed for i8 {}
    impl Sealed for f32 {}
    impl Sealed for super::Rgb {}
}

/// A type a voxel can hold: `()` (a binary tree: no value column at all, the same bits and speed as a tree
/// without values), `u8`, `u16`, `u32`, `i8`, `f32` or [`Rgb`]. Sealed: the file formats and the run-time
/// [`Dtype`] know exactly these.
pub trait Value: Copy + PartialEq + Debug + Send + Sync + 'static + sealed::Sealed {
    /// Whether the type carries anything (`false` for `()` alone): when not, no value column exists.
    const STORED: bool;

    /// The run-time name (`None` for `()`).
    const DTYPE: Option<Dtype>;

    /// The value's identity: two values are the same when their keys are (bit-equality for `f32`).
    type Key: Copy + Eq + Ord + Hash + Debug + Send + Sync;

    /// The key of the value.
    fn key(self) -> Self::Key;

    /// Whether `self` and `other` are the same value (bit-equal).
    #[inline]
    fn same(self, other: Self) -> bool {
        self.key() == other.key()
    }

    /// Whether [`Value::check`] can refuse a value of the type (`f32` alone): a loop checking many
    /// values is skipped when not.
    const REFUSES: bool = false;

    /// Refuses a value no voxel may hold (a NaN).
    ///
    /// # Errors
    /// [`ValueError::NaN`].
    #[inline]
    fn check(self) -> Result<(), ValueError> {
        Ok(())
    }

    /// The smaller of two values (channel by channel for [`Rgb`]).
    fn min_value(self, other: Self) -> Self;

    /// The larger of two values (channel by channel for [`Rgb`]).
    fn max_value(self, other: Self) -> Self;

    /// The sum of two values, saturating for integers (channel by channel for [`Rgb`]); for `f32` the
    /// float sum (`inf + -inf` is a NaN, which a tree refuses).
    fn sum_value(self, other: Self) -> Self;

    /// Whether `lo <= self <= hi` (on every channel for [`Rgb`]).
    fn in_range(self, lo: Self, hi: Self) -> bool;

    /// The value written as [`Value::parse`] reads it: a number, or `r,g,b` for a colour.
    fn text(self) -> String;

    /// The value of a text: a number of the type (`-3`, `255`, `0.25`, `inf`), or `r,g,b` for a colour.
    ///
    /// # Errors
    /// A message saying what was expected (a NaN is refused).
    fn parse(text: &str) -> Result<Self, String>;

    /// Appends the value's bytes, little-endian.
    fn write_le(self, out: &mut Vec<u8>);

    /// The value of [`Dtype::bytes`] little-endian bytes (the slice is exactly that long).
    fn read_le(bytes: &[u8]) -> Self;
}

impl Value for () {
    const STORED: bool = false;
    const DTYPE: Option<Dtype> = None;
    type Key = ();
    #[inline(always)]
    fn key(self) {}
    #[inline(always)]
    fn min_value(self, _: Self) {}
    #[inline(always)]
    fn max_value(self, _: Self) {}
    #[inline(always)]
    fn sum_value(self, _: Self) {}
    #[inline(always)]
    fn in_range(self, _: Self, _: Self) -> bool {
        true
    }
    fn text(self) -> String {
        String::new()
    }
    fn parse(text: &str) -> Result<Self, String> {
        if text.is_empty() {
            Ok(())
        } else {
            Err(format!("'{text}': a tree without values holds no value"))
        }
    }
    #[inline(always)]
    fn write_le(self, _: &mut Vec<u8>) {}
    #[inline(always)]
    fn read_le(_: &[u8]) -> Self {}
}

macro_rules! integer_value {
    ($t:ty, $d:expr) => {
        impl Value for $t {
            const STORED: bool = true;
            const DTYPE: Option<Dtype> = Some($d);
            type Key = $t;
            #[inline(always)]
            fn key(self) -> $t {
                self
            }
            #[inline]
            fn min_value(self, other: Self) -> Self {
                self.min(other)
            }
            #[inline]
            fn max_value(self, other: Self) -> Self {
                self.max(other)
            }
            #[inline]
            fn sum_value(self, other: Self) -> Self {
                self.saturating_add(other)
            }
            #[inline]
            fn in_range(self, lo: Self, hi: Self) -> bool {
                lo <= self && self <= hi
            }
            fn text(self) -> String {
                self.to_string()
            }
            fn parse(text: &str) -> Result<Self, String> {
                text.trim().parse::<$t>().map_err(|_| {
                    format!(
                        "'{text}' is not a {} value ({} to {})",
                        $d.name(),
                        <$t>::MIN,
                        <$t>::MAX
                    )
                })
            }
            #[inline]
            fn write_le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            #[inline]
            fn read_le(bytes: &[u8]) -> Self {
                <$t>::from_le_bytes(bytes.try_into().expect("the value's width"))
            }
        }
    };
}

integer_value!(u8, Dtype::U8);
integer_value!(u16, Dtype::U16);
integer_value!(u32, Dtype::U32);
integer_value!(i8, Dtype::I8);

impl Value for f32 {
    const STORED: bool = true;
    const DTYPE: Option<Dtype> = Some(Dtype::F32);
    const REFUSES: bool = true;
    type Key = u32;
    #[inline(always)]
    fn key(self) -> u32 {
        self.to_bits()
    }
    #[inline]
    fn min_value(self, other: Self) -> Self {
        self.min(other)
    }
    #[inline]
    fn max_value(self, other: Self) -> Self {
        self.max(other)
    }
    #[inline]
    fn sum_value(self, other: Self) -> Self {
        self + other
    }
    #[inline]
    fn in_range(self, lo: Self, hi: Self) -> bool {
        lo <= self && self <= hi
    }
    #[inline]
    fn check(self) -> Result<(), ValueError> {
        if self.is_nan() {
            Err(ValueError::NaN)
        } else {
            Ok(())
        }
    }
    fn text(self) -> String {
        self.to_string()
    }
    fn parse(text: &str) -> Result<Self, String> {
        match text.trim().parse::<f32>() {
            Ok(v) if !v.is_nan() => Ok(v),
            _ => Err(format!(
                "'{text}' is not a float32 value (a number, not NaN)"
            )),
        }
    }
    #[inline]
    fn write_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    #[inline]
    fn read_le(bytes: &[u8]) -> Self {
        f32::from_le_bytes(bytes.try_into().expect("four bytes"))
    }
}

impl Value for Rgb {
    const STORED: bool = true;
    const DTYPE: Option<Dtype> = Some(Dtype::Rgb);
    type Key = [u8; 3];
    #[inline(always)]
    fn key(self) -> [u8; 3] {
        self
    }
    #[inline]
    fn min_value(self, other: Self) -> Self {
        std::array::from_fn(|c| self[c].min(other[c]))
    }
    #[inline]
    fn max_value(self, other: Self) -> Self {
        std::array::from_fn(|c| self[c].max(other[c]))
    }
    #[inline]
    fn sum_value(self, other: Self) -> Self {
        std::array::from_fn(|c| self[c].saturating_add(other[c]))
    }
    #[inline]
    fn in_range(self, lo: Self, hi: Self) -> bool {
        (0..3).all(|c| lo[c] <= self[c] && self[c] <= hi[c])
    }
    fn text(self) -> String {
        format!("{},{},{}", self[0], self[1], self[2])
    }
    fn parse(text: &str) -> Result<Self, String> {
        let parts: Vec<Result<u8, _>> = text.split(',').map(|c| c.trim().parse::<u8>()).collect();
        match parts.as_slice() {
            [Ok(r), Ok(g), Ok(b)] => Ok([*r, *g, *b]),
            _ => Err(format!(
                "'{text}' is not an rgb8 colour (r,g,b, each 0 to 255)"
            )),
        }
    }
    #[inline]
    fn write_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self);
    }
    #[inline]
    fn read_le(bytes: &[u8]) -> Self {
        bytes.try_into().expect("three bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A type says it refuses values exactly when one of its samples (its extremes, and NaN for `f32`)
    /// is refused.
    fn refuses_when_a_sample_is_refused<V: Value>(samples: &[V]) {
        let refused = samples.iter().any(|v| v.check().is_err());
        assert_eq!(V::REFUSES, refused, "{:?}", V::DTYPE);
    }

    #[test]
    fn only_f32_refuses_values() {
        refuses_when_a_sample_is_refused(&[()]);
        refuses_when_a_sample_is_refused(&[u8::MIN, u8::MAX]);
        refuses_when_a_sample_is_refused(&[i8::MIN, 0, i8::MAX]);
        refuses_when_a_sample_is_refused(&[u16::MIN, u16::MAX]);
        refuses_when_a_sample_is_refused(&[u32::MIN, u32::MAX]);
        refuses_when_a_sample_is_refused(&[0.0f32, f32::INFINITY, f32::NEG_INFINITY, f32::NAN]);
        refuses_when_a_sample_is_refused::<Rgb>(&[[0; 3], [255; 3]]);
    }

    fn round_trip<V: Value>(values: &[V]) {
        for &v in values {
            let mut bytes = Vec::new();
            v.write_le(&mut bytes);
            assert_eq!(bytes.len(), V::DTYPE.map_or(0, Dtype::bytes));
            assert!(V::read_le(&bytes).same(v), "{v:?}");
        }
    }

    #[test]
    fn values_go_through_their_bytes_and_dtypes_through_their_names_and_codes() {
        round_trip(&[0u8, 7, 255]);
        round_trip(&[0u16, 65535]);
        round_trip(&[0u32, u32::MAX]);
        round_trip(&[-128i8, 0, 127]);
        round_trip(&[0.0f32, -0.0, 1.5, f32::INFINITY, f32::MIN_POSITIVE]);
        round_trip(&[[1u8, 2, 3]]);
        assert_eq!(u8::parse("255"), Ok(255));
        assert!(u8::parse("256").is_err() && i8::parse("-129").is_err());
        assert_eq!(f32::parse("-0.5"), Ok(-0.5));
        assert!(f32::parse("nan").is_err());
        assert_eq!(Rgb::parse("1, 2,3"), Ok([1, 2, 3]));
        assert!(Rgb::parse("1,2").is_err());
        assert_eq!(Rgb::parse(&[0u8, 9, 255].text()), Ok([0, 9, 255]));
        assert_eq!(u16::parse(&7u16.text()), Ok(7));
        for d in Dtype::ALL {
            assert_eq!(Dtype::parse(d.name()), Some(d));
            assert_eq!(Dtype::from_code(d.code()), Some(d));
        }
        assert_eq!(Dtype::from_code(0), None);
        assert_eq!(Dtype::parse("float64"), None);
    }
}
