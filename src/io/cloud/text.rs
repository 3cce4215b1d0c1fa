//! XYZ and CSV text: three numbers a line.

use super::finite;
use crate::io::geometry_file::Fault;

/// Three numbers a line (separated by spaces, tabs, commas or semicolons), extra columns ignored, `#`
/// comments and blank lines skipped; `header`: the first content line may be a header (CSV).
pub(super) fn read(bytes: &[u8], header: bool) -> Result<Vec<[f64; 3]>, Fault> {
    let mut points = Vec::new();
    let mut first = true;
    for (n, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = n + 1;
        let text = std::str::from_utf8(line)
            .map_err(|_| Fault::line(n, "not UTF-8 text"))?
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
                    bad = Some(format!("'{f}' is not a number"));
                    break;
                }
                None => {
                    bad = Some(format!("expected 3 numbers x y z, found {a}"));
                    break;
                }
            }
        }
        let was_first = std::mem::replace(&mut first, false);
        if let Some(why) = bad {
            if header && was_first {
                continue; // a header line
            }
            return Err(Fault::line(n, why));
        }
        points.push(finite(p, |why| Fault::line(n, format!("the point {why}")))?);
    }
    Ok(points)
}
