//! ASPRS LAS 1.0–1.4, and LAZ (LASzip-compressed LAS): every point's `X`, `Y`, `Z` (the first 12 bytes of
//! every point format), scaled and offset as the header says, and its intensity, classification and, in
//! the point formats that have it, its RGB colour (see [`super`] for how colours become 8 bits).
//!
//! The header is read by the `las` crate; everything it declares is checked against the file before
//! anything is allocated for it:
//! * the point count (in LAS 1.4 the legacy count at byte 107 and the 64-bit one at byte 247 must agree
//!   when both are given) against the point data: uncompressed, `count × record length` bytes between the
//!   offset to the point data and the first extended record (or the end of the file); compressed, the
//!   chunk table (its chunks' point counts must add up to the count, or, for chunks of a fixed size, their
//!   number must be the count's);
//! * the variable-length records and the extended ones against the bytes that follow them;
//! * each LAZ chunk is decoded by the `laz` crate from its own bytes only, so a chunk that cannot hold the
//!   points it should is an error, not points read from the bytes after it; the layers a LAS 1.4 chunk
//!   declares for its coordinates are checked against the chunk before they are read.

use std::io::Cursor;

use laz::las::selective::DecompressionSelection;
use laz::laszip::{ChunkTable, LazItemType, LazVlr};
use laz::record::{
    LayeredPointRecordDecompressor, RecordDecompressor, SequentialPointRecordDecompressor,
};

use super::{finite, Points};
use crate::io::geometry_file::Fault;
use crate::solid::cloud::PointAttributes;
use crate::value::Rgb;

/// Byte offsets of header fields (ASPRS LAS 1.4 R15, table 3).
const LEGACY_POINT_COUNT: usize = 107;
const POINT_COUNT: usize = 247;
const POINT_FORMAT: usize = 104;
const RECORD_LENGTH: usize = 105;
const HEADER_SIZE: usize = 94;
const OFFSET_TO_POINT_DATA: usize = 96;
const START_OF_FIRST_EVLR: usize = 235;
/// A variable-length record's header (54 bytes) and an extended one's (60).
const VLR_HEADER: usize = 54;
const EVLR_HEADER: usize = 60;

