//! Dense 3-D scalar volumes (CT, MRI) to rays by a threshold or a label.
//!
//! Formats: headerless raw samples with a JSON sidecar (the layout of `data/volumes`: `shape_xyz`,
//! `dtype` one of `uint8 int8 uint16 int16 uint32 int32 float32 float64`, `endianness`, x fastest), and NIfTI-1
//! (`.nii`, `.nii.gz`, read with the `nifti` crate; the stored values are rescaled by `scl_slope`/`scl_inter`
//! as NIfTI prescribes). Volume voxel `(i, j, k)` becomes universe voxel `offset + (i, j, k)`, unscaled.
//!
//! The cost is one pass over the samples (a dense input has to be read anyway) plus the rays.
//! [`VolumeSource`] gives the same runs one slab of columns at a time, so that a tree can be built out of
//! core without holding the whole ray set.
//!
//! ```
//! use ktree::solid::volume::{Select, Volume};
//! use std::path::Path;
//! let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/volumes/itk_t1_brain.json");
//! let brain = Volume::read(&path).unwrap(); // 128 × 128 × 62 samples
//! assert_eq!(brain.fitting_level(), 7);
//! let rays = brain.to_rays(7, [0, 0, 0], Select::AtLeast(1.0)).unwrap();
//! assert_eq!(rays.voxel_count(), brain.count(Select::AtLeast(1.0)) as u128);
//! ```

use std::borrow::Cow;
use std::convert::Infallible;
use std::ops::Range;
use std::path::Path;

use super::volume_format::{
    check_window, checked_samples, label_of, open_nifti_stream, placed_universe,
    smallest_label_type, NiftiStream, RawLayout,
};
use super::SolidError;
use crate::rays::{ColumnKeys, Ray, RaySet, RaySource, SlabRuns, ValueRuns};
use crate::space::Universe;
use crate::value::{Dtype, Value};

/// Which samples are inside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Select {
    /// `value ≥ threshold`.
    AtLeast(f64),
    /// `value == label` (segmentation labels).
    Label(f64),
}

impl Select {
    fn test(&self, v: f64) -> bool {
        match *self {
            Select::AtLeast(t) => v >= t,
            Select::Label(l) => v == l,
        }
    }
}

/// A dense scalar volume, samples x fastest; its shape and samples are checked to agree when made.
///
/// ```
/// use ktree::solid::volume::{Select, Volume};
/// let v = Volume::new([2, 1, 3], vec![0.0, 9.0, 0.0, 9.0, 9.0, 9.0], [1.0; 3]).unwrap();
/// assert_eq!(v.count(Select::AtLeast(5.0)), 4);
/// let rays = v.to_rays(2, [0, 0, 0], Select::AtLeast(5.0)).unwrap();
/// assert_eq!(rays.voxel_count(), 4);
/// assert!(Volume::new([2, 2, 2], vec![0.0; 7], [1.0; 3]).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Volume {
    shape: [usize; 3],
    values: Vec<f64>,
    spacing: [f64; 3],
}

/// Largest number of samples accepted (checked before allocating).
pub const MAX_SAMPLES: usize = 1 << 31;
impl Volume {
    /// The volume of the raw samples `bytes` laid out as `layout` says (their length checked).
    fn from_layout(layout: &RawLayout, bytes: &[u8]) -> Self {
        Self {
            shape: layout.shape(),
            values: layout.decode(bytes),
            spacing: layout.spacing(),
        }
    }

    /// Reads a volume: a `.json` sidecar (or the `.raw` beside one) or a NIfTI file (`.nii`, `.nii.gz`).
    ///
    /// # Errors
    /// [`SolidError::Io`] or [`SolidError::Parse`] naming the file and what is wrong.
    pub fn read(path: &Path) -> Result<Self, SolidError> {
        let name = path.to_string_lossy().to_ascii_lowercase();
        if name.ends_with(".nii") || name.ends_with(".nii.gz") {
            Self::read_nifti(path)
        } else if name.ends_with(".json") {
            Self::read_raw(path)
        } else if name.ends_with(".raw") {
            Self::read_raw(&path.with_extension("json"))
        } else {
            Err(SolidError::Parse {
                path: path.to_path_buf(),
                what: "unknown volume format (known: .json sidecar with .raw, .nii, .nii.gz)"
                    .into(),
            })
        }
    }

