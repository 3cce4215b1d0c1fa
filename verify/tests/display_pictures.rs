//! 2-D and 4-D pictures: a 4-D tree's slices equal the dense array's slices (and are reduced trees); a
//! quadtree picture fills exactly the pixels of full cells; a time strip has one frame per slice.
// Geometry over axes reads clearest with indices.
#![allow(clippy::needless_range_loop)]

use ktree_verify::cases;

use cases::ray_sets;
use ktree::display::plane::{quadtree_canvas, quadtree_svg};
use ktree::display::slices::{slice_4d, time_strip};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ktree_verify::config(64))]

    #[test]
    fn slices_of_4d_trees_match_the_dense_array(case in ray_sets::<4>(), axis in 0..4usize, pos in 0..16u32) {
        let tree = stack(&case.rays);
        let side = tree.universe().side() as u32;
        let pos = pos % side;
        let slice = slice_4d(&tree, axis, pos).unwrap();
        slice.assert_well_formed();
        let dense4 = tree.to_dense().unwrap();
        let dense3 = slice.to_dense().unwrap();
        let u4 = tree.universe();
        let u3 = slice.universe();
        for (i, &v) in dense3.iter().enumerate() {
            let p = u3.dense_point(i);
            let mut q = [0u32; 4];
            let mut j = 0;
            for (k, c) in q.iter_mut().enumerate() {
                if k == axis { *c = pos; } else { *c = p[j]; j += 1; }
            }
            prop_assert_eq!(v, dense4[u4.dense_index(q)], "voxel {:?} of slice {} on axis {}", p, pos, axis);
        }
        prop_assert!(slice_4d(&tree, axis, side).is_err());
    }

    #[test]
    fn quadtree_pictures_fill_exactly_the_full_cells(case in ray_sets::<2>()) {
        let tree = stack(&case.rays);
        let side = tree.universe().side() as u32;
        let size = 4 * side.max(16);
        let canvas = quadtree_canvas(&tree, size).unwrap();
        let scale = size / side;
        // Sample the centre of every voxel's pixel block (away from the drawn boundaries).
        for y in 0..side {
            for x in 0..side {
                let (px, py) = (x * scale + scale / 2, size - 1 - (y * scale + scale / 2));
                let i = 3 * (py * size + px) as usize;
                let filled = canvas.rgb[i..i + 3] == [70, 110, 170];
                let grid = canvas.rgb[i..i + 3] == [150, 150, 150];
                prop_assert!(grid || filled == tree.contains([x, y]), "voxel ({}, {})", x, y);
            }
        }
        let svg = quadtree_svg(&tree, 256);
        prop_assert_eq!(svg.matches("<rect x=").count(), tree.leaves().count());
    }
}

#[test]
fn a_moving_ball_makes_a_strip_of_frames() {
    // A 4-D "ball" (a sphere growing then shrinking in time): the middle frame shows the largest ball.
    let tree = stack(&ball_rays::<4>(4, [16, 16, 16, 16], 14).unwrap());
    let (strip, frames) = time_strip(&tree, 3, 5, 64).unwrap();
    assert_eq!(frames.len(), 5);
    assert_eq!(strip.width, 5 * (64 + 4));
    let painted: Vec<u64> = frames.iter().map(|(_, f)| f.stats.painted).collect();
    assert!(
        painted[2] > painted[0] && painted[2] > painted[4],
        "{painted:?}"
    );
    assert!(time_strip(&tree, 3, 0, 64).is_err());
    assert!(time_strip(&tree, 4, 2, 64).is_err());
}
