//! No panic through the public API: every public reader is driven with arbitrary bytes (raw, and with the
//! `.ktree` checksum made valid so the structural checks are reached), and every public constructor with
//! arbitrary values. Each returns a value or an error; a panic fails the test.

use std::path::Path;

use ktree::io::{read_ktree, read_ktree_any, read_rays};
use ktree::ops::{Affine, AxisMap, FixedAffine, Projective};
use ktree::rays::ball_rays;
use ktree::solid::mesh::{MeshTransform, TriangleMesh};
use ktree::solid::volume::{Select, Volume};
use ktree::solid::{BoxSolid, Frame, Quadric, Rational, Sample};
use ktree::{KTree, Ray, RaySet, Universe};
use proptest::prelude::*;

/// Bytes that are sometimes text: arbitrary bytes, or lines of small numbers and words.
fn bytes() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..512),
        "([0-9 .eE+-]{0,12}|v|f|vn|solid|facet|normal|outer|loop|vertex|endloop|endfacet|ply|format ascii 1.0|element vertex 3|property float x|end_header|#)( |\n){1,40}"
            .prop_map(String::into_bytes),
    ]
}

fn frame() -> impl Strategy<Value = Frame> {
    prop_oneof![Just(Frame::Voxel), Just(Frame::UnitCube)]
}

fn rational() -> impl Strategy<Value = Rational> {
    (any::<i64>(), any::<i64>()).prop_map(|(n, d)| Rational::new(n, d).unwrap_or(Rational::int(n)))
}

fn with_valid_crc(mut bytes: Vec<u8>) -> Vec<u8> {
    if bytes.len() >= 4 {
        let at = bytes.len() - 4;
        let crc = crc32(&bytes[..at]);
        bytes[at..].copy_from_slice(&crc.to_le_bytes());
    }
    bytes
}

/// CRC-32 (IEEE), bit by bit: the test needs no dependency for it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A `.ktree` header for K, L, D levels with sizes, then arbitrary bytes: mostly gets past the magic.
fn ktree_like() -> impl Strategy<Value = Vec<u8>> {
    (
        0u8..6,
        0u8..25,
        0u32..6,
        proptest::collection::vec(0u64..40, 0..6),
        proptest::collection::vec(any::<u8>(), 0..64),
    )
        .prop_map(|(k, l, d, sizes, body)| {
            let mut b = b"KTREE\0".to_vec();
            b.extend_from_slice(&1u16.to_le_bytes());
            b.extend_from_slice(&[k, l, 0, 0]);
            b.extend_from_slice(&d.to_le_bytes());
            for s in sizes {
                b.extend_from_slice(&s.to_le_bytes());
            }
            b.extend_from_slice(&body);
            with_valid_crc(b)
        })
}

fn mesh_checks(mesh: &TriangleMesh) {
    let _ = (
        mesh.bounds(),
        mesh.signed_volume(),
        mesh.surface_area(),
        mesh.open_edges(),
    );
    for level in [0, 1, 4] {
        if let Ok(p) = MeshTransform::fit(mesh, level) {
            let _ = mesh.to_rays(level, &p);
        }
    }
}

fn volume_checks(v: &Volume) {
    let level = v.fitting_level();
    if level <= 6 {
        for select in [Select::AtLeast(0.0), Select::Label(1.0)] {
            let _ = v.to_rays(level, [0; 3], select);
            let _ = v.to_rays(level, [u32::MAX; 3], select);
        }
    }
}

