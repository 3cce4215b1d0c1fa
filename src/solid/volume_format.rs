//! How volume files lay out their samples and what a sample may be: a raw volume's JSON sidecar, a NIfTI
//! header's layout (checked), the samples' decoding, and the rules for labels and windows — shared by the
//! volume held in memory ([`Volume`](super::volume::Volume)) and the file read plane by plane
//! ([`VolumeFile`](super::volume_file::VolumeFile)).

use std::io::{BufRead, Read};
use std::path::Path;

use serde::Deserialize;

use super::volume::MAX_SAMPLES;
use super::SolidError;
use crate::space::Universe;
use crate::value::Dtype;

#[derive(Deserialize)]
struct Sidecar {
    shape_xyz: [usize; 3],
    dtype: String,
    #[serde(default)]
    endianness: Option<String>,
    #[serde(default)]
    spacing_xyz: Option<[f64; 3]>,
    #[serde(default)]
    file: Option<String>,
}

/// Bytes of a NIfTI-1 header.
const NIFTI_HEADER_BYTES: u64 = 348;
/// Largest offset of the samples in a NIfTI file (room for header extensions).
const MAX_NIFTI_OFFSET: f32 = (1u32 << 24) as f32;

/// The sample layout a raw volume's JSON sidecar describes.
pub(super) struct RawLayout {
    meta: Sidecar,
    samples: usize,
    size: usize,
    big: bool,
}

impl RawLayout {
    /// The layout of a volume to be held in memory: at most [`MAX_SAMPLES`] samples.
    pub(super) fn parse(text: &[u8], json: &Path) -> Result<Self, SolidError> {
        Self::parse_within(text, json, MAX_SAMPLES)
    }

    /// The layout of a volume read plane by plane: any number of samples.
    pub(super) fn parse_streamed(text: &[u8], json: &Path) -> Result<Self, SolidError> {
        Self::parse_within(text, json, usize::MAX)
    }

    /// The raw file the sidecar `json` describes: its `file`, or the same name with `.raw`.
    pub(super) fn raw_file(&self, json: &Path) -> std::path::PathBuf {
        match &self.meta.file {
            Some(f) => json.with_file_name(f),
            None => json.with_extension("raw"),
        }
    }

    pub(super) fn shape(&self) -> [usize; 3] {
        self.meta.shape_xyz
    }

    pub(super) fn spacing(&self) -> [f64; 3] {
        self.meta.spacing_xyz.unwrap_or([1.0; 3])
    }

    pub(super) fn dtype(&self) -> &str {
        &self.meta.dtype
    }

    pub(super) fn sample_bytes(&self) -> usize {
        self.size
    }

    pub(super) fn big_endian(&self) -> bool {
        self.big
    }

    fn parse_within(text: &[u8], json: &Path, limit: usize) -> Result<Self, SolidError> {
        let parse = |what: String| SolidError::Parse {
            path: json.to_path_buf(),
            what,
        };
        let meta: Sidecar = serde_json::from_slice(text)
            .map_err(|e| parse(format!("line {} column {}: {e}", e.line(), e.column())))?;
        let size = match meta.dtype.as_str() {
            "uint8" | "int8" => 1,
            "uint16" | "int16" => 2,
            "uint32" | "int32" | "float32" => 4,
            "float64" => 8,
            other => return Err(parse(format!("unknown dtype '{other}'"))),
        };
        let big = match meta.endianness.as_deref() {
            None | Some("little") => false,
            Some("big") => true,
            Some(other) => return Err(parse(format!("unknown endianness '{other}'"))),
        };
        let samples = checked_samples(meta.shape_xyz, limit)
            .ok_or_else(|| parse(format!("shape {:?} is empty or too large", meta.shape_xyz)))?;
        Ok(Self {
            meta,
            samples,
            size,
            big,
        })
    }

