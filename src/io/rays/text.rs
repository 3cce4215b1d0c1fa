//! The ray text format, for users and for checking from outside the project:
//!
//! ```text
//! # ktree rays v1          <- lines starting with # are comments (blank lines are skipped too)
//! K L                      <- first other line: dimension and level
//! c_0 ... c_{K-2} z1 z2    <- one run per line: the column's K−1 coordinates, then z1 z2 (covers z1 <= z < z2)
//! ```
//!
//! Extension (added, optional): a run line may carry `2·K` more numbers, the surface normal at `z1` then the
//! normal at `z2`; then every run line of the file must. Overlapping or touching runs of one column are
//! merged as [`RaySet::from_rays`] documents.

use std::fmt;
use std::io::{BufRead, Write};
use std::path::Path;

use thiserror::Error;

use crate::rays::AnyRaySet;
use crate::rays::RaySource;
use crate::rays::{Normal, Ray, RayError, RaySet};
use crate::space::{max_level, MAX_K};

/// What was wrong with a ray file.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum RaysTextErrorKind {
    /// The file has no header line (it is empty or only comments).
    #[error("empty file: expected a header line `K L`")]
    Empty,
    /// The header is not two numbers.
    #[error("header must be `K L` (two whole numbers), found {0:?}")]
    BadHeader(String),
    /// `K` is not 1…4.
    #[error("K = {0} is not supported (1 to {MAX_K})")]
    BadDimension(u64),
    /// `L` is beyond [`max_level`] for `K`.
    #[error("level {level} is too large for K = {k} (at most {max})")]
    LevelTooLarge {
        /// The dimension.
        k: usize,
        /// The level.
        level: u64,
        /// The largest level for `k`.
        max: u32,
    },
    /// A run line has the wrong number of fields.
    #[error(
        "expected {expected} numbers (K−1 column coordinates, z1, z2{normals}), found {found}"
    )]
    FieldCount {
        /// Fields expected.
        expected: usize,
        /// Fields found.
        found: usize,
        /// A note about optional normals.
        normals: &'static str,
    },
    /// A field is not a number.
    #[error("field {field} ({text:?}) is not a {what}")]
    NotANumber {
        /// 1-based field number.
        field: usize,
        /// The text.
        text: String,
        /// "whole number" or "number".
        what: &'static str,
    },
    /// A coordinate or run end lies outside the universe, or the run is empty or reversed.
    #[error("{0}")]
    BadRun(String),
    /// The file could not be read.
    #[error("cannot read")]
    Io(crate::fs::IoCause),
}

/// An error in a ray file, with the file and the line (or the whole file) where it happened.
pub type RaysTextError = crate::io::FileError<RaysTextErrorKind>;

impl crate::io::ProblemKind for RaysTextErrorKind {
    fn io_cause(&self) -> Option<&std::io::Error> {
        match self {
            Self::Io(cause) => Some(cause.error()),
            _ => None,
        }
    }
}

/// Reads a ray file into a ray set of the dimension its header names.
///
/// ```
/// use ktree::io::read_rays;
/// use ktree::AnyRaySet;
/// let text = "# ktree rays v1\n2 3\n1 0 4\n1 3 6\n";
/// let AnyRaySet::K2(rays) = read_rays(text.as_bytes(), "example").unwrap() else { panic!() };
/// assert_eq!(rays.len(), 1); // [0,4) and [3,6) merged
/// let err = read_rays("2 3\n1 5 4\n".as_bytes(), "bad.rays").unwrap_err();
/// assert_eq!(err.to_string(), "bad.rays:2: ray 0: run [5, 4) is empty or reversed (need z1 < z2)");
/// ```
///
/// # Errors
/// [`RaysTextError`] naming the file and line of the first problem.
pub fn read_rays(reader: impl BufRead, file: &str) -> Result<AnyRaySet, RaysTextError> {
    let mut lines = NumberedLines::new(reader, file, 0);
    let (k, level) = read_header(&mut lines)?;
    match k {
        1 => read_body::<1, _>(lines, level).map(AnyRaySet::K1),
        2 => read_body::<2, _>(lines, level).map(AnyRaySet::K2),
        3 => read_body::<3, _>(lines, level).map(AnyRaySet::K3),
        _ => read_body::<4, _>(lines, level).map(AnyRaySet::K4),
    }
}

