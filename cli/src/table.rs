//! Tables of numbers read by `ktree query` and `ktree raycast`: a `.csv` or `.txt` file (numbers separated
//! by commas or white space, one row a line, blank lines and lines starting with `#` skipped), a `.npy`
//! array of shape `(N, C)`, or standard input (`-`, either form). Every error names the file and the line
//! (text) or the byte offset (`.npy`).

use std::io::Read;
use std::path::Path;

use crate::common::error::{CliError, CliResult};

/// Rows of `C` numbers, and where each came from.
pub struct Table<T> {
    /// The rows, each of the expected number of columns.
    pub rows: Vec<Vec<T>>,
    /// The file's name as given.
    name: String,
    /// The line of each row (text), or none (`.npy`: rows are numbered).
    lines: Option<Vec<usize>>,
}

impl<T> Table<T> {
    /// Where row `i` is, for errors: `file:line` or `file: row i`.
    pub fn place(&self, i: usize) -> String {
        match &self.lines {
            Some(lines) => format!("{}:{}", self.name, lines[i]),
            None => format!("{}: row {i}", self.name),
        }
    }
}

/// A number of a table: integers for points, reals for rays.
pub trait Number: Sized + Copy {
    /// What the number is called in errors ("an integer").
    const WHAT: &'static str;
    /// The number written as text.
    fn parse(text: &str) -> Option<Self>;
    /// The number of an integer element of a `.npy` array.
    fn from_int(v: i128) -> Option<Self>;
    /// The number of a real element of a `.npy` array (`None`: reals are not accepted).
    fn from_real(v: f64) -> Option<Self>;
}

impl Number for i64 {
    const WHAT: &'static str = "an integer";
    fn parse(text: &str) -> Option<Self> {
        text.parse().ok()
    }
    fn from_int(v: i128) -> Option<Self> {
        i64::try_from(v).ok()
    }
    fn from_real(_: f64) -> Option<Self> {
        None
    }
}

impl Number for f64 {
    const WHAT: &'static str = "a number";
    fn parse(text: &str) -> Option<Self> {
        text.parse().ok()
    }
    fn from_int(v: i128) -> Option<Self> {
        Some(v as f64)
    }
    fn from_real(v: f64) -> Option<Self> {
        Some(v)
    }
}

/// Reads a table of `columns` numbers a row from `path` (`-`: standard input).
pub fn read<T: Number>(path: &Path, columns: usize) -> CliResult<Table<T>> {
    let stdin = path.as_os_str() == "-";
    let name = if stdin {
        "standard input".to_string()
    } else {
        path.display().to_string()
    };
    let mut bytes = Vec::new();
    let read = if stdin {
        std::io::stdin().read_to_end(&mut bytes).map(|_| ())
    } else {
        std::fs::File::open(path).and_then(|mut f| f.read_to_end(&mut bytes).map(|_| ()))
    };
    read.map_err(|e| CliError::about(format!("cannot read {name}"), e))?;
    let npy_name = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    let table = if bytes.starts_with(MAGIC) || npy_name {
        read_npy(&bytes, name, columns)
    } else {
        read_text(&bytes, name, columns)
    };
    Ok(table?)
}

fn read_text<T: Number>(bytes: &[u8], name: String, columns: usize) -> Result<Table<T>, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        format!("{name}:{line}: not text (UTF-8)")
    })?;
    let (mut rows, mut lines) = (Vec::new(), Vec::new());
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        if fields.len() != columns {
            return Err(format!(
                "{name}:{}: expected {columns} numbers, found {}",
                i + 1,
                fields.len()
            ));
        }
        let row = fields
            .iter()
            .map(|f| {
                T::parse(f).ok_or_else(|| format!("{name}:{}: '{f}' is not {}", i + 1, T::WHAT))
            })
            .collect::<Result<Vec<T>, String>>()?;
        rows.push(row);
        lines.push(i + 1);
    }
    Ok(Table {
        rows,
        name,
        lines: Some(lines),
    })
}

/// The first bytes of every `.npy` file.
const MAGIC: &[u8] = b"\x93NUMPY";