    /// Checks the raw data's length before it is read or decoded.
    pub(super) fn check_length(&self, got: u64, raw: &Path) -> Result<(), SolidError> {
        let want = self.samples as u64 * self.size as u64;
        if got == want {
            return Ok(());
        }
        Err(SolidError::Parse {
            path: raw.to_path_buf(),
            what: format!(
                "{got} bytes, but shape {:?} of {} needs {want}",
                self.meta.shape_xyz, self.meta.dtype
            ),
        })
    }

    /// The samples packed in `bytes`, decoded.
    pub(super) fn decode(&self, bytes: &[u8]) -> Vec<f64> {
        let mut values = Vec::with_capacity(self.samples);
        decode_into(&self.meta.dtype, self.big, bytes, &mut values);
        values
    }
}

/// A sample at `at` (`x, y, z`) as a label of type `V`: a whole number from 0 (the background) that `V`
/// holds.
pub(super) fn label_of<V: TryFrom<u32>>(at: [usize; 3], v: f64) -> Result<V, SolidError> {
    let [x, y, z] = at;
    if !(v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0) {
        return Err(SolidError::BadParameter(format!(
            "sample ({x}, {y}, {z}) is {v}: labels are whole numbers from 0 (the background) up"
        )));
    }
    V::try_from(v as u32).map_err(|_| {
        SolidError::BadParameter(format!(
            "sample ({x}, {y}, {z}) is {v}: more than the largest label of the type"
        ))
    })
}

/// Checks a window of samples `lo ..= hi`: two finite numbers, the first no larger.
pub(super) fn check_window(lo: f64, hi: f64) -> Result<(), SolidError> {
    if lo.is_finite() && hi.is_finite() && lo <= hi {
        return Ok(());
    }
    Err(SolidError::BadParameter(format!(
        "the window {lo}:{hi} is not two finite numbers, the first no larger"
    )))
}

/// The smallest label type that holds the labels up to `largest`.
pub(super) fn smallest_label_type(largest: u32) -> Dtype {
    if largest <= u32::from(u8::MAX) {
        Dtype::U8
    } else if largest <= u32::from(u16::MAX) {
        Dtype::U16
    } else {
        Dtype::U32
    }
}

/// The number of samples of `shape` if it is not empty, at most `limit`, and at most 2^20 an axis.
pub(super) fn checked_samples(shape: [usize; 3], limit: usize) -> Option<usize> {
    let n = shape.iter().try_fold(1usize, |p, &s| p.checked_mul(s))?;
    (n > 0 && n <= limit && shape.iter().all(|&s| s <= 1 << 20)).then_some(n)
}

/// Where a NIfTI file's samples are and what they are.
pub(super) struct NiftiLayout {
    pub(super) shape: [usize; 3],
    pub(super) datatype: nifti::NiftiType,
    /// Bytes a sample.
    pub(super) sample: u64,
    /// The byte the samples start at.
    pub(super) offset: u64,
}

/// A NIfTI header's layout, checked: a 3-D volume (or 4-D of one time point), its sample count (at most
/// [`MAX_SAMPLES`] when `in_memory`), bits a sample matching the data type, and the samples' offset.
fn nifti_layout(
    header: &nifti::NiftiHeader,
    file: &Path,
    in_memory: bool,
) -> Result<NiftiLayout, SolidError> {
    let parse = |what: String| SolidError::Parse {
        path: file.to_path_buf(),
        what,
    };
    let nifti_error = |e: nifti::NiftiError| parse(format!("NIfTI: {e}"));
    let dim = header.dim().map_err(nifti_error)?.to_vec();
    if dim.len() < 3 || dim.len() > 4 || (dim.len() == 4 && dim[3] != 1) {
        return Err(parse(format!(
            "NIfTI: expected a 3-D volume, found dimensions {dim:?}"
        )));
    }
    let shape = [dim[0] as usize, dim[1] as usize, dim[2] as usize];
    let limit = if in_memory { MAX_SAMPLES } else { usize::MAX };
    checked_samples(shape, limit)
        .ok_or_else(|| parse(format!("shape {shape:?} is empty or too large")))?;
    let datatype = header.data_type().map_err(nifti_error)?;
    let sample = datatype.size_of() as u64;
    if u64::from(header.bitpix.unsigned_abs()) != 8 * sample {
        return Err(parse(format!(
            "NIfTI: {} bits per sample do not match the data type {datatype:?}",
            header.bitpix
        )));
    }
    let offset = header.vox_offset;
    if !(offset >= NIFTI_HEADER_BYTES as f32 + 4.0 && offset <= MAX_NIFTI_OFFSET) {
        return Err(parse(format!(
            "NIfTI: the samples' offset {offset} is not from 352 to {MAX_NIFTI_OFFSET}"
        )));
    }
    Ok(NiftiLayout {
        shape,
        datatype,
        sample,
        offset: offset as u64,
    })
}

