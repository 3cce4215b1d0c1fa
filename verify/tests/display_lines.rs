//! Line drawings (V1–V5) on random small objects from random directions: every drawn point is a true
//! edge of the object (no cracks) and is not hidden (a brute-force ray cast through all full voxels
//! decides), every robustly visible edge of the object is drawn, touching collinear pieces are one line,
//! and the paper's pairwise hidden-line method and the bucketed one give the same drawing.
// Geometry over axes reads clearest with indices.
#![allow(clippy::needless_range_loop)]

use ktree::display::{line_drawing, HiddenLineMethod, LineDrawing};
use ktree::KTree;
use proptest::prelude::*;

const LEVEL: u32 = 3;
const SIDE: usize = 1 << LEVEL;

/// A small object: a union of boxes plus scattered voxels, as a dense array (axis 0 fastest).
fn objects() -> impl Strategy<Value = Vec<bool>> {
    let s = SIDE as u32;
    let boxes = prop::collection::vec(prop::array::uniform3((0..s, 1..=s)), 1..4);
    let voxels = prop::collection::vec(prop::array::uniform3(0..s), 0..12);
    (boxes, voxels).prop_map(move |(boxes, voxels)| {
        let mut dense = vec![false; SIDE * SIDE * SIDE];
        for b in boxes {
            for z in b[2].0..(b[2].0 + b[2].1).min(s) {
                for y in b[1].0..(b[1].0 + b[1].1).min(s) {
                    for x in b[0].0..(b[0].0 + b[0].1).min(s) {
                        dense[idx([x, y, z])] = true;
                    }
                }
            }
        }
        for v in voxels {
            dense[idx(v)] = true;
        }
        dense
    })
}

fn idx(p: [u32; 3]) -> usize {
    p[0] as usize + SIDE * (p[1] as usize + SIDE * p[2] as usize)
}

fn full(dense: &[bool], p: [i64; 3]) -> bool {
    p.iter().all(|&c| (0..SIDE as i64).contains(&c)) && dense[idx(p.map(|c| c as u32))]
}

fn toward() -> impl Strategy<Value = [f64; 3]> {
    prop_oneof![
        4 => prop::array::uniform3(prop_oneof![-1.0..-0.15f64, 0.15..1.0f64]),
        // Exact axis and diagonal views (ties decided by the symbolic tilt).
        1 => prop::sample::select(vec![
            [0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0],
            [1.0, 1.0, 1.0], [1.0, -1.0, 0.0], [0.0, 1.0, 1.0],
        ]),
    ]
}

/// The chord of the ray `p + t·v` through the box `[lo − grow, lo + 1 + grow]^3` intersected with
/// `t > t_min` has positive length.
fn ray_meets_voxel(p: [f64; 3], v: [f64; 3], lo: [f64; 3], grow: f64, t_min: f64) -> bool {
    let (mut t0, mut t1) = (t_min, f64::INFINITY);
    for k in 0..3 {
        let (a, b) = (lo[k] - grow, lo[k] + 1.0 + grow);
        if v[k] == 0.0 {
            if !(a < p[k] && p[k] < b) {
                return false;
            }
            continue;
        }
        let (x, y) = ((a - p[k]) / v[k], (b - p[k]) / v[k]);
        t0 = t0.max(x.min(y));
        t1 = t1.min(x.max(y));
    }
    t0 < t1
}

fn voxels_of(dense: &[bool]) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for z in 0..SIDE {
        for y in 0..SIDE {
            for x in 0..SIDE {
                if dense[x + SIDE * (y + SIDE * z)] {
                    out.push([x as f64, y as f64, z as f64]);
                }
            }
        }
    }
    out
}

/// Whether the unit lattice edge along `axis` at `fixed` (other axes, lower first), starting at `u`, is an
/// edge of the object: one, three, or two diagonal of its four voxels are full.
fn is_edge(dense: &[bool], axis: usize, fixed: [u32; 2], u: i64) -> bool {
    let [b, c] = match axis {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    };
    let mut occ = [[false; 2]; 2];
    for (i, row) in occ.iter_mut().enumerate() {
        for (j, o) in row.iter_mut().enumerate() {
            let mut p = [0i64; 3];
            p[axis] = u;
            p[b] = i64::from(fixed[0]) - 1 + i as i64;
            p[c] = i64::from(fixed[1]) - 1 + j as i64;
            *o = full(dense, p);
        }
    }
    let n = occ.iter().flatten().filter(|&&o| o).count();
    n == 1 || n == 3 || (n == 2 && occ[0][0] == occ[1][1])
}