/// Reads the header line `K L` and checks it.
pub(super) fn read_header<R: BufRead>(
    lines: &mut NumberedLines<'_, R>,
) -> Result<(usize, u32), RaysTextError> {
    let Some(header) = lines.next_content()? else {
        return Err(lines.error(0, RaysTextErrorKind::Empty));
    };
    let line = lines.line;
    let fields: Vec<&str> = header.split_ascii_whitespace().collect();
    let parsed: Option<Vec<u64>> = fields.iter().map(|f| f.parse().ok()).collect();
    let (k, level) = match parsed.as_deref() {
        Some(&[k, level]) => (k, level),
        _ => return Err(lines.error(line, RaysTextErrorKind::BadHeader(header.clone()))),
    };
    if !(1..=MAX_K as u64).contains(&k) {
        return Err(lines.error(line, RaysTextErrorKind::BadDimension(k)));
    }
    let k = k as usize;
    if level > u64::from(max_level(k)) {
        return Err(lines.error(
            line,
            RaysTextErrorKind::LevelTooLarge {
                k,
                level,
                max: max_level(k),
            },
        ));
    }
    Ok((k, level as u32))
}

/// Reads a ray file from disk.
///
/// # Errors
/// As [`read_rays`]; a file that cannot be opened is [`RaysTextErrorKind::Io`].
pub fn read_rays_file(path: &Path) -> Result<AnyRaySet, RaysTextError> {
    let name = path.display().to_string();
    let file = std::fs::File::open(path)
        .map_err(|e| RaysTextError::at_line(name.clone(), 0, RaysTextErrorKind::Io(e.into())))?;
    read_rays(std::io::BufReader::new(file), &name)
}

/// Writes a ray set in the text format (with normals when the set carries them).
///
/// # Errors
/// Any I/O error.
pub fn write_rays<const K: usize>(mut w: impl Write, rays: &RaySet<K>) -> std::io::Result<()> {
    writeln!(w, "# ktree rays v1")?;
    if rays.has_normals() {
        writeln!(
            w,
            "# columns: c_0..c_{{K-2}} z1 z2, normal at z1 (K numbers), normal at z2 (K numbers)"
        )?;
    }
    writeln!(w, "{K} {}", rays.level())?;
    write_ray_lines(w, rays)
}

/// Writes the rays of `source` in the text format slab by slab (slabs one cell of depth `depth` wide,
/// as the out-of-core build uses), holding one slab's runs at a time and calling `progress(done, total)`
/// after each slab; returns the number of runs and of voxels written. The file is the one [`write_rays`]
/// writes for the whole set, without the whole set's cap on the number of runs.
///
/// ```
/// use ktree::io::{write_rays, write_rays_source};
/// use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
/// let ball = Solid::Quadric(Quadric::<3>::ball([Rational::int(16); 3], Rational::int(11), Frame::Voxel).unwrap());
/// let (mut whole, mut streamed) = (Vec::new(), Vec::new());
/// write_rays(&mut whole, &ball.to_rays(5, Sample::Centre, false).unwrap()).unwrap();
/// let source = SolidSource::new(&ball, 5, Sample::Centre).unwrap();
/// write_rays_source(&mut streamed, &source, 3, &|_, _| {}).unwrap();
/// assert_eq!(streamed, whole);
/// ```
///
/// # Errors
/// Any I/O error; an error of the source, as [`std::io::ErrorKind::Other`] carrying it.
pub fn write_rays_source<const K: usize, S>(
    mut w: impl Write,
    source: &S,
    depth: u32,
    progress: &dyn Fn(u64, u64),
) -> std::io::Result<(u64, u128)>
where
    S: RaySource<K>,
    S::Error: std::error::Error + Send + Sync + 'static,
{
    let universe = source.universe();
    let level = universe.level();
    let m = depth.min(level);
    let side = 1u32 << (level - m);
    let slabs = if K == 1 {
        vec![0]
    } else {
        source.occupied_slabs(m)
    };
    writeln!(w, "# ktree rays v1")?;
    writeln!(w, "{K} {level}")?;
    let (mut runs, mut voxels) = (0u64, 0u128);
    for (i, &b0) in slabs.iter().enumerate() {
        let slab = source
            .slab(b0 * side..(b0 + 1) * side)
            .map_err(std::io::Error::other)?;
        let rays = RaySet::from_sorted_parts(
            universe,
            slab.keys.into_owned(),
            slab.runs.into_owned(),
            None,
        );
        runs += rays.len() as u64;
        voxels += rays.voxel_count();
        write_ray_lines(&mut w, &rays)?;
        progress(i as u64 + 1, slabs.len() as u64);
    }
    Ok((runs, voxels))
}

