//! Structure-aware NIfTI-1: a valid single-file header (`n+1`, 3-D or 4-D, a data type from the standard's
//! list with its bit count, the samples at byte 352) and samples of the right length, then arbitrary edits
//! to header fields and bytes, optionally gzip-compressed.
#![no_main]
use std::io::Write;

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// NIfTI data type codes and their bits per sample (including types ktree does not convert).
const TYPES: [(i16, i16); 12] = [
    (2, 8),
    (4, 16),
    (8, 32),
    (16, 32),
    (64, 64),
    (256, 8),
    (512, 16),
    (768, 32),
    (1024, 64),
    (1280, 64),
    (128, 24),
    (32, 64),
];

#[derive(Debug, Arbitrary)]
enum Edit {
    Xor { at: u16, mask: u8 },
    Dim { index: u8, value: i16 },
    Bitpix(i16),
    VoxOffset(f32),
    Scale { slope: f32, inter: f32 },
    Truncate(u16),
}

#[derive(Debug, Arbitrary)]
struct Input {
    shape: [u8; 3],
    four_d: bool,
    datatype: u8,
    big_endian: bool,
    samples: Vec<u8>,
    edits: Vec<Edit>,
    gzip: bool,
}

fuzz_target!(|input: Input| {
    let shape = input.shape.map(|s| i16::from(s % 8 + 1));
    let (code, bits) = TYPES[usize::from(input.datatype) % TYPES.len()];
    let mut dim = [0i16; 8];
    dim[0] = if input.four_d { 4 } else { 3 };
    dim[1..4].copy_from_slice(&shape);
    dim[4] = 1;
    dim[5..].fill(1);
    let mut h = vec![0u8; 352];
    let put16 = |h: &mut [u8], at: usize, v: i16| {
        let b = if input.big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        if let Some(field) = h.get_mut(at..at + 2) {
            field.copy_from_slice(&b);
        }
    };
    let put32 = |h: &mut [u8], at: usize, b: [u8; 4], be: [u8; 4]| {
        if let Some(field) = h.get_mut(at..at + 4) {
            field.copy_from_slice(if input.big_endian { &be } else { &b });
        }
    };
    put32(&mut h, 0, 348i32.to_le_bytes(), 348i32.to_be_bytes());
    for (i, d) in dim.iter().enumerate() {
        put16(&mut h, 40 + 2 * i, *d);
    }
    put16(&mut h, 70, code);
    put16(&mut h, 72, bits);
    for i in 0..8 {
        put32(&mut h, 76 + 4 * i, 1f32.to_le_bytes(), 1f32.to_be_bytes());
    }
    put32(&mut h, 108, 352f32.to_le_bytes(), 352f32.to_be_bytes());
    put32(&mut h, 112, 1f32.to_le_bytes(), 1f32.to_be_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    let n: usize = shape.iter().map(|&s| s as usize).product();
    let mut samples = input.samples;
    samples.resize(n * bits as usize / 8, 0x3c);
    h.extend_from_slice(&samples);
    for edit in &input.edits {
        match *edit {
            Edit::Xor { at, mask } => {
                if !h.is_empty() {
                    let at = usize::from(at) % h.len();
                    h[at] ^= mask;
                }
            }
            Edit::Dim { index, value } => put16(&mut h, 40 + 2 * usize::from(index % 8), value),
            Edit::Bitpix(b) => put16(&mut h, 72, b),
            Edit::VoxOffset(v) => put32(&mut h, 108, v.to_le_bytes(), v.to_be_bytes()),
            Edit::Scale { slope, inter } => {
                put32(&mut h, 112, slope.to_le_bytes(), slope.to_be_bytes());
                put32(&mut h, 116, inter.to_le_bytes(), inter.to_be_bytes());
            }
            Edit::Truncate(k) => {
                let keep = h.len().saturating_sub(usize::from(k));
                h.truncate(keep);
            }
        }
    }
    let file = if input.gzip {
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        gz.write_all(&h).expect("to memory");
        gz.finish().expect("to memory")
    } else {
        h
    };
    if let Ok(v) = ktree::solid::volume::Volume::from_nifti_bytes(&file, Path::new("fuzz")) {
        ktree_fuzz::check_volume(&v);
    }
});
