//! `ktree render --colour`: a tree with values is drawn in its values' colours (the CT skull's densities on
//! a colour ramp), one colour R,G,B for any tree; `--colour value` of a tree
//! without values and a bad colour are one-line errors.

mod common;

use common::{data_dir, ktree, run};

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
