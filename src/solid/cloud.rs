//! Point clouds to voxels: PLY (vertices, no faces), PCD, XYZ/CSV text and LAS/LAZ files.
//!
//! **Voxels.** A point `p` falls in voxel `floor((p − origin) / s)` per axis, computed in `f64` exactly as
//! numpy's `np.floor((p - origin) / s)`; a voxel is full when it holds at least `min_points` points
//! ([`CloudVoxelizer`]). The default origin is the minimum corner of the points' bounding box (so every
//! index is ≥ 0), the default level the smallest whose universe holds every voxel. With a level given,
//! points outside the universe are an error naming how many and the first, unless
//! [`CloudVoxelizer::crop`] drops them.
//!
//! **Work:** `O(n log n)` for `n` points: the voxel keys are packed in a `u64`, sorted, counted and turned
//! into runs along z, never inserted one by one.
//!
//! **Formats** ([`PointCloud::read`], by extension):
//! * `.ply`: ASCII and binary (little and big endian) PLY whose `vertex` element has `x`, `y`, `z`
//!   properties of any scalar type; other elements and properties are skipped. A PLY with faces is a mesh
//!   ([`ply_has_faces`]).
//! * `.pcd`: PCL's format, `DATA ascii` and `DATA binary` (`binary_compressed` is refused with an error),
//!   fields `x`, `y`, `z` of any `TYPE`/`SIZE`, other fields skipped.
//! * `.xyz`, `.csv`, `.txt`: three numbers a line (separated by spaces, tabs, commas or semicolons), extra
//!   columns ignored, `#` comments and blank lines skipped; a `.csv` may start with a header line.
//! * `.las`, `.laz`: ASPRS LAS 1.0–1.4, compressed or not, read by the `las` crate (MIT,
//!   <https://github.com/gadomski/las-rs>, with its `laz` feature), coordinates scaled and offset as the
//!   header says.
//!
//! Errors name the file and the line (text) or byte offset (binary) of the first fault; counts from headers
//! are checked against the file's length before anything is allocated; a NaN or infinite coordinate is an
//! error naming its line or point.
//!
//! ```
//! use ktree::solid::cloud::{CloudVoxelizer, PointCloud};
//! use std::path::Path;
//! let text = b"# x y z\n0.1 0.1 0.1\n0.2 0.3 0.1 255\n1.7 0.1 0.1\n";
//! let cloud = PointCloud::from_bytes(text, "xyz", Path::new("mem.xyz")).unwrap();
//! assert_eq!(cloud.len(), 3);
//! let v = CloudVoxelizer::new(0.5).unwrap().voxelize(cloud.points()).unwrap();
//! assert_eq!(v.origin, [0.1, 0.1, 0.1]);
//! assert_eq!(v.rays.voxel_count(), 2); // voxels (0, 0, 0) and (3, 0, 0)
//! assert_eq!(v.rays.level(), 2); // the smallest universe holding x = 3
//! ```

use std::path::Path;

use super::SolidError;
use crate::rays::{Ray, RaySet};
use crate::space::max_level;
use crate::tree::KTree;

/// The file extensions [`PointCloud::read`] knows.
pub const CLOUD_FORMATS: [&str; 7] = ["ply", "pcd", "xyz", "csv", "txt", "las", "laz"];

/// The largest level of a cloud's universe (3 · 21 bits of a voxel key fit a `u64`).
pub const MAX_LEVEL: u32 = 21;

/// A point cloud: finite 3-D points, in file order.
///
/// ```
/// use ktree::solid::cloud::PointCloud;
/// assert!(PointCloud::new(vec![[0.0, 1.0, 2.0]]).is_ok());
/// assert!(PointCloud::new(vec![[0.0, f64::NAN, 2.0]]).is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointCloud {
    points: Vec<[f64; 3]>,
}

impl PointCloud {
    /// A cloud of `points`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] naming the first point with a NaN or infinite coordinate.
    pub fn new(points: Vec<[f64; 3]>) -> Result<Self, SolidError> {
        check_finite(&points)?;
        Ok(Self { points })
    }

    /// The points.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there is no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Takes the points out.
    pub fn into_points(self) -> Vec<[f64; 3]> {
        self.points
    }

