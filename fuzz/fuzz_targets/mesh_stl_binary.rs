//! The STL reader on binary files: an 80-byte header, the triangle count (from the input, or the count
//! that matches the bytes present), then the input's bytes as 50-byte triangle records.
#![no_main]
use arbitrary::{Arbitrary, Unstructured};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let honest = bool::arbitrary(&mut u).unwrap_or(true);
    let claimed = u32::arbitrary(&mut u).unwrap_or(0);
    let body = u.take_rest();
    let count = if honest {
        (body.len() / 50) as u32
    } else {
        claimed
    };
    let mut file = vec![b'b'; 80];
    file.extend_from_slice(&count.to_le_bytes());
    file.extend_from_slice(body);
    ktree_fuzz::check_mesh(&file, "stl");
});
