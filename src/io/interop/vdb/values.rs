//! Reading an OpenVDB file's bytes: a cursor whose errors name the byte offset, and the value buffers of
//! the tree's nodes as OpenVDB stores them (`io::readCompressedValues`).
//!
//! A node's values (an internal node's tiles, a leaf's voxels) are stored as: one byte saying how inactive
//! values are kept (0: all are the background, 1: all are minus the background, 2: all are one value that
//! follows, 3–5: a selection mask follows choosing between two of them — ±background, one stored value and
//! the background, two stored values; 6: every value is stored), those values and the mask, then the
//! values themselves — only the active ones when the grid's compression flags have active-mask compression
//! (bit 1) and the byte is not 6, else all. The values are stored raw, or as a zlib chunk (flags bit 0) or a
//! Blosc chunk (bit 2, see [`super::blosc`]): an `i64` size, negative for the raw bytes of that length,
//! then that many bytes. A grid saved with half floats stores these buffers (not the inactive values, the
//! background or the root's tiles) as IEEE half floats, and no chunk at all for an empty buffer.

use std::borrow::Cow;

use super::blosc;
use crate::io::interop::grid::{GridFileError, GridFileErrorKind};

const COMPRESS_ZIP: u32 = 0x1;
const COMPRESS_ACTIVE_MASK: u32 = 0x2;
const COMPRESS_BLOSC: u32 = 0x4;

/// A cursor over a `.vdb` file's bytes whose errors name the byte offset.
pub(super) struct Reader<'a> {
    pub bytes: &'a [u8],
    pub at: usize,
    pub file: &'a str,
}

impl<'a> Reader<'a> {
    pub fn fail(&self, kind: GridFileErrorKind) -> GridFileError {
        GridFileError::new(self.file, self.at, kind)
    }