    /// Reads a cloud, choosing the format by extension (see the [module docs](self)).
    ///
    /// # Errors
    /// [`SolidError::Io`] when the file cannot be read, [`SolidError::Parse`] naming the file and the line or
    /// byte otherwise.
    pub fn read(path: &Path) -> Result<Self, SolidError> {
        let format = extension(path);
        if !CLOUD_FORMATS.contains(&format.as_str()) {
            return Self::from_bytes(&[], &format, path);
        }
        let bytes = std::fs::read(path).map_err(|source| SolidError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes(&bytes, &format, path)
    }

    /// Parses a cloud held in memory; `format` is the extension without the dot (any case), `file` names the
    /// input in errors.
    ///
    /// # Errors
    /// [`SolidError::Parse`] naming `file` and the line or byte of the first fault.
    pub fn from_bytes(bytes: &[u8], format: &str, file: &Path) -> Result<Self, SolidError> {
        let parse = |what: String| SolidError::Parse {
            path: file.to_path_buf(),
            what,
        };
        let points = match format.to_ascii_lowercase().as_str() {
            "ply" => read_ply(bytes),
            "pcd" => read_pcd(bytes),
            "xyz" | "txt" => read_text(bytes, false),
            "csv" => read_text(bytes, true),
            "las" | "laz" => read_las(bytes),
            other => Err(format!(
                "unknown point cloud format '.{other}' (known: .ply, .pcd, .xyz, .csv, .txt, .las, .laz)"
            )),
        }
        .map_err(parse)?;
        Ok(Self { points })
    }
}

/// The lower-case extension of a path.
fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// Whether a file is read as a point cloud by [`PointCloud::read`]: `.pcd`, `.xyz`, `.csv`, `.txt`, `.las`,
/// `.laz`, or a `.ply` whose header declares no face ([`ply_has_faces`]).
///
/// # Errors
/// [`SolidError::Io`] when a PLY file cannot be read.
pub fn is_cloud_file(path: &Path) -> Result<bool, SolidError> {
    let format = extension(path);
    if format != "ply" {
        return Ok(CLOUD_FORMATS.contains(&format.as_str()));
    }
    let mut head = Vec::new();
    let file = std::fs::File::open(path).map_err(|source| SolidError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    // A header is short: 64 KiB holds any sensible one.
    std::io::Read::read_to_end(&mut std::io::Read::take(file, 1 << 16), &mut head).map_err(
        |source| SolidError::Io {
            path: path.to_path_buf(),
            source,
        },
    )?;
    Ok(!ply_has_faces(&head))
}

/// Whether a PLY header declares a `face` element with at least one entry (the file is then a mesh).
///
/// ```
/// use ktree::solid::cloud::ply_has_faces;
/// assert!(!ply_has_faces(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n"));
/// assert!(ply_has_faces(b"ply\nformat ascii 1.0\nelement vertex 3\nelement face 1\nend_header\n"));
/// ```
pub fn ply_has_faces(bytes: &[u8]) -> bool {
    for line in bytes.split(|&b| b == b'\n') {
        let text = String::from_utf8_lossy(line);
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        match words.as_slice() {
            ["end_header", ..] => return false,
            ["element", "face", count, ..] if count.parse::<u64>().map_or(true, |c| c > 0) => {
                return true
            }
            _ => {}
        }
    }
    false
}

fn check_finite(points: &[[f64; 3]]) -> Result<(), SolidError> {
    match points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        Some(i) => Err(SolidError::BadParameter(format!(
            "point {i} has a coordinate that is not finite: {:?}",
            points[i]
        ))),
        None => Ok(()),
    }
}

/// How a cloud becomes voxels: voxel size, origin, level, the points a voxel needs, and what to do with
/// points outside the universe.
///
/// ```
/// use ktree::solid::cloud::CloudVoxelizer;
/// let points = [[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [5.0, 0.0, 0.0]];
/// let v = CloudVoxelizer::new(1.0).unwrap().origin([0.0; 3]).level(2).min_points(2);
/// assert!(v.voxelize(&points).is_err()); // x = 5 is outside the universe of side 4
/// let r = v.crop(true).voxelize(&points).unwrap();
/// assert_eq!((r.rays.voxel_count(), r.cropped), (1, 1)); // (0, 0, 0) holds two points
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudVoxelizer {
    voxel_size: f64,
    origin: Option<[f64; 3]>,
    level: Option<u32>,
    min_points: u64,
    crop: bool,
}

/// The voxels of a cloud and what was chosen on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudVoxels {
    /// The full voxels.
    pub rays: RaySet<3>,
    /// The origin used (given or the bounding box's minimum corner).
    pub origin: [f64; 3],
    /// Points outside the universe that were dropped ([`CloudVoxelizer::crop`]).
    pub cropped: u64,
    /// Voxels that held at least one point but fewer than the minimum.
    pub sparse: u64,
}

impl CloudVoxelizer {
    /// Voxels of side `voxel_size`, the default origin and level, one point a voxel, no cropping.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] unless `voxel_size` is finite and positive.
    pub fn new(voxel_size: f64) -> Result<Self, SolidError> {
        if !(voxel_size.is_finite() && voxel_size > 0.0) {
            return Err(SolidError::BadParameter(format!(
                "voxel size {voxel_size}: expected a finite number > 0"
            )));
        }
        Ok(Self {
            voxel_size,
            origin: None,
            level: None,
            min_points: 1,
            crop: false,
        })
    }

    /// The corner of voxel (0, 0, 0) (default: the minimum corner of the points' bounding box).
    pub fn origin(mut self, origin: [f64; 3]) -> Self {
        self.origin = Some(origin);
        self
    }