/// The points of a LAS or LAZ file.
pub(super) fn read(bytes: &[u8]) -> Result<Points, Fault> {
    let header = las::raw::Header::read_from(bytes)
        .map_err(|e| Fault::byte(0, format!("LAS header: {e}")))?;
    let legacy = u64::from(header.number_of_point_records);
    let count = match header.large_file {
        Some(large) if large.number_of_point_records != 0 => {
            if legacy != 0 && legacy != large.number_of_point_records {
                return Err(Fault::byte(
                    LEGACY_POINT_COUNT,
                    format!(
                        "LAS: the legacy point count {legacy} disagrees with the point count {} at byte {POINT_COUNT}",
                        large.number_of_point_records
                    ),
                ));
            }
            large.number_of_point_records
        }
        _ => legacy,
    };
    let count_at = if legacy == 0 && header.large_file.is_some() {
        POINT_COUNT
    } else {
        LEGACY_POINT_COUNT
    };
    let format = las::point::Format::new(header.point_data_record_format)
        .map_err(|e| Fault::byte(POINT_FORMAT, format!("LAS: {e}")))?;
    let record = usize::from(header.point_data_record_length);
    if record < usize::from(format.len()) || record < 12 {
        return Err(Fault::byte(
            RECORD_LENGTH,
            format!(
                "LAS: records of {record} bytes are shorter than point format {}'s {} bytes",
                header.point_data_record_format & 0x3f,
                format.len()
            ),
        ));
    }
    // The header's size at least as its version's fields take (ASPRS: 227 bytes, 235 in 1.3, 375 in 1.4).
    let least = match header.version.minor {
        0..=2 => 227,
        3 => 235,
        _ => 375,
    };
    if header.header_size < least {
        return Err(Fault::byte(
            HEADER_SIZE,
            format!(
                "LAS: a header of {} bytes, but LAS 1.{}'s takes {least}",
                header.header_size, header.version.minor
            ),
        ));
    }
    let start = header.offset_to_point_data as usize;
    if start > bytes.len() || start < usize::from(header.header_size) {
        return Err(Fault::byte(
            OFFSET_TO_POINT_DATA,
            format!(
                "LAS: the point data are said to start at byte {start}, outside the {} bytes after the {}-byte header",
                bytes.len().saturating_sub(usize::from(header.header_size)),
                header.header_size
            ),
        ));
    }
    let vlrs = variable_length_records(bytes, usize::from(header.header_size), start, &header)?;
    let end = match header.evlr {
        Some(evlr) => {
            check_extended_records(bytes, evlr.start_of_first_evlr, evlr.number_of_evlrs, start)?
        }
        None => bytes.len(),
    };
    let scale = [
        (header.x_scale_factor, header.x_offset),
        (header.y_scale_factor, header.y_offset),
        (header.z_scale_factor, header.z_offset),
    ];
    let point = |i: u64, raw: &[u8], at: usize| -> Result<[f64; 3], Fault> {
        let p = std::array::from_fn(|a| {
            let v =
                i32::from_le_bytes([raw[4 * a], raw[4 * a + 1], raw[4 * a + 2], raw[4 * a + 3]]);
            f64::from(v) * scale[a].0 + scale[a].1
        });
        finite(p, |why| Fault::byte(at, format!("LAS point {i} {why}")))
    };
    let mut columns = Columns::new(&format);
    if !format.is_compressed {
        let need = count.saturating_mul(record as u64);
        let have = (end - start) as u64;
        if need > have {
            return Err(Fault::byte(
                count_at,
                format!(
                    "LAS: the header declares {count} points of {record} bytes ({need} bytes), but the point data (bytes {start} to {end}) hold {have}"
                ),
            ));
        }
        let mut points = Vec::with_capacity(count as usize);
        columns.reserve(count as usize);
        for i in 0..count {
            let at = start + i as usize * record;
            points.push(point(i, &bytes[at..at + 12], at)?);
            columns.push(&bytes[at..at + record]);
        }
        return Ok((points, columns.finish()));
    }
    let laszip = vlrs.laszip.ok_or_else(|| {
        Fault::byte(
            POINT_FORMAT,
            "LAZ: the point format says compressed, but no LASzip record describes the compression",
        )
    })?;
    let vlr = LazVlr::read_from(&bytes[laszip.clone()])
        .map_err(|e| Fault::byte(laszip.start, format!("LAZ: the LASzip record: {e}")))?;
    let items: usize = vlr
        .items()
        .iter()
        .map(|item| usize::from(item.size()))
        .sum();
    if items != record {
        return Err(Fault::byte(
            laszip.start,
            format!("LAZ: the LASzip record describes points of {items} bytes, the header says {record}"),
        ));
    }
    // The record's first field (ASPRS's LASzip record): 1 a single stream, 2 and 3 chunks (of points, of
    // layers).
    let compressor = u16::from_le_bytes([bytes[laszip.start], bytes[laszip.start + 1]]);
    let chunks = chunks(bytes, (start, end), count, (&vlr, compressor), count_at)?;
    let mut points = Vec::with_capacity(count as usize);
    let mut raw = vec![0u8; record];
    for (k, chunk) in chunks.iter().enumerate() {
        let data = &bytes[chunk.bytes.clone()];
        let mut decoder = decoder(data, &vlr, (record, format.has_color), chunk.points)
            .map_err(|why| Fault::byte(chunk.bytes.start, format!("LAZ chunk {k}: {why}")))?;
        for j in 0..chunk.points {
            decoder.decompress_next(&mut raw).map_err(|e| {
                let why = if e.kind() == std::io::ErrorKind::UnexpectedEof {
                    format!(
                        "its {} bytes end after {j} of the {} points the header and the chunk table give it",
                        data.len(),
                        chunk.points
                    )
                } else {
                    e.to_string()
                };
                Fault::byte(chunk.bytes.start, format!("LAZ chunk {k}: {why}"))
            })?;
            let i = points.len() as u64;
            points.push(point(i, &raw, chunk.bytes.start)?);
            columns.push(&raw);
        }
    }
    Ok((points, columns.finish()))
}

/// The attributes of the points read so far: intensity, class, and the colour as stored (16 bits a
/// channel), made 8 bits when all are read.
struct Columns {
    /// Where the class is in a record, and the mask of its bits.
    class: (usize, u8),
    /// Where the colour is, in the formats that have one.
    rgb: Option<usize>,
    intensities: Vec<f32>,
    classes: Vec<u8>,
    colours: Vec<[u16; 3]>,
}

