//! The scalar fields of binary records shared by PLY and PCD: integers of 1, 2, 4 or 8 bytes, signed or
//! not, and 4- or 8-byte floats, read as `f64` in either byte order.

/// A scalar field of a binary record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    /// Its size in bytes.
    pub(crate) fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// Whether it holds whole numbers.
    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, Self::F32 | Self::F64)
    }

    /// Reads one value from the start of `b` (at least [`Scalar::size`] bytes), big-endian or not.
    pub(crate) fn get(self, b: &[u8], big: bool) -> f64 {
        macro_rules! num {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                (if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }) as f64
            }};
        }
        match self {
            Self::I8 => f64::from(b[0] as i8),
            Self::U8 => f64::from(b[0]),
            Self::I16 => num!(i16, 2),
            Self::U16 => num!(u16, 2),
            Self::I32 => num!(i32, 4),
            Self::U32 => num!(u32, 4),
            Self::I64 => num!(i64, 8),
            Self::U64 => num!(u64, 8),
            Self::F32 => num!(f32, 4),
            Self::F64 => num!(f64, 8),
        }
    }

    /// The PLY type of this name (`char`, `uchar`, …, `float64`).
    pub(crate) fn ply(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    /// The PCD field of this `TYPE` (`I`, `U`, `F`) and `SIZE`.
    pub(crate) fn pcd(kind: &str, size: &str) -> Option<Self> {
        Some(match (kind, size) {
            ("I", "1") => Self::I8,
            ("U", "1") => Self::U8,
            ("I", "2") => Self::I16,
            ("U", "2") => Self::U16,
            ("I", "4") => Self::I32,
            ("U", "4") => Self::U32,
            ("I", "8") => Self::I64,
            ("U", "8") => Self::U64,
            ("F", "4") => Self::F32,
            ("F", "8") => Self::F64,
            _ => return None,
        })
    }
}
