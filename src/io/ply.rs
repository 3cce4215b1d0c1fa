//! PLY, read the same way for point clouds and meshes: the header ([`PlyHeader`]) and then the entries of
//! its elements in file order ([`read_body`]), ASCII (an entry a line) or binary of either byte order.
//!
//! The header is checked a line at a time, and the counts it declares against the bytes that follow it,
//! before anything is allocated for them.

use super::geometry_file::Fault;
use super::location::Place;
use super::scalar::Scalar;

/// A property of a PLY element: a scalar, or a list with the type of its length and of its items.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum PlyProperty {
    Scalar {
        name: String,
        kind: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl PlyProperty {
    /// The bytes it takes at least in a binary entry.
    fn min_size(&self) -> usize {
        match self {
            Self::Scalar { kind, .. } => kind.size(),
            Self::List { count, .. } => count.size(),
        }
    }
}

/// An element a PLY header declares: its name, how many entries the body holds, and their properties.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct PlyElement {
    pub(crate) name: String,
    pub(crate) count: u64,
    pub(crate) properties: Vec<PlyProperty>,
}

impl PlyElement {
    /// The index of the scalar property `name`.
    pub(crate) fn scalar(&self, name: &str) -> Option<usize> {
        self.properties
            .iter()
            .position(|p| matches!(p, PlyProperty::Scalar { name: n, .. } if n == name))
    }

    /// The index of the first list property named one of `names`.
    pub(crate) fn list(&self, names: &[&str]) -> Option<usize> {
        self.properties.iter().position(
            |p| matches!(p, PlyProperty::List { name, .. } if names.contains(&name.as_str())),
        )
    }

    /// The bytes an entry takes at least in a binary body (at least one in any body).
    fn min_size(&self, binary: bool) -> u64 {
        if binary {
            self.properties
                .iter()
                .map(|p| p.min_size() as u64)
                .sum::<u64>()
                .max(1)
        } else {
            1
        }
    }
}

/// The header of a PLY file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct PlyHeader {
    /// `None`: ASCII; `Some(big)`: binary, big-endian or not.
    pub(crate) big: Option<bool>,
    pub(crate) elements: Vec<PlyElement>,
    /// The byte offset of the body.
    pub(crate) body: usize,
    /// The header's lines (the body starts on the next).
    pub(crate) lines: usize,
}

impl PlyHeader {
    /// Reads the header at the start of `bytes`, a line at a time, the first bad line ending it: a number
    /// on a `format` or `element` line that does not fit a `u64`, an unknown line, format or type, a
    /// property before any element, an element of entries with no property. Then checks that the body
    /// can hold the entries declared ([`PlyHeader::check_counts`]). Errors name the line or byte.
    pub(crate) fn parse(bytes: &[u8]) -> Result<Self, Fault> {
        let header = Self::parse_lines(bytes)?;
        header.check_counts(bytes)?;
        Ok(header)
    }