impl Columns {
    /// The columns of points of `format` (ASPRS LAS 1.4 R15, tables 7 to 17).
    fn new(format: &las::point::Format) -> Self {
        let rgb = format
            .has_color
            .then_some(match (format.is_extended, format.has_gps_time) {
                (true, _) => 30,
                (false, true) => 28,
                (false, false) => 20,
            });
        Self {
            class: if format.is_extended {
                (16, 0xff)
            } else {
                (15, 0x1f)
            },
            rgb,
            intensities: Vec::new(),
            classes: Vec::new(),
            colours: Vec::new(),
        }
    }

    fn reserve(&mut self, n: usize) {
        self.intensities.reserve_exact(n);
        self.classes.reserve_exact(n);
        if self.rgb.is_some() {
            self.colours.reserve_exact(n);
        }
    }

    /// Keeps the attributes of one point's record (at least as long as its format's).
    fn push(&mut self, record: &[u8]) {
        let u16_at = |at: usize| u16::from_le_bytes([record[at], record[at + 1]]);
        self.intensities.push(f32::from(u16_at(12)));
        self.classes.push(record[self.class.0] & self.class.1);
        if let Some(at) = self.rgb {
            self.colours
                .push([u16_at(at), u16_at(at + 2), u16_at(at + 4)]);
        }
    }

    /// The attributes: colours by their high byte, unless every channel is below 256 (8-bit colours
    /// stored in 16 bits, kept as they are).
    fn finish(self) -> PointAttributes {
        let eight_bits = self.colours.iter().flatten().all(|&c| c < 256);
        let shift = if eight_bits { 0 } else { 8 };
        let colours = self.rgb.map(|_| {
            self.colours
                .iter()
                .map(|c| c.map(|v| (v >> shift) as u8))
                .collect::<Vec<Rgb>>()
        });
        PointAttributes {
            colours,
            intensities: Some(self.intensities),
            classes: Some(self.classes),
        }
    }
}

/// What the variable-length records hold for this reader: where the LASzip record's data lie.
struct Vlrs {
    laszip: Option<std::ops::Range<usize>>,
}

/// Walks the variable-length records between the header and the point data.
fn variable_length_records(
    bytes: &[u8],
    mut at: usize,
    start: usize,
    header: &las::raw::Header,
) -> Result<Vlrs, Fault> {
    let mut laszip = None;
    for k in 0..header.number_of_variable_length_records {
        if at + VLR_HEADER > start {
            return Err(Fault::byte(
                at,
                format!(
                    "LAS: variable-length record {k} of {} runs past the start of the point data (byte {start})",
                    header.number_of_variable_length_records
                ),
            ));
        }
        let user = &bytes[at + 2..at + 18];
        let id = u16::from_le_bytes([bytes[at + 18], bytes[at + 19]]);
        let length = usize::from(u16::from_le_bytes([bytes[at + 20], bytes[at + 21]]));
        let data = at + VLR_HEADER..at + VLR_HEADER + length;
        if data.end > start {
            return Err(Fault::byte(
                at,
                format!("LAS: variable-length record {k}'s {length} bytes run past the start of the point data (byte {start})"),
            ));
        }
        let user = user.split(|&b| b == 0).next().unwrap_or_default();
        if user == LazVlr::USER_ID.as_bytes() && id == LazVlr::RECORD_ID {
            laszip = Some(data.clone());
        }
        at = data.end;
    }
    Ok(Vlrs { laszip })
}

/// Checks the extended variable-length records of LAS 1.4 (each declares a 64-bit length) against the
/// file; returns where the point data end: at the first record, or the end of the file without one.
fn check_extended_records(bytes: &[u8], first: u64, n: u32, start: usize) -> Result<usize, Fault> {
    if first == 0 || n == 0 {
        return Ok(bytes.len());
    }
    let first = usize::try_from(first).unwrap_or(usize::MAX);
    if first < start || first > bytes.len() {
        return Err(Fault::byte(
            START_OF_FIRST_EVLR,
            format!(
                "LAS: the extended variable-length records are said to start at byte {first}, outside bytes {start} to {} after the point data's start",
                bytes.len()
            ),
        ));
    }
    let mut at = first;
    for _ in 0..n {
        let room = bytes.len().saturating_sub(at.saturating_add(EVLR_HEADER)) as u64;
        let Some(length) = bytes
            .get(at + 20..at + 28)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
        else {
            return Err(Fault::byte(
                at,
                "LAS: the file ends inside an extended variable-length record's header",
            ));
        };
        if length > room {
            return Err(Fault::byte(
                at,
                format!(
                    "LAS: the extended variable-length record there declares {length} bytes of data, but the file has {room} bytes after its header"
                ),
            ));
        }
        at += EVLR_HEADER + length as usize;
    }
    Ok(first)
}

