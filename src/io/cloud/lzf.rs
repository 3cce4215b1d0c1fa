//! LZF decompression (Marc Lehmann's liblzf format, as PCL writes it in `binary_compressed` PCD files).
//!
//! Written here: the decoder is a few dozen lines, and of the crates that offer it one is deprecated
//! (`lzf`) and the other new and little used (`lzf-rust`). Every read and every back reference is
//! checked, so any input gives bytes or an error.
//!
//! A token is a control byte `c`: below 32, a literal run of `c + 1` bytes follows; otherwise a back
//! reference of length `(c >> 5) + 2` (a length of 7 + 2 takes one more byte added) to the distance
//! `((c & 31) << 8) + next byte + 1` behind the end of the output.

/// The most output bytes one input byte makes (a back reference of 264 bytes takes 3).
pub(super) const MAX_RATIO: u64 = 88;

/// Decompresses `input` into exactly `len` bytes. `at` is the offset of `input` in the file, for errors.
///
/// # Errors
/// The byte offset and what is wrong: a run or reference cut short, a reference before the start of the
/// output, more or fewer bytes than `len`.
pub(super) fn decompress(input: &[u8], len: usize, at: usize) -> Result<Vec<u8>, (usize, String)> {
    let mut out = Vec::with_capacity(len);
    let mut i = 0;
    let cut = |i: usize| {
        (
            at + i,
            "LZF: the compressed data end inside a token".to_string(),
        )
    };
    while i < input.len() {
        let token = i;
        let control = usize::from(input[i]);
        i += 1;
        let (start, n) = if control < 32 {
            let n = control + 1;
            let literal = input.get(i..i + n).ok_or_else(|| cut(token))?;
            if out.len() + n > len {
                return Err(too_long(at + token, len));
            }
            out.extend_from_slice(literal);
            i += n;
            continue;
        } else {
            let mut n = control >> 5;
            if n == 7 {
                n += usize::from(*input.get(i).ok_or_else(|| cut(token))?);
                i += 1;
            }
            let low = usize::from(*input.get(i).ok_or_else(|| cut(token))?);
            i += 1;
            let back = ((control & 31) << 8) + low + 1;
            if back > out.len() {
                return Err((
                    at + token,
                    format!(
                        "LZF: a reference {back} bytes back, but only {} bytes are decompressed",
                        out.len()
                    ),
                ));
            }
            (out.len() - back, n + 2)
        };
        if out.len() + n > len {
            return Err(too_long(at + token, len));
        }
        // The reference may overlap what it writes: byte by byte.
        for k in start..start + n {
            out.push(out[k]);
        }
    }
    if out.len() != len {
        return Err((
            at + input.len(),
            format!(
                "LZF: the compressed data make {} bytes, the header says {len}",
                out.len()
            ),
        ));
    }
    Ok(out)
}

fn too_long(at: usize, len: usize) -> (usize, String) {
    (
        at,
        format!("LZF: the compressed data make more than the {len} bytes the header says"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_and_overlapping_references_decompress() {
        // "abc" as a literal, then 6 bytes from 3 back (overlapping): "abcabcabc"; then 1 byte back x 9.
        let data = [2, b'a', b'b', b'c', 4 << 5, 2, 7 << 5, 0, 0];
        let out = decompress(&data, 9 + 7 + 2, 0).unwrap();
        assert_eq!(&out[..9], b"abcabcabc");
        assert!(out[9..].iter().all(|&b| b == b'c'));
    }

    #[test]
    fn bad_streams_are_errors_naming_the_byte() {
        assert_eq!(decompress(&[5, 1, 2], 6, 10).unwrap_err().0, 10); // a literal cut short
        assert_eq!(decompress(&[0, 1, 1 << 5, 4], 3, 0).unwrap_err().0, 2); // 5 bytes back of 1
        assert!(decompress(&[0, 1], 2, 0)
            .unwrap_err()
            .1
            .contains("make 1 bytes"));
        assert!(decompress(&[1, 1, 2], 1, 0).is_err()); // more than declared
        assert_eq!(decompress(&[], 0, 0).unwrap(), Vec::<u8>::new());
    }
}
