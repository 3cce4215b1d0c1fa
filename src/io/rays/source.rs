//! A ray file read slab by slab: [`open_rays_file`] makes one pass over the file that checks every line
//! and that the runs are sorted as in a [`RaySet`](crate::RaySet) (by column, axis 0 most significant, then along the
//! last axis, disjoint and not touching — as `write_rays` writes them), and records where the runs of each
//! axis-0 coordinate begin. The [`RaysFileSource`] it returns then reads a slab's lines alone (a seek and
//! a parse) when asked for them, so building a tree from it out of core never holds all the runs.
//!
//! A file that is not sorted so (runs out of order, overlapping or touching, which [`RaySet::from_rays`](crate::RaySet::from_rays)
//! would sort and merge) or has a bad line is read whole instead, exactly as
//! [`read_rays_file`](super::read_rays_file) reads it: the same rays, or the same error naming the file
//! and line.
//!
//! ```
//! use ktree::io::{open_rays_file, write_rays_file, AnyRaysFileSource, RaysFile};
//! use ktree::stacking::{paper::stack, Builder};
//! use ktree::{Ray, RaySet};
//! let rays = RaySet::<3>::from_rays(4, [Ray::new([1, 2, 3], 9), Ray::new([9, 0, 0], 16)]).unwrap();
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("two.rays");
//! write_rays_file(&path, &rays).unwrap();
//! let RaysFile::Sorted(AnyRaysFileSource::K3(source)) = open_rays_file(&path).unwrap() else { panic!() };
//! assert_eq!(source.runs(), 2);
//! assert_eq!(Builder::new(&source).split_depth(2).build().unwrap(), stack(&rays));
//! ```

use std::borrow::Cow;
use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::ops::Range;
use std::path::{Path, PathBuf};

use super::text::{read_header, read_rays_file, NumberedLines, RaysTextError, RaysTextErrorKind};
use crate::rays::AnyRaySet;
use crate::rays::{ColumnKeys, Ray, RaySource, SlabRuns};
use crate::space::Universe;

/// A ray file opened by [`open_rays_file`].
#[derive(Debug, Clone)]
pub enum RaysFile {
    /// Sorted as a [`RaySet`](crate::RaySet): read slab by slab.
    Sorted(AnyRaysFileSource),
    /// Not sorted so: read whole.
    Whole(AnyRaySet),
}

/// A [`RaysFileSource`] of the dimension its file names.
#[derive(Debug, Clone)]
pub enum AnyRaysFileSource {
    /// `K = 1`.
    K1(RaysFileSource<1>),
    /// `K = 2`.
    K2(RaysFileSource<2>),
    /// `K = 3`.
    K3(RaysFileSource<3>),
    /// `K = 4`.
    K4(RaysFileSource<4>),
}

/// A ray file sorted as a [`RaySet`](crate::RaySet), whose runs are read slab by slab (see the module's notes).
#[derive(Debug, Clone)]
pub struct RaysFileSource<const K: usize> {
    path: PathBuf,
    name: String,
    universe: Universe<K>,
    normals: bool,
    /// For each axis-0 coordinate with runs (the one column for `K = 1`), in increasing order: it, the
    /// byte offset and the 1-based number of the line of its first run.
    starts: Vec<(u32, u64, usize)>,
    runs: u64,
    voxels: u128,
}

/// Opens a ray file for reading slab by slab if its runs are sorted as in a [`RaySet`](crate::RaySet) (one pass over
/// the file), else reads it whole as [`read_rays_file`] does.
///
/// # Errors
/// As [`read_rays_file`]: the file and line of the first problem.
pub fn open_rays_file(path: &Path) -> Result<RaysFile, RaysTextError> {
    match index(path) {
        Some(source) => Ok(RaysFile::Sorted(source)),
        None => read_rays_file(path).map(RaysFile::Whole),
    }
}

/// The index of a sorted file; `None` when the file must be read whole.
fn index(path: &Path) -> Option<AnyRaysFileSource> {
    let name = path.display().to_string();
    let file = File::open(path).ok()?;
    let mut lines = NumberedLines::new(BufReader::new(file), &name, 0);
    let (k, level) = read_header(&mut lines).ok()?;
    Some(match k {
        1 => AnyRaysFileSource::K1(RaysFileSource::index(path, lines, level)?),
        2 => AnyRaysFileSource::K2(RaysFileSource::index(path, lines, level)?),
        3 => AnyRaysFileSource::K3(RaysFileSource::index(path, lines, level)?),
        _ => AnyRaysFileSource::K4(RaysFileSource::index(path, lines, level)?),
    })
}