/// A LAZ chunk: its bytes and the points it holds.
struct Chunk {
    bytes: std::ops::Range<usize>,
    points: u64,
}

/// The chunks of the compressed point data between `start` and `end`, checked against the point count.
fn chunks(
    bytes: &[u8],
    (start, end): (usize, usize),
    count: u64,
    (vlr, compressor): (&LazVlr, u16),
    count_at: usize,
) -> Result<Vec<Chunk>, Fault> {
    match compressor {
        // One stream without a chunk table: its points read until the data end.
        1 => {
            return Ok(vec![Chunk {
                bytes: start..end,
                points: count,
            }])
        }
        2 | 3 => {}
        c => return Err(Fault::byte(start, format!("LAZ: unknown compressor {c}"))),
    }
    // The chunk table's offset is the first 8 bytes of the point data; a writer that could not go back
    // to fill it in wrote it in the last 8 bytes of the file instead.
    let i64_at = |at: usize| {
        bytes
            .get(at..at + 8)
            .map(|b| i64::from_le_bytes(b.try_into().unwrap_or_default()))
    };
    let data = start + 8;
    let valid = |t: Option<i64>| {
        t.and_then(|t| usize::try_from(t).ok())
            .filter(|&t| t >= data && t.saturating_add(8) <= end)
    };
    let table = valid(i64_at(start))
        .or_else(|| valid(bytes.len().checked_sub(8).and_then(i64_at)))
        .ok_or_else(|| {
            Fault::byte(start, "LAZ: no chunk table (its offset, here or in the file's last 8 bytes, points nowhere in the point data)")
        })?;
    let n = u32::from_le_bytes(bytes[table + 4..table + 8].try_into().unwrap_or_default()) as u64;
    let variable = vlr.uses_variable_size_chunks();
    let size = u64::from(vlr.chunk_size());
    // Each chunk takes a byte at least; chunks of a fixed size are as many as the count needs.
    let fixed = count.div_ceil(size.max(1));
    if (!variable && n != fixed) || n > (table - data) as u64 {
        return Err(Fault::byte(
            table,
            if variable {
                format!("LAZ: the chunk table declares {n} chunks, more than the {} bytes of compressed points can hold", table - data)
            } else {
                format!(
                    "LAZ: the chunk table declares {n} chunks of {size} points, but the {count} points the header declares (byte {count_at}) take {fixed}"
                )
            },
        ));
    }
    // The table's entries are an arithmetic-coded stream after its version and count.
    if n > 0 && starts_impossibly(&bytes[table..end], 8) {
        return Err(Fault::byte(
            table + 8,
            format!("LAZ: {}", impossible_start("the chunk table's stream")),
        ));
    }
    let entries = ChunkTable::read(&mut Cursor::new(&bytes[table..end]), variable)
        .map_err(|e| Fault::byte(table, format!("LAZ: the chunk table: {e}")))?;
    let mut chunks = Vec::with_capacity(entries.len());
    let (mut at, mut held) = (data, 0u64);
    for (k, e) in entries.as_ref().iter().enumerate() {
        let points = if variable {
            e.point_count
        } else {
            size.min(count - held)
        };
        let next = (at as u64).saturating_add(e.byte_count);
        if next > table as u64 {
            return Err(Fault::byte(
                table,
                format!("LAZ: the chunk table gives chunk {k} {} bytes from byte {at}, past the table's start", e.byte_count),
            ));
        }
        chunks.push(Chunk {
            bytes: at..next as usize,
            points,
        });
        (at, held) = (next as usize, held.saturating_add(points));
    }
    if held != count {
        return Err(Fault::byte(
            count_at,
            format!("LAZ: the header declares {count} points, but the chunk table (byte {table}) gives its chunks {held}"),
        ));
    }
    Ok(chunks)
}

