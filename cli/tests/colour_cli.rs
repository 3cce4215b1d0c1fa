//! `ktree render --colour`: a tree with values is drawn in its values' colours (the CT skull's densities on
//! a colour ramp), one colour R,G,B for any tree; `--colour value` of a tree
//! without values and a bad colour are one-line errors.

mod common;

use common::{data_dir, ktree, run};
use ktree::io::write_ktree_file;

#[test]
fn trees_with_values_are_drawn_in_their_values_colours() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let grey = data_dir().join("volumes/skull_grey.json");
    // The CT's densities from 20000 up as float32: the colour ramp from the least to the most dense.
    run(&[
        "voxelize",
        grey.to_str().unwrap(),
        "--window",
        "20000:60000",
        "--out",
        &s("c.ktree"),
    ]);
    run(&[
        "render",
        &s("c.ktree"),
        "--colour",
        "value",
        "--camera",
        "top",
        "--size",
        "160x160",
        "--out",
        &s("c.png"),
    ]);
    let image = image::open(dir.path().join("c.png")).unwrap().to_rgb8();
    // Hues (colours scaled to their largest channel) of the object's pixels: more than one class shows.
    let mut hues = std::collections::BTreeSet::new();
    for p in image.pixels() {
        let [r, g, b] = p.0;
        if [r, g, b] == [255, 255, 255] {
            continue;
        }
        let m = f64::from(r.max(g).max(b)).max(1.0);
        hues.insert([r, g, b].map(|c| (f64::from(c) / m * 8.0).round() as u8));
    }
    assert!(hues.len() >= 2, "{hues:?}");
    // One colour for all.
    run(&[
        "render",
        &s("c.ktree"),
        "--colour",
        "200,30,30",
        "--size",
        "64x64",
        "--out",
        &s("red.png"),
    ]);
    let red = image::open(dir.path().join("red.png")).unwrap().to_rgb8();
    assert!(red
        .pixels()
        .any(|p| u32::from(p.0[0]) > 2 * u32::from(p.0[1]).max(1) && p.0 != [255, 255, 255]));
}

#[test]
fn colour_errors() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let grey = data_dir().join("volumes/skull_grey.json");
    run(&[
        "voxelize",
        grey.to_str().unwrap(),
        "--threshold",
        "29000",
        "--out",
        &s("b.ktree"),
    ]);
    let (ok, _, err) = ktree(&[
        "render",
        &s("b.ktree"),
        "--colour",
        "value",
        "--out",
        &s("b.png"),
    ]);
    assert!(!ok && err.contains("holds none"), "{err}");
    let (ok, _, err) = ktree(&[
        "render",
        &s("b.ktree"),
        "--colour",
        "red",
        "--out",
        &s("b.png"),
    ]);
    assert!(!ok && err.contains("'red'"), "{err}");
    assert!(!dir.path().join("b.png").exists());
}

/// A shade of `base`: every channel `base`'s times one factor (to rounding).
fn is_shade(px: [u8; 3], base: [u8; 3]) -> bool {
    let factor =
        f64::from(px[0].max(px[1]).max(px[2])) / f64::from(base[0].max(base[1]).max(base[2]));
    (0..3).all(|c| (f64::from(px[c]) - f64::from(base[c]) * factor).abs() <= 3.0)
}

