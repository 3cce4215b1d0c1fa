//! Scans from point cloud files: a scan list (a text file naming a point file and its pose a line), or a
//! folder of point files.
//!
//! ```text
//! # comment lines and blank lines are skipped
//! scans/a.pcd  1.0 2.0 0.5  0.0 0.0 1.57   <- points in the sensor's frame, posed at x y z roll pitch yaw
//! world/b.ply  4.0 0.0 1.2                 <- points in world coordinates, the sensor at x y z
//! ```
//!
//! A relative path is relative to the list's folder; a path has no spaces. The point files are read by
//! [`read_cloud`] (PLY, PCD, XYZ/CSV/TXT, LAS/LAZ), their coordinates rounded to `f32`. A posed scan is
//! placed as OctoMap places a scan graph's node ([`ScanNode::to_scan`]): translation as `f32`, angles as
//! `f64`, as `octomath::Pose6D` takes them.

use std::path::{Path, PathBuf};

use super::graph::ScanNode;
use super::pose::Pose;
use super::Scan;
use crate::io::cloud::{is_cloud_file, read_cloud};
use crate::io::geometry_file::{io_error, Fault, GeometryFileError};

/// Reads a scan list and every point file it names, in its order.
///
/// ```
/// use ktree::io::read_scan_list;
/// let dir = tempfile::tempdir().unwrap();
/// std::fs::write(dir.path().join("a.xyz"), "1 0 0\n").unwrap();
/// std::fs::write(dir.path().join("list.txt"), "# two scans\na.xyz 0 0 1\na.xyz 0 0 1 0 0 3.14159265\n").unwrap();
/// let scans = read_scan_list(&dir.path().join("list.txt")).unwrap();
/// assert_eq!((scans[0].points.clone(), scans[0].origin), (vec![[1.0, 0.0, 0.0]], [0.0, 0.0, 1.0]));
/// let turned = scans[1].points[0];
/// assert!((turned[0] + 1.0).abs() < 1e-6 && turned[1].abs() < 1e-6 && turned[2] == 1.0);
/// ```
///
/// # Errors
/// The list's [`GeometryFileError`] naming its line (a line without a path and 3 or 6 numbers, a number
/// that is not one or not finite, a point beyond `f32`'s range), or the error of a point file as
/// [`read_cloud`] gives it (naming that file).
pub fn read_scan_list(list: &Path) -> Result<Vec<Scan>, GeometryFileError> {
    let text = std::fs::read(list).map_err(|e| io_error(list, e))?;
    let base = list.parent().unwrap_or(Path::new(""));
    let mut scans = Vec::new();
    for (entry, line) in parse_list(&text).map_err(|f| f.in_file(list))? {
        let path = base.join(&entry.path);
        let cloud = read_cloud(&path)?;
        let points =
            to_f32(cloud.points(), &path).map_err(|m| Fault::line(line, m).in_file(list))?;
        let scan = match entry.placement {
            Placement::World(origin) => Scan { points, origin },
            Placement::Posed(pose) => ScanNode {
                id: 0,
                pose,
                points,
            }
            .to_scan(),
        };
        scans.push(scan);
    }
    Ok(scans)
}

/// Reads the point files of a folder (those [`is_cloud_file`] accepts; other files and folders are
/// skipped) in the order of their names, each a scan in world coordinates seen from `origin`.
///
/// ```
/// use ktree::io::read_scan_directory;
/// let dir = tempfile::tempdir().unwrap();
/// std::fs::write(dir.path().join("b.xyz"), "2 0 0\n").unwrap();
/// std::fs::write(dir.path().join("a.xyz"), "1 0 0\n").unwrap();
/// std::fs::write(dir.path().join("notes.md"), "not a cloud").unwrap();
/// let scans = read_scan_directory(dir.path(), [0.0, 0.0, 1.0]).unwrap();
/// assert_eq!(scans.len(), 2);
/// assert_eq!((scans[0].points[0], scans[1].points[0]), ([1.0, 0.0, 0.0], [2.0, 0.0, 0.0]));
/// ```
///
/// # Errors
/// [`GeometryFileErrorKind::Io`](crate::io::GeometryFileErrorKind::Io) when the folder cannot be listed,
/// and the error of a point file as [`read_cloud`] gives it.
pub fn read_scan_directory(dir: &Path, origin: [f32; 3]) -> Result<Vec<Scan>, GeometryFileError> {
    let mut files: Vec<PathBuf> = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| io_error(dir, e))? {
        let path = entry.map_err(|e| io_error(dir, e))?.path();
        if path.is_file() && is_cloud_file(&path)? {
            files.push(path);
        }
    }
    files.sort();
    files
        .iter()
        .map(|path| {
            let cloud = read_cloud(path)?;
            let points = to_f32(cloud.points(), path).map_err(|m| Fault::whole(m).in_file(path))?;
            Ok(Scan { points, origin })
        })
        .collect()
}

