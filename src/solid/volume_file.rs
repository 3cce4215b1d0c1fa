//! A volume file read plane by plane along z, front to back, without holding its samples: the input of a
//! tree of labels built slab by slab ([`KTree::from_value_slabs`]) from a volume larger than memory.
//!
//! The formats and the samples' values are those of [`Volume`](super::volume::Volume): raw samples with a
//! JSON sidecar (the raw file's length checked against the sidecar before anything is read), and NIfTI-1
//! (`.nii`, or `.nii.gz` told by the gzip magic, inflated as it is read; the header checked as
//! [`Volume::read_nifti`](super::volume::Volume::read_nifti) checks it, the samples rescaled by
//! `scl_slope`/`scl_inter` by the `nifti` crate's own decoding). A volume read here may hold more than
//! [`MAX_SAMPLES`](super::volume::MAX_SAMPLES) samples; one plane may not. A plane's memory is taken as its
//! bytes arrive, so a damaged header claiming a huge volume costs only what the file holds.
//!
//! ```
//! use ktree::solid::volume::Volume;
//! use ktree::solid::volume_file::{label_tree, VolumeFile};
//! use std::path::Path;
//! let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/volumes/itk_t1_brain.json");
//! let file = VolumeFile::open(&path).unwrap();
//! assert_eq!(file.shape(), [128, 128, 62]);
//! // The brain's intensities up to 255 taken as labels, read 1 MiB at a time.
//! let tree = label_tree::<u8>(&path, 7, [0, 0, 0], 1 << 20).unwrap();
//! let volume = Volume::read(&path).unwrap();
//! assert_eq!(tree, ktree::KTree::from_value_runs(&volume.to_label_runs::<u8>(7, [0, 0, 0]).unwrap()));
//! ```

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use super::volume_format::{
    check_window, decode_into, label_of, open_nifti_stream, placed_universe, smallest_label_type,
    NiftiStream, RawLayout,
};
use super::SolidError;
use crate::rays::RayError;
use crate::value::{Dtype, Value};
use crate::KTree;

/// Largest number of samples in one plane (checked before a plane is allocated).
pub const MAX_PLANE_SAMPLES: usize = 1 << 31;

/// How a plane's bytes become samples.
enum Samples {
    /// A raw file's type name, sample size and byte order.
    Raw {
        dtype: String,
        size: usize,
        big: bool,
    },
    /// A NIfTI file's data type, byte order and scaling.
    Nifti {
        datatype: nifti::NiftiType,
        size: usize,
        endianness: nifti::Endianness,
        slope: f32,
        inter: f32,
    },
}

/// A volume file open for reading its planes along z in order.
pub struct VolumeFile {
    path: PathBuf,
    shape: [usize; 3],
    spacing: [f64; 3],
    samples: Samples,
    input: Box<dyn Read>,
    planes_read: usize,
    bytes: Vec<u8>,
}

impl std::fmt::Debug for VolumeFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VolumeFile")
            .field("path", &self.path)
            .field("shape", &self.shape)
            .field("planes_read", &self.planes_read)
            .finish_non_exhaustive()
    }
}

impl VolumeFile {
    /// Opens a volume: a `.json` sidecar (or the `.raw` beside one) or a NIfTI file (`.nii`, `.nii.gz`),
    /// its header read and checked.
    ///
    /// # Errors
    /// [`SolidError::Io`] or [`SolidError::Parse`] naming the file and what is wrong.
    pub fn open(path: &Path) -> Result<Self, SolidError> {
        let name = path.to_string_lossy().to_ascii_lowercase();
        let file = if name.ends_with(".nii") || name.ends_with(".nii.gz") {
            Self::open_nifti(path)?
        } else if name.ends_with(".json") {
            Self::open_raw(path)?
        } else if name.ends_with(".raw") {
            Self::open_raw(&path.with_extension("json"))?
        } else {
            return Err(SolidError::Parse {
                path: path.to_path_buf(),
                what: "unknown volume format (known: .json sidecar with .raw, .nii, .nii.gz)"
                    .into(),
            });
        };
        let [nx, ny, _] = file.shape;
        if nx * ny > MAX_PLANE_SAMPLES {
            return Err(SolidError::Parse {
                path: file.path,
                what: format!("a plane of {nx} × {ny} samples is more than {MAX_PLANE_SAMPLES}"),
            });
        }
        Ok(file)
    }