/// `ktree render` of a quadtree with values: each voxel's pixel (8 pixels a voxel, sampled at its centre,
/// never on a leaf's outline) is its label's palette colour, white where empty; `--colour R,G,B` paints
/// every voxel with a value, of a quadtree with or without values.
#[test]
fn quadtrees_with_values_are_drawn_in_their_values_colours() {
    use ktree::display::palette::label_colour;
    use ktree::io::ktree::v3::write_valued_ktree_file;
    use ktree::KTree;
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    // 8 × 8 voxels: label 1 + x / 3 + 2 (y / 4) (labels 1 … 6), a hole at the top right.
    let dense: Vec<Option<u16>> = (0..64u16)
        .map(|i| {
            let (x, y) = (i % 8, i / 8);
            (x < 6 || y < 5).then_some(1 + x / 3 + 2 * (y / 4))
        })
        .collect();
    let tree = KTree::<2, u16>::from_dense_values(3, &dense).unwrap();
    write_valued_ktree_file(std::path::Path::new(&s("labels2d.ktree")), &tree).unwrap();
    let out = run(&[
        "render",
        &s("labels2d.ktree"),
        "--size",
        "64x64",
        "--out",
        &s("labels2d.png"),
    ]);
    assert!(out.contains("quadtree with values"), "{out}");
    let image = image::open(dir.path().join("labels2d.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(image.dimensions(), (64, 64));
    for (i, v) in dense.iter().enumerate() {
        let (x, y) = (i as u32 % 8, i as u32 / 8);
        let want = v.map_or([255, 255, 255], |v| label_colour(u64::from(v)));
        assert_eq!(
            image.get_pixel(8 * x + 4, 64 - 8 * y - 4).0,
            want,
            "voxel ({x}, {y}) of label {v:?}"
        );
    }
    run(&[
        "render",
        &s("labels2d.ktree"),
        "--colour",
        "10,200,10",
        "--size",
        "64x64",
        "--out",
        &s("green.png"),
    ]);
    let green = image::open(dir.path().join("green.png")).unwrap().to_rgb8();
    assert_eq!(green.get_pixel(4, 60).0, [10, 200, 10]);
    assert_eq!(green.get_pixel(60, 4).0, [255, 255, 255]);
    // The tree's shape, without values: one colour asked for, or the default.
    write_ktree_file(&dir.path().join("shape.ktree"), &tree.shape()).unwrap();
    for (colour, want) in [(Some("200,30,30"), [200, 30, 30]), (None, [70, 110, 170])] {
        let mut args = vec!["render".to_string(), s("shape.ktree")];
        if let Some(c) = colour {
            args.extend(["--colour".into(), c.into()]);
        }
        args.extend(["--size", "64x64", "--out"].map(String::from));
        args.push(s("shape.png"));
        run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let shape = image::open(dir.path().join("shape.png")).unwrap().to_rgb8();
        assert_eq!(shape.get_pixel(4, 60).0, want, "{colour:?}");
        assert_eq!(shape.get_pixel(60, 4).0, [255, 255, 255]);
    }
}

/// `ktree render` of a 4-D tree with values: a strip of time slices, a ball of label 1 in the first half
/// of time and of label 2 in the second; the strip's first frame shows shades of label 1's colour only,
/// its second of label 2's, and the strip is the library's `time_strip_values` pixel for pixel.
#[test]
fn strips_of_4d_trees_with_values_are_drawn_in_their_values_colours() {
    use ktree::display::palette::{label_colour, value_colours};
    use ktree::display::slices::time_strip_values;
    use ktree::io::ktree::v3::write_valued_ktree_file;
    use ktree::KTree;
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let dense: Vec<Option<u8>> = (0..1usize << 16)
        .map(|i| {
            let [x, y, z, t] = [0, 4, 8, 12].map(|s| ((i >> s) & 15) as f64 + 0.5);
            let inside = (x - 8.0).powi(2) + (y - 8.0).powi(2) + (z - 8.0).powi(2) <= 30.0;
            inside.then_some(if t < 8.0 { 1 } else { 2 })
        })
        .collect();
    let tree = KTree::<4, u8>::from_dense_values(4, &dense).unwrap();
    write_valued_ktree_file(std::path::Path::new(&s("moving.ktree")), &tree).unwrap();
    let out = run(&[
        "render",
        &s("moving.ktree"),
        "--frames",
        "2",
        "--size",
        "96x96",
        "--out",
        &s("strip.png"),
    ]);
    assert!(out.contains("2 frames"), "{out}");
    let image = image::open(dir.path().join("strip.png")).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (2 * (96 + 4), 96));
    for (frame, label) in [(0u32, 1u64), (1, 2)] {
        let mut object = 0;
        for y in 0..96 {
            for x in 0..96 {
                let px = image.get_pixel(frame * 100 + x, y).0;
                if px == [255, 255, 255] {
                    continue;
                }
                object += 1;
                assert!(
                    is_shade(px, label_colour(label)),
                    "frame {frame} ({x}, {y}): {px:?} is not a shade of label {label}'s colour"
                );
            }
        }
        assert!(object > 500, "frame {frame}: {object} pixels of the object");
    }
    let (strip, _) = time_strip_values(&tree, 3, 2, 96, value_colours(&tree)).unwrap();
    assert!(image.as_raw() == &strip.rgb);
    // Without values, --colour value is the error it was.
    write_ktree_file(&dir.path().join("shape4.ktree"), &tree.shape()).unwrap();
    let (ok, _, err) = ktree(&[
        "render",
        &s("shape4.ktree"),
        "--colour",
        "value",
        "--out",
        &s("shape4.png"),
    ]);
    assert!(!ok && err.contains("holds none"), "{err}");
    let shape2 = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
    write_ktree_file(&dir.path().join("shape2.ktree"), &shape2).unwrap();
    let (ok, _, err) = ktree(&[
        "render",
        &s("shape2.ktree"),
        "--colour",
        "value",
        "--out",
        &s("shape2.png"),
    ]);
    assert!(!ok && err.contains("holds none"), "{err}");
    assert!(!dir.path().join("shape4.png").exists() && !dir.path().join("shape2.png").exists());
}