    /// The universe level (default: the smallest holding every voxel).
    pub fn level(mut self, level: u32) -> Self {
        self.level = Some(level);
        self
    }

    /// The points a voxel must hold to be full (default 1; 0 is taken as 1).
    pub fn min_points(mut self, n: u64) -> Self {
        self.min_points = n.max(1);
        self
    }

    /// Drop points outside the universe instead of failing (default: fail).
    pub fn crop(mut self, crop: bool) -> Self {
        self.crop = crop;
        self
    }

    /// The voxels of `points`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for a NaN or infinite coordinate or origin, points outside the universe
    /// of the level given (naming how many and the first) unless cropping, or a cloud too large for
    /// [`MAX_LEVEL`].
    pub fn voxelize(&self, points: &[[f64; 3]]) -> Result<CloudVoxels, SolidError> {
        check_finite(points)?;
        let origin = match self.origin {
            Some(o) if o.iter().all(|c| c.is_finite()) => o,
            Some(o) => {
                return Err(SolidError::BadParameter(format!(
                    "origin {o:?}: expected finite coordinates"
                )))
            }
            None => bounds(points).map_or([0.0; 3], |b| b.0),
        };
        let s = self.voxel_size;
        // numpy's floor((p - origin) / s), per axis.
        let index = |p: &[f64; 3]| -> [f64; 3] {
            std::array::from_fn(|a| ((p[a] - origin[a]) / s).floor())
        };
        let level = match self.level {
            Some(l) => {
                crate::Universe::<3>::new(l)?;
                l
            }
            None => {
                let mut top = 0.0f64;
                for (i, p) in points.iter().enumerate() {
                    let v = index(p);
                    if let Some(a) = (0..3).find(|&a| v[a] < 0.0) {
                        return Err(SolidError::BadParameter(format!(
                            "point {i} {p:?} lies below the origin {origin:?} along axis {a}: give --level and --crop to drop such points, or another origin"
                        )));
                    }
                    top = top.max(v[0]).max(v[1]).max(v[2]);
                }
                let mut l = 0;
                while l <= MAX_LEVEL && top >= (1u64 << l) as f64 {
                    l += 1;
                }
                if l > MAX_LEVEL.min(max_level(3)) {
                    return Err(SolidError::BadParameter(format!(
                        "the cloud spans voxel index {top} at voxel size {s}: more than a universe of level {MAX_LEVEL} holds; use a larger voxel size"
                    )));
                }
                l
            }
        };
        let side = (1u64 << level) as f64;
        let mut keys = Vec::with_capacity(points.len());
        let mut outside = 0u64;
        let mut first_outside = None;
        for (i, p) in points.iter().enumerate() {
            let v = index(p);
            if v.iter().all(|&c| (0.0..side).contains(&c)) {
                keys.push(((v[0] as u64) << 42) | ((v[1] as u64) << 21) | (v[2] as u64));
            } else {
                outside += 1;
                first_outside.get_or_insert((i, *p, v));
            }
        }
        if let (Some((i, p, v)), false) = (first_outside, self.crop) {
            return Err(SolidError::BadParameter(format!(
                "{outside} points lie outside the universe of level {level} (side {side} voxels); the first is point {i} {p:?} in voxel {v:?}: use a larger level or voxel size, another origin, or --crop to drop them"
            )));
        }
        keys.sort_unstable();
        let mask = (1u64 << 21) - 1;
        let mut rays = Vec::new();
        let mut sparse = 0;
        let mut open: Option<(u64, u32, u32)> = None; // column, z1, z2
        for group in keys.chunk_by(|a, b| a == b) {
            if (group.len() as u64) < self.min_points {
                sparse += 1;
                continue;
            }
            let (column, z) = (group[0] >> 21, (group[0] & mask) as u32);
            match &mut open {
                Some((c, _, z2)) if *c == column && *z2 == z => *z2 = z + 1,
                _ => {
                    if let Some(run) = open.replace((column, z, z + 1)) {
                        rays.push(run);
                    }
                }
            }
        }
        rays.extend(open);
        let rays = RaySet::from_rays(
            level,
            rays.into_iter()
                .map(|(c, z1, z2)| Ray::new([(c >> 21) as u32, (c & mask) as u32, z1], z2)),
        )?;
        Ok(CloudVoxels {
            rays,
            origin,
            cropped: outside,
            sparse,
        })
    }
}

/// The minimum and maximum corners of `points` (`None` for none).
pub fn bounds(points: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), p| {
        (
            std::array::from_fn(|a| lo[a].min(p[a])),
            std::array::from_fn(|a| hi[a].max(p[a])),
        )
    }))
}