    fn parse_lines(bytes: &[u8]) -> Result<Self, Fault> {
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
                .map_err(|_| Fault::line(n, "the PLY header is not text"))?
                .trim();
            if n == 1 {
                if line != "ply" {
                    return Err(Fault::line(1, "a PLY file starts with 'ply'"));
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
                return Err(Fault::line(
                    n,
                    format!("number too large in the PLY header line '{line}'"),
                ));
            }
            let property = |elements: &mut Vec<PlyElement>, p: PlyProperty| {
                elements
                    .last_mut()
                    .map(|e| e.properties.push(p))
                    .ok_or_else(|| Fault::line(n, "a PLY property before any element"))
            };
            match words.as_slice() {
                ["format", f, _] => {
                    big = Some(match *f {
                        "ascii" => None,
                        "binary_little_endian" => Some(false),
                        "binary_big_endian" => Some(true),
                        f => return Err(Fault::line(n, format!("unknown PLY format '{f}'"))),
                    });
                }
                ["element", name, count] => {
                    let count = count
                        .parse::<u64>()
                        .map_err(|_| Fault::line(n, format!("bad element count '{count}'")))?;
                    elements.push(PlyElement {
                        name: name.to_string(),
                        count,
                        properties: Vec::new(),
                    });
                }
                ["property", "list", c, t, name] => {
                    let (Some(count), Some(item)) = (Scalar::ply(c), Scalar::ply(t)) else {
                        return Err(Fault::line(n, format!("unknown property type in '{line}'")));
                    };
                    if !count.is_integer() {
                        return Err(Fault::line(
                            n,
                            format!("a list's length must be of an integer type: '{line}'"),
                        ));
                    }
                    let name = name.to_string();
                    property(&mut elements, PlyProperty::List { name, count, item })?;
                }
                ["property", t, name] => {
                    let kind = Scalar::ply(t)
                        .ok_or_else(|| Fault::line(n, format!("unknown property type '{t}'")))?;
                    let name = name.to_string();
                    property(&mut elements, PlyProperty::Scalar { name, kind })?;
                }
                ["end_header"] => {
                    let big =
                        big.ok_or_else(|| Fault::line(n, "the PLY header has no format line"))?;
                    if let Some(e) = elements
                        .iter()
                        .find(|e| e.count > 0 && e.properties.is_empty())
                    {
                        return Err(Fault::line(
                            n,
                            format!(
                                "PLY element '{}' has {} entries but no property",
                                e.name, e.count
                            ),
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
                _ => {
                    return Err(Fault::line(
                        n,
                        format!("unexpected PLY header line '{line}'"),
                    ))
                }
            }
        }
        Err(Fault::whole(
            "the PLY header has no end line (no end_header)",
        ))
    }

    /// Checks that the body can hold the entries declared: each takes at least a byte (in a binary body,
    /// its scalars and list lengths), so a header declaring more is refused before anything is allocated
    /// for them.
    fn check_counts(&self, bytes: &[u8]) -> Result<(), Fault> {
        let body = (bytes.len() - self.body) as u64;
        let binary = self.big.is_some();
        let need = self.elements.iter().fold(0u64, |sum, e| {
            sum.saturating_add(e.count.saturating_mul(e.min_size(binary)))
        });
        if need > body {
            let declared = self
                .elements
                .iter()
                .map(|e| format!("{} '{}'", e.count, e.name))
                .collect::<Vec<_>>()
                .join(", ");
            return Err(Fault::byte(
                self.body,
                format!(
                    "the PLY header declares {declared} entries, which take at least {need} bytes, but only {body} bytes follow it"
                ),
            ));
        }
        Ok(())
    }

    /// The index of the element `name`.
    pub(crate) fn element(&self, name: &str) -> Option<usize> {
        self.elements.iter().position(|e| e.name == name)
    }
}

/// Whether a PLY header declares a `face` element with at least one entry (the file is then a mesh).
///
/// # Errors
/// The header's first fault, as [`PlyHeader::parse`] finds it (without the check of its counts, so that a
/// file's head is enough).
pub(crate) fn ply_has_faces(head: &[u8]) -> Result<bool, Fault> {
    let header = PlyHeader::parse_lines(head)?;
    Ok(header
        .elements
        .iter()
        .any(|e| e.name == "face" && e.count > 0))
}

/// The values of one entry of an element: property `j`'s values (one for a scalar, the items of a list)
/// are `values[starts[j]..starts[j + 1]]`.
#[derive(Debug, Default)]
pub(crate) struct PlyEntry {
    values: Vec<f64>,
    starts: Vec<usize>,
}

impl PlyEntry {
    /// The value of the scalar property `j`.
    pub(crate) fn scalar(&self, j: usize) -> f64 {
        self.values[self.starts[j]]
    }

    /// The items of the list property `j`.
    pub(crate) fn list(&self, j: usize) -> &[f64] {
        &self.values[self.starts[j]..self.starts[j + 1]]
    }

    fn clear(&mut self) {
        self.values.clear();
        self.starts.clear();
        self.starts.push(0);
    }

    fn end_property(&mut self) {
        self.starts.push(self.values.len());
    }
}

/// Reads the entries of the elements `0..=last` in file order, handing each to `visit` with its element,
/// its index in the element and where it starts (its line, or its byte offset).
///
/// # Errors
/// The first fault of the body, naming the line or byte; whatever `visit` returns.
pub(crate) fn read_body(
    bytes: &[u8],
    header: &PlyHeader,
    last: usize,
    mut visit: impl FnMut(usize, u64, &PlyEntry, Place) -> Result<(), Fault>,
) -> Result<(), Fault> {
    let mut entry = PlyEntry::default();
    match header.big {
        Some(big) => {
            let mut at = header.body;
            for (e, element) in header.elements.iter().enumerate().take(last + 1) {
                for i in 0..element.count {
                    let start = at;
                    entry.clear();
                    for p in &element.properties {
                        at = read_binary_property(bytes, at, p, big, &mut entry.values)
                            .ok_or_else(|| {
                                Fault::byte(start, format!("PLY {} {i} is cut short", element.name))
                            })?;
                        entry.end_property();
                    }
                    visit(e, i, &entry, Place::Byte(start as u64))?;
                }
            }
        }
        None => {
            let mut lines = bytes[header.body..]
                .split(|&b| b == b'\n')
                .enumerate()
                .map(|(i, l)| (header.lines + 1 + i, l))
                .filter(|(_, l)| !l.iter().all(u8::is_ascii_whitespace));
            for (e, element) in header.elements.iter().enumerate().take(last + 1) {
                let name = &element.name;
                for i in 0..element.count {
                    let (n, line) = lines.next().ok_or_else(|| {
                        Fault::whole(format!(
                            "the PLY file ends at {name} {i} of {}",
                            element.count
                        ))
                    })?;
                    let text =
                        std::str::from_utf8(line).map_err(|_| Fault::line(n, "not UTF-8 text"))?;
                    let mut words = text.split_ascii_whitespace();
                    let mut word = || {
                        words
                            .next()
                            .ok_or_else(|| Fault::line(n, format!("{name} {i} has too few values")))
                    };
                    entry.clear();
                    for p in &element.properties {
                        match p {
                            PlyProperty::Scalar { .. } => {
                                let w = word()?;
                                entry.values.push(number(w, n)?);
                            }
                            PlyProperty::List { .. } => {
                                let w = word()?;
                                let len: u64 = w.parse().map_err(|_| {
                                    Fault::line(n, format!("list length '{w}' is not a count"))
                                })?;
                                for _ in 0..len {
                                    let w = word()?;
                                    entry.values.push(number(w, n)?);
                                }
                            }
                        }
                        entry.end_property();
                    }
                    visit(e, i, &entry, Place::Line(n))?;
                }
            }
        }
    }
    Ok(())
}

/// A number of an ASCII body.
fn number(word: &str, line: usize) -> Result<f64, Fault> {
    word.parse()
        .map_err(|_| Fault::line(line, format!("'{word}' is not a number")))
}

/// Appends the values of the property at `at` to `values`, returning the offset after it (`None`: past the
/// end, or a list length that is not a count).
fn read_binary_property(
    bytes: &[u8],
    at: usize,
    p: &PlyProperty,
    big: bool,
    values: &mut Vec<f64>,
) -> Option<usize> {
    let field = |at: usize, kind: Scalar| -> Option<(f64, usize)> {
        let end = at.checked_add(kind.size())?;
        (end <= bytes.len()).then(|| (kind.get(&bytes[at..], big), end))
    };
    match *p {
        PlyProperty::Scalar { kind, .. } => {
            let (v, end) = field(at, kind)?;
            values.push(v);
            Some(end)
        }
        PlyProperty::List { count, item, .. } => {
            let (n, mut end) = field(at, count)?;
            // The items must fit in what is left, so a length never decides more than the file holds.
            let left = (bytes.len() - end) / item.size();
            if !(0.0..=left as f64).contains(&n) {
                return None;
            }
            for _ in 0..n as usize {
                let (v, next) = field(end, item)?;
                values.push(v);
                end = next;
            }
            Some(end)
        }
    }
}