fn check_drawing(dense: &[bool], d: &LineDrawing) -> Result<(), TestCaseError> {
    let voxels = voxels_of(dense);
    let v = d.view_dir.map(|x| -x);
    // 1. Every drawn point is on an object edge and not hidden.
    for e in &d.lines {
        prop_assert!(e.u0 < e.u1);
        let len = e.u1 - e.u0;
        let samples = (len * 3.0).ceil() as usize + 1;
        for s in 0..samples {
            let u = e.u0 + len * (s as f64 + 0.37) / samples as f64;
            prop_assert!(
                is_edge(dense, e.axis as usize, e.fixed, u.floor() as i64),
                "drawn point {:?} at u = {u} is not an edge of the object (a crack?)",
                e
            );
            let p = e.point(u);
            for lo in &voxels {
                prop_assert!(
                    !ray_meets_voxel(p, v, *lo, -1e-6, 1e-6),
                    "drawn point {:?} of {:?} is hidden by voxel {:?}",
                    p,
                    e,
                    lo
                );
            }
        }
    }
    // 2. Every robustly visible object edge is drawn.
    for axis in 0..3usize {
        for f0 in 0..=SIDE as u32 {
            for f1 in 0..=SIDE as u32 {
                for u in 0..SIDE as i64 {
                    if !is_edge(dense, axis, [f0, f1], u) {
                        continue;
                    }
                    let mid = u as f64 + 0.5;
                    let line = ktree::display::Edge3 {
                        axis: axis as u8,
                        fixed: [f0, f1],
                        u0: mid,
                        u1: mid,
                    };
                    let p = line.point(mid);
                    if voxels
                        .iter()
                        .any(|lo| ray_meets_voxel(p, v, *lo, 1e-6, 1e-3))
                    {
                        continue; // hidden, or too close to hidden to call
                    }
                    let drawn = d.lines.iter().any(|e| {
                        e.axis as usize == axis
                            && e.fixed == [f0, f1]
                            && e.u0 - 1e-6 <= mid
                            && mid <= e.u1 + 1e-6
                    });
                    prop_assert!(
                        drawn,
                        "visible edge along axis {} at {:?}, u = {} is not drawn",
                        axis,
                        [f0, f1],
                        u
                    );
                }
            }
        }
    }
    // 3. Dots removed: no two drawn lines of the same lattice line touch.
    for w in d.lines.windows(2) {
        if w[0].axis == w[1].axis && w[0].fixed == w[1].fixed {
            prop_assert!(
                w[1].u0 > w[0].u1 + 1e-9,
                "lines {:?} and {:?} touch",
                w[0],
                w[1]
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(128))]

    #[test]
    fn drawn_lines_are_visible_edges_and_visible_edges_are_drawn(dense in objects(), dir in toward()) {
        let tree = KTree::<3>::from_dense(LEVEL, &dense).unwrap();
        tree.assert_well_formed();
        let fast = line_drawing(&tree, dir, HiddenLineMethod::Bucketed).unwrap();
        check_drawing(&dense, &fast)?;
        let slow = line_drawing(&tree, dir, HiddenLineMethod::Pairwise).unwrap();
        prop_assert_eq!(fast.lines.len(), slow.lines.len());
        for (a, b) in fast.lines.iter().zip(&slow.lines) {
            prop_assert!(a.key_eq(b) && (a.u0 - b.u0).abs() < 1e-9 && (a.u1 - b.u1).abs() < 1e-9, "{:?} vs {:?}", a, b);
        }
        let s = fast.stats;
        prop_assert_eq!(s.graphics_nodes + s.surrounded, s.full_leaves);
        prop_assert!(s.graphics_nodes <= tree.counts().full);
        prop_assert!(slow.stats.pair_tests >= fast.stats.pair_tests);
    }
}

trait KeyEq {
    fn key_eq(&self, other: &Self) -> bool;
}

impl KeyEq for ktree::display::Edge3 {
    fn key_eq(&self, other: &Self) -> bool {
        self.axis == other.axis && self.fixed == other.fixed
    }
}

fn dense_of(level: u32, boxes: &[([u32; 3], [u32; 3])]) -> Vec<bool> {
    let side = 1usize << level;
    let mut dense = vec![false; side * side * side];
    for &(lo, hi) in boxes {
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    dense[x as usize + side * (y as usize + side * z as usize)] = true;
                }
            }
        }
    }
    dense
}

