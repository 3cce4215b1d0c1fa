//! PCL's PCD files: `DATA ascii`, `binary` (records of the fields in order) and `binary_compressed`
//! (`u32` compressed and uncompressed sizes, then LZF data holding the fields column by column: every
//! point's first field, then every point's second, …, padding fields named `_` left out).
//!
//! A point whose `x`, `y` and `z` are all NaN is PCL's mark of a pixel without a measurement in an
//! organized cloud (`is_dense` false): it has no position and is skipped (with its attributes). Any other
//! coordinate that is not finite is an error.
//!
//! The fields `rgb` or `rgba` (PCL's packed colour), `intensity` and `label` or `class` are kept when
//! present, each from its first value.

use super::{class, finite, lzf, unpack, Points};
use crate::io::geometry_file::Fault;
use crate::io::scalar::Scalar;
use crate::solid::cloud::PointAttributes;

/// A field of a PCD point: its name, type and number of values.
struct Field<'a> {
    name: &'a str,
    kind: Scalar,
    count: usize,
}

impl Field<'_> {
    fn size(&self) -> usize {
        self.kind.size() * self.count
    }
}

/// The header of a PCD file.
struct Header<'a> {
    fields: Vec<Field<'a>>,
    /// The points the header declares.
    count: u64,
    /// `DATA`'s word.
    data: &'a str,
    /// The header's lines (the last is `DATA`).
    lines: usize,
    /// The byte offset of the body.
    body: usize,
}

impl<'a> Header<'a> {
    fn parse(bytes: &'a [u8]) -> Result<Self, Fault> {
        let mut names: Vec<&str> = Vec::new();
        let mut sizes: Vec<&str> = Vec::new();
        let mut types: Vec<&str> = Vec::new();
        let mut counts: Option<Vec<usize>> = None;
        let mut points: Option<u64> = None;
        let (mut width, mut height) = (None, None);
        let mut at = 0;
        for (i, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
            let n = i + 1;
            at += line.len();
            let line = std::str::from_utf8(line)
                .map_err(|_| Fault::line(n, "the PCD header is not text"))?
                .trim();
            let mut words = line.split_ascii_whitespace();
            let key = words.next().unwrap_or("");
            let rest: Vec<&str> = words.collect();
            let number = |w: &[&str]| -> Result<u64, Fault> {
                w.first()
                    .and_then(|v| v.parse().ok())
                    .ok_or_else(|| Fault::line(n, format!("{key}: expected a number")))
            };
            match key {
                "" | "VERSION" | "VIEWPOINT" => {}
                k if k.starts_with('#') => {}
                "FIELDS" => names = rest,
                "SIZE" => sizes = rest,
                "TYPE" => types = rest,
                "COUNT" => {
                    counts = Some(
                        rest.iter()
                            .map(|c| c.parse::<usize>().ok().filter(|&c| c > 0 && c <= 1 << 16))
                            .collect::<Option<_>>()
                            .ok_or_else(|| Fault::line(n, "COUNT: expected numbers 1…65536"))?,
                    )
                }
                "WIDTH" => width = Some(number(&rest)?),
                "HEIGHT" => height = Some(number(&rest)?),
                "POINTS" => points = Some(number(&rest)?),
                "DATA" => {
                    let data = rest.first().copied().unwrap_or("");
                    return Self::fields(
                        names,
                        sizes,
                        types,
                        counts,
                        (points, width, height),
                        data,
                    )
                    .map(|(fields, count)| Self {
                        fields,
                        count,
                        data,
                        lines: n,
                        body: at,
                    })
                    .map_err(|m| Fault::line(n, m));
                }
                _ => return Err(Fault::line(n, format!("unknown PCD header line '{line}'"))),
            }
        }
        Err(Fault::whole("the PCD header has no DATA line"))
    }

