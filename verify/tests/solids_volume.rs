//! Volumes to rays: every selected sample becomes exactly one voxel (random volumes, raw + sidecar and
//! NIfTI files), and the skull and brain of data/volumes give the counts their samples give.

use ktree_verify::cases;

use ktree::solid::volume::{Select, Volume};
use ktree::stacking::paper::stack;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn samples_become_voxels(
        shape in prop::array::uniform3(1usize..9),
        seed in prop::collection::vec(0u8..4, 512),
        offset in prop::array::uniform3(0u32..8),
        label in any::<bool>(),
    ) {
        let n = shape.iter().product::<usize>();
        let v = Volume::new(shape, seed[..n].iter().map(|&x| f64::from(x)).collect(), [1.0; 3]).unwrap();
        let select = if label { Select::Label(2.0) } else { Select::AtLeast(2.0) };
        let rays = v.to_rays(4, offset, select).unwrap();
        let mut count = 0;
        for x in 0..16u32 {
            for y in 0..16u32 {
                for z in 0..16u32 {
                    let p = [x, y, z];
                    let inside_vol = (0..3).all(|a| p[a] >= offset[a] && ((p[a] - offset[a]) as usize) < shape[a]);
                    let want = inside_vol && {
                        let [i, j, k] = [0, 1, 2].map(|a| (p[a] - offset[a]) as usize);
                        let s = v.values()[i + shape[0] * (j + shape[1] * k)];
                        if label { s == 2.0 } else { s >= 2.0 }
                    };
                    count += usize::from(want);
                    prop_assert_eq!(rays.contains(p), want, "voxel {:?}", p);
                }
            }
        }
        prop_assert_eq!(count, v.count(select));
        stack(&rays).assert_well_formed();
    }
}

#[test]
fn real_volumes_give_their_counts() {
    let dir = cases::data_dir("volumes");
    let skull = Volume::read(&dir.join("skull_grey.json")).unwrap();
    assert_eq!(skull.shape(), [64, 64, 64]);
    // The source's own example uses the iso-value 2.9, stored ×10 000.
    let rays = skull
        .to_rays(skull.fitting_level(), [0; 3], Select::AtLeast(29_000.0))
        .unwrap();
    assert_eq!(
        rays.voxel_count() as usize,
        skull.count(Select::AtLeast(29_000.0))
    );
    assert!(
        (22_000..23_000).contains(&(rays.voxel_count() as usize)),
        "{}",
        rays.voxel_count()
    );
    let brain = Volume::read(&dir.join("itk_t1_brain.raw")).unwrap();
    assert_eq!(brain.fitting_level(), 7);
    let rays = brain.to_rays(7, [0; 3], Select::AtLeast(1.0)).unwrap();
    assert_eq!(rays.voxel_count(), 248_680); // the sidecar's nonzero_voxels
    stack(&rays).assert_well_formed();
}

/// A hand-written NIfTI-1 file (348-byte header, 4 bytes of extension flags, then int16 samples).
fn nifti_bytes(shape: [u16; 3], values: &[i16], slope: f32, inter: f32) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dims = [
        3i16,
        shape[0] as i16,
        shape[1] as i16,
        shape[2] as i16,
        1,
        1,
        1,
        1,
    ];
    for (i, d) in dims.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&4i16.to_le_bytes()); // DT_INT16
    h[72..74].copy_from_slice(&16i16.to_le_bytes());
    for i in 0..8 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&slope.to_le_bytes());
    h[116..120].copy_from_slice(&inter.to_le_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    for v in values {
        h.extend(v.to_le_bytes());
    }
    h
}

#[test]
fn nifti_and_raw_read_alike() {
    let dir = tempfile::tempdir().unwrap();
    let shape = [5u16, 3, 4];
    let values: Vec<i16> = (0..60).map(|i| (i * 7 % 11) as i16 - 3).collect();
    let nii = dir.path().join("v.nii");
    std::fs::write(&nii, nifti_bytes(shape, &values, 2.0, 1.0)).unwrap();
    let a = Volume::read(&nii).unwrap();
    assert_eq!(a.shape(), [5, 3, 4]);
    assert_eq!(a.values()[7], f64::from(values[7]) * 2.0 + 1.0);
    let json = dir.path().join("v.json");
    std::fs::write(
        &json,
        r#"{"shape_xyz": [5, 3, 4], "dtype": "int16", "endianness": "little"}"#,
    )
    .unwrap();
    let raw: Vec<u8> = values
        .iter()
        .flat_map(|v| (v * 2 + 1).to_le_bytes())
        .collect();
    std::fs::write(dir.path().join("v.raw"), &raw).unwrap();
    let b = Volume::read(&json).unwrap();
    assert_eq!(a.values(), b.values());
    let sel = Select::AtLeast(5.0);
    assert_eq!(
        a.to_rays(3, [1, 2, 3], sel).unwrap(),
        b.to_rays(3, [1, 2, 3], sel).unwrap()
    );
    // Bad input names the file: truncated raw data, bad JSON, a volume too large for the universe.
    std::fs::write(dir.path().join("v.raw"), &raw[..50]).unwrap();
    let e = Volume::read(&json).unwrap_err().to_string();
    assert!(e.contains("v.raw") && e.contains("50 bytes"), "{e}");
    std::fs::write(&json, "{\"shape_xyz\": [5, 3]}").unwrap();
    let e = Volume::read(&json).unwrap_err().to_string();
    assert!(e.contains("v.json") && e.contains("line 1"), "{e}");
    assert!(b.to_rays(2, [0; 3], sel).is_err());
    std::fs::write(&nii, &nifti_bytes(shape, &values, 1.0, 0.0)[..200]).unwrap();
    assert!(Volume::read(&nii).is_err());
}