/// The lines of the runs of a ray set (after the header).
fn write_ray_lines<const K: usize>(mut w: impl Write, rays: &RaySet<K>) -> std::io::Result<()> {
    let mut line = String::new();
    for (i, ray) in rays.iter().enumerate() {
        use fmt::Write as _;
        line.clear();
        for c in &ray.start[..K - 1] {
            let _ = write!(line, "{c} ");
        }
        let _ = write!(line, "{} {}", ray.z1(), ray.z2);
        if let Some(normals) = rays.normals(i) {
            for v in normals.iter().flatten() {
                let _ = write!(line, " {v}");
            }
        }
        writeln!(w, "{line}")?;
    }
    Ok(())
}

/// Writes a ray file atomically (temporary file, then rename).
///
/// # Errors
/// A [`FileOpError`](crate::fs::FileOpError) naming the path, its source the I/O error.
pub fn write_rays_file<const K: usize>(
    path: &Path,
    rays: &RaySet<K>,
) -> Result<(), crate::fs::FileOpError> {
    crate::fs::write_atomic_with(path, |w| write_rays(w, rays))
}

pub(super) struct NumberedLines<'a, R> {
    reader: R,
    pub(super) line: usize,
    buf: String,
    file: &'a str,
    /// The byte offset of the next line.
    offset: u64,
    /// The byte offset of the last line read.
    pub(super) line_offset: u64,
}

impl<'a, R: BufRead> NumberedLines<'a, R> {
    /// Lines of `reader` (named `file` in errors), the first of them line `line + 1`.
    pub(super) fn new(reader: R, file: &'a str, line: usize) -> Self {
        Self {
            reader,
            line,
            buf: String::new(),
            file,
            offset: 0,
            line_offset: 0,
        }
    }

    pub(super) fn error(&self, line: usize, kind: RaysTextErrorKind) -> RaysTextError {
        RaysTextError::at_line(self.file.to_string(), line, kind)
    }

    /// The next line that is not blank or a comment, trimmed.
    pub(super) fn next_content(&mut self) -> Result<Option<String>, RaysTextError> {
        loop {
            self.buf.clear();
            let n = self
                .reader
                .read_line(&mut self.buf)
                .map_err(|e| self.error(self.line + 1, RaysTextErrorKind::Io(e.into())))?;
            if n == 0 {
                return Ok(None);
            }
            self.line += 1;
            self.line_offset = self.offset;
            self.offset += n as u64;
            let t = self.buf.trim();
            if !t.is_empty() && !t.starts_with('#') {
                return Ok(Some(t.to_string()));
            }
        }
    }

    /// Parses the run line `text` (the last line read): `K + 1` whole numbers, then `2·K` normal
    /// components when `normals`.
    pub(super) fn parse_run<const K: usize>(
        &self,
        text: &str,
        normals: bool,
    ) -> Result<(Ray<K>, Option<[Normal<K>; 2]>), RaysTextError> {
        let line = self.line;
        let plain = K + 1;
        let fields: Vec<&str> = text.split_ascii_whitespace().collect();
        let expected = if normals { plain + 2 * K } else { plain };
        if fields.len() != expected {
            let normals = if normals {
                ", then 2·K normal components"
            } else {
                ""
            };
            return Err(self.error(
                line,
                RaysTextErrorKind::FieldCount {
                    expected,
                    found: fields.len(),
                    normals,
                },
            ));
        }
        let mut start = [0u32; K];
        let mut z2 = 0u32;
        for (i, f) in fields[..plain].iter().enumerate() {
            let v: u32 = f.parse().map_err(|_| {
                self.error(
                    line,
                    RaysTextErrorKind::NotANumber {
                        field: i + 1,
                        text: f.to_string(),
                        what: "whole number",
                    },
                )
            })?;
            if i < K {
                start[i] = v;
            } else {
                z2 = v;
            }
        }
        if !normals {
            return Ok((Ray::new(start, z2), None));
        }
        let mut n = [[0f32; K]; 2];
        for (i, f) in fields[plain..].iter().enumerate() {
            n[i / K][i % K] = f.parse().map_err(|_| {
                self.error(
                    line,
                    RaysTextErrorKind::NotANumber {
                        field: plain + i + 1,
                        text: f.to_string(),
                        what: "number",
                    },
                )
            })?;
        }
        Ok((Ray::new(start, z2), Some(n)))
    }
}

