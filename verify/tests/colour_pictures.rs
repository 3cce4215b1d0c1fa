//! Pictures coloured by value: every pixel of a valued octree drawn with `RenderOptions::paint` through
//! `LeavesOfValues` is a shade of the colour of the value of the leaf seen there (the leaf each pixel
//! shows is kept by the renderer), and the picture shows the same pixels as the tree's shape drawn plainly.
//! Random quadtrees with values (`values_canvas`) and 4-D trees with values (`time_strip_values`) against
//! the dense array of values they were made from: each voxel's pixel is its value's palette colour (white
//! where empty), each frame of a strip the rendering of the dense array's slice painted with the palette.

use ktree::display::palette::{label_colour, ramp, value_colours};
use ktree::display::plane::values_canvas;
use ktree::display::slices::time_strip_values;
use ktree::display::{default_camera, render, Camera, Paint, RenderOptions, ISO_TOWARD_EYE};
use ktree::space::Cell;
use ktree::tree::valued::LeavesOfValues;
use ktree::tree::Rgb;
use ktree::value::{Dtype, Value};
use ktree::KTree;
use ktree_verify::labels::{painted_at, Painted, Palette};
use proptest::prelude::*;

/// The palette colour of each voxel of `dense` (`None`: empty), worked out from the dense array alone:
/// labels by `label_colour`, floats on `ramp` from the array's smallest value to its largest, colours as
/// they are.
fn reference_colours<V: Value>(dense: &[Option<V>]) -> Vec<Option<[u8; 3]>> {
    let number = |v: V| v.text().parse::<f64>().unwrap();
    let floats = dense
        .iter()
        .flatten()
        .filter(|_| V::DTYPE == Some(Dtype::F32));
    let (lo, hi) = floats.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
        (lo.min(number(v)), hi.max(number(v)))
    });
    dense
        .iter()
        .map(|v| {
            v.map(|v| match V::DTYPE {
                Some(Dtype::Rgb) => {
                    let mut bytes = Vec::new();
                    v.write_le(&mut bytes);
                    [bytes[0], bytes[1], bytes[2]]
                }
                Some(Dtype::F32) if hi > lo => ramp((number(v) - lo) / (hi - lo)),
                Some(Dtype::F32) => ramp(0.5),
                _ => label_colour(number(v) as i64 as u64),
            })
        })
        .collect()
}

/// A quadtree with values drawn 8 pixels a voxel: the pixel at each voxel's centre (never on a leaf's
/// outline) is the reference colour of its value, white where it is empty.
fn quadtree_pixels<V: Palette>(o: &Painted<2>) -> Result<(), TestCaseError> {
    let dense = o.dense::<V>();
    let expected = reference_colours(&dense);
    let tree = KTree::<2, V>::from_dense_values(o.level, &dense).unwrap();
    let side = 1u32 << o.level;
    let size = 8 * side;
    let canvas = values_canvas(&tree, size, value_colours(&tree)).unwrap();
    prop_assert_eq!((canvas.width, canvas.height), (size, size));
    for (i, want) in expected.iter().enumerate() {
        let [x, y] = o.universe().dense_point(i);
        // Axis 0 to the right, axis 1 up.
        let (col, row) = (8 * x + 4, size - 8 * y - 4);
        let at = 3 * (row * size + col) as usize;
        let got = &canvas.rgb[at..at + 3];
        let want = want.unwrap_or([255, 255, 255]);
        prop_assert_eq!(got, &want[..], "voxel ({}, {}): {:?}", x, y, dense[i]);
    }
    Ok(())
}