    fn open_raw(json: &Path) -> Result<Self, SolidError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SolidError::Io { path, source }
        };
        let text = std::fs::read(json).map_err(io(json))?;
        let layout = RawLayout::parse_streamed(&text, json)?;
        let raw = layout.raw_file(json);
        let file = File::open(&raw).map_err(io(&raw))?;
        let got = file.metadata().map_err(io(&raw))?.len();
        layout.check_length(got, &raw)?;
        Ok(Self::new(
            raw,
            layout.shape(),
            layout.spacing(),
            Samples::Raw {
                dtype: layout.dtype().to_string(),
                size: layout.sample_bytes(),
                big: layout.big_endian(),
            },
            Box::new(BufReader::new(file)),
        ))
    }

    fn open_nifti(path: &Path) -> Result<Self, SolidError> {
        let parse = |what: String| SolidError::Parse {
            path: path.to_path_buf(),
            what,
        };
        let file = File::open(path).map_err(|source| SolidError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let NiftiStream {
            mut input,
            header_bytes,
            header,
            layout,
        } = open_nifti_stream(BufReader::new(file), path, false)?;
        // Past the header's extensions, to the first sample.
        let skip = layout.offset - header_bytes.len() as u64;
        let skipped = std::io::copy(&mut (&mut input).take(skip), &mut std::io::sink())
            .map_err(|e| parse(format!("NIfTI: {e}")))?;
        if skipped < skip {
            return Err(parse(format!(
                "NIfTI: {} bytes, but the samples start at byte {}: truncated",
                header_bytes.len() as u64 + skipped,
                layout.offset
            )));
        }
        Ok(Self::new(
            path.to_path_buf(),
            layout.shape,
            [
                f64::from(header.pixdim[1]),
                f64::from(header.pixdim[2]),
                f64::from(header.pixdim[3]),
            ],
            Samples::Nifti {
                datatype: layout.datatype,
                size: layout.sample as usize,
                endianness: header.endianness,
                slope: header.scl_slope,
                inter: header.scl_inter,
            },
            input,
        ))
    }

    fn new(
        path: PathBuf,
        shape: [usize; 3],
        spacing: [f64; 3],
        samples: Samples,
        input: Box<dyn Read>,
    ) -> Self {
        Self {
            path,
            shape,
            spacing,
            samples,
            input,
            planes_read: 0,
            bytes: Vec::new(),
        }
    }

    /// The samples along x, y and z.
    pub fn shape(&self) -> [usize; 3] {
        self.shape
    }

    /// The voxel size the file states (informative only).
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// Reads the next `count` planes along z (fewer if the volume ends first) and gives each sample to
    /// `each` with its position `[x, y, z]` in the volume, x fastest.
    ///
    /// # Errors
    /// [`SolidError::Parse`] naming the file and the plane where it ends early; the first error of `each`.
    pub fn read_planes(
        &mut self,
        count: usize,
        mut each: impl FnMut([usize; 3], f64) -> Result<(), SolidError>,
    ) -> Result<(), SolidError> {
        let [nx, _, nz] = self.shape;
        let mut plane = Vec::new();
        for _ in 0..count.min(nz - self.planes_read) {
            let z = self.planes_read;
            plane.clear();
            self.read_plane(&mut plane)?;
            for (i, &v) in plane.iter().enumerate() {
                each([i % nx, i / nx, z], v)?;
            }
        }
        Ok(())
    }

    /// Skips the next `count` planes along z (fewer if the volume ends first): their bytes are read and
    /// dropped.
    ///
    /// # Errors
    /// [`SolidError::Parse`] naming the file and the plane where it ends early.
    pub fn skip_planes(&mut self, count: usize) -> Result<(), SolidError> {
        let [nx, ny, nz] = self.shape;
        let size = match &self.samples {
            Samples::Raw { size, .. } | Samples::Nifti { size, .. } => *size,
        };
        let count = count.min(nz - self.planes_read);
        let want = (nx * ny * size) as u64 * count as u64;
        let z = self.planes_read;
        let skipped = std::io::copy(&mut (&mut self.input).take(want), &mut std::io::sink())
            .map_err(|e| SolidError::Parse {
                path: self.path.clone(),
                what: format!("planes z = {z} … {} cannot be read: {e}", z + count),
            })?;
        if skipped < want {
            return Err(SolidError::Parse {
                path: self.path.clone(),
                what: format!(
                    "plane z = {} (of {nz}) cannot be read: the file ends",
                    z + (skipped / (nx * ny * size).max(1) as u64) as usize
                ),
            });
        }
        self.planes_read += count;
        Ok(())
    }

    /// Reads the next plane's samples into `out`.
    fn read_plane(&mut self, out: &mut Vec<f64>) -> Result<(), SolidError> {
        let [nx, ny, nz] = self.shape;
        let z = self.planes_read;
        let size = match &self.samples {
            Samples::Raw { size, .. } | Samples::Nifti { size, .. } => *size,
        };
        // Read as the bytes arrive (never allocated ahead of them: a damaged header's claim of a huge
        // plane costs only the bytes the file holds).
        let want = (nx * ny * size) as u64;
        self.bytes.clear();
        let cannot = |what: String| SolidError::Parse {
            path: self.path.clone(),
            what: format!("plane z = {z} (of {nz}) cannot be read: {what}"),
        };
        (&mut self.input)
            .take(want)
            .read_to_end(&mut self.bytes)
            .map_err(|e| cannot(e.to_string()))?;
        if (self.bytes.len() as u64) < want {
            return Err(cannot(format!(
                "the file ends {} bytes into it, of {want}",
                self.bytes.len()
            )));
        }
        match &self.samples {
            Samples::Raw { dtype, big, .. } => {
                decode_into(dtype, *big, &self.bytes, out);
            }
            Samples::Nifti {
                datatype,
                endianness,
                slope,
                inter,
                ..
            } => {
                for (i, chunk) in self.bytes.chunks_exact(size).enumerate() {
                    let v = datatype
                        .read_primitive_value::<_, f64>(chunk, *endianness, *slope, *inter)
                        .map_err(|e| SolidError::Parse {
                            path: self.path.clone(),
                            what: format!("NIfTI: sample ({}, {}, {z}): {e}", i % nx, i / nx),
                        })?;
                    out.push(v);
                }
            }
        }
        self.planes_read += 1;
        Ok(())
    }

    /// The smallest label type (`uint8`, `uint16` or `uint32`) that holds every label of the volume, reading
    /// it to the end: every sample a whole number from 0 up.
    ///
    /// # Errors
    /// As [`VolumeFile::read_planes`]; [`SolidError::BadParameter`] naming the first sample that is not a
    /// label.
    pub fn label_dtype(mut self) -> Result<Dtype, SolidError> {
        let mut largest = 0u32;
        let nz = self.shape[2];
        self.read_planes(nz, |at, v| {
            largest = largest.max(label_of::<u32>(at, v)?);
            Ok(())
        })?;
        Ok(smallest_label_type(largest))
    }
}