impl<const K: usize> RaysFileSource<K> {
    /// Reads the run lines after the header; `None` at the first bad line or run out of order.
    fn index(
        path: &Path,
        mut lines: NumberedLines<'_, BufReader<File>>,
        level: u32,
    ) -> Option<Self> {
        let universe = Universe::<K>::new(level).ok()?;
        let mut normals = None;
        let mut starts: Vec<(u32, u64, usize)> = Vec::new();
        let (mut runs, mut voxels) = (0u64, 0u128);
        let mut last: Option<(u64, u32)> = None;
        while let Some(text) = lines.next_content().ok()? {
            let with_normals =
                *normals.get_or_insert(text.split_ascii_whitespace().count() == K + 1 + 2 * K);
            let (ray, _) = lines.parse_run::<K>(&text, with_normals).ok()?;
            let (key, z1, z2) = checked(&universe, &ray).ok()?;
            if last.is_some_and(|(k, end)| key < k || (key == k && z1 <= end)) {
                return None;
            }
            let x = if K == 1 { 0 } else { ray.start[0] };
            if starts.last().is_none_or(|s| s.0 != x) {
                starts.push((x, lines.line_offset, lines.line));
            }
            last = Some((key, z2));
            runs += 1;
            voxels += u128::from(z2 - z1);
        }
        Some(Self {
            path: path.to_path_buf(),
            name: path.display().to_string(),
            universe,
            normals: normals == Some(true),
            starts,
            runs,
            voxels,
        })
    }

    /// The number of runs in the file.
    pub fn runs(&self) -> u64 {
        self.runs
    }

    /// The number of voxels the runs cover.
    pub fn voxel_count(&self) -> u128 {
        self.voxels
    }

    /// The bytes the source holds: its index of where each axis-0 coordinate's runs begin.
    pub fn heap_bytes(&self) -> u64 {
        std::mem::size_of_val(&self.starts[..]) as u64
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn error(&self, line: usize, kind: RaysTextErrorKind) -> RaysTextError {
        RaysTextError::at_line(self.name.clone(), line, kind)
    }
}

/// The column key and run of a ray, checked to lie in the universe as [`RaySet::from_rays`](crate::RaySet::from_rays) checks it.
fn checked<const K: usize>(
    universe: &Universe<K>,
    ray: &Ray<K>,
) -> Result<(u64, u32, u32), String> {
    let side = universe.side();
    for (axis, &c) in ray.start[..K - 1].iter().enumerate() {
        if u64::from(c) >= side {
            return Err(format!(
                "coordinate {c} on axis {axis} is outside the universe of side {side}"
            ));
        }
    }
    let key = ColumnKeys::<K>::new(universe.level()).pack(ray.start);
    let (z1, z2) = (ray.z1(), ray.z2);
    if u64::from(z2) > side || z1 >= z2 {
        return Err(format!(
            "run [{z1}, {z2}) is empty, reversed or outside the universe of side {side}"
        ));
    }
    Ok((key, z1, z2))
}

impl<const K: usize> RaySource<K> for RaysFileSource<K> {
    type Error = RaysTextError;

    fn universe(&self) -> Universe<K> {
        self.universe
    }

    /// Reads the lines of the slab's runs. A file changed since it was opened is an error naming the line.
    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, RaysTextError> {
        let (mut keys, mut runs) = (Vec::new(), Vec::new());
        let at = if K == 1 {
            0
        } else {
            self.starts.partition_point(|s| s.0 < x.start)
        };
        let Some(&(first_x, offset, line)) = self.starts.get(at) else {
            return Ok(SlabRuns {
                keys: Cow::Owned(keys),
                runs: Cow::Owned(runs),
            });
        };
        if K > 1 && first_x >= x.end {
            return Ok(SlabRuns {
                keys: Cow::Owned(keys),
                runs: Cow::Owned(runs),
            });
        }
        let io = |e: std::io::Error| self.error(line, RaysTextErrorKind::Io(e.into()));
        let mut file = File::open(&self.path).map_err(io)?;
        file.seek(SeekFrom::Start(offset)).map_err(io)?;
        let mut lines = NumberedLines::new(BufReader::new(file), &self.name, line - 1);
        let mut last: Option<(u64, u32)> = None;
        while let Some(text) = lines.next_content()? {
            let (ray, _) = lines.parse_run::<K>(&text, self.normals)?;
            let changed = |what: String| {
                self.error(
                    lines.line,
                    RaysTextErrorKind::BadRun(format!(
                        "{what} (the file changed since it was opened)"
                    )),
                )
            };
            if K > 1 && ray.start[0] >= x.end {
                break;
            }
            let (key, z1, z2) = checked(&self.universe, &ray).map_err(&changed)?;
            let x0 = if K == 1 { 0 } else { ray.start[0] };
            if (K > 1 && x0 < x.start)
                || last.is_some_and(|(k, end)| key < k || (key == k && z1 <= end))
                || (last.is_none() && x0 != first_x)
            {
                return Err(changed("runs out of order".into()));
            }
            last = Some((key, z2));
            keys.push(key);
            runs.push((z1, z2));
        }
        Ok(SlabRuns {
            keys: Cow::Owned(keys),
            runs: Cow::Owned(runs),
        })
    }

    /// The slabs holding an axis-0 coordinate with runs.
    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        if K == 1 {
            return vec![0];
        }
        let level = self.universe.level();
        let t = level - m.min(level);
        let mut slabs: Vec<u32> = self.starts.iter().map(|s| s.0 >> t).collect();
        slabs.dedup();
        slabs
    }
}