    /// The fields and the point count of the header's lines.
    #[allow(clippy::type_complexity)]
    fn fields(
        names: Vec<&'a str>,
        sizes: Vec<&str>,
        types: Vec<&str>,
        counts: Option<Vec<usize>>,
        (points, width, height): (Option<u64>, Option<u64>, Option<u64>),
        data: &str,
    ) -> Result<(Vec<Field<'a>>, u64), String> {
        let counts = counts.unwrap_or_else(|| vec![1; names.len()]);
        if sizes.len() != names.len() || types.len() != names.len() || counts.len() != names.len() {
            return Err(format!(
                "PCD: FIELDS, SIZE, TYPE and COUNT list {}, {}, {} and {} entries",
                names.len(),
                sizes.len(),
                types.len(),
                counts.len()
            ));
        }
        let count = match (points, width, height) {
            (Some(p), _, _) => p,
            (None, Some(w), Some(h)) => w.checked_mul(h).ok_or("PCD: WIDTH × HEIGHT overflows")?,
            _ => {
                return Err(format!(
                    "PCD 'DATA {data}': no POINTS line (nor WIDTH and HEIGHT)"
                ))
            }
        };
        let mut fields = Vec::with_capacity(names.len());
        for (i, &name) in names.iter().enumerate() {
            let kind = Scalar::pcd(types[i], sizes[i]).ok_or_else(|| {
                format!(
                    "PCD: field '{name}' has TYPE {} SIZE {}: expected I/U of 1, 2, 4, 8 or F of 4, 8 bytes",
                    types[i], sizes[i]
                )
            })?;
            fields.push(Field {
                name,
                kind,
                count: counts[i],
            });
        }
        Ok((fields, count))
    }

    /// The index of the field `name`.
    fn field(&self, name: &str) -> Result<usize, Fault> {
        self.fields
            .iter()
            .position(|f| f.name == name)
            .ok_or_else(|| Fault::line(self.lines, format!("PCD: no field '{name}'")))
    }
}

/// A field's first value of one point as stored: its bytes (binary) or its word (ASCII).
#[derive(Clone, Copy)]
enum Raw<'a> {
    Bytes(&'a [u8]),
    Word(&'a str),
}

impl Raw<'_> {
    /// The value as a number.
    fn number(self, kind: Scalar) -> Result<f64, String> {
        match self {
            Raw::Bytes(b) => Ok(kind.get(b, false)),
            Raw::Word(w) => w.parse().map_err(|_| format!("'{w}' is not a number")),
        }
    }

    /// The 32 bits of a packed colour: those of the float (`F 4`) or of the integer.
    fn bits(self, kind: Scalar) -> Result<u32, String> {
        match (self, kind) {
            (Raw::Bytes(b), _) => Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            (Raw::Word(w), Scalar::F32) => w
                .parse::<f32>()
                .map(f32::to_bits)
                .map_err(|_| format!("'{w}' is not a number")),
            (Raw::Word(w), _) => w
                .parse::<i64>()
                .map(|v| v as u32)
                .map_err(|_| format!("'{w}' is not a whole number")),
        }
    }
}

/// The attribute fields a PCD file has, and their values as read.
struct Attributes {
    rgb: Option<usize>,
    intensity: Option<usize>,
    label: Option<usize>,
    read: PointAttributes,
}

impl Attributes {
    fn new(header: &Header) -> Result<Self, Fault> {
        let find = |names: &[&str]| header.fields.iter().position(|f| names.contains(&f.name));
        let rgb = find(&["rgb", "rgba"]);
        if let Some(f) = rgb.filter(|&f| header.fields[f].kind.size() != 4) {
            return Err(Fault::line(
                header.lines,
                format!(
                    "PCD: field '{}' holds a packed colour in 4 bytes, not {}",
                    header.fields[f].name,
                    header.fields[f].kind.size()
                ),
            ));
        }
        let (intensity, label) = (find(&["intensity"]), find(&["label", "class"]));
        // Columns grow with the points read (a count from a header is not trusted to allocate).
        Ok(Self {
            rgb,
            intensity,
            label,
            read: PointAttributes {
                colours: rgb.map(|_| Vec::new()),
                intensities: intensity.map(|_| Vec::new()),
                classes: label.map(|_| Vec::new()),
            },
        })
    }