/// A decoder of one chunk's `points` points from its bytes `data`, only the coordinates, intensity,
/// classification and (`rgb`) colour asked for.
fn decoder<'a>(
    data: &'a [u8],
    vlr: &LazVlr,
    (record, rgb): (usize, bool),
    points: u64,
) -> Result<Box<dyn RecordDecompressor<Cursor<&'a [u8]>> + 'a>, String> {
    let version = vlr.items().first().map_or(0, |item| item.version());
    let mut decoder: Box<dyn RecordDecompressor<Cursor<&'a [u8]>> + 'a> = match version {
        1 | 2 => {
            // The first point is stored whole; the arithmetic-coded stream of the others follows.
            if points > 0 && starts_impossibly(data, record) {
                return Err(impossible_start(&format!(
                    "its stream (byte {record} of the chunk)"
                )));
            }
            Box::new(SequentialPointRecordDecompressor::new(Cursor::new(data)))
        }
        3 | 4 => {
            check_layers(data, vlr, record, points)?;
            Box::new(LayeredPointRecordDecompressor::new(Cursor::new(data)))
        }
        v => return Err(format!("unknown LASzip item version {v}")),
    };
    decoder
        .set_fields_from(vlr.items())
        .map_err(|e| e.to_string())?;
    let mut selection = DecompressionSelection::xy_returns_channel()
        .decompress_z()
        .decompress_classification()
        .decompress_intensity();
    if rgb {
        selection = selection.decompress_rgb();
    }
    decoder.set_selection(selection);
    Ok(decoder)
}

/// Whether the arithmetic-coded stream at byte `at` of `data` starts impossibly. A stream starts with
/// the decoder's first four bytes, a number below the coder's initial range of 2^32 − 1: no LASzip
/// encoder writes `FF FF FF FF` there. The `laz` crate's decoder does not check this and panics on the
/// first symbol it decodes from such a (damaged) stream. A stream shorter than four bytes is left to the
/// decoder, which reports its end.
fn starts_impossibly(data: &[u8], at: usize) -> bool {
    data.get(at..at.saturating_add(4)) == Some(&[0xff; 4])
}

/// The error for a stream that [`starts_impossibly`].
fn impossible_start(what: &str) -> String {
    format!("{what} starts with FF FF FF FF, which no LASzip encoder writes")
}

/// A layered chunk (LAS 1.4 point formats) starts with its first point whole, then its point count, the
/// byte counts of all its layers, and the layers one after the other: the point's nine (`x`, `y` with
/// the returns and channel; `z`; classification; flags; intensity; scan angle; user data; point source;
/// GPS time), then the colour's, the near infrared's, the wave packet's and one a byte of extra bytes, as
/// the LASzip record lists its items. The count is checked against the chunk table, the layers against the
/// chunk, and each layer's stream's start (see [`starts_impossibly`]).
fn check_layers(data: &[u8], vlr: &LazVlr, record: usize, points: u64) -> Result<(), String> {
    if points == 0 {
        return Ok(());
    }
    let u32_at = |at: usize| {
        data.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("its {} bytes end inside its layers' sizes", data.len()))
    };
    let held = u64::from(u32_at(record)?);
    if held != points {
        return Err(format!(
            "the chunk says it holds {held} points, the header and the chunk table give it {points}"
        ));
    }
    let n: usize = vlr
        .items()
        .iter()
        .map(|item| match item.item_type() {
            LazItemType::Point14 => 9,
            LazItemType::RGBNIR14 => 2,
            LazItemType::Byte14(count) => usize::from(count),
            _ => 1,
        })
        .sum();
    let sizes = (0..n)
        .map(|k| u32_at(record + 4 + 4 * k))
        .collect::<Result<Vec<u32>, String>>()?;
    let mut at = record + 4 + 4 * n;
    for (k, &size) in sizes.iter().enumerate() {
        if size > 0 && starts_impossibly(data, at) {
            return Err(impossible_start(&format!(
                "its layer {k}'s stream (byte {at} of the chunk)"
            )));
        }
        at = at.saturating_add(size as usize);
    }
    if at > data.len() {
        return Err(format!(
            "its layers declare {} bytes, more than the {} after their sizes",
            at - (record + 4 + 4 * n),
            data.len() - (record + 4 + 4 * n)
        ));
    }
    Ok(())
}
