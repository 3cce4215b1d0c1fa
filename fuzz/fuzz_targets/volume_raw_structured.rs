//! Structure-aware raw volumes: a sidecar from arbitrary shape, dtype and endianness (mostly valid ones),
//! raw bytes of the right length or not.
#![no_main]
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

const DTYPES: [&str; 9] = [
    "uint8", "int8", "uint16", "int16", "uint32", "int32", "float32", "float64", "complex",
];

#[derive(Debug, Arbitrary)]
struct Input {
    shape: [u64; 3],
    small: bool,
    dtype: u8,
    endianness: u8,
    spacing: Option<[f64; 3]>,
    raw: Vec<u8>,
    pad: bool,
}

fuzz_target!(|input: Input| {
    let shape = if input.small {
        input.shape.map(|s| s % 9)
    } else {
        input.shape
    };
    let dtype = DTYPES[usize::from(input.dtype) % DTYPES.len()];
    let endianness = ["little", "big", "middle"][usize::from(input.endianness) % 3];
    let spacing = match input.spacing {
        Some(s) if s.iter().all(|x| x.is_finite()) => {
            format!(r#", "spacing_xyz": [{}, {}, {}]"#, s[0], s[1], s[2])
        }
        _ => String::new(),
    };
    let sidecar = format!(
        r#"{{"shape_xyz": [{}, {}, {}], "dtype": "{dtype}", "endianness": "{endianness}"{spacing}}}"#,
        shape[0], shape[1], shape[2]
    );
    let size = [1, 1, 2, 2, 4, 4, 4, 8, 16][usize::from(input.dtype) % DTYPES.len()];
    let want = shape.iter().try_fold(size as u64, |p, &s| p.checked_mul(s));
    let mut raw = input.raw;
    if input.pad {
        if let Some(want) = want.filter(|&w| w <= 1 << 16) {
            raw.resize(want as usize, 0x5a);
        }
    }
    if let Ok(v) =
        ktree::solid::volume::Volume::from_raw_bytes(sidecar.as_bytes(), &raw, Path::new("fuzz"))
    {
        ktree_fuzz::check_volume(&v);
    }
});