    pub fn fail_at(&self, at: usize, kind: GridFileErrorKind) -> GridFileError {
        GridFileError::new(self.file, at, kind)
    }

    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], GridFileError> {
        match self.bytes.get(self.at..self.at.saturating_add(n)) {
            Some(b) if self.at.checked_add(n).is_some() => {
                self.at += n;
                Ok(b)
            }
            _ => Err(self.fail(GridFileErrorKind::Truncated(format!(
                "{what}: {n} bytes needed, {} left",
                self.bytes.len() - self.at.min(self.bytes.len())
            )))),
        }
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, GridFileError> {
        Ok(u32::from_le_bytes(
            self.take(4, what)?.try_into().expect("4 bytes"),
        ))
    }

    pub fn i32(&mut self, what: &str) -> Result<i32, GridFileError> {
        Ok(i32::from_le_bytes(
            self.take(4, what)?.try_into().expect("4 bytes"),
        ))
    }

    pub fn i64(&mut self, what: &str) -> Result<i64, GridFileError> {
        Ok(i64::from_le_bytes(
            self.take(8, what)?.try_into().expect("8 bytes"),
        ))
    }

    pub fn f64x3(&mut self, what: &str) -> Result<[f64; 3], GridFileError> {
        let b = self.take(24, what)?;
        Ok(std::array::from_fn(|i| {
            f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().expect("8 bytes"))
        }))
    }

    pub fn string(&mut self, what: &str) -> Result<String, GridFileError> {
        let n = self.u32(what)? as usize;
        let b = self.take(n, what)?;
        Ok(String::from_utf8_lossy(b).into_owned())
    }

    /// A node mask of `words` u64 words.
    pub fn mask(&mut self, words: usize) -> Result<Vec<u64>, GridFileError> {
        let b = self.take(8 * words, "node mask")?;
        Ok(b.chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect())
    }

    /// One value of the grid's type at full precision (a background, a tile, an inactive value).
    pub fn value(&mut self, kind: ValueKind, what: &str) -> Result<Sample, GridFileError> {
        let b = self.take(kind.size(), what)?;
        Ok(kind.decode(b, false))
    }

    /// One scalar value (a level set's background or tile): a vector's first component.
    pub fn scalar(&mut self, kind: ValueKind, what: &str) -> Result<f64, GridFileError> {
        self.value(kind, what).map(|v| v[0])
    }

    /// `n` bytes of a value buffer: raw, or the chunk the compression flags say.
    fn chunk(&mut self, compression: u32, n: usize) -> Result<Cow<'a, [u8]>, GridFileError> {
        if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
            return self.take(n, "values").map(Cow::Borrowed);
        }
        let codec = if compression & COMPRESS_BLOSC != 0 {
            "Blosc"
        } else {
            "zlib"
        };
        let size_at = self.at;
        let size = self.i64("chunk size")?;
        if size <= 0 {
            if size.unsigned_abs() != n as u64 {
                return Err(self.fail_at(
                    size_at,
                    GridFileErrorKind::Data(format!(
                        "a raw {codec} chunk of {} bytes where {n} are expected",
                        size.unsigned_abs()
                    )),
                ));
            }
            return self.take(n, "values").map(Cow::Borrowed);
        }
        let stored = usize::try_from(size).unwrap_or(usize::MAX);
        let chunk_at = self.at;
        let chunk = self.take(stored, "compressed values")?;
        let decoded = if compression & COMPRESS_BLOSC != 0 {
            blosc::decode(chunk, n).map_err(|e| self.fail_at(chunk_at + e.at, e.kind))?
        } else {
            inflate(chunk, n).map_err(|m| self.fail_at(chunk_at, GridFileErrorKind::Data(m)))?
        };
        Ok(Cow::Owned(decoded))
    }

    /// A node's `count` values (`readCompressedValues`), as stored: `active` is the node's value mask
    /// (its stored values are checked to be as many as it asks for), `background` the grid's. Nothing is
    /// decoded until [`NodeValues::each`] asks.
    pub fn values(
        &mut self,
        coding: &ValueCoding,
        count: usize,
        active: &[u64],
        background: Sample,
    ) -> Result<NodeValues<'a>, GridFileError> {
        let kind = coding.kind;
        let flag_at = self.at;
        let metadata = self.take(1, "value compression byte")?[0];
        if metadata > 6 {
            return Err(self.fail_at(
                flag_at,
                GridFileErrorKind::Data(format!("value compression byte {metadata} is not 0 to 6")),
            ));
        }
        let mut inactive = [
            if metadata == 0 {
                background
            } else {
                kind.negative(background)
            },
            background,
        ];
        if matches!(metadata, 2 | 4 | 5) {
            inactive[0] = self.value(kind, "inactive value")?;
        }
        if metadata == 5 {
            inactive[1] = self.value(kind, "inactive value")?;
        }
        let selection = if matches!(metadata, 3..=5) {
            Some(self.take(count / 8, "selection mask")?)
        } else {
            None
        };
        let masked = coding.compression & COMPRESS_ACTIVE_MASK != 0 && metadata != 6;
        let stored = if masked {
            active.iter().map(|w| w.count_ones() as usize).sum()
        } else {
            count
        };
        let size = if coding.half {
            2 * kind.components()
        } else {
            kind.size()
        };
        let stored = if coding.half && stored == 0 {
            Cow::Borrowed(&[][..])
        } else {
            self.chunk(coding.compression, stored * size)?
        };
        Ok(NodeValues {
            count,
            kind,
            half: coding.half,
            size,
            stored,
            masked,
            inactive,
            selection,
        })
    }
}

/// A node's values as a file stores them: the stored ones (every value, or the active ones only) and how
/// the inactive ones are rebuilt (OpenVDB's `readCompressedValues`).
pub(super) struct NodeValues<'a> {
    count: usize,
    kind: ValueKind,
    half: bool,
    /// Bytes of one stored value.
    size: usize,
    stored: Cow<'a, [u8]>,
    /// Whether only the active values are stored.
    masked: bool,
    /// The inactive values where the selection mask's bit is off and on.
    inactive: [Sample; 2],
    selection: Option<&'a [u8]>,
}

impl NodeValues<'_> {
    /// Calls `f(n, value)` for each value `n` of the node in order; `active` is the value mask the
    /// values were read with.
    pub fn each(&self, active: &[u64], mut f: impl FnMut(usize, Sample)) {
        let mut stored = self
            .stored
            .chunks_exact(self.size)
            .map(|b| self.kind.decode(b, self.half));
        for n in 0..self.count {
            let value = if !self.masked || active[n / 64] >> (n % 64) & 1 == 1 {
                stored.next().expect("one stored value an active bit")
            } else {
                let on = self.selection.is_some_and(|s| s[n / 8] >> (n % 8) & 1 == 1);
                self.inactive[usize::from(on)]
            };
            f(n, value);
        }
    }

    /// The mask of the values below `threshold`.
    pub fn below(&self, active: &[u64], threshold: f64) -> Vec<u64> {
        let mut mask = vec![0u64; self.count.div_ceil(64)];
        self.each(active, |n, v| {
            if v[0] < threshold {
                mask[n / 64] |= 1 << (n % 64);
            }
        });
        mask
    }
}