    /// Reads raw samples described by a JSON sidecar (the raw file is the sidecar's `file`, or the same name
    /// with `.raw`). The raw file's length is checked against the sidecar's shape before it is read.
    ///
    /// # Errors
    /// As [`Volume::read`].
    pub fn read_raw(json: &Path) -> Result<Self, SolidError> {
        let text = std::fs::read(json).map_err(|source| SolidError::Io {
            path: json.to_path_buf(),
            source,
        })?;
        let layout = RawLayout::parse(&text, json)?;
        let raw = layout.raw_file(json);
        let got = std::fs::metadata(&raw)
            .map_err(|source| SolidError::Io {
                path: raw.clone(),
                source,
            })?
            .len();
        layout.check_length(got, &raw)?;
        let bytes = std::fs::read(&raw).map_err(|source| SolidError::Io {
            path: raw.clone(),
            source,
        })?;
        layout.check_length(bytes.len() as u64, &raw)?;
        Ok(Self::from_layout(&layout, &bytes))
    }

    /// Decodes raw samples held in memory, described by the bytes of a JSON sidecar (its `file` field is
    /// ignored); `file` names the input in errors. [`Volume::read_raw`] reads the files and calls the same
    /// checks.
    ///
    /// ```
    /// use std::path::Path;
    /// use ktree::solid::volume::Volume;
    /// let sidecar = br#"{"shape_xyz": [2, 1, 1], "dtype": "uint16", "endianness": "big"}"#;
    /// let v = Volume::from_raw_bytes(sidecar, &[0, 7, 1, 0], Path::new("mem.json")).unwrap();
    /// assert_eq!(v.values(), [7.0, 256.0]);
    /// assert!(Volume::from_raw_bytes(sidecar, &[0, 7], Path::new("mem.json")).is_err());
    /// ```
    ///
    /// # Errors
    /// [`SolidError::Parse`] for a bad sidecar or a sample count that does not match its shape.
    pub fn from_raw_bytes(sidecar: &[u8], raw: &[u8], file: &Path) -> Result<Self, SolidError> {
        let layout = RawLayout::parse(sidecar, file)?;
        layout.check_length(raw.len() as u64, file)?;
        Ok(Self::from_layout(&layout, raw))
    }