/// The tree of the labels of the volume file at `path` placed at `offset` in a universe of level `level`
/// (each sample's label its value, 0 the background), read slab by slab along z in at most about
/// `slab_bytes` of labels at once ([`KTree::from_value_slabs`] of [`label_slabs`]): the same tree as
/// [`Volume::to_label_runs`](super::volume::Volume::to_label_runs) gives, without holding the volume.
///
/// # Errors
/// As [`VolumeFile::open`] and [`VolumeFile::read_planes`]; [`SolidError::BadParameter`] naming a sample
/// that is not a label of `V`, or a volume that does not fit the universe.
pub fn label_tree<V: Value + TryFrom<u32>>(
    path: &Path,
    level: u32,
    offset: [u32; 3],
    slab_bytes: usize,
) -> Result<KTree<3, V>, SolidError> {
    label_slabs::<V>(path, level, offset)?.tree(level, slab_bytes)
}

/// The tree of the samples from `lo` to `hi` (both included) of the volume file at `path`, as `f32`
/// values, every other sample (and a NaN) the background, read slab by slab as [`label_tree`] reads: the
/// same tree as [`Volume::to_window_runs`](super::volume::Volume::to_window_runs) gives.
///
/// ```
/// use ktree::solid::volume::Volume;
/// use ktree::solid::volume_file::window_tree;
/// use std::path::Path;
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/volumes/itk_t1_brain.json");
/// let tree = window_tree(&path, 7, [0, 0, 0], 100.0, 200.0, 1 << 16).unwrap();
/// let volume = Volume::read(&path).unwrap();
/// assert_eq!(tree, ktree::KTree::from_value_runs(&volume.to_window_runs(7, [0, 0, 0], 100.0, 200.0).unwrap()));
/// ```
///
/// # Errors
/// As [`label_tree`]; [`SolidError::BadParameter`] for a window that is empty or not finite.
pub fn window_tree(
    path: &Path,
    level: u32,
    offset: [u32; 3],
    lo: f64,
    hi: f64,
    slab_bytes: usize,
) -> Result<KTree<3, f32>, SolidError> {
    window_slabs(path, level, offset, lo, hi)?.tree(level, slab_bytes)
}

/// A volume file as a box of values read slab by slab along z: where it lies in the universe, the value
/// meaning empty, and its planes read in order as values by the rule `R` ([`Labels`], [`Window`]) — what
/// [`KTree::from_value_slabs`] (or `stacking::ValueSlabs`, which writes the tree to a file without
/// holding it) takes.
pub struct VolumeSlabs<V, R> {
    /// The box the volume fills (one range a coordinate, x first).
    pub region: [std::ops::Range<u32>; 3],
    /// The value meaning empty.
    pub background: V,
    file: VolumeFile,
    rule: R,
}