/// The universe of `level`, checked to hold a volume of `shape` samples placed at `offset`.
pub(super) fn placed_universe(
    shape: [usize; 3],
    level: u32,
    offset: [u32; 3],
) -> Result<Universe<3>, SolidError> {
    let universe = Universe::<3>::new(level)?;
    let side = universe.side();
    if (0..3).any(|a| u64::from(offset[a]) + shape[a] as u64 > side) {
        return Err(SolidError::BadParameter(format!(
            "the volume ({shape:?} samples at offset {offset:?}) does not fit a level-{level} universe of side {side}"
        )));
    }
    Ok(universe)
}

/// A NIfTI stream opened: gzip-compressed or not (told by its magic), its header read and checked
/// ([`nifti_layout`]), the stream left just past the header's 348 bytes.
pub(super) struct NiftiStream<'a> {
    /// The rest of the (inflated) stream.
    pub(super) input: Box<dyn Read + 'a>,
    /// The header's bytes as read.
    pub(super) header_bytes: Vec<u8>,
    pub(super) header: nifti::NiftiHeader,
    pub(super) layout: NiftiLayout,
}

/// Opens the NIfTI stream `input` of `file` ([`NiftiStream`]); `in_memory` as for [`nifti_layout`].
pub(super) fn open_nifti_stream<'a>(
    mut input: impl BufRead + 'a,
    file: &Path,
    in_memory: bool,
) -> Result<NiftiStream<'a>, SolidError> {
    let parse = |what: String| SolidError::Parse {
        path: file.to_path_buf(),
        what,
    };
    let gz = input
        .fill_buf()
        .map_err(|e| parse(format!("NIfTI: {e}")))?
        .starts_with(&[0x1f, 0x8b]);
    let mut input: Box<dyn Read + 'a> = if gz {
        Box::new(flate2::bufread::GzDecoder::new(input))
    } else {
        Box::new(input)
    };
    let mut header_bytes = Vec::new();
    (&mut input)
        .take(NIFTI_HEADER_BYTES)
        .read_to_end(&mut header_bytes)
        .map_err(|e| parse(format!("NIfTI: {e}")))?;
    let header = nifti::NiftiHeader::from_reader(&header_bytes[..])
        .map_err(|e| parse(format!("NIfTI: {e}")))?;
    let layout = nifti_layout(&header, file, in_memory)?;
    Ok(NiftiStream {
        input,
        header_bytes,
        header,
        layout,
    })
}

/// Appends the samples packed in `bytes` as `dtype` (a raw sidecar's type name), big-endian when `big`, to
/// `out`; a trailing partial sample is ignored.
pub(super) fn decode_into(dtype: &str, big: bool, bytes: &[u8], out: &mut Vec<f64>) {
    macro_rules! num {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            out.extend(bytes.chunks_exact(N).map(|c| {
                let b: [u8; N] = c.try_into().unwrap_or_default();
                let v = if big {
                    <$t>::from_be_bytes(b)
                } else {
                    <$t>::from_le_bytes(b)
                };
                #[allow(clippy::cast_lossless)]
                let v = v as f64;
                v
            }))
        }};
    }
    match dtype {
        "uint8" => num!(u8),
        "int8" => num!(i8),
        "uint16" => num!(u16),
        "int16" => num!(i16),
        "uint32" => num!(u32),
        "int32" => num!(i32),
        "float32" => num!(f32),
        _ => num!(f64),
    }
}