/// A 4-D tree with values as a strip along axis 3: each frame is the rendering of the dense array's slice
/// at the frame's position, painted with the reference colours, framed as the strip frames (the bounding
/// box of the voxels with values); every pixel of the object is a shade of the reference colour of the
/// voxel seen there, and the background is white.
fn strip_pixels<V: Palette>(o: &Painted<4>, frames: usize) -> Result<(), TestCaseError> {
    let dense = o.dense::<V>();
    let expected = reference_colours(&dense);
    let tree = KTree::<4, V>::from_dense_values(o.level, &dense).unwrap();
    let size = 40;
    let (strip, shown) = time_strip_values(&tree, 3, frames, size, value_colours(&tree)).unwrap();
    prop_assert_eq!(shown.len(), frames);
    prop_assert_eq!(strip.width, frames as u32 * (size + 4));
    let u = o.universe();
    let side = u.side() as u32;
    // The camera: the voxels' bounding box, time left out.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (i, v) in dense.iter().enumerate() {
        if v.is_some() {
            let p = u.dense_point(i);
            for a in 0..3 {
                lo[a] = lo[a].min(f64::from(p[a]));
                hi[a] = hi[a].max(f64::from(p[a]) + 1.0);
            }
        }
    }
    if lo[0] > hi[0] {
        (lo, hi) = ([0.0; 3], [f64::from(side); 3]);
    }
    let camera = Camera::framing(lo, hi, ISO_TOWARD_EYE, None, size, size).unwrap();
    for (f, (position, image)) in shown.iter().enumerate() {
        let want_position = ((2 * f as u64 + 1) * u64::from(side) / (2 * frames as u64))
            .min(u64::from(side) - 1) as u32;
        prop_assert_eq!(*position, want_position);
        let at = |p: [u32; 3]| u.dense_index([p[0], p[1], p[2], *position]);
        let slice: Vec<Option<V>> = (0..(side as usize).pow(3))
            .map(|j| {
                let (x, y, z) = (
                    j as u32 % side,
                    j as u32 / side % side,
                    j as u32 / side / side,
                );
                dense[at([x, y, z])]
            })
            .collect();
        let reference = KTree::<3, V>::from_dense_values(o.level, &slice).unwrap();
        let paint = |cell: &Cell<3>| expected[at(cell.origin())].unwrap();
        let drawn = render(
            &LeavesOfValues(&reference),
            &camera,
            &RenderOptions {
                width: size,
                height: size,
                cells: true,
                paint: Some(Paint(&paint)),
                ..Default::default()
            },
        )
        .unwrap();
        prop_assert!(image.rgb == drawn.rgb, "frame {} differs", f);
        for (i, cell) in drawn.cells.as_ref().unwrap().iter().enumerate() {
            let px = &image.rgb[3 * i..3 * i + 3];
            let Some(cell) = cell else {
                prop_assert_eq!(px, &[255, 255, 255][..], "pixel {} of frame {}", i, f);
                continue;
            };
            let base = expected[at(cell.origin())].unwrap();
            let peak = f64::from(base[0].max(base[1]).max(base[2]));
            if peak == 0.0 {
                prop_assert_eq!(px, &[0, 0, 0][..]);
                continue;
            }
            let factor = f64::from(px[0].max(px[1]).max(px[2])) / peak;
            for c in 0..3 {
                let want = f64::from(base[c]) * factor;
                prop_assert!(
                    (f64::from(px[c]) - want).abs() <= 3.0,
                    "pixel {} of frame {}: {:?} is not a shade of {:?}",
                    i,
                    f,
                    px,
                    base
                );
            }
        }
        // The strip holds the frame.
        let x0 = f as u32 * (size + 4);
        for y in 0..size {
            let src = 3 * (y * size) as usize;
            let dst = 3 * (y * strip.width + x0) as usize;
            prop_assert!(
                strip.rgb[dst..dst + 3 * size as usize] == image.rgb[src..src + 3 * size as usize]
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test]
    fn quadtree_pictures_have_their_values_colours(o in (1u32..=4).prop_flat_map(painted_at::<2>)) {
        quadtree_pixels::<u8>(&o)?;
        quadtree_pixels::<u32>(&o)?;
        quadtree_pixels::<f32>(&o)?;
        quadtree_pixels::<Rgb>(&o)?;
    }
    #[test]
    fn strips_have_their_values_colours(
        o in (1u32..=3).prop_flat_map(painted_at::<4>),
        frames in 1usize..4,
    ) {
        strip_pixels::<u16>(&o, frames)?;
        strip_pixels::<f32>(&o, frames)?;
        strip_pixels::<Rgb>(&o, frames)?;
    }
}

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