impl KTree<3> {
    /// The octree of the voxels holding at least one of `points`: voxel `floor((p − origin) / voxel_size)`,
    /// origin default the points' minimum corner, level default the smallest holding every voxel (see
    /// [`CloudVoxelizer`] for more options).
    ///
    /// ```
    /// use ktree::KTree;
    /// let tree = KTree::from_points(&[[0.5, 0.5, 0.5], [3.5, 0.5, 0.5]], 1.0, Some([0.0; 3]), None).unwrap();
    /// assert_eq!((tree.level(), tree.voxel_count()), (2, 2));
    /// ```
    ///
    /// # Errors
    /// As [`CloudVoxelizer::voxelize`].
    pub fn from_points(
        points: &[[f64; 3]],
        voxel_size: f64,
        origin: Option<[f64; 3]>,
        level: Option<u32>,
    ) -> Result<KTree<3>, SolidError> {
        let mut v = CloudVoxelizer::new(voxel_size)?;
        if let Some(o) = origin {
            v = v.origin(o);
        }
        if let Some(l) = level {
            v = v.level(l);
        }
        Ok(KTree::from_rays(&v.voxelize(points)?.rays))
    }
}

// ---------------------------------------------------------------------------------------------------------
// Text: XYZ and CSV.

/// Three numbers a line; `header`: the first content line may be a header (CSV).
fn read_text(bytes: &[u8], header: bool) -> Result<Vec<[f64; 3]>, String> {
    let mut points = Vec::new();
    let mut first = true;
    for (n, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = n + 1;
        let text = std::str::from_utf8(line)
            .map_err(|_| format!("line {line_no}: not UTF-8 text"))?
            .trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let mut fields = text
            .split(|c: char| c == ',' || c == ';' || c.is_ascii_whitespace())
            .filter(|f| !f.is_empty());
        let mut p = [0.0; 3];
        let mut bad = None;
        for (a, c) in p.iter_mut().enumerate() {
            match fields.next().map(|f| (f, f.parse::<f64>())) {
                Some((_, Ok(v))) => *c = v,
                Some((f, Err(_))) => {
                    bad = Some(format!("line {line_no}: '{f}' is not a number"));
                    break;
                }
                None => {
                    bad = Some(format!(
                        "line {line_no}: expected 3 numbers x y z, found {a}"
                    ));
                    break;
                }
            }
        }
        let was_first = std::mem::replace(&mut first, false);
        if let Some(why) = bad {
            if header && was_first {
                continue; // a header line
            }
            return Err(why);
        }
        if !p.iter().all(|c: &f64| c.is_finite()) {
            return Err(format!(
                "line {line_no}: coordinate not finite ({} {} {})",
                p[0], p[1], p[2]
            ));
        }
        points.push(p);
    }
    Ok(points)
}

// ---------------------------------------------------------------------------------------------------------
// Binary fields shared by PLY and PCD.