fn read_body<const K: usize, R: BufRead>(
    mut lines: NumberedLines<'_, R>,
    level: u32,
) -> Result<RaySet<K>, RaysTextError> {
    let mut rays: Vec<Ray<K>> = Vec::new();
    let mut normals: Vec<[Normal<K>; 2]> = Vec::new();
    let mut line_of: Vec<usize> = Vec::new();
    let mut has_normals: Option<bool> = None;
    while let Some(text) = lines.next_content()? {
        let expect_normals =
            *has_normals.get_or_insert(text.split_ascii_whitespace().count() == K + 1 + 2 * K);
        let (ray, n) = lines.parse_run::<K>(&text, expect_normals)?;
        rays.push(ray);
        line_of.push(lines.line);
        normals.extend(n);
    }
    let result = if has_normals == Some(true) {
        RaySet::from_rays_with_normals(level, rays.into_iter().zip(normals))
    } else {
        RaySet::from_rays(level, rays)
    };
    result.map_err(|e| {
        let line = match &e {
            RayError::ColumnOutside { index, .. }
            | RayError::RunOutside { index, .. }
            | RayError::EmptyRun { index, .. } => line_of[*index],
            _ => 0,
        };
        lines.error(line, RaysTextErrorKind::BadRun(e.to_string()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> RaysTextError {
        read_rays(text.as_bytes(), "t.rays").unwrap_err()
    }

    #[test]
    fn bad_input_names_the_line() {
        assert_eq!(err("").kind, RaysTextErrorKind::Empty);
        assert_eq!(err("# only a comment\n\n").kind, RaysTextErrorKind::Empty);
        assert!(matches!(err("3\n").kind, RaysTextErrorKind::BadHeader(_)));
        assert!(matches!(err("x 3\n").kind, RaysTextErrorKind::BadHeader(_)));
        assert_eq!(err("5 3\n").kind, RaysTextErrorKind::BadDimension(5));
        assert!(matches!(
            err("3 22\n").kind,
            RaysTextErrorKind::LevelTooLarge { .. }
        ));
        let e = err("# c\n3 4\n1 2 3 4\n1 2 3\n");
        assert_eq!(
            (e.line(), e.kind.clone()),
            (
                Some(4),
                RaysTextErrorKind::FieldCount {
                    expected: 4,
                    found: 3,
                    normals: ""
                }
            )
        );
        let e = err("3 4\n1 2 x 4\n");
        assert_eq!(e.line(), Some(2));
        assert!(matches!(
            e.kind,
            RaysTextErrorKind::NotANumber { field: 3, .. }
        ));
        let e = err("3 4\n1 2 3 4\n1 16 3 4\n");
        assert_eq!(e.line(), Some(3));
        assert!(e.to_string().starts_with("t.rays:3: "), "{e}");
        assert_eq!(err("3 4\n1 2 3 17\n").line(), Some(2));
        assert_eq!(err("3 4\n1 2 -3 7\n").line(), Some(2));
        assert_eq!(err("1 4\n5 5\n").line(), Some(2));
    }

    #[test]
    fn round_trip_with_and_without_normals() {
        let rays =
            RaySet::<3>::from_rays(4, [Ray::new([1, 2, 3], 9), Ray::new([0, 15, 0], 16)]).unwrap();
        let mut buf = Vec::new();
        write_rays(&mut buf, &rays).unwrap();
        assert_eq!(read_rays(&buf[..], "x").unwrap(), AnyRaySet::K3(rays));
        let n = [[0.0, -1.0], [0.25, 1.0]];
        let rays = RaySet::<2>::from_rays_with_normals(3, [(Ray::new([1, 2], 5), n)]).unwrap();
        let mut buf = Vec::new();
        write_rays(&mut buf, &rays).unwrap();
        assert_eq!(read_rays(&buf[..], "x").unwrap(), AnyRaySet::K2(rays));
    }
}
