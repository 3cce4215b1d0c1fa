//! OctoMap's scan log text (`.log`, the input of its `log2graph` tool, read by
//! `ScanGraph::readPlainASCII`): a `NODE x y z roll pitch yaw` line opens a scan posed there, and each line
//! after it is a point `x y z` in that scan's sensor frame.
//!
//! ```text
//! # a comment
//! NODE 1.0 2.0 0.5 0 0 1.5708
//! 0.5 0.0 0.1
//! 0.6 0.1 0.1
//! NODE ...
//! ```
//!
//! As OctoMap reads it: numbers are read as `f32` (the angles too, widened for the pose), and empty lines,
//! lines starting with `#` and lines starting with a space are skipped. Unlike OctoMap, a line that is not
//! what it should be is an error naming it (OctoMap reads garbage for it), and the last line counts even
//! without a newline after it (OctoMap drops it).

use std::path::Path;

use super::graph::ScanNode;
use super::pose::Pose;
use crate::io::geometry_file::{Fault, GeometryFileError};

/// Reads a scan log (`file` names it in errors) into its scans, each a [`ScanNode`] with the ids 0, 1, …
/// in the file's order.
///
/// ```
/// use ktree::io::read_scan_log;
/// let text = b"# two scans\nNODE 1 0 0 0 0 0\n1 0 0\n2 0 0\nNODE 0 0 0 0 0 0\n0 0 1\n";
/// let nodes = read_scan_log(text, "a.log".as_ref()).unwrap();
/// assert_eq!(nodes.len(), 2);
/// assert_eq!(nodes[0].to_scan().points, [[2.0, 0.0, 0.0], [3.0, 0.0, 0.0]]);
/// let e = read_scan_log(b"NODE 1 0 0 0 0 0\n1 x 0\n", "a.log".as_ref()).unwrap_err();
/// assert_eq!(e.to_string(), "a.log:2: 'x' is not a number");
/// ```
///
/// # Errors
/// [`GeometryFileErrorKind::Malformed`](crate::io::GeometryFileErrorKind::Malformed) naming the line: a
/// point before the first `NODE`, a `NODE` line without six numbers or a point line without three, a
/// field that is not a number or not finite.
pub fn read_scan_log(text: &[u8], file: &Path) -> Result<Vec<ScanNode>, GeometryFileError> {
    parse_log(text).map_err(|fault| fault.in_file(file))
}

fn parse_log(text: &[u8]) -> Result<Vec<ScanNode>, Fault> {
    let mut nodes: Vec<ScanNode> = Vec::new();
    for (i, line) in text.split(|&b| b == b'\n').enumerate() {
        let number = i + 1;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if line.is_empty() || line[0] == b'#' || line[0] == b' ' {
            continue;
        }
        let line = std::str::from_utf8(line)
            .map_err(|_| Fault::line(number, "the line is not UTF-8 text"))?;
        let mut fields = line.split_whitespace();
        let Some(first) = fields.next() else {
            continue;
        };
        if first == "NODE" {
            let v: [f32; 6] = numbers(number, fields, "a NODE line has x y z roll pitch yaw")?;
            let pose = Pose::from_xyz_rpy(
                v[0],
                v[1],
                v[2],
                f64::from(v[3]),
                f64::from(v[4]),
                f64::from(v[5]),
            );
            let id = u32::try_from(nodes.len())
                .map_err(|_| Fault::line(number, "more than 2^32 scans"))?;
            nodes.push(ScanNode {
                id,
                pose,
                points: Vec::new(),
            });
        } else {
            let Some(node) = nodes.last_mut() else {
                return Err(Fault::line(
                    number,
                    "a point before the first NODE line (which gives the scan's pose)",
                ));
            };
            let p: [f32; 3] = numbers(
                number,
                std::iter::once(first).chain(fields),
                "a point line has x y z",
            )?;
            node.points.push(p);
        }
    }
    Ok(nodes)
}

/// Exactly `N` finite `f32` fields.
fn numbers<'a, const N: usize>(
    line: usize,
    fields: impl Iterator<Item = &'a str>,
    expected: &str,
) -> Result<[f32; N], Fault> {
    let mut out = [0.0f32; N];
    let mut count = 0;
    for field in fields {
        if count == N {
            return Err(Fault::line(
                line,
                format!("{expected}: more than {N} numbers"),
            ));
        }
        let v: f32 = field
            .parse()
            .map_err(|_| Fault::line(line, format!("'{field}' is not a number")))?;
        if !v.is_finite() {
            return Err(Fault::line(
                line,
                format!("'{field}' is not a finite float"),
            ));
        }
        out[count] = v;
        count += 1;
    }
    if count < N {
        return Err(Fault::line(
            line,
            format!("{expected}: {count} numbers, {N} needed"),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Place;

    #[test]
    fn logs_read_as_octomap_reads_them() {
        let text = b"# c\n\nNODE 0 0 0 0 0 0\n 9 9 9\n1 2 3\r\n4 5 6";
        let nodes = parse_log(text).unwrap();
        assert_eq!(nodes.len(), 1);
        // The line starting with a space is skipped, as OctoMap skips it; the last line counts.
        assert_eq!(nodes[0].points, [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(parse_log(b"").unwrap(), []);
    }

    #[test]
    fn bad_logs_name_the_line() {
        let cases: [(&[u8], usize, &str); 6] = [
            (b"1 2 3\n", 1, "before the first NODE"),
            (b"NODE 0 0 0 0 0\n", 1, "5 numbers, 6 needed"),
            (b"NODE 0 0 0 0 0 0\n1 2\n", 2, "2 numbers, 3 needed"),
            (b"NODE 0 0 0 0 0 0\n1 2 3 4\n", 2, "more than 3"),
            (b"NODE 0 0 0 0 0 0\n\n1 2 inf\n", 3, "not a finite"),
            (b"NODE 0 0 0 0 0 0\n1 2 3\n\xff\n", 3, "not UTF-8"),
        ];
        for (text, line, message) in cases {
            let e = parse_log(text).unwrap_err();
            assert_eq!(e.place, Place::Line(line), "{e:?}");
            assert!(e.message.contains(message), "{e:?}");
        }
    }
}
