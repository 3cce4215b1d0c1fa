//! Bounded allocation: files whose headers claim huge sizes are rejected with a clear error before anything
//! of that size is allocated. Each runs the CLI under `ulimit -v` (256 MiB of address space), far below what
//! the claims would need, and a valid file is read under the same limit as a control.

mod common;

use std::path::Path;
use std::process::Command;

/// Address space for the CLI, in KiB.
const LIMIT_KIB: u32 = 256 * 1024;

/// Runs `ktree ARGS` under `ulimit -v`: (success, stderr).
fn ktree_limited(args: &[&str]) -> (bool, String) {
    let out = Command::new("bash")
        .arg("-c")
        .arg(format!("ulimit -v {LIMIT_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_ktree"))
        .args(args)
        .output()
        .expect("run bash");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn expect_error(args: &[&str], file: &str, words: &str) {
    let (ok, err) = ktree_limited(args);
    assert!(!ok, "{args:?} succeeded");
    assert!(
        err.contains(file)
            && err.contains(words)
            && !err.contains("panicked")
            && !err.contains("memory allocation"),
        "{args:?}: expected an error naming {file} with '{words}', got: {err}"
    );
}

fn ktree_header(k: u8, level: u8, sizes: &[u64]) -> Vec<u8> {
    let mut b = b"KTREE\0".to_vec();
    b.extend_from_slice(&1u16.to_le_bytes());
    b.extend_from_slice(&[k, level, 0, 0]);
    b.extend_from_slice(&(sizes.len() as u32).to_le_bytes());
    for s in sizes {
        b.extend_from_slice(&s.to_le_bytes());
    }
    b.extend_from_slice(&[0; 24]);
    b.extend_from_slice(&[0; 8]);
    b
}

fn nifti_header(dims: [i16; 3], datatype: i16, bitpix: i16) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3, dims[0], dims[1], dims[2], 1, 1, 1, 1]
        .iter()
        .enumerate()
    {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&datatype.to_le_bytes());
    h[72..74].copy_from_slice(&bitpix.to_le_bytes());
    for i in 0..8 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&1f32.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    h
}

fn path(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn a_valid_file_reads_under_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let rays = path(dir.path(), "ok.rays", b"3 4\n1 2 3 9\n");
    let (ok, err) = ktree_limited(&["stats", "--rays", &rays]);
    assert!(ok, "{err}");
    let mut nii = nifti_header([4, 4, 4], 2, 8);
    nii.extend_from_slice(&[1; 64]);
    let nii = path(dir.path(), "ok.nii", &nii);
    let (ok, err) = ktree_limited(&[
        "voxelize",
        &nii,
        "--threshold",
        "1",
        "--out",
        &format!("{nii}.rays"),
    ]);
    assert!(ok, "{err}");
}

#[test]
fn ktree_headers_claiming_huge_trees_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    // 2^60 nodes on level 1 of a level-20 octree.
    let huge = path(
        dir.path(),
        "huge.ktree",
        &ktree_header(3, 20, &[1, 1 << 60]),
    );
    expect_error(&["stats", &huge], "huge.ktree", "truncated or padded");
    // Node counts whose sum overflows.
    let wrap = path(
        dir.path(),
        "wrap.ktree",
        &ktree_header(3, 20, &[1, u64::MAX, u64::MAX]),
    );
    expect_error(&["stats", &wrap], "wrap.ktree", "overflow");
    // 4 billion stored levels.
    let mut deep = ktree_header(2, 3, &[1]);
    deep[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    let deep = path(dir.path(), "deep.ktree", &deep);
    expect_error(&["stats", &deep], "deep.ktree", "levels stored");
}

#[test]
fn mesh_headers_claiming_huge_meshes_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let ply = path(
        dir.path(),
        "huge.ply",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1000000000000\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0",
    );
    expect_error(
        &["voxelize", &ply, "--level", "5", "--fit", "--out", "o.rays"],
        "huge.ply",
        "bytes follow",
    );
    // A binary STL whose count claims 4 billion triangles.
    let mut stl = vec![b' '; 80];
    stl.extend_from_slice(&u32::MAX.to_le_bytes());
    stl.extend_from_slice(&[0; 100]);
    let stl = path(dir.path(), "huge.stl", &stl);
    expect_error(
        &["voxelize", &stl, "--level", "5", "--fit", "--out", "o.rays"],
        "huge.stl",
        "STL",
    );
}

#[test]
fn volume_headers_claiming_huge_volumes_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    // 1024³ doubles (8 GiB) announced, 10 bytes present.
    let mut nii = nifti_header([1024, 1024, 1024], 64, 64);
    nii.extend_from_slice(&[0; 10]);
    let nii = path(dir.path(), "huge.nii", &nii);
    expect_error(
        &["voxelize", &nii, "--threshold", "1", "--out", "o.rays"],
        "huge.nii",
        "truncated",
    );
    // The same, gzip-compressed: inflated only as far as the bytes exist.
    let gz = {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(&std::fs::read(&nii).unwrap()).unwrap();
        e.finish().unwrap()
    };
    let gz = path(dir.path(), "huge.nii.gz", &gz);
    expect_error(
        &["voxelize", &gz, "--threshold", "1", "--out", "o.rays"],
        "huge.nii.gz",
        "truncated",
    );
    // More samples than any volume ktree reads.
    let json = path(
        dir.path(),
        "huge.json",
        br#"{"shape_xyz": [1048576, 1048576, 1048576], "dtype": "float64"}"#,
    );
    path(dir.path(), "huge.raw", &[0; 16]);
    expect_error(
        &["voxelize", &json, "--threshold", "1", "--out", "o.rays"],
        "huge.json",
        "too large",
    );
    // A plausible shape whose samples are missing.
    let json = path(
        dir.path(),
        "short.json",
        br#"{"shape_xyz": [1024, 1024, 512], "dtype": "float64"}"#,
    );
    path(dir.path(), "short.raw", &[0; 16]);
    expect_error(
        &["voxelize", &json, "--threshold", "1", "--out", "o.rays"],
        "short.raw",
        "needs",
    );
}