    /// Reads a NIfTI-1 file with the `nifti` crate (3-D volumes only; a 4-D file with one time point is
    /// accepted): the file's bytes go to [`Volume::from_nifti_bytes`].
    ///
    /// # Errors
    /// As [`Volume::read`].
    pub fn read_nifti(path: &Path) -> Result<Self, SolidError> {
        let bytes = std::fs::read(path).map_err(|source| SolidError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_nifti_bytes(&bytes, path)
    }

    /// Parses a single-file NIfTI-1 volume (`.nii`, or gzip-compressed `.nii.gz`, told by the gzip magic)
    /// held in memory; `file` names the input in errors. The header's shape is checked against
    /// [`MAX_SAMPLES`] and against the bytes present before the samples are allocated.
    ///
    /// # Errors
    /// [`SolidError::Parse`] naming `file` and what is wrong.
    pub fn from_nifti_bytes(bytes: &[u8], file: &Path) -> Result<Self, SolidError> {
        use nifti::{NiftiObject, RandomAccessNiftiVolume};
        use std::io::Read;
        let parse = |what: String| SolidError::Parse {
            path: file.to_path_buf(),
            what,
        };
        let nifti_error = |e: nifti::NiftiError| parse(format!("NIfTI: {e}"));
        let io_error = |e: std::io::Error| parse(format!("NIfTI: {e}"));
        // The header, then exactly the bytes it describes (never more: a compressed file is inflated only as
        // far as the header's own claim, which is bounded by MAX_SAMPLES).
        let NiftiStream {
            mut input,
            header_bytes: mut data,
            header,
            layout,
        } = open_nifti_stream(bytes, file, true)?;
        let (shape, n) = (layout.shape, layout.shape.iter().product::<usize>());
        let dim = header.dim().map_err(nifti_error)?.to_vec();
        let (offset, sample) = (layout.offset, layout.sample);
        let need = offset + n as u64 * sample;
        (&mut input)
            .take(need - data.len() as u64)
            .read_to_end(&mut data)
            .map_err(io_error)?;
        if (data.len() as u64) < need {
            return Err(parse(format!(
                "NIfTI: {} bytes, but the header describes {need}: truncated",
                data.len()
            )));
        }
        let obj = nifti::InMemNiftiObject::from_reader(&data[..]).map_err(nifti_error)?;
        drop(data);
        let pix = obj.header().pixdim;
        let vol = obj.into_volume();
        let mut values = Vec::with_capacity(n);
        let mut coords = vec![0u16; dim.len()];
        for z in 0..dim[2] {
            for y in 0..dim[1] {
                for x in 0..dim[0] {
                    coords[0] = x;
                    coords[1] = y;
                    coords[2] = z;
                    values.push(vol.get_f64(&coords).map_err(nifti_error)?);
                }
            }
        }
        Ok(Self {
            shape,
            values,
            spacing: [f64::from(pix[1]), f64::from(pix[2]), f64::from(pix[3])],
        })
    }

    /// A volume of `shape` samples along x, y, z, `values` x fastest (`offset = x + nx·(y + ny·z)`), voxel
    /// size `spacing` (informative only).
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] when the shape is empty or beyond 2^20 samples an axis or 2^31 in all,
    /// or `values` does not hold exactly one sample per voxel of the shape.
    pub fn new(shape: [usize; 3], values: Vec<f64>, spacing: [f64; 3]) -> Result<Self, SolidError> {
        let n = checked_samples(shape, MAX_SAMPLES).ok_or_else(|| {
            SolidError::BadParameter(format!("volume shape {shape:?} is empty or too large"))
        })?;
        if values.len() != n {
            return Err(SolidError::BadParameter(format!(
                "volume shape {shape:?} needs {n} samples, {} given",
                values.len()
            )));
        }
        Ok(Self {
            shape,
            values,
            spacing,
        })
    }

    /// Samples along x, y, z.
    pub fn shape(&self) -> [usize; 3] {
        self.shape
    }

    /// The samples (converted to `f64`), x fastest: `offset = x + nx·(y + ny·z)`.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Voxel size in mm where known (informative only).
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// The number of selected samples.
    pub fn count(&self, select: Select) -> usize {
        self.values.iter().filter(|&&v| select.test(v)).count()
    }

    /// The smallest level whose universe holds the volume.
    pub fn fitting_level(&self) -> u32 {
        let m = self.shape.iter().copied().max().unwrap_or(1).max(1);
        m.next_power_of_two().trailing_zeros()
    }

    /// The selected samples as rays along z, the volume's voxel `(i, j, k)` at universe voxel `offset + (i, j, k)`.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level; [`SolidError::BadParameter`] if the volume does not fit.
    pub fn to_rays(
        &self,
        level: u32,
        offset: [u32; 3],
        select: Select,
    ) -> Result<RaySet<3>, SolidError> {
        let universe = self.placed(level, offset)?;
        let (columns, runs) = self.slab_runs(level, offset, select, 0..universe.side());
        Ok(RaySet::from_sorted_parts(universe, columns, runs, None))
    }

    /// The smallest label type that holds every sample as a label: `uint8`, `uint16` or `uint32`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] naming the first sample that is not a label (a non-negative integer up
    /// to `u32::MAX`), with its `(x, y, z)`.
    pub fn label_dtype(&self) -> Result<Dtype, SolidError> {
        let mut largest = 0u32;
        for (i, &v) in self.values.iter().enumerate() {
            largest = largest.max(label_of::<u32>(self.position(i), v)?);
        }
        Ok(smallest_label_type(largest))
    }

    /// The `(x, y, z)` of sample `i`.
    fn position(&self, i: usize) -> [usize; 3] {
        let [nx, ny, _] = self.shape;
        [i % nx, i / nx % ny, i / (nx * ny)]
    }

