//! Blosc-1 frames, as OpenVDB stores its Blosc-compressed value buffers (c-blosc 1.x, format version 2).
//!
//! A frame is a 16-byte header — format version, codec version, flags, type size, then `u32` little-endian
//! the bytes it holds (`nbytes`), the block size and the frame's own length (`cbytes`) — followed, unless
//! the flags say the data was copied as it is, by one `i32` start offset per block (from the frame's
//! first byte) and the blocks. A block is split into one stream per byte of the type (when the flags allow
//! it, the type size is at most 16, the block holds at least 128 values and is not the last, shorter
//! one) or is one stream; each stream is its compressed length (`i32`) and its bytes, copied as they are
//! when that length equals the stream's size. With byte shuffle, the decoded block holds byte 0 of every
//! value, then byte 1, …, and the bytes left over after the last whole value as they are.
//!
//! Decoded here: the LZ4 codec (the one OpenVDB writes, decoded by `lz4_flex`) and copied frames, with or
//! without byte shuffle. Every size is checked against the frame before it is used, and the output is
//! only ever the size the caller expects.

use crate::io::interop::grid::GridFileErrorKind;

/// The header's length.
const HEADER: usize = 16;
/// Blocks are split into streams only for type sizes up to this…
const MAX_SPLITS: usize = 16;
/// …and blocks of at least this many values.
const MIN_SPLIT_VALUES: usize = 128;
/// The codec number (the flags' top three bits) of LZ4.
const LZ4: u8 = 1;
const FLAG_SHUFFLE: u8 = 0x01;
const FLAG_COPIED: u8 = 0x02;
const FLAG_BIT_SHUFFLE: u8 = 0x04;
const FLAG_RESERVED: u8 = 0x08;
const FLAG_NO_SPLIT: u8 = 0x10;

/// A problem in a Blosc frame: the byte offset in the frame where it was found, and what it is.
#[derive(Debug)]
pub(super) struct BloscError {
    pub at: usize,
    pub kind: GridFileErrorKind,
}

fn data(at: usize, message: String) -> BloscError {
    BloscError {
        at,
        kind: GridFileErrorKind::Data(message),
    }
}

fn truncated(at: usize, message: String) -> BloscError {
    BloscError {
        at,
        kind: GridFileErrorKind::Truncated(message),
    }
}

fn unsupported(at: usize, message: String) -> BloscError {
    BloscError {
        at,
        kind: GridFileErrorKind::Unsupported(message),
    }
}

fn le_u32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

/// The codec names of Blosc's codec numbers, for messages.
fn codec_name(code: u8) -> &'static str {
    match code {
        0 => "BloscLZ",
        1 => "LZ4",
        2 => "Snappy",
        3 => "zlib",
        4 => "Zstd",
        _ => "unknown",
    }
}

