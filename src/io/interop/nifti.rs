//! NIfTI-1 volumes out: an octree's universe written as a dense NIfTI volume (`.nii`, or gzip-compressed
//! `.nii.gz`), with the values of a valued tree as the samples — labels as `uint8`/`uint16`/`uint32`/`int8`,
//! densities as `float32`, colours as `RGB24` — and a tree without values as `uint8` 0/1. Empty voxels are
//! 0 (black for colours). The file is written by the `nifti` crate; volumes are read back by
//! [`crate::solid::volume::Volume`].
//!
//! Placement: sample `(i, j, k)` is ktree voxel `(i, j, k)` of the universe (side `2^L` on every axis);
//! `pixdim` is the voxel size and the `qform` and `sform` (code 1, scanner coordinates) put the centre of
//! voxel `(i, j, k)` at `origin + voxel_size · (i + ½, j + ½, k + ½)`, as NIfTI's affine maps indices
//! to voxel centres.

use std::path::{Path, PathBuf};

use nifti::writer::WriterOptions;
use nifti::NiftiHeader;

use crate::space::WorldFrame;
use crate::tree::KTree;
use crate::value::{Dtype, Value};

/// NIfTI's largest side: its dimensions are 16-bit signed numbers.
const MAX_SIDE: u64 = i16::MAX as u64;

/// Largest volume written: 2^31 samples (a level 10 universe has 2^30).
const MAX_SAMPLES: u64 = 1 << 31;

/// Why a NIfTI file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum NiftiWriteError {
    /// The universe is too large for a dense NIfTI volume.
    #[error("{path}: a universe of side {side} is too large for a NIfTI volume (at most {max} samples, sides up to {MAX_SIDE})", path = .path.display(), max = MAX_SAMPLES)]
    TooLarge {
        /// The output.
        path: PathBuf,
        /// The universe's side.
        side: u64,
    },
    /// The `nifti` crate or the file system failed.
    #[error("{path}: cannot write the NIfTI file", path = .path.display())]
    Write {
        /// The output.
        path: PathBuf,
        /// What failed.
        #[source]
        source: nifti::NiftiError,
    },
    /// The written file could not be moved into place.
    #[error("{path}: cannot move the written file into place", path = .path.display())]
    Rename {
        /// The output.
        path: PathBuf,
        /// What failed.
        #[source]
        source: std::io::Error,
    },
}

/// Writes `tree`'s universe as a NIfTI-1 volume at `path` (gzip-compressed when the name ends with
/// `.gz`), placed in the world by `frame`. The file appears whole or not at all (written beside it, then
/// renamed).
///
/// ```
/// use ktree::io::write_nifti_file;
/// use ktree::space::WorldFrame;
/// use ktree::solid::volume::Volume;
/// use ktree::KTree;
/// let dir = std::env::temp_dir().join(format!("ktree-nifti-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let mut dense = vec![None; 8];
/// dense[5] = Some(7u16); // voxel (1, 0, 1)
/// let tree = KTree::<3, u16>::from_dense_values(1, &dense).unwrap();
/// let path = dir.join("labels.nii");
/// write_nifti_file(&path, &tree, &WorldFrame::default()).unwrap();
/// let back = Volume::read(&path).unwrap();
/// assert_eq!(back.shape(), [2, 2, 2]);
/// assert_eq!(back.values()[1 + 2 * (0 + 2 * 1)], 7.0);
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
///
/// # Errors
/// [`NiftiWriteError::TooLarge`] before allocating for a universe of more than 2^31 voxels;
/// [`NiftiWriteError::Write`] / [`NiftiWriteError::Rename`] naming the file.
pub fn write_nifti_file<V: Value>(
    path: &Path,
    tree: &KTree<3, V>,
    frame: &WorldFrame,
) -> Result<(), NiftiWriteError> {
    let side = tree.universe().side();
    if side > MAX_SIDE || side.pow(3) > MAX_SAMPLES {
        return Err(NiftiWriteError::TooLarge {
            path: path.to_owned(),
            side,
        });
    }
    let n = side as usize;
    let header = header(frame);
    let temp = temporary_beside(path);
    let options = WriterOptions::new(&temp).reference_header(&header);
    let written = match V::DTYPE {
        None => options.write_nifti(&filled(tree, n, 0u8, |_| 1u8)),
        Some(Dtype::U8) => options.write_nifti(&filled(tree, n, 0u8, |v| le::<V, 1>(v)[0])),
        Some(Dtype::I8) => options.write_nifti(&filled(tree, n, 0i8, |v| le::<V, 1>(v)[0] as i8)),
        Some(Dtype::U16) => options.write_nifti(&filled(tree, n, 0u16, |v| {
            u16::from_le_bytes(le::<V, 2>(v))
        })),
        Some(Dtype::U32) => options.write_nifti(&filled(tree, n, 0u32, |v| {
            u32::from_le_bytes(le::<V, 4>(v))
        })),
        Some(Dtype::F32) => options.write_nifti(&filled(tree, n, 0f32, |v| {
            f32::from_le_bytes(le::<V, 4>(v))
        })),
        Some(Dtype::Rgb) => options.write_rgb_nifti(&filled(tree, n, [0u8; 3], le::<V, 3>)),
    };
    let finish = written
        .map_err(|source| NiftiWriteError::Write {
            path: path.to_owned(),
            source,
        })
        .and_then(|()| {
            std::fs::rename(&temp, path).map_err(|source| NiftiWriteError::Rename {
                path: path.to_owned(),
                source,
            })
        });
    if finish.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    finish
}