    /// Keeps the attributes of a point whose fields' first values `raw(f)` gives; `Err` the reason why
    /// one cannot be read.
    fn push<'a>(&mut self, header: &Header, raw: impl Fn(usize) -> Raw<'a>) -> Result<(), String> {
        let kind = |f: usize| header.fields[f].kind;
        if let (Some(f), Some(c)) = (self.rgb, &mut self.read.colours) {
            c.push(unpack(raw(f).bits(kind(f))?));
        }
        if let (Some(f), Some(c)) = (self.intensity, &mut self.read.intensities) {
            c.push(raw(f).number(kind(f))? as f32);
        }
        if let (Some(f), Some(c)) = (self.label, &mut self.read.classes) {
            c.push(class(raw(f).number(kind(f))?).map_err(|why| format!("the point {why}"))?);
        }
        Ok(())
    }
}

/// The points of a PCD file.
pub(super) fn read(bytes: &[u8]) -> Result<Points, Fault> {
    let header = Header::parse(bytes)?;
    let xyz = [header.field("x")?, header.field("y")?, header.field("z")?];
    let mut attributes = Attributes::new(&header)?;
    let (body, count) = (header.body, header.count);
    let points = match header.data {
        "ascii" => read_ascii(bytes, &header, xyz, &mut attributes),
        "binary" => {
            let record: usize = header.fields.iter().map(Field::size).sum();
            records(bytes, body, count, record)?;
            // The first value of each field: its byte offset in a record.
            let offsets: Vec<usize> = (0..header.fields.len())
                .map(|f| header.fields[..f].iter().map(Field::size).sum())
                .collect();
            let mut out = Vec::with_capacity(count as usize);
            for i in 0..count as usize {
                let at = body + i * record;
                let p = std::array::from_fn(|a| {
                    header.fields[xyz[a]]
                        .kind
                        .get(&bytes[at + offsets[xyz[a]]..], false)
                });
                if measured(p) {
                    out.push(finite(p, |why| {
                        Fault::byte(at, format!("point {i} {why}"))
                    })?);
                    attributes
                        .push(&header, |f| Raw::Bytes(&bytes[at + offsets[f]..]))
                        .map_err(|why| Fault::byte(at, format!("PCD point {i}: {why}")))?;
                }
            }
            Ok(out)
        }
        "binary_compressed" => read_compressed(bytes, &header, xyz, &mut attributes),
        other => Err(Fault::line(
            header.lines,
            format!("unknown PCD DATA '{other}' (expected ascii, binary or binary_compressed)"),
        )),
    }?;
    Ok((points, attributes.read))
}

fn read_ascii(
    bytes: &[u8],
    header: &Header,
    xyz: [usize; 3],
    attributes: &mut Attributes,
) -> Result<Vec<[f64; 3]>, Fault> {
    let (body, count) = (header.body, header.count);
    if count > (bytes.len() - body) as u64 {
        return Err(Fault::byte(
            body,
            format!(
                "PCD: {count} points declared but only {} bytes follow the header",
                bytes.len() - body
            ),
        ));
    }
    // The first value of each field: its index among a point's values.
    let index: Vec<usize> = (0..header.fields.len())
        .map(|f| header.fields[..f].iter().map(|f| f.count).sum())
        .collect();
    let values: usize = header.fields.iter().map(|f| f.count).sum();
    let mut out = Vec::with_capacity(count as usize);
    let mut rows = bytes[body..]
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, l)| (header.lines + 1 + i, l))
        .filter(|(_, l)| !l.iter().all(u8::is_ascii_whitespace));
    for i in 0..count {
        let (n, line) = rows
            .next()
            .ok_or_else(|| Fault::whole(format!("the PCD file ends at point {i} of {count}")))?;
        let text = std::str::from_utf8(line).map_err(|_| Fault::line(n, "not UTF-8 text"))?;
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        if words.len() != values {
            return Err(Fault::line(
                n,
                format!("expected {values} values, found {}", words.len()),
            ));
        }
        let mut p = [0.0; 3];
        for a in 0..3 {
            let w = words[index[xyz[a]]];
            p[a] = w
                .parse()
                .map_err(|_| Fault::line(n, format!("'{w}' is not a number")))?;
        }
        if measured(p) {
            out.push(finite(p, |why| Fault::line(n, format!("point {i} {why}")))?);
            attributes
                .push(header, |f| Raw::Word(words[index[f]]))
                .map_err(|why| Fault::line(n, format!("point {i}: {why}")))?;
        }
    }
    Ok(out)
}