/// zlib data that must decode to exactly `n` bytes.
fn inflate(chunk: &[u8], n: usize) -> Result<Vec<u8>, String> {
    let mut out = vec![0u8; n];
    let mut z = flate2::Decompress::new(true);
    let status = z
        .decompress(chunk, &mut out, flate2::FlushDecompress::Finish)
        .map_err(|e| format!("bad zlib data ({e})"))?;
    if status != flate2::Status::StreamEnd || z.total_out() != n as u64 {
        return Err(format!(
            "the zlib data does not decode to the {n} bytes expected (after {} bytes: {status:?})",
            z.total_out()
        ));
    }
    Ok(out)
}

/// One value of a grid: its components (a scalar is the first, the others 0), each exact for every type read
/// (`int64` beyond 2^53 rounded).
pub(super) type Sample = [f64; 3];

/// A grid's value type, as stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ValueKind {
    /// `bool` (one byte), read as 0 or 1.
    Bool,
    /// `float`.
    F32,
    /// `double`.
    F64,
    /// `int32`.
    I32,
    /// `int64`.
    I64,
    /// `vec3s`: three floats.
    Vec3S,
    /// `vec3d`: three doubles.
    Vec3D,
}

impl ValueKind {
    /// Components of a value.
    pub fn components(self) -> usize {
        match self {
            Self::Vec3S | Self::Vec3D => 3,
            _ => 1,
        }
    }

    /// Bytes of one value at full precision.
    pub fn size(self) -> usize {
        self.components()
            * match self {
                Self::Bool => 1,
                Self::F32 | Self::I32 | Self::Vec3S => 4,
                Self::F64 | Self::I64 | Self::Vec3D => 8,
            }
    }

    /// Whether its values are floating point (and so may be stored as half floats).
    pub fn is_float(self) -> bool {
        matches!(self, Self::F32 | Self::F64 | Self::Vec3S | Self::Vec3D)
    }

    fn decode(self, b: &[u8], half: bool) -> Sample {
        let mut v = [0.0; 3];
        let size = if half && self.is_float() {
            2
        } else {
            self.size() / self.components()
        };
        for (c, b) in v.iter_mut().zip(b.chunks_exact(size)) {
            *c = match (self, size) {
                (Self::Bool, _) => f64::from(u8::from(b[0] != 0)),
                (_, 2) => half::f16::from_le_bytes([b[0], b[1]]).to_f64(),
                (Self::I32, _) => f64::from(i32::from_le_bytes(b.try_into().expect("4 bytes"))),
                (Self::I64, _) => i64::from_le_bytes(b.try_into().expect("8 bytes")) as f64,
                (_, 4) => f64::from(f32::from_le_bytes(b.try_into().expect("4 bytes"))),
                _ => f64::from_le_bytes(b.try_into().expect("8 bytes")),
            };
        }
        v
    }

    /// OpenVDB's `math::negative` of a value (a bool is its own negative).
    fn negative(self, v: Sample) -> Sample {
        match self {
            Self::Bool => v,
            _ => v.map(|c| -c),
        }
    }
}

/// How a grid's node values are stored: the grid's compression flags, its value type, half floats.
#[derive(Debug, Clone, Copy)]
pub(super) struct ValueCoding {
    pub compression: u32,
    pub kind: ValueKind,
    pub half: bool,
}