/// Decodes a Blosc frame that must hold exactly `expected` bytes. `frame` is the chunk the file gives
/// it; the frame may end before the chunk does.
///
/// # Errors
/// [`BloscError`] with the offset in `frame`: a frame shorter than its header or its blocks, sizes that
/// contradict each other or `expected`, a stream that does not decode to its size, or a codec, bit
/// shuffle or format version other than the ones above ([`GridFileErrorKind::Unsupported`]).
pub(super) fn decode(frame: &[u8], expected: usize) -> Result<Vec<u8>, BloscError> {
    if frame.len() < HEADER {
        return Err(truncated(
            0,
            format!(
                "a Blosc header is {HEADER} bytes, the chunk has {}",
                frame.len()
            ),
        ));
    }
    let (version, flags, typesize) = (frame[0], frame[2], usize::from(frame[3]));
    let nbytes = le_u32(frame, 4) as usize;
    let blocksize = le_u32(frame, 8) as usize;
    let cbytes = le_u32(frame, 12) as usize;
    if nbytes != expected {
        return Err(data(
            4,
            format!("the Blosc frame holds {nbytes} bytes, {expected} expected"),
        ));
    }
    if cbytes > frame.len() {
        return Err(truncated(
            12,
            format!(
                "the Blosc frame is {cbytes} bytes long, the chunk has {}",
                frame.len()
            ),
        ));
    }
    if cbytes < HEADER {
        return Err(data(
            12,
            format!("the Blosc frame's length {cbytes} is shorter than its header"),
        ));
    }
    let frame = &frame[..cbytes];
    if nbytes == 0 {
        return Ok(Vec::new());
    }
    if version != 2 {
        return Err(unsupported(
            0,
            format!("Blosc format version {version} (version 2, Blosc 1.x, is read)"),
        ));
    }
    if flags & FLAG_RESERVED != 0 {
        return Err(unsupported(2, format!("Blosc flags {flags:#04x}")));
    }
    if flags & FLAG_BIT_SHUFFLE != 0 {
        return Err(unsupported(
            2,
            "Blosc bit shuffle (byte shuffle is read)".into(),
        ));
    }
    if typesize == 0 {
        return Err(data(3, "a Blosc type size of 0".into()));
    }
    if blocksize == 0 || blocksize > nbytes {
        return Err(data(
            8,
            format!("a Blosc block size of {blocksize} for {nbytes} bytes"),
        ));
    }
    if flags & FLAG_COPIED != 0 {
        if cbytes != HEADER + nbytes {
            return Err(data(
                12,
                format!(
                    "a copied Blosc frame of {nbytes} bytes is {cbytes} bytes long, not {}",
                    HEADER + nbytes
                ),
            ));
        }
        return Ok(frame[HEADER..].to_vec());
    }
    let codec = flags >> 5;
    if codec != LZ4 {
        return Err(unsupported(
            2,
            format!(
                "the Blosc codec {} (LZ4, OpenVDB's, is read)",
                codec_name(codec)
            ),
        ));
    }
    let blocks = nbytes.div_ceil(blocksize);
    if blocks > (cbytes - HEADER) / 4 {
        return Err(truncated(
            HEADER,
            format!("{blocks} Blosc block starts do not fit in a frame of {cbytes} bytes"),
        ));
    }
    let shuffle = flags & FLAG_SHUFFLE != 0 && typesize > 1;
    let mut out = vec![0u8; nbytes];
    let mut shuffled = vec![0u8; if shuffle { blocksize } else { 0 }];
    for j in 0..blocks {
        let start_at = HEADER + 4 * j;
        let last_short = j + 1 == blocks && !nbytes.is_multiple_of(blocksize);
        let bsize = if last_short {
            nbytes % blocksize
        } else {
            blocksize
        };
        let splits = if flags & FLAG_NO_SPLIT == 0
            && typesize <= MAX_SPLITS
            && bsize / typesize >= MIN_SPLIT_VALUES
            && !last_short
        {
            typesize
        } else {
            1
        };
        if bsize % splits != 0 {
            return Err(data(
                8,
                format!("a Blosc block of {bsize} bytes does not split into {splits} streams"),
            ));
        }
        let stream_len = bsize / splits;
        let target = &mut out[j * blocksize..j * blocksize + bsize];
        let decoded: &mut [u8] = if shuffle {
            &mut shuffled[..bsize]
        } else {
            target
        };
        let mut at = i32::from_le_bytes(frame[start_at..start_at + 4].try_into().expect("4 bytes"));
        // Where the current stream's start was given: the block's start for the first stream, the
        // previous stream's length for the others.
        let mut start_given_at = start_at;
        for s in 0..splits {
            let len_at = usize::try_from(at)
                .ok()
                .filter(|&a| a <= cbytes.saturating_sub(4));
            let Some(len_at) = len_at else {
                return Err(truncated(
                    start_given_at,
                    format!(
                        "Blosc block {j}, stream {s} starts at byte {at}, past the frame of {cbytes} bytes"
                    ),
                ));
            };
            let len = i32::from_le_bytes(frame[len_at..len_at + 4].try_into().expect("4 bytes"));
            let bytes_at = len_at + 4;
            let len = usize::try_from(len)
                .ok()
                .filter(|&n| n <= cbytes - bytes_at)
                .ok_or_else(|| {
                    truncated(
                        len_at,
                        format!(
                            "Blosc block {j}, stream {s}: {len} bytes announced, {} left in the frame",
                            cbytes - bytes_at
                        ),
                    )
                })?;
            let src = &frame[bytes_at..bytes_at + len];
            let part = &mut decoded[s * stream_len..(s + 1) * stream_len];
            if len == stream_len {
                part.copy_from_slice(src);
            } else {
                match lz4_flex::block::decompress_into(src, part) {
                    Ok(n) if n == stream_len => {}
                    Ok(n) => {
                        return Err(data(
                            bytes_at,
                            format!(
                                "Blosc block {j}, stream {s}: LZ4 gives {n} bytes, {stream_len} expected"
                            ),
                        ))
                    }
                    Err(e) => {
                        // An empty stream's data would start at the frame's end: its length is wrong.
                        return Err(data(
                            if len == 0 { len_at } else { bytes_at },
                            format!("Blosc block {j}, stream {s}: bad LZ4 data ({e})"),
                        ))
                    }
                }
            }
            at = (bytes_at + len) as i32;
            start_given_at = len_at;
        }
        if shuffle {
            unshuffle(
                typesize,
                &shuffled[..bsize],
                &mut out[j * blocksize..j * blocksize + bsize],
            );
        }
    }
    Ok(out)
}