/// `binary_compressed`: the sizes, checked against the file and the fields before the LZF data are
/// decompressed, then each point's x, y, z from their columns.
fn read_compressed(
    bytes: &[u8],
    header: &Header,
    xyz: [usize; 3],
    attributes: &mut Attributes,
) -> Result<Vec<[f64; 3]>, Fault> {
    let body = header.body;
    let u32_at = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| Fault::byte(at, "PCD: the file ends before the compressed sizes"))
    };
    let (compressed, uncompressed) = (u32_at(body)? as usize, u32_at(body + 4)? as usize);
    let data = body + 8;
    let have = bytes.len() - data.min(bytes.len());
    if compressed > have {
        return Err(Fault::byte(
            body,
            format!("PCD: {compressed} bytes of compressed data declared but the file has {have} after the sizes"),
        ));
    }
    // Padding fields (named `_`) are not stored.
    let stored: Vec<&Field> = header.fields.iter().filter(|f| f.name != "_").collect();
    let point: u64 = stored.iter().map(|f| f.size() as u64).sum();
    let need = header.count.saturating_mul(point);
    if need != uncompressed as u64 {
        return Err(Fault::byte(
            body + 4,
            format!(
                "PCD: {} points of {point} bytes need {need} bytes, but the uncompressed size is {uncompressed}",
                header.count
            ),
        ));
    }
    if uncompressed as u64 > (compressed as u64).saturating_mul(lzf::MAX_RATIO) {
        return Err(Fault::byte(
            body + 4,
            format!(
                "PCD: {uncompressed} bytes cannot come from {compressed} bytes of LZF data (at most {} times as many)",
                lzf::MAX_RATIO
            ),
        ));
    }
    let columns = lzf::decompress(&bytes[data..data + compressed], uncompressed, data)
        .map_err(|(at, why)| Fault::byte(at, format!("PCD: {why}")))?;
    let count = header.count as usize;
    // Where the column of x, y, z starts, and the bytes a point takes in it.
    let column = |f: usize| -> (usize, usize) {
        let before: usize = header.fields[..f]
            .iter()
            .filter(|s| s.name != "_")
            .map(Field::size)
            .sum();
        (before * count, header.fields[f].size())
    };
    // Padding fields hold no attribute: their column is never asked for.
    let columns_of: Vec<(usize, usize)> = (0..header.fields.len()).map(column).collect();
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let p = std::array::from_fn(|a| {
            let (start, step) = columns_of[xyz[a]];
            header.fields[xyz[a]]
                .kind
                .get(&columns[start + i * step..], false)
        });
        if measured(p) {
            out.push(finite(p, |why| {
                Fault::byte(data, format!("PCD: the compressed point {i} {why}"))
            })?);
            attributes
                .push(header, |f| {
                    let (start, step) = columns_of[f];
                    Raw::Bytes(&columns[start + i * step..])
                })
                .map_err(|why| {
                    Fault::byte(data, format!("PCD: the compressed point {i}: {why}"))
                })?;
        }
    }
    Ok(out)
}

/// Whether a point has a position: not all of x, y, z NaN (PCL's mark of a point without a measurement).
fn measured(p: [f64; 3]) -> bool {
    !p.iter().all(|c| c.is_nan())
}

/// Checks that `count` binary records of `record` bytes each fit after `at`, before anything is read.
fn records(bytes: &[u8], at: usize, count: u64, record: usize) -> Result<(), Fault> {
    let need = count.saturating_mul(record as u64);
    let have = (bytes.len() - at) as u64;
    if need > have {
        return Err(Fault::byte(
            at,
            format!(
                "PCD: {count} points of {record} bytes need {need} bytes but the file has {have} after its header"
            ),
        ));
    }
    Ok(())
}