/// A `.npy` array of shape `(N, columns)` (or `(N,)` for one column) of integers, reals or booleans,
/// in either byte order and either memory order.
fn read_npy<T: Number>(bytes: &[u8], name: String, columns: usize) -> Result<Table<T>, String> {
    let bad = |offset: usize, what: &str| format!("{name}: byte {offset}: {what}");
    if !bytes.starts_with(MAGIC) || bytes.len() < 10 {
        return Err(bad(0, "not a .npy file (no \\x93NUMPY header)"));
    }
    let (len, start) = match bytes[6] {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(bad(6, &format!("unsupported .npy version {v}"))),
    };
    let header = bytes
        .get(start..start + len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| bad(start, "the header is cut short or not text"))?;
    let field = |key: &str| -> Result<&str, String> {
        let at = header
            .find(&format!("'{key}'"))
            .ok_or_else(|| bad(start, &format!("the header has no '{key}'")))?;
        let rest = header[at + key.len() + 2..].trim_start();
        rest.strip_prefix(':')
            .map(str::trim_start)
            .ok_or_else(|| bad(start, &format!("the header's '{key}' has no value")))
    };
    let descr = field("descr")?;
    let descr = descr
        .strip_prefix('\'')
        .and_then(|d| d.split('\'').next())
        .ok_or_else(|| bad(start, "the header's 'descr' is not a string"))?;
    let fortran = field("fortran_order")?.starts_with("True");
    let shape_text = field("shape")?;
    let shape: Vec<usize> = shape_text
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad(start, "the header's 'shape' is not a tuple"))?
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse()
                .map_err(|_| bad(start, &format!("'{s}' in the shape is not a size")))
        })
        .collect::<Result<_, _>>()?;
    let (n, c) = match shape[..] {
        [n, c] => (n, c),
        [n] if columns == 1 => (n, 1),
        _ => {
            return Err(bad(
                start,
                &format!("the array has shape {shape:?}; expected (N, {columns})"),
            ))
        }
    };
    if c != columns {
        return Err(bad(
            start,
            &format!("the array has {c} columns; expected {columns}"),
        ));
    }
    let (order, kind, size) = {
        let mut ch = descr.chars();
        let order = ch.next().unwrap_or('?');
        let kind = ch.next().unwrap_or('?');
        (order, kind, ch.as_str().parse::<usize>().unwrap_or(0))
    };
    let big = match order {
        '<' | '|' | '=' => false,
        '>' => true,
        _ => return Err(bad(start, &format!("unsupported dtype '{descr}'"))),
    };
    let ok = matches!(
        (kind, size),
        ('i' | 'u', 1 | 2 | 4 | 8) | ('f', 4 | 8) | ('b', 1)
    );
    if !ok {
        return Err(bad(start, &format!("unsupported dtype '{descr}'")));
    }
    let data = start + len;
    let need = n
        .checked_mul(c)
        .and_then(|e| e.checked_mul(size))
        .ok_or_else(|| bad(start, "the shape is too large"))?;
    if bytes.len() < data + need {
        return Err(bad(
            bytes.len(),
            &format!("the data ends after {} of {need} bytes", bytes.len() - data),
        ));
    }
    let element = |i: usize| -> Result<T, String> {
        let at = data + i * size;
        let mut raw = [0u8; 8];
        raw[..size].copy_from_slice(&bytes[at..at + size]);
        if big {
            raw[..size].reverse();
        }
        let value = match kind {
            'f' if size == 4 => T::from_real(f64::from(f32::from_le_bytes(
                raw[..4].try_into().expect("4 bytes"),
            ))),
            'f' => T::from_real(f64::from_le_bytes(raw)),
            'u' | 'b' => T::from_int(i128::from(u64::from_le_bytes(raw))),
            _ => {
                let shift = 64 - 8 * size as u32;
                T::from_int(i128::from(i64::from_le_bytes(raw) << shift >> shift))
            }
        };
        value.ok_or_else(|| {
            bad(
                at,
                &format!("element {i} (dtype '{descr}') is not {}", T::WHAT),
            )
        })
    };
    let mut rows = Vec::with_capacity(n);
    for r in 0..n {
        let row = (0..c)
            .map(|j| element(if fortran { j * n + r } else { r * c + j }))
            .collect::<Result<Vec<T>, String>>()?;
        rows.push(row);
    }
    Ok(Table {
        rows,
        name,
        lines: None,
    })
}