    /// The samples as labels of type `V`, placed at `offset` in a universe of level `level`: each run of
    /// equal non-zero samples along z one valued run; 0 is the background (empty).
    ///
    /// ```
    /// use ktree::solid::volume::Volume;
    /// use ktree::KTree;
    /// let v = Volume::new([2, 1, 2], vec![0.0, 3.0, 7.0, 3.0], [1.0; 3]).unwrap();
    /// let tree = KTree::from_value_runs(&v.to_label_runs::<u8>(1, [0, 0, 0]).unwrap());
    /// assert_eq!(tree.value_at([1, 0, 1]), Some(3));
    /// assert_eq!(tree.value_at([0, 0, 0]), None);
    /// ```
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for a sample that is not a label of `V` (naming it) or a volume that
    /// does not fit; [`SolidError::Space`] for a bad level.
    pub fn to_label_runs<V: Value + TryFrom<u32>>(
        &self,
        level: u32,
        offset: [u32; 3],
    ) -> Result<ValueRuns<3, V>, SolidError> {
        self.to_value_runs(level, offset, |i, v| {
            if v == 0.0 {
                return Ok(None);
            }
            label_of::<V>(self.position(i), v).map(Some)
        })
    }

    /// The samples from `lo` to `hi` (both included) as `f32` values, placed at `offset` in a universe
    /// of level `level`; every other sample (and a NaN) is the background. A CT's window of intensities
    /// kept as they are, the rest of the scan left out.
    ///
    /// ```
    /// use ktree::solid::volume::Volume;
    /// use ktree::KTree;
    /// let v = Volume::new([2, 1, 2], vec![0.5, 3.0, 7.25, 3.0], [1.0; 3]).unwrap();
    /// let tree = KTree::from_value_runs(&v.to_window_runs(1, [0, 0, 0], 1.0, 8.0).unwrap());
    /// assert_eq!(tree.value_at([0, 0, 1]), Some(7.25));
    /// assert_eq!(tree.value_at([0, 0, 0]), None); // 0.5 is below the window
    /// ```
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for a window that is empty, not finite, or a volume that does not fit;
    /// [`SolidError::Space`] for a bad level.
    pub fn to_window_runs(
        &self,
        level: u32,
        offset: [u32; 3],
        lo: f64,
        hi: f64,
    ) -> Result<ValueRuns<3, f32>, SolidError> {
        check_window(lo, hi)?;
        self.to_value_runs(level, offset, |_, v| {
            Ok((lo <= v && v <= hi).then_some(v as f32))
        })
    }

    /// The samples as valued runs along z, placed at `offset`: `value_of(index, sample)` gives each
    /// sample's value (`None`: the background); runs of equal values are joined.
    fn to_value_runs<V: Value>(
        &self,
        level: u32,
        offset: [u32; 3],
        value_of: impl Fn(usize, f64) -> Result<Option<V>, SolidError>,
    ) -> Result<ValueRuns<3, V>, SolidError> {
        self.placed(level, offset)?;
        let [nx, ny, nz] = self.shape;
        let mut runs = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                let mut current: Option<(usize, V)> = None;
                for z in 0..=nz {
                    let value = if z < nz {
                        let i = x + nx * (y + ny * z);
                        value_of(i, self.values[i])?
                    } else {
                        None
                    };
                    match (current, value) {
                        (Some((_, a)), Some(b)) if a.same(b) => continue,
                        (Some((start, a)), _) => {
                            let p = [
                                offset[0] + x as u32,
                                offset[1] + y as u32,
                                offset[2] + start as u32,
                            ];
                            runs.push((Ray::new(p, offset[2] + z as u32), a));
                        }
                        (None, _) => {}
                    }
                    current = value.map(|v| (z, v));
                }
            }
        }
        ValueRuns::from_runs(level, runs).map_err(|e| SolidError::BadParameter(e.to_string()))
    }

    /// The universe of level `level`, checked to hold the volume at `offset`.
    fn placed(&self, level: u32, offset: [u32; 3]) -> Result<Universe<3>, SolidError> {
        placed_universe(self.shape, level, offset)
    }

    /// The column keys and runs of the universe columns whose axis-0 coordinate lies in `x`, in
    /// [`RaySet`] order (the volume placed at `offset`, checked to fit).
    fn slab_runs(
        &self,
        level: u32,
        offset: [u32; 3],
        select: Select,
        x: Range<u64>,
    ) -> (Vec<u64>, Vec<(u32, u32)>) {
        let [nx, ny, nz] = self.shape;
        let first = x.start.saturating_sub(u64::from(offset[0])).min(nx as u64) as usize;
        let last = x.end.saturating_sub(u64::from(offset[0])).min(nx as u64) as usize;
        let mut columns = Vec::new();
        let mut runs = Vec::new();
        for x in first..last {
            for y in 0..ny {
                let key = ColumnKeys::<3>::new(level).pack([
                    offset[0] + x as u32,
                    offset[1] + y as u32,
                    0,
                ]);
                let mut start = None;
                for z in 0..=nz {
                    let inside = z < nz && select.test(self.values[x + nx * (y + ny * z)]);
                    match (start, inside) {
                        (None, true) => start = Some(z),
                        (Some(s), false) => {
                            columns.push(key);
                            runs.push((offset[2] + s as u32, offset[2] + z as u32));
                            start = None;
                        }
                        _ => {}
                    }
                }
            }
        }
        (columns, runs)
    }
}