/// The header fields the writer copies: voxel size, units and the two affines.
fn header(frame: &WorldFrame) -> NiftiHeader {
    let s = frame.voxel_size as f32;
    let centre = frame.origin.map(|o| (o + frame.voxel_size / 2.0) as f32);
    let mut descrip = b"ktree".to_vec();
    descrip.resize(80, 0);
    NiftiHeader {
        pixdim: [1.0, s, s, s, 0.0, 0.0, 0.0, 0.0],
        xyzt_units: 2, // millimetres: NIfTI's usual unit; the numbers are the frame's
        qform_code: 1,
        sform_code: 1,
        quatern_b: 0.0,
        quatern_c: 0.0,
        quatern_d: 0.0,
        quatern_x: centre[0],
        quatern_y: centre[1],
        quatern_z: centre[2],
        srow_x: [s, 0.0, 0.0, centre[0]],
        srow_y: [0.0, s, 0.0, centre[1]],
        srow_z: [0.0, 0.0, s, centre[2]],
        descrip,
        ..NiftiHeader::default()
    }
}

/// The universe as an `n × n × n` array indexed `[x, y, z]`: `empty` where no value, `sample(v)` in each
/// full leaf.
fn filled<V: Value, A: Copy>(
    tree: &KTree<3, V>,
    n: usize,
    empty: A,
    sample: impl Fn(V) -> A,
) -> ndarray::Array3<A> {
    let mut grid = ndarray::Array3::from_elem((n, n, n), empty);
    for (cell, value) in tree.value_leaves() {
        let Some(v) = value else { continue };
        let a = sample(v);
        let o = cell.origin().map(|c| c as usize);
        let side = cell.side() as usize;
        grid.slice_mut(ndarray::s![
            o[0]..o[0] + side,
            o[1]..o[1] + side,
            o[2]..o[2] + side
        ])
        .fill(a);
    }
    grid
}

/// A value's `N` little-endian bytes (`N` is its dtype's width).
fn le<V: Value, const N: usize>(v: V) -> [u8; N] {
    let mut bytes = Vec::with_capacity(N);
    v.write_le(&mut bytes);
    let mut out = [0u8; N];
    out.copy_from_slice(&bytes);
    out
}

/// A name beside `path` for writing before the rename, ending in `.nii` or `.nii.gz` (which tells the
/// writer whether to compress) with no other dot (the writer replaces the last extension).
fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(Default::default, |n| n.to_string_lossy().into_owned());
    let gz = name.ends_with(".gz");
    path.with_file_name(format!(
        "_{}-{}-partial.nii{}",
        name.replace('.', "-"),
        std::process::id(),
        if gz { ".gz" } else { "" }
    ))
}