/// A scalar field of a binary record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Scalar {
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
    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// Reads one value from the start of `b` (at least `size` bytes).
    fn get(self, b: &[u8], big: bool) -> f64 {
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

    fn ply(name: &str) -> Option<Self> {
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

    fn pcd(kind: &str, size: &str) -> Option<Self> {
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

/// Header lines with their line numbers.
type Lines<'a> = Vec<(usize, &'a str)>;

/// The header lines of a text header ending at the line `end` (PLY `end_header`, PCD `DATA …`), with their
/// line numbers, and the byte offset of the body.
fn header_lines<'a>(
    bytes: &'a [u8],
    is_end: impl Fn(&str) -> bool,
    what: &str,
) -> Result<(Lines<'a>, usize), String> {
    let mut lines = Vec::new();
    let mut at = 0;
    for (n, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        at += line.len();
        let text = std::str::from_utf8(line)
            .map_err(|_| format!("line {}: {what} header is not text", n + 1))?
            .trim();
        lines.push((n + 1, text));
        if is_end(text) {
            return Ok((lines, at));
        }
    }
    Err(format!("{what}: the header has no end line"))
}

/// The bytes of `count` binary records of `record` bytes each starting at `at`, checked against the length
/// of the file before anything is read.
fn records(bytes: &[u8], at: usize, count: u64, record: usize, what: &str) -> Result<(), String> {
    let need = count.saturating_mul(record as u64);
    let have = (bytes.len() - at) as u64;
    if need > have {
        return Err(format!(
            "byte {at}: {what}: {count} points of {record} bytes need {need} bytes but the file has {have} after its header"
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------------------
// PLY.

/// A PLY property: a scalar, or a list with its count and item types.
#[derive(Debug, Clone)]
pub(super) enum PlyProperty {
    Scalar(String, Scalar),
    List(Scalar, Scalar),
}

/// An element a PLY header declares: its name, how many entries the body holds, and their properties.
#[derive(Debug, Clone)]
pub(super) struct PlyElement {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) properties: Vec<PlyProperty>,
}

/// The header of a PLY file, read the same way for point clouds (here) and meshes (whose body `ply-rs`
/// then parses, [`TriangleMesh`](super::mesh::TriangleMesh)).
#[derive(Debug, Clone)]
pub(super) struct PlyHeader {
    /// `None`: ASCII; `Some(big)`: binary, big-endian or not.
    pub(super) big: Option<bool>,
    pub(super) elements: Vec<PlyElement>,
    /// The byte offset of the body.
    pub(super) body: usize,
    /// The header's lines (the body starts on the next).
    pub(super) lines: usize,
}

impl PlyHeader {
    /// Reads the header at the start of `bytes`, a line at a time, the first bad line ending it: a number
    /// on a `format` or `element` line that does not fit a `u64`, an unknown line, format or type, a
    /// property before any element, an element of entries with no property. Errors name the line.
    pub(super) fn parse(bytes: &[u8]) -> Result<Self, String> {
        let mut big = None;
        let mut elements: Vec<PlyElement> = Vec::new();
        let mut at = 0;
        for (i, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
            let n = i + 1;
            at += line.len();
            if !line.ends_with(b"\n") && line.trim_ascii() != b"end_header" {
                // The file ends inside its header.
                break;
            }
            let line = std::str::from_utf8(line)
                .map_err(|_| format!("line {n}: the PLY header is not text"))?
                .trim();
            if n == 1 {
                if line != "ply" {
                    return Err("line 1: a PLY file starts with 'ply'".into());
                }
                continue;
            }
            let words: Vec<&str> = line.split_ascii_whitespace().collect();
            let numbered = matches!(words.first(), Some(&("format" | "element")));
            if numbered
                && line
                    .split(|c: char| !c.is_ascii_digit())
                    .any(|run| !run.is_empty() && run.parse::<u64>().is_err())
            {
                return Err(format!(
                    "line {n}: PLY: number too large in header line '{line}'"
                ));
            }
            match words.as_slice() {
                ["format", f, _] => {
                    big = Some(match *f {
                        "ascii" => None,
                        "binary_little_endian" => Some(false),
                        "binary_big_endian" => Some(true),
                        f => return Err(format!("line {n}: PLY: unknown format '{f}'")),
                    });
                }
                ["element", name, count] => {
                    let count = count
                        .parse::<u64>()
                        .map_err(|_| format!("line {n}: bad element count '{count}'"))?;
                    elements.push(PlyElement {
                        name: name.to_string(),
                        count,
                        properties: Vec::new(),
                    });
                }
                ["property", "list", c, t, _] => {
                    let (Some(c), Some(t)) = (Scalar::ply(c), Scalar::ply(t)) else {
                        return Err(format!("line {n}: unknown property type in '{line}'"));
                    };
                    let e = elements
                        .last_mut()
                        .ok_or_else(|| format!("line {n}: property before any element"))?;
                    e.properties.push(PlyProperty::List(c, t));
                }
                ["property", t, name] => {
                    let t = Scalar::ply(t)
                        .ok_or_else(|| format!("line {n}: unknown property type '{t}'"))?;
                    let e = elements
                        .last_mut()
                        .ok_or_else(|| format!("line {n}: property before any element"))?;
                    e.properties.push(PlyProperty::Scalar(name.to_string(), t));
                }
                ["end_header"] => {
                    let big = big.ok_or("PLY: no format line")?;
                    if let Some(e) = elements
                        .iter()
                        .find(|e| e.count > 0 && e.properties.is_empty())
                    {
                        return Err(format!(
                            "PLY: element '{}' has {} entries but no property",
                            e.name, e.count
                        ));
                    }
                    return Ok(Self {
                        big,
                        elements,
                        body: at,
                        lines: n,
                    });
                }
                ["comment", ..] | ["obj_info", ..] | [] => {}
                _ => return Err(format!("line {n}: unexpected header line '{line}'")),
            }
        }
        Err("PLY: the header has no end line (no end_header)".into())
    }

    /// Checks that the body can hold the entries declared: each takes at least a byte, so a header
    /// declaring more entries than bytes follow it is refused before anything is allocated for them.
    pub(super) fn check_counts(&self, bytes: &[u8]) -> Result<(), String> {
        let body = (bytes.len() - self.body) as u64;
        let declared = self
            .elements
            .iter()
            .fold(0u64, |sum, e| sum.saturating_add(e.count));
        if declared > body {
            return Err(format!(
                "byte {}: PLY: the header declares {declared} elements but only {body} bytes follow it",
                self.body
            ));
        }
        Ok(())
    }
}

fn read_ply(bytes: &[u8]) -> Result<Vec<[f64; 3]>, String> {
    let header = PlyHeader::parse(bytes)?;
    let (big, body, elements) = (header.big, header.body, &header.elements);
    if let Some(e) = elements.iter().find(|e| e.name == "face" && e.count > 0) {
        return Err(format!(
            "PLY: the file has {} faces: it is a mesh, not a point cloud",
            e.count
        ));
    }
    let Some(vertex) = elements.iter().position(|e| e.name == "vertex") else {
        return Err("PLY: no 'vertex' element".into());
    };
    let props = &elements[vertex].properties;
    let axis = |name: &str| {
        props
            .iter()
            .position(|p| matches!(p, PlyProperty::Scalar(n, _) if n == name))
            .ok_or_else(|| format!("PLY: the vertex element has no scalar property '{name}'"))
    };
    let xyz = [axis("x")?, axis("y")?, axis("z")?];
    let count = elements[vertex].count;
    match big {
        None => read_ply_ascii(bytes, body, header.lines, &elements[..=vertex], xyz),
        Some(big) => {
            // Elements before the vertices are skipped record by record.
            let mut at = body;
            for PlyElement {
                name,
                count,
                properties,
            } in &elements[..vertex]
            {
                for _ in 0..*count {
                    for p in properties {
                        at = skip_ply_property(bytes, at, p, big)
                            .ok_or_else(|| format!("byte {at}: PLY: element '{name}' cut short"))?;
                    }
                }
            }
            let min: usize = props
                .iter()
                .map(|p| match p {
                    PlyProperty::Scalar(_, t) => t.size(),
                    PlyProperty::List(c, _) => c.size(),
                })
                .sum();
            records(bytes, at, count, min, "PLY vertices")?;
            let mut points = Vec::with_capacity(count as usize);
            for i in 0..count {
                let start = at;
                let mut p = [0.0; 3];
                for (j, prop) in props.iter().enumerate() {
                    if let PlyProperty::Scalar(_, t) = prop {
                        if let Some(a) = xyz.iter().position(|&k| k == j) {
                            if at + t.size() <= bytes.len() {
                                p[a] = t.get(&bytes[at..], big);
                            }
                        }
                    }
                    at = skip_ply_property(bytes, at, prop, big)
                        .ok_or_else(|| format!("byte {start}: PLY: vertex {i} cut short"))?;
                }
                if !p.iter().all(|c: &f64| c.is_finite()) {
                    return Err(format!(
                        "byte {start}: PLY vertex {i} has a coordinate that is not finite ({} {} {})",
                        p[0], p[1], p[2]
                    ));
                }
                points.push(p);
            }
            Ok(points)
        }
    }
}

/// The offset after one property at `at`, or `None` past the end.
fn skip_ply_property(bytes: &[u8], at: usize, p: &PlyProperty, big: bool) -> Option<usize> {
    let end = match p {
        PlyProperty::Scalar(_, t) => at.checked_add(t.size())?,
        PlyProperty::List(c, t) => {
            let head = at.checked_add(c.size())?;
            if head > bytes.len() {
                return None;
            }
            let n = c.get(&bytes[at..], big);
            if !(0.0..=bytes.len() as f64).contains(&n) {
                return None;
            }
            head.checked_add((n as usize).checked_mul(t.size())?)?
        }
    };
    (end <= bytes.len()).then_some(end)
}

fn read_ply_ascii(
    bytes: &[u8],
    body: usize,
    header_lines: usize,
    elements: &[PlyElement],
    xyz: [usize; 3],
) -> Result<Vec<[f64; 3]>, String> {
    let mut lines = bytes[body..]
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, l)| (header_lines + 1 + i, l))
        .filter(|(_, l)| !l.iter().all(u8::is_ascii_whitespace));
    let (vertex, before) = elements.split_last().expect("the vertex element");
    for PlyElement { name, count, .. } in before {
        for _ in 0..*count {
            lines
                .next()
                .ok_or_else(|| format!("PLY: the file ends inside element '{name}'"))?;
        }
    }
    let count = vertex.count;
    // Each vertex takes a line of at least one byte: a larger count cannot fit.
    if count > (bytes.len() - body) as u64 {
        return Err(format!(
            "byte {body}: PLY: {count} vertices declared but only {} bytes follow the header",
            bytes.len() - body
        ));
    }
    let mut points = Vec::with_capacity(count as usize);
    for i in 0..count {
        let (n, line) = lines
            .next()
            .ok_or_else(|| format!("PLY: the file ends at vertex {i} of {count}"))?;
        let text = std::str::from_utf8(line).map_err(|_| format!("line {n}: not UTF-8 text"))?;
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        let mut p = [0.0; 3];
        let mut w = 0; // the word where property j starts
        for (j, prop) in vertex.properties.iter().enumerate() {
            let word = |w: usize| {
                words
                    .get(w)
                    .ok_or_else(|| format!("line {n}: vertex {i} has too few values"))
            };
            if let Some(a) = xyz.iter().position(|&k| k == j) {
                let v = word(w)?;
                p[a] = v
                    .parse()
                    .map_err(|_| format!("line {n}: '{v}' is not a number"))?;
            }
            w += match prop {
                PlyProperty::Scalar(..) => 1,
                PlyProperty::List(..) => {
                    let v = word(w)?;
                    let len: usize = v
                        .parse()
                        .map_err(|_| format!("line {n}: list length '{v}' is not a count"))?;
                    len.saturating_add(1)
                }
            };
        }
        if !p.iter().all(|c: &f64| c.is_finite()) {
            return Err(format!(
                "line {n}: vertex {i} has a coordinate that is not finite ({} {} {})",
                p[0], p[1], p[2]
            ));
        }
        points.push(p);
    }
    Ok(points)
}

// ---------------------------------------------------------------------------------------------------------
// PCD.

fn read_pcd(bytes: &[u8]) -> Result<Vec<[f64; 3]>, String> {
    let (lines, body) = header_lines(bytes, |l| l.starts_with("DATA"), "PCD")?;
    let mut fields: Vec<&str> = Vec::new();
    let mut sizes: Vec<&str> = Vec::new();
    let mut types: Vec<&str> = Vec::new();
    let mut counts: Option<Vec<usize>> = None;
    let mut points: Option<u64> = None;
    let (mut width, mut height) = (None, None);
    let mut data = "";
    for &(n, line) in &lines {
        let mut words = line.split_ascii_whitespace();
        let key = words.next().unwrap_or("");
        let rest: Vec<&str> = words.collect();
        let number = |w: &[&str]| -> Result<u64, String> {
            w.first()
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("line {n}: {key}: expected a number"))
        };
        match key {
            "" | "VERSION" | "VIEWPOINT" => {}
            k if k.starts_with('#') => {}
            "FIELDS" => fields = rest,
            "SIZE" => sizes = rest,
            "TYPE" => types = rest,
            "COUNT" => {
                counts = Some(
                    rest.iter()
                        .map(|c| c.parse::<usize>().ok().filter(|&c| c > 0 && c <= 1 << 16))
                        .collect::<Option<_>>()
                        .ok_or_else(|| format!("line {n}: COUNT: expected numbers 1…65536"))?,
                )
            }
            "WIDTH" => width = Some(number(&rest)?),
            "HEIGHT" => height = Some(number(&rest)?),
            "POINTS" => points = Some(number(&rest)?),
            "DATA" => data = rest.first().copied().unwrap_or(""),
            _ => return Err(format!("line {n}: unknown PCD header line '{line}'")),
        }
    }
    let counts = counts.unwrap_or_else(|| vec![1; fields.len()]);
    if sizes.len() != fields.len() || types.len() != fields.len() || counts.len() != fields.len() {
        return Err(format!(
            "PCD: FIELDS, SIZE, TYPE and COUNT list {}, {}, {} and {} entries",
            fields.len(),
            sizes.len(),
            types.len(),
            counts.len()
        ));
    }
    let count = match (points, width, height) {
        (Some(p), _, _) => p,
        (None, Some(w), Some(h)) => w.checked_mul(h).ok_or("PCD: WIDTH × HEIGHT overflows")?,
        _ => return Err("PCD: no POINTS line (nor WIDTH and HEIGHT)".into()),
    };
    let mut kinds = Vec::with_capacity(fields.len());
    for i in 0..fields.len() {
        kinds.push(Scalar::pcd(types[i], sizes[i]).ok_or_else(|| {
            format!(
                "PCD: field '{}' has TYPE {} SIZE {}: expected I/U of 1, 2, 4, 8 or F of 4, 8 bytes",
                fields[i], types[i], sizes[i]
            )
        })?);
    }
    // The first value of x, y, z: (field index, value index among a point's values, byte offset).
    let mut xyz = [(0usize, 0usize, 0usize); 3];
    for (a, name) in ["x", "y", "z"].iter().enumerate() {
        let f = fields
            .iter()
            .position(|f| f == name)
            .ok_or_else(|| format!("PCD: no field '{name}'"))?;
        xyz[a] = (
            f,
            counts[..f].iter().sum(),
            (0..f).map(|i| kinds[i].size() * counts[i]).sum(),
        );
    }
    let values: usize = counts.iter().sum();
    let record: usize = (0..fields.len()).map(|i| kinds[i].size() * counts[i]).sum();
    let finite = |p: [f64; 3], at: String| -> Result<[f64; 3], String> {
        if p.iter().all(|c| c.is_finite()) {
            Ok(p)
        } else {
            Err(format!(
                "{at} has a coordinate that is not finite ({} {} {})",
                p[0], p[1], p[2]
            ))
        }
    };
    match data {
        "ascii" => {
            if count > (bytes.len() - body) as u64 {
                return Err(format!(
                    "byte {body}: PCD: {count} points declared but only {} bytes follow the header",
                    bytes.len() - body
                ));
            }
            let mut out = Vec::with_capacity(count as usize);
            let first_line = lines.len() + 1;
            let mut rows = bytes[body..]
                .split(|&b| b == b'\n')
                .enumerate()
                .map(|(i, l)| (first_line + i, l))
                .filter(|(_, l)| !l.iter().all(u8::is_ascii_whitespace));
            for i in 0..count {
                let (n, line) = rows
                    .next()
                    .ok_or_else(|| format!("PCD: the file ends at point {i} of {count}"))?;
                let text =
                    std::str::from_utf8(line).map_err(|_| format!("line {n}: not UTF-8 text"))?;
                let words: Vec<&str> = text.split_ascii_whitespace().collect();
                if words.len() != values {
                    return Err(format!(
                        "line {n}: expected {values} values, found {}",
                        words.len()
                    ));
                }
                let mut p = [0.0; 3];
                for a in 0..3 {
                    let w = words[xyz[a].1];
                    p[a] = w
                        .parse()
                        .map_err(|_| format!("line {n}: '{w}' is not a number"))?;
                }
                out.push(finite(p, format!("line {n}: point {i}"))?);
            }
            Ok(out)
        }
        "binary" => {
            records(bytes, body, count, record, "PCD")?;
            let mut out = Vec::with_capacity(count as usize);
            for (i, r) in bytes[body..]
                .chunks_exact(record.max(1))
                .take(count as usize)
                .enumerate()
            {
                let p = std::array::from_fn(|a| kinds[xyz[a].0].get(&r[xyz[a].2..], false));
                out.push(finite(p, format!("byte {}: point {i}", body + i * record))?);
            }
            Ok(out)
        }
        "binary_compressed" => Err(format!(
            "line {}: PCD 'DATA binary_compressed' is not read: convert it to ascii or binary (pcl_convert_pcd_ascii_binary)",
            lines.len()
        )),
        other => Err(format!(
            "line {}: unknown PCD DATA '{other}' (expected ascii or binary)",
            lines.len()
        )),
    }
}

// ---------------------------------------------------------------------------------------------------------
// LAS and LAZ.

/// Checks the length of a LAS 1.4 file's first extended variable-length record against the file before the
/// `las` crate reads it: that reader allocates the length the record declares (64 bits, so a few bytes
/// could ask for petabytes). The header gives the record's offset (`start_of_first_evlr`, a `u64` at byte
/// 235) and count (a `u32` at byte 243); the record's length is a `u64` 20 bytes into its 60-byte header.
fn check_las_evlr(bytes: &[u8]) -> Result<(), String> {
    let u64_at = |at: usize| -> Option<u64> {
        let b = bytes.get(at..at.checked_add(8)?)?;
        Some(u64::from_le_bytes(b.try_into().ok()?))
    };
    if bytes.get(24..26) != Some(&[1, 4][..]) {
        return Ok(()); // only version 1.4 has extended records
    }
    let (Some(start), Some(count)) = (u64_at(235), bytes.get(243..247)) else {
        return Ok(()); // a short header: the reader reports it
    };
    if start == 0 || count == [0; 4] {
        return Ok(());
    }
    let Some(length) = usize::try_from(start)
        .ok()
        .and_then(|start| u64_at(start.checked_add(20)?))
    else {
        return Ok(()); // the record's header is past the end: the reader reports it
    };
    let room = (bytes.len() as u64).saturating_sub(start.saturating_add(60));
    if length > room {
        return Err(format!(
            "byte {start}: LAS: the extended variable-length record there declares {length} bytes of data, \
             but the file has {room} bytes after its header"
        ));
    }
    Ok(())
}

fn read_las(bytes: &[u8]) -> Result<Vec<[f64; 3]>, String> {
    check_las_evlr(bytes)?;
    // The reader needs an owned input.
    let mut reader = las::Reader::new(std::io::Cursor::new(bytes.to_vec()))
        .map_err(|e| format!("LAS header: {e}"))?;
    let header = reader.header();
    let count = header.number_of_points();
    let format = *header.point_format();
    if !format.is_compressed {
        let record = u64::from(format.len());
        let need = count.saturating_mul(record);
        if need > bytes.len() as u64 {
            return Err(format!(
                "byte 0: LAS: the header declares {count} points of {record} bytes ({need} bytes) but the file has {}",
                bytes.len()
            ));
        }
    }
    // Read in batches, so a count in the header never decides an allocation.
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut batch = las::PointDataBuilder::new().for_header(header).build();
    loop {
        let read = reader
            .fill_points(1 << 16, &mut batch)
            .map_err(|e| format!("LAS point {}: {e}", points.len()))?;
        if read == 0 {
            break;
        }
        for p in batch.points() {
            let i = points.len();
            let p = p.map_err(|e| format!("LAS point {i}: {e}"))?;
            let p = [p.x, p.y, p.z];
            if !p.iter().all(|c: &f64| c.is_finite()) {
                return Err(format!(
                    "LAS point {i} has a coordinate that is not finite ({} {} {})",
                    p[0], p[1], p[2]
                ));
            }
            points.push(p);
        }
    }
    Ok(points)
}