/// How a volume's samples become values: `value(position, sample)`, the background meaning empty.
pub trait SampleRule<V> {
    /// The value of the sample `sample` at `position`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] naming a sample the rule refuses.
    fn value(&self, position: [usize; 3], sample: f64) -> Result<V, SolidError>;
}

/// Each sample's label is its value (a whole number from 0 up that `V` holds; 0 the background).
pub struct Labels;

impl<V: Value + TryFrom<u32>> SampleRule<V> for Labels {
    #[inline]
    fn value(&self, position: [usize; 3], sample: f64) -> Result<V, SolidError> {
        label_of::<V>(position, sample)
    }
}

/// The samples from `lo` to `hi` (both included) kept as `f32` values, every other sample (and a NaN)
/// the background (NaN).
pub struct Window {
    lo: f64,
    hi: f64,
}

impl SampleRule<f32> for Window {
    #[inline]
    fn value(&self, _: [usize; 3], sample: f64) -> Result<f32, SolidError> {
        Ok(if self.lo <= sample && sample <= self.hi {
            sample as f32
        } else {
            f32::NAN
        })
    }
}

impl<V: Value, R: SampleRule<V>> VolumeSlabs<V, R> {
    /// Appends the values of the planes whose z (in the universe) is in `planes` to `out`, x fastest.
    /// Planes are read front to back: those before `planes` not read yet are skipped (read and dropped —
    /// a compressed file cannot seek), and a plane already read is not read again.
    ///
    /// # Errors
    /// As [`VolumeFile::read_planes`]; the rule's error; [`SolidError::BadParameter`] for planes before
    /// those already read.
    pub fn read(
        &mut self,
        planes: std::ops::Range<u32>,
        out: &mut Vec<V>,
    ) -> Result<(), SolidError> {
        let first = planes.start.saturating_sub(self.region[2].start) as usize;
        if first < self.file.planes_read {
            return Err(SolidError::BadParameter(format!(
                "{}: plane z = {first} was already read (planes are read front to back)",
                self.file.path.display()
            )));
        }
        self.file.skip_planes(first - self.file.planes_read)?;
        let rule = &self.rule;
        self.file.read_planes(planes.len(), |at, v| {
            out.push(rule.value(at, v)?);
            Ok(())
        })
    }

    /// The tree of the volume in a universe of level `level`, read in at most about `slab_bytes` of
    /// values at once.
    fn tree(mut self, level: u32, slab_bytes: usize) -> Result<KTree<3, V>, SolidError>
    where
        V: Send + Sync,
    {
        let (region, background) = (self.region.clone(), self.background);
        KTree::from_value_slabs(level, region, background, slab_bytes, |planes, out| {
            self.read(planes, out)
        })
        .map_err(|e: SolidError| match e {
            SolidError::Rays(RayError::Space(s)) => SolidError::Space(s),
            other => other,
        })
    }
}

/// The labels of the volume file at `path` placed at `offset` in a universe of level `level` as a box
/// read slab by slab (each sample's label its value, 0 the background): what [`label_tree`] builds.
///
/// # Errors
/// As [`VolumeFile::open`]; a volume that does not fit the universe. Its reader's: as
/// [`VolumeFile::read_planes`], and [`SolidError::BadParameter`] naming a sample that is not a label of `V`.
pub fn label_slabs<V: Value + TryFrom<u32>>(
    path: &Path,
    level: u32,
    offset: [u32; 3],
) -> Result<VolumeSlabs<V, Labels>, SolidError> {
    let background = label_of::<V>([0; 3], 0.0)?;
    volume_slabs(path, level, offset, background, Labels)
}

/// The samples from `lo` to `hi` (both included) of the volume file at `path` placed at `offset` as a box
/// of `f32` values read slab by slab, every other sample (and a NaN) the background: what [`window_tree`]
/// builds.
///
/// # Errors
/// As [`label_slabs`]; [`SolidError::BadParameter`] for a window that is empty or not finite.
pub fn window_slabs(
    path: &Path,
    level: u32,
    offset: [u32; 3],
    lo: f64,
    hi: f64,
) -> Result<VolumeSlabs<f32, Window>, SolidError> {
    check_window(lo, hi)?;
    // NaN is the background: no sample kept is one.
    volume_slabs(path, level, offset, f32::NAN, Window { lo, hi })
}

/// The volume file at `path` placed at `offset` as a box read slab by slab by `rule`.
fn volume_slabs<V, R>(
    path: &Path,
    level: u32,
    offset: [u32; 3],
    background: V,
    rule: R,
) -> Result<VolumeSlabs<V, R>, SolidError> {
    let file = VolumeFile::open(path)?;
    let shape = file.shape;
    placed_universe(shape, level, offset)?;
    Ok(VolumeSlabs {
        region: std::array::from_fn(|a| offset[a]..offset[a] + shape[a] as u32),
        background,
        file,
        rule,
    })
}