/// The positions of the set bits of mask words, in order.
pub(super) fn ones(words: &[u64]) -> impl Iterator<Item = usize> + '_ {
    words.iter().enumerate().flat_map(|(i, &w)| {
        let mut rest = w;
        std::iter::from_fn(move || {
            (rest != 0).then(|| {
                let b = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                i * 64 + b
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reader(bytes: &[u8]) -> Reader<'_> {
        Reader {
            bytes,
            at: 0,
            file: "t",
        }
    }

    /// A node's values, decoded.
    fn decoded(
        bytes: &[u8],
        coding: &ValueCoding,
        count: usize,
        active: &[u64],
        background: f64,
    ) -> Result<Vec<f64>, GridFileError> {
        let node = reader(bytes).values(coding, count, active, [background, 0.0, 0.0])?;
        let mut all = Vec::new();
        node.each(active, |n, v| {
            assert_eq!(n, all.len());
            all.push(v[0]);
        });
        Ok(all)
    }

    const F32: ValueCoding = ValueCoding {
        compression: COMPRESS_ACTIVE_MASK | COMPRESS_BLOSC,
        kind: ValueKind::F32,
        half: false,
    };

    #[test]
    fn inactive_values_come_back_from_the_selection_mask() {
        // 64 values, 2 active (0.5 and -0.25), the rest ±background chosen by the mask (byte 3).
        let active = [0b1001u64];
        let mut b = vec![3u8];
        let mut selection = [0u8; 8];
        selection[0] = 0b0100; // value 2 is +background, the other inactive ones −background
        b.extend_from_slice(&selection);
        let values: Vec<u8> = [0.5f32, -0.25]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        b.extend_from_slice(&(-(values.len() as i64)).to_le_bytes());
        b.extend_from_slice(&values);
        let v = decoded(&b, &F32, 64, &active, 3.0).unwrap();
        assert_eq!(v[..5], [0.5, -3.0, 3.0, -0.25, -3.0]);
        assert!(v[5..].iter().all(|&x| x == -3.0));
        // The same values through a Blosc frame, and through zlib.
        let mut blosc = vec![3u8];
        blosc.extend_from_slice(&selection);
        let frame = blosc::tests::encode(&values, 4, 8, true, true, true);
        blosc.extend_from_slice(&(frame.len() as i64).to_le_bytes());
        blosc.extend_from_slice(&frame);
        assert_eq!(decoded(&blosc, &F32, 64, &active, 3.0).unwrap(), v);
        let mut zip = vec![3u8];
        zip.extend_from_slice(&selection);
        let packed = {
            use std::io::Write;
            let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
            e.write_all(&values).unwrap();
            e.finish().unwrap()
        };
        zip.extend_from_slice(&(packed.len() as i64).to_le_bytes());
        zip.extend_from_slice(&packed);
        let coding = ValueCoding {
            compression: COMPRESS_ACTIVE_MASK | COMPRESS_ZIP,
            ..F32
        };
        assert_eq!(decoded(&zip, &coding, 64, &active, 3.0).unwrap(), v);
        // Cut anywhere: an error naming a byte inside the buffer, never a panic.
        for (input, coding) in [(&b, &F32), (&blosc, &F32), (&zip, &coding)] {
            for cut in 0..input.len() {
                let e = decoded(&input[..cut], coding, 64, &active, 3.0).unwrap_err();
                assert!(e.offset().unwrap() <= cut as u64, "{e}");
            }
        }
    }

    #[test]
    fn half_floats_and_raw_chunks_of_the_wrong_size() {
        let coding = ValueCoding {
            compression: 0,
            kind: ValueKind::F32,
            half: true,
        };
        // Byte 6: all 8 values stored, as halves.
        let mut b = vec![6u8];
        for v in [1.0f32, -2.5, 0.0, -0.0, 3.0, -1.0, 65504.0, -0.125] {
            b.extend_from_slice(&half::f16::from_f32(v).to_le_bytes());
        }
        let v = decoded(&b, &coding, 8, &[0], 3.0).unwrap();
        assert_eq!(v, [1.0, -2.5, 0.0, -0.0, 3.0, -1.0, 65504.0, -0.125]);
        // No active value, mask compression, halves: no chunk at all.
        let coding = ValueCoding {
            compression: COMPRESS_ACTIVE_MASK | COMPRESS_BLOSC,
            ..coding
        };
        let v = decoded(&[1u8], &coding, 8, &[0], 3.0).unwrap();
        assert_eq!(v, [-3.0; 8]);
        // A raw chunk announcing another size than the buffer's.
        let mut b = vec![6u8];
        b.extend_from_slice(&(-3i64).to_le_bytes());
        b.extend_from_slice(&[0; 32]);
        let e = decoded(&b, &F32, 8, &[0], 3.0).unwrap_err();
        assert_eq!(e.offset(), Some(1), "{e}");
    }
}
