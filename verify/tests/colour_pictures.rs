//! Pictures coloured by value: every pixel of a valued octree drawn with `RenderOptions::paint` through
//! `LeavesOfValues` is a shade of the colour of the value of the leaf seen there (the leaf each pixel
//! shows is kept by the renderer), and the picture shows the same pixels as the tree's shape drawn plainly.

use ktree::display::palette::{label_colour, value_colours};
use ktree::display::{default_camera, render, Paint, RenderOptions, ISO_TOWARD_EYE};
use ktree::space::Cell;
use ktree::tree::valued::LeavesOfValues;
use ktree::KTree;

#[test]
fn each_pixel_is_a_shade_of_its_leafs_value() {
    // An L = 4 octree: labels 1, 2, 3 in three slabs of a ball-like blob.
    let side = 16u32;
    let dense: Vec<Option<u8>> = (0..side.pow(3))
        .map(|i| {
            let (x, y, z) = (i % side, i / side % side, i / side / side);
            let d = [x, y, z].map(|c| (2.0 * c as f64 + 1.0 - side as f64).powi(2));
            (d.iter().sum::<f64>() < 180.0).then_some(1 + (x * 3 / side) as u8)
        })
        .collect();
    let tree = KTree::<3, u8>::from_dense_values(4, &dense).unwrap();
    let colour = value_colours(&tree);
    let paint = |cell: &Cell<3>| colour(tree.value_at(cell.origin()).unwrap());
    let view = LeavesOfValues(&tree);
    let camera = default_camera(&view, ISO_TOWARD_EYE, None, 120, 120).unwrap();
    let options = RenderOptions {
        width: 120,
        height: 120,
        cells: true,
        paint: Some(Paint(&paint)),
        ..Default::default()
    };
    let image = render(&view, &camera, &options).unwrap();
    let plain = render(
        &tree.shape(),
        &camera,
        &RenderOptions {
            cells: true,
            ..options
        },
    )
    .unwrap();
    let cells = image.cells.as_ref().unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for (i, cell) in cells.iter().enumerate() {
        assert_eq!(
            cell.is_some(),
            plain.cells.as_ref().unwrap()[i].is_some(),
            "pixel {i}"
        );
        let Some(cell) = cell else { continue };
        let value = tree.value_at(cell.origin()).unwrap();
        seen.insert(value);
        let base = label_colour(u64::from(value));
        let px = &image.rgb[3 * i..3 * i + 3];
        // A shade: every channel the base's times one factor (to rounding).
        let factor =
            f64::from(px[0].max(px[1]).max(px[2])) / f64::from(base[0].max(base[1]).max(base[2]));
        for c in 0..3 {
            let want = f64::from(base[c]) * factor;
            assert!(
                (f64::from(px[c]) - want).abs() <= 3.0,
                "pixel {i}: {px:?} is not a shade of {base:?}"
            );
        }
    }
    assert_eq!(seen.len(), 3, "all three labels are in sight");
}