#[test]
fn a_box_of_many_leaves_is_nine_lines() {
    // A 3×5×2 box at an odd offset: many leaves, cracks between them, but one box outline: 9 lines.
    let dense = dense_of(3, &[([1, 1, 3], [4, 6, 5])]);
    let tree = KTree::<3>::from_dense(3, &dense).unwrap();
    assert!(tree.counts().full > 4);
    let d = line_drawing(&tree, [0.7, -1.0, 0.8], HiddenLineMethod::Pairwise).unwrap();
    assert_eq!(d.lines.len(), 9, "{:?}", d.lines);
    assert!(d.stats.edge_pieces > 9, "cracks and dots were joined");
}

#[test]
fn a_diagonal_view_keeps_edges_behind_a_wall_hidden() {
    // Seen along (1, −1, 0), the column's corner edge lines up with the outline shared by the wall's
    // voxels around a surrounded one (the wall meets the crossing column there): nothing may show
    // through that seam.
    let dense = dense_of(
        3,
        &[
            ([0, 2, 0], [6, 3, 7]),
            ([4, 0, 0], [5, 4, 3]),
            ([2, 3, 3], [3, 4, 7]),
        ],
    );
    let tree = KTree::<3>::from_dense(3, &dense).unwrap();
    for method in [HiddenLineMethod::Pairwise, HiddenLineMethod::Bucketed] {
        let d = line_drawing(&tree, [1.0, -1.0, 0.0], method).unwrap();
        check_drawing(&dense, &d).unwrap();
    }
}

#[test]
fn an_l_shape_shows_its_concave_edge() {
    // Two boxes forming an L: the concave crease between the lower slab's top and the tower's front.
    let dense = dense_of(3, &[([0, 0, 0], [4, 4, 2]), ([0, 2, 2], [4, 4, 4])]);
    let tree = KTree::<3>::from_dense(3, &dense).unwrap();
    let d = line_drawing(&tree, [0.6, -1.0, 0.9], HiddenLineMethod::Bucketed).unwrap();
    let concave = d
        .lines
        .iter()
        .any(|e| e.axis == 0 && e.fixed == [2, 2] && e.u0 <= 0.0 && e.u1 >= 4.0);
    assert!(concave, "{:?}", d.lines);
    // Seen from behind-below, the crease is hidden.
    let back = line_drawing(&tree, [-0.6, 1.0, -0.9], HiddenLineMethod::Bucketed).unwrap();
    assert!(!back.lines.iter().any(|e| e.axis == 0 && e.fixed == [2, 2]));
}

#[test]
fn a_zero_direction_is_an_error() {
    let tree = KTree::<3>::full(2).unwrap();
    assert!(line_drawing(&tree, [0.0, 0.0, 0.0], HiddenLineMethod::Bucketed).is_err());
    assert!(line_drawing(&tree, [f64::NAN, 0.0, 1.0], HiddenLineMethod::Bucketed).is_err());
    // An exact axis view works (ties are broken symbolically) and shows the square outline.
    let top = line_drawing(&tree, [0.0, 0.0, 1.0], HiddenLineMethod::Bucketed).unwrap();
    assert!(top.lines.len() >= 4);
}

/// The views along lattice directions, where lattice lines project onto one another: the diagonals,
/// the face diagonals and the axes, both ways.
fn lattice_views() -> Vec<[f64; 3]> {
    let mut views = Vec::new();
    for x in [-1.0, 0.0, 1.0] {
        for y in [-1.0, 0.0, 1.0] {
            for z in [-1.0, 0.0, 1.0] {
                if [x, y, z] != [0.0, 0.0, 0.0] {
                    views.push([x, y, z]);
                }
            }
        }
    }
    views
}

