//! Traversal order for display (M7, V2): for random trees and random view directions (and eye points), no
//! cell visited later occludes one visited earlier; back to front is the exact reverse.
// Geometry over axes reads clearest with indices.
#![allow(clippy::needless_range_loop)]

use ktree_verify::cases;

use cases::ray_sets;
use ktree::display::{ordered_full_cells, Order, Viewer};
use ktree::space::Cell;
use ktree::stacking::paper::stack;
use proptest::prelude::*;

/// Whether box `j` occludes box `i` seen along `d` (exact for axis-aligned open boxes, any K): some point
/// of `i` is behind some point of `j` on a line of direction `d`.
fn occludes<const K: usize>(j: &Cell<K>, i: &Cell<K>, d: [f64; K]) -> bool {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for k in 0..K {
        let (jl, jh) = (
            f64::from(j.origin()[k]),
            f64::from(j.origin()[k]) + j.side() as f64,
        );
        let (il, ih) = (
            f64::from(i.origin()[k]),
            f64::from(i.origin()[k]) + i.side() as f64,
        );
        // Need lo < −t·d_k < hi with lo = jl − ih, hi = jh − il.
        let (lo, hi) = (jl - ih, jh - il);
        if d[k] == 0.0 {
            if !(lo < 0.0 && 0.0 < hi) {
                return false;
            }
            continue;
        }
        let (a, b) = (lo / -d[k], hi / -d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 < t1
}

/// Whether the open segment from `eye` to `x` passes through the open box of `cell` (chord > 0).
fn segment_hits(eye: [f64; 3], x: [f64; 3], cell: &Cell<3>) -> bool {
    let (mut t0, mut t1) = (1e-9f64, 1.0f64 - 1e-9);
    for k in 0..3 {
        let lo = f64::from(cell.origin()[k]);
        let hi = lo + cell.side() as f64;
        let d = x[k] - eye[k];
        if d == 0.0 {
            if !(lo < eye[k] && eye[k] < hi) {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo - eye[k]) / d, (hi - eye[k]) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 < t1
}

fn direction() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(prop_oneof![-1.0..-0.05f64, 0.05..1.0f64, Just(0.0)])
        .prop_filter("non-zero", |d| d.iter().any(|&x| x != 0.0))
}

proptest! {
    #![proptest_config(ktree_verify::config(96))]

    #[test]
    fn no_later_cell_occludes_an_earlier_one(case in ray_sets::<3>(), d in direction()) {
        let tree = stack(&case.rays);
        tree.assert_well_formed();
        let cells = ordered_full_cells(&tree, Viewer::Direction(d), Order::FrontToBack);
        prop_assert_eq!(cells.len(), tree.full_cells().count());
        let n = cells.len().min(700);
        for i in 0..n {
            for j in i + 1..n {
                prop_assert!(
                    !occludes(&cells[j], &cells[i], d),
                    "cell {:?} (visited {}) occludes {:?} (visited {}) along {:?}", cells[j], j, cells[i], i, d
                );
            }
        }
        let mut back = ordered_full_cells(&tree, Viewer::Direction(d), Order::BackToFront);
        back.reverse();
        prop_assert_eq!(back, cells);
    }

    #[test]
    fn perspective_order_holds_for_sampled_points(
        case in ray_sets::<3>(),
        eye in prop::array::uniform3(-40.0..110.0f64),
    ) {
        let tree = stack(&case.rays);
        let cells = ordered_full_cells(&tree, Viewer::Eye(eye), Order::FrontToBack);
        prop_assert_eq!(cells.len(), tree.full_cells().count());
        let n = cells.len().min(300);
        for i in 0..n {
            let c = &cells[i];
            let s = c.side() as f64;
            let o = c.origin().map(f64::from);
            for sample in 0..9 {
                let f = |bit: usize| -> f64 { if sample == 8 { 0.5 } else if sample >> bit & 1 == 1 { 0.8 } else { 0.2 } };
                let x = [o[0] + f(0) * s, o[1] + f(1) * s, o[2] + f(2) * s];
                for (j, later) in cells.iter().enumerate().take(n).skip(i + 1) {
                    prop_assert!(
                        !segment_hits(eye, x, later),
                        "from eye {:?}: cell {:?} (visited {}) hides a point of {:?} (visited {})", eye, later, j, c, i
                    );
                }
            }
        }
    }

    #[test]
    fn quadtree_order_holds_in_two_dimensions(case in ray_sets::<2>(), dx in -1.0..1.0f64, dy in -1.0..1.0f64) {
        // Meagher's Fig. 8a: the 2-D hidden-line sequence.
        prop_assume!(dx.abs() + dy.abs() > 1e-3);
        let tree = stack(&case.rays);
        let cells = ordered_full_cells(&tree, Viewer::Direction([dx, dy]), Order::FrontToBack);
        let n = cells.len().min(500);
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (&cells[i], &cells[j]);
                let occ = occludes(b, a, [dx, dy]);
                prop_assert!(!occ, "{:?} (visited {}) occludes {:?} (visited {})", b, j, a, i);
            }
        }
    }
}

#[test]
fn near_child_is_the_viewers_octant() {
    assert_eq!(ktree::display::near_child([1.0, 1.0, 1.0]), 0);
    assert_eq!(ktree::display::near_child([-1.0, 1.0, 1.0]), 1);
    assert_eq!(ktree::display::near_child([-1.0, -1.0, -1.0]), 7);
}