/// A volume placed in a universe with a selection, producing its rays slab by slab for
/// [`Builder::to_file`](crate::stacking::Builder::to_file) and [`Builder::build`](crate::stacking::Builder::build):
/// each slab's runs come from the volume's samples in that slab alone, and equal the runs of that slab in
/// [`Volume::to_rays`]. No whole ray set is held.
///
/// ```
/// use ktree::solid::volume::{Select, Volume, VolumeSource};
/// use ktree::stacking::{paper::stack, Builder};
/// let v = Volume::new([3, 2, 2], vec![0.0, 9.0, 9.0, 9.0, 0.0, 9.0, 9.0, 9.0, 9.0, 0.0, 0.0, 9.0], [1.0; 3]).unwrap();
/// let whole = v.to_rays(3, [1, 2, 3], Select::AtLeast(5.0)).unwrap();
/// let source = VolumeSource::new(v, 3, [1, 2, 3], Select::AtLeast(5.0)).unwrap();
/// assert_eq!(Builder::new(&source).split_depth(1).build().unwrap(), stack(&whole));
/// ```
#[derive(Debug, Clone)]
pub struct VolumeSource {
    volume: Volume,
    universe: Universe<3>,
    offset: [u32; 3],
    select: Select,
}

impl VolumeSource {
    /// The samples of `volume` chosen by `select`, its sample `(i, j, k)` at voxel `offset + (i, j, k)` of a
    /// universe of level `level` (as [`Volume::to_rays`]).
    ///
    /// # Errors
    /// As [`Volume::to_rays`].
    pub fn new(
        volume: Volume,
        level: u32,
        offset: [u32; 3],
        select: Select,
    ) -> Result<Self, SolidError> {
        let universe = volume.placed(level, offset)?;
        Ok(Self {
            volume,
            universe,
            offset,
            select,
        })
    }

    /// The volume.
    pub fn volume(&self) -> &Volume {
        &self.volume
    }

    /// The bytes the source holds: the volume's samples.
    pub fn heap_bytes(&self) -> u64 {
        std::mem::size_of_val(self.volume.values()) as u64
    }
}

impl RaySource<3> for VolumeSource {
    type Error = Infallible;

    fn universe(&self) -> Universe<3> {
        self.universe
    }

    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, Infallible> {
        let (keys, runs) = self.volume.slab_runs(
            self.universe.level(),
            self.offset,
            self.select,
            u64::from(x.start)..u64::from(x.end),
        );
        Ok(SlabRuns {
            keys: Cow::Owned(keys),
            runs: Cow::Owned(runs),
        })
    }

    /// The slabs that meet the volume's extent along axis 0.
    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        let t = self.universe.level() - m.min(self.universe.level());
        let lo = self.offset[0] >> t;
        let hi = (u64::from(self.offset[0]) + self.volume.shape[0] as u64 - 1) >> t;
        (lo..=hi as u32).collect()
    }
}