/// The axis-aligned lines expected of one box seen along `d_ε` (the tilted direction into the scene,
/// given by its signs): its twelve edges but the three at the far corner, each whole.
fn box_front_edges(
    lo: [u32; 3],
    hi: [u32; 3],
    into_scene_increasing: [bool; 3],
) -> Vec<(u8, [u32; 2], f64, f64)> {
    let far: [u32; 3] = std::array::from_fn(|k| {
        if into_scene_increasing[k] {
            hi[k]
        } else {
            lo[k]
        }
    });
    let mut out = Vec::new();
    for axis in 0..3usize {
        let [b, c] = match axis {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        for fb in [lo[b], hi[b]] {
            for fc in [lo[c], hi[c]] {
                if fb == far[b] && fc == far[c] {
                    continue; // meets the far corner
                }
                out.push((
                    axis as u8,
                    [fb, fc],
                    f64::from(lo[axis]),
                    f64::from(hi[axis]),
                ));
            }
        }
    }
    out.sort_by(|a, b| a.partial_cmp(b).unwrap());
    out
}

fn lines_of(d: &LineDrawing) -> Vec<(u8, [u32; 2], f64, f64)> {
    let mut out: Vec<_> = d
        .lines
        .iter()
        .map(|e| (e.axis, e.fixed, e.u0, e.u1))
        .collect();
    out.sort_by(|a, b| a.partial_cmp(b).unwrap());
    out
}

#[test]
fn a_box_seen_along_a_lattice_direction_is_its_nine_front_edges() {
    // A cube (whose far corner projects onto its near one along a diagonal) and a flat box, from every
    // diagonal, face diagonal and axis: exactly the nine edges not at the far corner of the tilted view,
    // whose zero components are tilted towards +.
    for (lo, hi) in [([2, 2, 2], [5, 5, 5]), ([1, 1, 3], [4, 6, 5])] {
        let dense = dense_of(3, &[(lo, hi)]);
        let tree = KTree::<3>::from_dense(3, &dense).unwrap();
        for toward in lattice_views() {
            let increasing = toward.map(|x| x <= 0.0);
            let want = box_front_edges(lo, hi, increasing);
            for method in [HiddenLineMethod::Pairwise, HiddenLineMethod::Bucketed] {
                let d = line_drawing(&tree, toward, method).unwrap();
                check_drawing(&dense, &d).unwrap();
                assert_eq!(
                    lines_of(&d),
                    want,
                    "box {lo:?}..{hi:?} seen from {toward:?}"
                );
            }
        }
    }
}

#[test]
fn a_lattice_view_is_drawn_along_the_requested_direction_exactly() {
    // Seen from +z the drawing's plane is the xy-plane itself: every drawn end projects to its own x and
    // y (up to the sign the screen frame gives), and the view direction is the requested one.
    let dense = dense_of(3, &[([1, 1, 3], [4, 6, 5])]);
    let tree = KTree::<3>::from_dense(3, &dense).unwrap();
    let top = line_drawing(&tree, [0.0, 0.0, 2.0], HiddenLineMethod::Bucketed).unwrap();
    assert_eq!(top.view_dir, [0.0, 0.0, -1.0]);
    for e in &top.lines {
        for u in [e.u0, e.u1] {
            let p = e.point(u);
            let q = top.project(p);
            assert_eq!([q[0].abs(), q[1].abs()], [p[0], p[1]], "{e:?}");
        }
    }
    let diagonal = line_drawing(&tree, [1.0, -1.0, 0.0], HiddenLineMethod::Bucketed).unwrap();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!((diagonal.view_dir[0] + h).abs() < 1e-15 && (diagonal.view_dir[1] - h).abs() < 1e-15);
    assert_eq!(diagonal.view_dir[0], -diagonal.view_dir[1]);
    assert_eq!(diagonal.view_dir[2], 0.0);
}

/// Scenes with walls in front of other edges, surrounded voxels behind them and seams along lattice
/// diagonals.
fn walled_scenes() -> Vec<Vec<bool>> {
    vec![
        // The wall and crossing column of the named diagonal case.
        dense_of(
            3,
            &[
                ([0, 2, 0], [6, 3, 7]),
                ([4, 0, 0], [5, 4, 3]),
                ([2, 3, 3], [3, 4, 7]),
            ],
        ),
        // A solid 3×3×3 block (its centre voxel surrounded) with rods behind it on three sides.
        dense_of(
            3,
            &[
                ([2, 2, 2], [5, 5, 5]),
                ([0, 0, 3], [8, 1, 4]),
                ([3, 0, 0], [4, 8, 1]),
                ([0, 3, 0], [1, 4, 8]),
                ([6, 6, 0], [7, 7, 8]),
            ],
        ),
        // A staircase of blocks touching along lattice diagonals, and a thick plate.
        dense_of(
            3,
            &[
                ([0, 0, 0], [2, 2, 2]),
                ([2, 2, 2], [4, 4, 4]),
                ([4, 4, 4], [6, 6, 6]),
                ([1, 5, 0], [7, 8, 3]),
                ([6, 0, 1], [8, 3, 8]),
            ],
        ),
    ]
}

fn check_views(views: &[[f64; 3]]) {
    for dense in walled_scenes() {
        let tree = KTree::<3>::from_dense(3, &dense).unwrap();
        for &toward in views {
            let fast = line_drawing(&tree, toward, HiddenLineMethod::Bucketed).unwrap();
            let slow = line_drawing(&tree, toward, HiddenLineMethod::Pairwise).unwrap();
            assert_eq!(fast.lines, slow.lines, "seen from {toward:?}");
            if let Err(e) = check_drawing(&dense, &fast) {
                panic!("seen from {toward:?}: {e}");
            }
        }
    }
}

#[test]
fn the_main_diagonal_views_keep_edges_behind_walls_hidden() {
    check_views(&[
        [1.0, 1.0, 1.0],
        [-1.0, -1.0, -1.0],
        [1.0, -1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [2.0, 2.0, 2.0],
    ]);
}

#[test]
fn the_face_diagonal_views_keep_edges_behind_walls_hidden() {
    check_views(&[
        [1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, -1.0],
    ]);
}

#[test]
fn the_axis_views_keep_edges_behind_walls_hidden() {
    check_views(&[
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ]);
}

#[test]
fn views_a_hair_off_a_diagonal_keep_edges_behind_walls_hidden() {
    // Directions within 10⁻⁴ of (1, −1, 0) and (1, 1, 1), one component scaled by 1 ± a small factor:
    // lattice lines project a hair apart, and the seams of the outlines must still hide what is behind.
    let mut views = Vec::new();
    for f in [1e-4 * 0.618_034, 1e-4 * 0.414_214, 1e-5, 1e-9, 1e-13] {
        for scale in [1.0 / (1.0 + f), 1.0 + f, 1.0 - f] {
            views.push([1.0, -scale, 0.0]);
            views.push([scale, -1.0, 0.0]);
            views.push([1.0, scale, 1.0]);
            views.push([1.0, 1.0, scale]);
        }
    }
    check_views(&views);
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]

    /// The pointer-free neighbour search agrees with the dense array: surrounded leaves, and the occupancy
    /// read along every edge of every full leaf from the three cells around it.
    #[test]
    fn neighbour_search_matches_the_dense_array(dense in objects()) {
        use ktree::display::neighbours::{edge_occupancy, is_surrounded, shifted};
        let tree = KTree::<3>::from_dense(LEVEL, &dense).unwrap();
        let side = SIDE as u64;
        for cell in tree.full_cells() {
            let s = cell.side() as i64;
            let o = cell.origin().map(i64::from);
            // Surrounded: every voxel just outside each face is full (and no face is on the boundary).
            let mut want = true;
            for axis in 0..3 {
                for upper in [false, true] {
                    let (b, c) = match axis { 0 => (1, 2), 1 => (0, 2), _ => (0, 1) };
                    for i in 0..s {
                        for j in 0..s {
                            let mut p = o;
                            p[axis] = if upper { o[axis] + s } else { o[axis] - 1 };
                            p[b] += i;
                            p[c] += j;
                            want &= full(&dense, p);
                        }
                    }
                }
            }
            prop_assert_eq!(is_surrounded(&tree, &cell), want, "cell {:?}", cell);
            // Edge occupancy of the diagonal neighbour along one edge per axis.
            for axis in 0..3usize {
                let (b, c) = match axis { 0 => (1, 2), 1 => (0, 2), _ => (0, 1) };
                let region = shifted(&cell, &[(b, true), (c, true)], side);
                let runs = edge_occupancy(&tree, region.as_ref(), s as u32, axis, (b, false), (c, false));
                let mut covered = 0u32;
                for &(start, end, is_full) in &runs {
                    prop_assert_eq!(start, covered);
                    covered = end;
                    for u in start..end {
                        let mut p = o;
                        p[axis] += i64::from(u);
                        p[b] += s;
                        p[c] += s;
                        prop_assert_eq!(full(&dense, p), is_full, "edge of {:?} along {} at {}", cell, axis, u);
                    }
                }
                prop_assert_eq!(covered, s as u32);
            }
        }
    }
}