/// Labels read slab by slab from the file ([`label_tree`]) are the tree of the volume read whole, for
/// raw samples of every integer type in both byte orders, NIfTI (scaled) and gzip-compressed NIfTI, at
/// offsets, for slabs of every thickness; damaged files are errors naming the file, never panics.
#[test]
fn labels_read_slab_by_slab_are_the_labels_of_the_whole_volume() {
    use ktree::solid::volume_file::{label_tree, VolumeFile};
    use ktree::KTree;
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let shape = [5usize, 6, 7];
    let n = shape.iter().product::<usize>();
    // Blocks of labels, some scattered voxels, a background of 0.
    let labels: Vec<u32> = (0..n)
        .map(|i| {
            let (x, y, z) = (i % 5, i / 5 % 6, i / 30);
            if i * 7919 % 23 == 0 {
                9
            } else if z < 2 {
                0
            } else {
                (1 + x / 3 + 2 * (y / 3)) as u32
            }
        })
        .collect();
    let whole = |path: &std::path::Path, level, offset| {
        let v = Volume::read(path).unwrap();
        KTree::from_value_runs(&v.to_label_runs::<u16>(level, offset).unwrap())
    };
    let check = |path: &std::path::Path| {
        assert_eq!(VolumeFile::open(path).unwrap().shape(), shape);
        assert_eq!(
            VolumeFile::open(path).unwrap().label_dtype().unwrap(),
            ktree::value::Dtype::U8
        );
        for (level, offset) in [(3, [0, 0, 0]), (4, [3, 9, 1]), (5, [17, 0, 20])] {
            let want = whole(path, level, offset);
            assert_eq!(
                want.voxel_count(),
                labels.iter().filter(|&&l| l > 0).count() as u128
            );
            for slab_bytes in [0, 60, 1 << 10, 1 << 20] {
                let got = label_tree::<u16>(path, level, offset, slab_bytes).unwrap();
                assert!(
                    got == want,
                    "{} at {offset:?}, slabs of {slab_bytes} bytes",
                    path.display()
                );
            }
        }
        // A volume that does not fit the universe.
        let e = label_tree::<u16>(path, 3, [4, 0, 0], 1 << 20)
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not fit"), "{e}");
    };
    for (dtype, size) in [
        ("uint8", 1),
        ("int16", 2),
        ("uint16", 2),
        ("int32", 4),
        ("uint32", 4),
    ] {
        for big in [false, true] {
            let raw: Vec<u8> = labels
                .iter()
                .flat_map(|&l| {
                    let le = l.to_le_bytes();
                    let mut b = le[..size].to_vec();
                    if big {
                        b.reverse();
                    }
                    b
                })
                .collect();
            let name = format!("{dtype}_{big}");
            std::fs::write(dir.path().join(format!("{name}.raw")), &raw).unwrap();
            let json = dir.path().join(format!("{name}.json"));
            let endianness = if big { "big" } else { "little" };
            std::fs::write(
                &json,
                format!(r#"{{"shape_xyz": [5, 6, 7], "dtype": "{dtype}", "endianness": "{endianness}"}}"#),
            )
            .unwrap();
            check(&json);
        }
    }
    // NIfTI with a scale (stored (label − 1) / 2 → label), and the same gzip-compressed.
    let stored: Vec<i16> = labels.iter().map(|&l| l as i16).collect();
    let nii_bytes = nifti_bytes(
        [5, 6, 7],
        &stored.iter().map(|&l| l * 2).collect::<Vec<_>>(),
        0.5,
        0.0,
    );
    let nii = dir.path().join("l.nii");
    std::fs::write(&nii, &nii_bytes).unwrap();
    check(&nii);
    let gz = dir.path().join("l.nii.gz");
    let write_gz = |bytes: &[u8]| {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        enc.write_all(bytes).unwrap();
        std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    };
    write_gz(&nii_bytes);
    check(&gz);
    // Damaged: a NIfTI file cut in the samples (plain and compressed), a raw file too short, a sample
    // that is not a label, a label beyond the type.
    std::fs::write(&nii, &nii_bytes[..352 + 2 * 70]).unwrap();
    let e = label_tree::<u16>(&nii, 3, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(e.contains("l.nii") && e.contains("plane z = 2"), "{e}");
    write_gz(&nii_bytes[..352 + 2 * 100]);
    let e = label_tree::<u16>(&gz, 3, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(e.contains("l.nii.gz") && e.contains("plane z = 3"), "{e}");
    let json = dir.path().join("uint8_false.json");
    std::fs::write(dir.path().join("uint8_false.raw"), vec![0u8; n - 1]).unwrap();
    let e = label_tree::<u16>(&json, 3, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("uint8_false.raw") && e.contains(&format!("{} bytes", n - 1)),
        "{e}"
    );
    let mut floats = stored.clone();
    floats[5 + 5 * 3] = -1;
    std::fs::write(&nii, nifti_bytes([5, 6, 7], &floats, 1.0, 0.5)).unwrap();
    let e = label_tree::<u16>(&nii, 3, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("(0, 0, 0)") && e.contains("whole numbers"),
        "{e}"
    );
    std::fs::write(&nii, nifti_bytes([5, 6, 7], &floats, 1.0, 0.0)).unwrap();
    let e = label_tree::<u8>(&nii, 3, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("(0, 4, 0)") && e.contains("whole numbers"),
        "{e}"
    );
    // A header claiming planes far larger than the file: an error at the first plane, nothing allocated
    // ahead of the bytes; a raw sidecar claiming more than its file holds: an error before reading.
    std::fs::write(&nii, nifti_bytes([30000, 30000, 2], &[], 1.0, 0.0)).unwrap();
    let e = label_tree::<u16>(&nii, 15, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("l.nii") && e.contains("plane z = 0") && e.contains("ends 0 bytes"),
        "{e}"
    );
    let e = VolumeFile::open(&nii)
        .unwrap()
        .label_dtype()
        .unwrap_err()
        .to_string();
    assert!(e.contains("plane z = 0"), "{e}");
    let huge = dir.path().join("huge.json");
    std::fs::write(
        &huge,
        r#"{"shape_xyz": [1048576, 1048576, 1], "dtype": "uint8", "file": "uint8_false.raw"}"#,
    )
    .unwrap();
    let e = VolumeFile::open(&huge).unwrap_err().to_string();
    assert!(e.contains("uint8_false.raw") && e.contains("bytes"), "{e}");
    floats[5 + 5 * 3] = 300;
    std::fs::write(&nii, nifti_bytes([5, 6, 7], &floats, 1.0, 0.0)).unwrap();
    let e = label_tree::<u8>(&nii, 3, [0; 3], 1 << 20)
        .unwrap_err()
        .to_string();
    assert!(e.contains("(0, 4, 0)") && e.contains("300"), "{e}");
}

/// A window of floats read slab by slab ([`window_tree`]) is the tree of the volume read whole: NaN and
/// the samples outside the window are the background, for every slab thickness and offset.
#[test]
fn a_window_read_slab_by_slab_is_the_window_of_the_whole_volume() {
    use ktree::solid::volume_file::window_tree;
    use ktree::KTree;
    let dir = tempfile::tempdir().unwrap();
    let samples: Vec<f32> = (0..6 * 5 * 7)
        .map(|i: usize| match i % 13 {
            0 => f32::NAN,
            1 => -2.5,
            k if i / 30 > 3 => 4.0 + (k % 2) as f32,
            k => k as f32 * 0.75,
        })
        .collect();
    let raw: Vec<u8> = samples.iter().flat_map(|v| v.to_be_bytes()).collect();
    std::fs::write(dir.path().join("w.raw"), raw).unwrap();
    let json = dir.path().join("w.json");
    std::fs::write(
        &json,
        r#"{"shape_xyz": [6, 5, 7], "dtype": "float32", "endianness": "big"}"#,
    )
    .unwrap();
    let volume = Volume::read(&json).unwrap();
    for (lo, hi) in [(-3.0, 100.0), (1.0, 4.0), (4.0, 4.0)] {
        for offset in [[0, 0, 0], [2, 3, 9]] {
            let want = KTree::from_value_runs(&volume.to_window_runs(4, offset, lo, hi).unwrap());
            assert!(want.voxel_count() > 0);
            for slab_bytes in [0, 200, 1 << 20] {
                let got = window_tree(&json, 4, offset, lo, hi, slab_bytes).unwrap();
                assert!(
                    got == want,
                    "window {lo}:{hi} at {offset:?}, slabs of {slab_bytes} bytes"
                );
            }
        }
    }
    assert!(window_tree(&json, 4, [0; 3], 2.0, 1.0, 1 << 20).is_err());
    assert!(window_tree(&json, 4, [0; 3], f64::NAN, 1.0, 1 << 20).is_err());
}