/// Undoes Blosc's byte shuffle of one block: `src` holds byte 0 of every whole value, then byte 1, …,
/// then the bytes after the last whole value as they are.
fn unshuffle(typesize: usize, src: &[u8], dst: &mut [u8]) {
    let values = src.len() / typesize;
    for (i, value) in dst.chunks_exact_mut(typesize).enumerate() {
        for (b, byte) in value.iter_mut().enumerate() {
            *byte = src[b * values + i];
        }
    }
    let whole = values * typesize;
    dst[whole..].copy_from_slice(&src[whole..]);
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A Blosc-1 frame of `data` as c-blosc lays it out: `compress` chooses per stream between LZ4 and a
    /// plain copy (a stream LZ4 does not shorten is copied, as c-blosc does).
    pub(in crate::io::interop) fn encode(
        data: &[u8],
        typesize: usize,
        blocksize: usize,
        shuffle: bool,
        split: bool,
        compress: bool,
    ) -> Vec<u8> {
        let mut flags = (LZ4 << 5) | if shuffle { FLAG_SHUFFLE } else { 0 };
        if !split {
            flags |= FLAG_NO_SPLIT;
        }
        let mut out = vec![2, 1, flags, typesize as u8];
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(&(blocksize as u32).to_le_bytes());
        out.extend_from_slice(&[0; 4]);
        if data.is_empty() {
            let n = out.len() as u32;
            out[12..16].copy_from_slice(&n.to_le_bytes());
            return out;
        }
        let blocks = data.len().div_ceil(blocksize);
        let starts_at = out.len();
        out.resize(out.len() + 4 * blocks, 0);
        for (j, block) in data.chunks(blocksize).enumerate() {
            let start = out.len() as u32;
            out[starts_at + 4 * j..starts_at + 4 * j + 4].copy_from_slice(&start.to_le_bytes());
            let mut b = block.to_vec();
            if shuffle && typesize > 1 {
                let values = block.len() / typesize;
                for i in 0..values {
                    for k in 0..typesize {
                        b[k * values + i] = block[i * typesize + k];
                    }
                }
            }
            let last_short = block.len() < blocksize;
            let splits = if split
                && typesize <= MAX_SPLITS
                && block.len() / typesize >= MIN_SPLIT_VALUES
                && !last_short
            {
                typesize
            } else {
                1
            };
            for stream in b.chunks(b.len() / splits) {
                let packed = lz4_flex::block::compress(stream);
                let body = if compress && packed.len() < stream.len() {
                    packed
                } else {
                    stream.to_vec()
                };
                out.extend_from_slice(&(body.len() as u32).to_le_bytes());
                out.extend_from_slice(&body);
            }
        }
        let n = out.len() as u32;
        out[12..16].copy_from_slice(&n.to_le_bytes());
        out
    }

    /// Bytes with runs (so that LZ4 finds matches) and noise.
    fn bytes() -> impl Strategy<Value = Vec<u8>> {
        prop::collection::vec((any::<u8>(), 1usize..40), 0..60).prop_map(|runs| {
            runs.into_iter()
                .flat_map(|(b, n)| std::iter::repeat_n(b, n))
                .collect()
        })
    }

    proptest! {
        #[test]
        fn frames_decode_to_their_bytes(
            data in bytes(),
            typesize in 1usize..=9,
            blocksize in 1usize..3000,
            shuffle: bool,
            split: bool,
            compress: bool,
        ) {
            check_frame(&data, typesize, blocksize, shuffle, split, compress)?;
        }
    }

    /// A frame of `data` decodes to it; every cut and every changed byte among the first 64 is an error
    /// at a byte inside the frame, or bytes of the expected length.
    fn check_frame(
        data: &[u8],
        typesize: usize,
        blocksize: usize,
        shuffle: bool,
        split: bool,
        compress: bool,
    ) -> Result<(), TestCaseError> {
        // As c-blosc chooses: at most the data, a multiple of the type size when above it.
        let mut blocksize = blocksize.min(data.len()).max(1);
        if blocksize > typesize {
            blocksize = blocksize / typesize * typesize;
        }
        let frame = encode(data, typesize, blocksize, shuffle, split, compress);
        prop_assert_eq!(decode(&frame, data.len()).unwrap(), data.to_vec());
        for cut in 0..frame.len() {
            if let Ok(d) = decode(&frame[..cut], data.len()) {
                prop_assert_eq!(d.len(), data.len());
            }
        }
        for at in 0..frame.len().min(64) {
            let mut bad = frame.clone();
            bad[at] ^= 0x5a;
            match decode(&bad, data.len()) {
                Ok(d) => prop_assert_eq!(d.len(), data.len()),
                Err(e) => prop_assert!(e.at < frame.len(), "byte {at} changed: {e:?}"),
            }
        }
        Ok(())
    }

    #[test]
    fn a_stream_length_that_leaves_no_room_is_named_at_its_byte() {
        // Found by the property above: a changed stream length made the next stream start past the
        // frame, and the error named the frame's end.
        let runs: [(u8, usize); 11] = [
            (0, 36),
            (1, 8),
            (2, 6),
            (3, 17),
            (4, 25),
            (5, 4),
            (6, 21),
            (4, 25),
            (7, 25),
            (8, 32),
            (0, 159),
        ];
        let data: Vec<u8> = runs
            .iter()
            .flat_map(|&(b, n)| std::iter::repeat_n(b, n))
            .collect();
        check_frame(&data, 2, 358, false, true, true).unwrap();
    }

    #[test]
    fn split_streams_and_shuffle_follow_c_blosc() {
        // 4096 bytes of 4-byte values: split into 4 streams, each LZ4-compressed.
        let data: Vec<u8> = (0..1024u32).flat_map(|v| (v / 7).to_le_bytes()).collect();
        let frame = encode(&data, 4, data.len(), true, true, true);
        assert!(frame.len() < data.len() / 2, "{} bytes", frame.len());
        assert_eq!(decode(&frame, data.len()).unwrap(), data);
        // A leftover block of 2 bytes after blocks of 12, shuffled per block.
        let data: Vec<u8> = (0..14u8).collect();
        assert_eq!(
            decode(&encode(&data, 4, 12, true, true, false), 14).unwrap(),
            data
        );
    }

    #[test]
    fn bad_frames_name_the_byte() {
        let data = vec![7u8; 1000];
        let frame = encode(&data, 4, 1000, true, true, true);
        let e = decode(&frame, 999).unwrap_err();
        assert_eq!(
            (e.at, matches!(e.kind, GridFileErrorKind::Data(_))),
            (4, true)
        );
        let e = decode(&frame[..10], 1000).unwrap_err();
        assert_eq!(e.at, 0);
        let e = decode(&frame[..frame.len() - 1], 1000).unwrap_err();
        assert_eq!(e.at, 12, "{e:?}");
        let mut zstd = frame.clone();
        zstd[2] = (4 << 5) | FLAG_SHUFFLE;
        let e = decode(&zstd, 1000).unwrap_err();
        assert!(
            matches!(&e.kind, GridFileErrorKind::Unsupported(m) if m.contains("Zstd")),
            "{e:?}"
        );
        // A stream whose length runs past the frame.
        let mut long = frame.clone();
        let first = le_u32(&frame, HEADER) as usize;
        long[first..first + 4].copy_from_slice(&5000i32.to_le_bytes());
        let e = decode(&long, 1000).unwrap_err();
        assert_eq!(e.at, first, "{e:?}");
    }
}