/// A cloud's points as `f32`, or a message for one beyond its range.
fn to_f32(points: &[[f64; 3]], file: &Path) -> Result<Vec<[f32; 3]>, String> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let q = p.map(|c| c as f32);
            if q.iter().all(|c| c.is_finite()) {
                Ok(q)
            } else {
                Err(format!(
                    "point {} of {} is beyond the range of a float",
                    i + 1,
                    file.display()
                ))
            }
        })
        .collect()
}

/// Where a listed scan's points are.
#[derive(Debug, Clone, PartialEq)]
enum Placement {
    /// In world coordinates, the sensor here.
    World([f32; 3]),
    /// In the sensor's frame, posed.
    Posed(Pose),
}

/// One line of a scan list.
#[derive(Debug, Clone, PartialEq)]
struct Entry {
    path: String,
    placement: Placement,
}

/// The entries of a list with their lines.
fn parse_list(text: &[u8]) -> Result<Vec<(Entry, usize)>, Fault> {
    let text = std::str::from_utf8(text).map_err(|e| {
        let line = 1 + text[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        Fault::line(line, "the line is not UTF-8 text")
    })?;
    let mut entries = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let number = i + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let fault = |m: String| Fault::line(number, m);
        let f32_at = |i: usize| -> Result<f32, Fault> {
            match fields[i].parse::<f32>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(fault(format!("'{}' is not a finite number", fields[i]))),
            }
        };
        let f64_at = |i: usize| -> Result<f64, Fault> {
            match fields[i].parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(fault(format!("'{}' is not a finite number", fields[i]))),
            }
        };
        let placement = match fields.len() {
            4 => Placement::World([f32_at(1)?, f32_at(2)?, f32_at(3)?]),
            7 => Placement::Posed(Pose::from_xyz_rpy(
                f32_at(1)?,
                f32_at(2)?,
                f32_at(3)?,
                f64_at(4)?,
                f64_at(5)?,
                f64_at(6)?,
            )),
            n => {
                return Err(fault(format!(
                    "a scan is a point file and x y z (world points) or x y z roll pitch yaw (posed): {} numbers given",
                    n - 1
                )))
            }
        };
        entries.push((
            Entry {
                path: fields[0].to_string(),
                placement,
            },
            number,
        ));
    }
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Place;

    #[test]
    fn lists_parse_and_bad_lines_are_named() {
        let entries = parse_list(b"# c\n\n a.ply 1 2 3\nb.pcd 0 0 0 0.5 0 0\n").unwrap();
        assert_eq!(entries.len(), 2);
        assert_eq!(entries[0].0.placement, Placement::World([1.0, 2.0, 3.0]));
        assert_eq!(entries[1].1, 4);
        assert_eq!(
            entries[1].0.placement,
            Placement::Posed(Pose::from_xyz_rpy(0.0, 0.0, 0.0, 0.5, 0.0, 0.0))
        );
        for (text, line) in [
            (&b"a.ply 1 2\n"[..], 1),
            (b"# c\na.ply 1 2 x\n", 2),
            (b"a.ply 1 2 3 4 5 nan\n", 1),
            (b"a.ply 1 2 3\n\xff\n", 2),
        ] {
            assert_eq!(parse_list(text).unwrap_err().place, Place::Line(line));
        }
    }
}