fn rays_and_trees<const K: usize>(
    level: u32,
    coords: &[(Vec<u32>, u32)],
    dense_len: usize,
    offset: [i64; K],
) {
    let _ = Universe::<K>::new(level);
    let _ = KTree::<K>::empty(level);
    let _ = KTree::<K>::full(level);
    let _ = KTree::<K>::from_dense(level, &vec![true; dense_len.min(1 << 12)]);
    let _ = RaySet::<K>::empty(level);
    let small = level.min(6);
    let rays = coords
        .iter()
        .map(|(c, z2)| Ray::new(std::array::from_fn(|a| c.get(a).copied().unwrap_or(0)), *z2));
    if let Ok(set) = RaySet::<K>::from_rays(small, rays) {
        let _ = set.translated(offset);
        let _ = set.complement();
        let tree = ktree::stacking::paper::stack(&set);
        tree.assert_well_formed();
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn readers_never_panic(data in bytes(), fixed in ktree_like()) {
        let _ = read_rays(&data[..], "arbitrary");
        let _ = read_ktree_any(&data, "arbitrary");
        let _ = read_ktree_any(&with_valid_crc(data.clone()), "arbitrary");
        let _ = read_ktree_any(&fixed, "crafted");
        let _ = read_ktree::<2>(&fixed, "crafted");
        for format in ["obj", "stl", "STL", "ply", "off", ""] {
            if let Ok(mesh) = ktree::io::read_mesh_bytes(&data, format, Path::new("arbitrary")) {
                mesh_checks(&mesh);
            }
        }
        let mut binary_stl = vec![0u8; 80];
        binary_stl.extend_from_slice(&((data.len() / 50) as u32).to_le_bytes());
        binary_stl.extend_from_slice(&data);
        if let Ok(mesh) = ktree::io::read_mesh_bytes(&binary_stl, "stl", Path::new("arbitrary")) {
            mesh_checks(&mesh);
        }
        let (sidecar, raw) = data.split_at(data.len() / 2);
        if let Ok(v) = Volume::from_raw_bytes(sidecar, raw, Path::new("arbitrary")) {
            volume_checks(&v);
        }
        if let Ok(v) = Volume::from_nifti_bytes(&data, Path::new("arbitrary")) {
            volume_checks(&v);
        }
        let _ = MeshTransform::parse(&String::from_utf8_lossy(&data));
    }

    #[test]
    fn raw_volumes_never_panic(
        shape in proptest::array::uniform3(prop_oneof![0u64..5, any::<u64>()]),
        dtype in "(uint8|int8|uint16|int16|uint32|int32|float32|float64|x)",
        big in any::<bool>(),
        raw in proptest::collection::vec(any::<u8>(), 0..200),
    ) {
        let sidecar = format!(
            r#"{{"shape_xyz": [{}, {}, {}], "dtype": "{dtype}", "endianness": "{}"}}"#,
            shape[0], shape[1], shape[2], if big { "big" } else { "little" }
        );
        if let Ok(v) = Volume::from_raw_bytes(sidecar.as_bytes(), &raw, Path::new("arbitrary")) {
            volume_checks(&v);
        }
    }

    #[test]
    fn constructors_never_panic(
        level in prop_oneof![0u32..8, any::<u32>()],
        coords in proptest::collection::vec((proptest::collection::vec(0u32..80, 4), 0u32..80), 0..12),
        dense_len in 0usize..5000,
        offset in proptest::array::uniform4(prop_oneof![-100i64..100, any::<i64>()]),
        ints in proptest::collection::vec(any::<i64>(), 4),
        matrix in proptest::collection::vec(proptest::collection::vec(prop_oneof![-9i128..9, any::<i128>()], 0..6), 0..6),
        floats in proptest::collection::vec(prop_oneof![-10.0f64..10.0, any::<f64>()], 0..26),
        frame in frame(),
        r in proptest::array::uniform3(rational()),
        hi in proptest::array::uniform3(rational()),
    ) {
        rays_and_trees::<1>(level, &coords, dense_len, [offset[0]]);
        rays_and_trees::<2>(level, &coords, dense_len, [offset[0], offset[1]]);
        rays_and_trees::<3>(level, &coords, dense_len, [offset[0], offset[1], offset[2]]);
        rays_and_trees::<4>(level, &coords, dense_len, offset);
        let _ = Rational::new(ints[0], ints[1]);
        let _ = ball_rays::<2>(level.min(6), [ints[0], ints[1]], ints[2]);
        let _ = ball_rays::<3>(level.min(5), [offset[0], offset[1], offset[2]], offset[3]);
        if let Ok(q) = Quadric::<3>::from_matrix(&matrix, frame) {
            let _ = q.to_rays(level.min(4), Sample::Centre, true);
            let _ = q.contains(level.min(30), Sample::Corner, [1, 2, 3]);
        }
        let rows: Vec<Vec<Rational>> = matrix.iter().map(|row| row.iter().map(|&x| Rational::int(x as i64)).collect()).collect();
        let _ = Quadric::<2>::from_rational_matrix(&rows, frame);
        if let Ok(q) = Quadric::<3>::ball(r, hi[0], frame) {
            let _ = q.to_rays(level.min(4), Sample::Centre, false);
        }
        let _ = Quadric::<3>::ellipsoid(r, hi, frame);
        if let Ok(b) = BoxSolid::<3>::new(r, hi, frame) {
            let _ = b.to_rays(level.min(4), Sample::Corner, true);
            let _ = b.contains(level.min(30), Sample::Centre, [0, 0, 0]);
        }
        let _ = AxisMap::<3>::new([ints[0] as usize % 5, ints[1] as usize % 4, ints[2] as usize], [true, false, true]);
        let _ = AxisMap::<2>::reflection(ints[3] as usize);
        let _ = AxisMap::<4>::quarter_turn(ints[0] as usize % 6, ints[1] as usize % 6);
        if let Ok(m) = Affine::<3>::from_homogeneous(&floats) {
            let _ = m.inverse();
            let _ = FixedAffine::new(&m, (ints[0] as u32) % 80);
            let _ = m.source_voxel([1, 2, 3]);
        }
        let _ = Affine::<2>::scaling_about(floats.first().copied().unwrap_or(0.0), [0.0, f64::NAN]);
        if let Ok(p) = Projective::<3>::from_homogeneous(&floats) {
            let _ = p.inverse();
        }
        let _ = Projective::<3>::perspective(level, ints[0] as usize, floats.first().copied().unwrap_or(1.0));
        let _ = MeshTransform::parse(&format!("{},{},{},{}", floats.first().unwrap_or(&1.0), ints[0], ints[1], hi[0].to_f64()));
        let _ = ktree::display::png::Canvas::new(ints[0] as u32, ints[1] as u32, [0, 0, 0]);
    }
}
