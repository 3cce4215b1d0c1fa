//! Signed distances against a brute-force dense reference in K = 1 … 4: for every voxel the least squared
//! distance over all full (or all empty) voxels of the universe. Windows over the whole universe and inside
//! it, point queries, narrow bands of several widths, and trees at the largest level of each K (small
//! objects in a huge universe, windows only).

use ktree::shape::Element;
use ktree::{KTree, Ray, RaySet, Universe};
use ktree_verify::objects::{obj_at, Obj};
use proptest::prelude::*;

/// Levels small enough for the brute force over all pairs of voxels.
const fn top_level(k: usize) -> u32 {
    match k {
        1 => 6,
        2 => 5,
        3 => 4,
        _ => 3,
    }
}

fn obj<const K: usize>() -> impl Strategy<Value = Obj<K>> {
    (0..=top_level(K)).prop_flat_map(obj_at::<K>)
}

fn squared<const K: usize>(p: [u32; K], q: [u32; K]) -> u64 {
    (0..K).map(|a| u64::from(p[a].abs_diff(q[a])).pow(2)).sum()
}

/// The signed squared distance of every voxel, in the universe's dense order: `(full, d²)`, `d²` the least
/// over all voxels of the other kind, `None` when there is none.
fn reference<const K: usize>(u: Universe<K>, dense: &[bool]) -> Vec<(bool, Option<u64>)> {
    let points: Vec<[u32; K]> = (0..dense.len()).map(|i| u.dense_point(i)).collect();
    (0..dense.len())
        .map(|i| {
            let d = (0..dense.len())
                .filter(|&j| dense[j] != dense[i])
                .map(|j| squared(points[i], points[j]))
                .min();
            (dense[i], d)
        })
        .collect()
}

fn signed(full: bool, d: Option<u64>) -> f64 {
    let v = d.map_or(f64::INFINITY, |d| (d as f64).sqrt());
    if full {
        -v
    } else {
        v
    }
}

/// The row-major (last axis fastest) index of `p` in the window `[lo, lo + shape)`.
fn window_index<const K: usize>(p: [u32; K], lo: [u32; K], shape: [usize; K]) -> Option<usize> {
    let mut i = 0;
    for a in 0..K {
        let x = p[a].checked_sub(lo[a])? as usize;
        if x >= shape[a] {
            return None;
        }
        i = i * shape[a] + x;
    }
    Some(i)
}

fn check_distances<const K: usize>(
    o: &Obj<K>,
    window: ([u32; K], [u32; K]),
    width: f64,
) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let u = o.universe();
    let dense = o.dense();
    let want = reference(u, &dense);
    let side = u.side() as u32;
    // The whole universe as one window.
    let all = tree
        .signed_distance_window([0; K], [side as usize; K])
        .unwrap();
    prop_assert_eq!(all.len(), dense.len());
    for (i, &(full, d)) in want.iter().enumerate() {
        let p = u.dense_point(i);
        let j = window_index(p, [0; K], [side as usize; K]).unwrap();
        prop_assert_eq!(all[j], signed(full, d) as f32, "at {:?}", p);
    }
    // A window inside: the corners drawn, clipped to the universe.
    let lo: [u32; K] = std::array::from_fn(|a| window.0[a] % side);
    let shape: [usize; K] = std::array::from_fn(|a| (window.1[a] % (side - lo[a] + 1)) as usize);
    let part = tree.signed_distance_window(lo, shape).unwrap();
    prop_assert_eq!(part.len(), shape.iter().product::<usize>());
    for (i, &(full, d)) in want.iter().enumerate() {
        let p = u.dense_point(i);
        if let Some(j) = window_index(p, lo, shape) {
            prop_assert_eq!(part[j], signed(full, d) as f32, "window at {:?}", p);
        }
    }
    // Points, in dense order.
    let points: Vec<[u32; K]> = (0..dense.len()).map(|i| u.dense_point(i)).collect();
    let at = tree.signed_distance_at(&points).unwrap();
    for (i, &(full, d)) in want.iter().enumerate() {
        prop_assert_eq!(at[i], signed(full, d), "point {:?}", points[i]);
    }
    // The narrow band: exactly the voxels with |sd| ≤ width, each once, with its value.
    let band = tree.narrow_band(width).unwrap();
    let mut got: Vec<([u32; K], f64)> = band.iter().collect();
    got.sort_by_key(|x| x.0);
    let mut expected: Vec<([u32; K], f64)> = want
        .iter()
        .enumerate()
        .filter(|(_, &(_, d))| d.is_some_and(|d| d as f64 <= width * width))
        .map(|(i, &(full, d))| (u.dense_point(i), signed(full, d)))
        .collect();
    expected.sort_by_key(|x| x.0);
    prop_assert_eq!(got, expected, "band {}", width);
    Ok(())
}

fn width() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![0.0, 1.0, 1.5, 2.0f64.sqrt(), 2.5, 3.0, 5.0, 100.0])
}

fn corners<const K: usize>() -> impl Strategy<Value = ([u32; K], [u32; K])> {
    (
        prop::array::uniform::<_, K>(0..64u32),
        prop::array::uniform::<_, K>(0..64u32),
    )
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn distances_match_dense_k1(o in obj::<1>(), w in corners::<1>(), b in width()) { check_distances(&o, w, b)?; }
    #[test]
    fn distances_match_dense_k2(o in obj::<2>(), w in corners::<2>(), b in width()) { check_distances(&o, w, b)?; }
    #[test]
    fn distances_match_dense_k3(o in obj::<3>(), w in corners::<3>(), b in width()) { check_distances(&o, w, b)?; }
    #[test]
    fn distances_match_dense_k4(o in obj::<4>(), w in corners::<4>(), b in width()) { check_distances(&o, w, b)?; }
}

/// Large balls by the distance transform against the dense definition (every offset of the ball).
fn check_large_radii<const K: usize>(o: &Obj<K>, r: f64) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let grown = tree.dilate_ball_by_distance(r).unwrap();
    grown.assert_well_formed();
    prop_assert_eq!(&grown, &tree.dilate(r, Element::Ball).unwrap());
    prop_assert_eq!(&grown, &dense_dilate(&tree, r), "dilate");
    let shrunk = tree.erode_ball_by_distance(r).unwrap();
    shrunk.assert_well_formed();
    prop_assert_eq!(&shrunk, &dense_erode(&tree, r), "erode");
    Ok(())
}

/// The dilation by the definition: a voxel is in when some full voxel lies at an offset of the ball.
fn dense_dilate<const K: usize>(tree: &KTree<K>, r: f64) -> KTree<K> {
    let dense = tree.to_dense().unwrap();
    let u = tree.universe();
    let e = r.floor() as i64;
    let side = u.side() as i64;
    let out: Vec<bool> = (0..dense.len())
        .map(|i| {
            let p = u.dense_point(i);
            offsets::<K>(e)
                .iter()
                .filter(|d| Element::Ball.contains(**d, r))
                .any(|d| {
                    let q: [i64; K] = std::array::from_fn(|a| i64::from(p[a]) - d[a]);
                    q.iter().all(|&x| (0..side).contains(&x))
                        && dense[u.dense_index(q.map(|x| x as u32))]
                })
        })
        .collect();
    KTree::from_dense(u.level(), &out).unwrap()
}

fn dense_erode<const K: usize>(tree: &KTree<K>, r: f64) -> KTree<K> {
    let dense = tree.to_dense().unwrap();
    let u = tree.universe();
    let e = r.floor() as i64;
    let side = u.side() as i64;
    let out: Vec<bool> = (0..dense.len())
        .map(|i| {
            let p = u.dense_point(i);
            offsets::<K>(e)
                .iter()
                .filter(|d| Element::Ball.contains(**d, r))
                .all(|d| {
                    let q: [i64; K] = std::array::from_fn(|a| i64::from(p[a]) + d[a]);
                    q.iter().all(|&x| (0..side).contains(&x))
                        && dense[u.dense_index(q.map(|x| x as u32))]
                })
        })
        .collect();
    KTree::from_dense(u.level(), &out).unwrap()
}

fn offsets<const K: usize>(e: i64) -> Vec<[i64; K]> {
    let w = 2 * e + 1;
    (0..w.pow(K as u32))
        .map(|mut i| {
            std::array::from_fn(|_| {
                let c = i % w - e;
                i /= w;
                c
            })
        })
        .collect()
}

proptest! {
    #![proptest_config(ktree_verify::config(16))]
    #[test]
    fn large_balls_k2(o in obj_at::<2>(5), r in prop::sample::select(vec![4.0, 4.5, 6.0, 7.9])) { check_large_radii(&o, r)?; }
    #[test]
    fn large_balls_k3(o in obj_at::<3>(4), r in prop::sample::select(vec![4.0, 4.5, 5.0])) { check_large_radii(&o, r)?; }
}

fn voxel_tree<const K: usize>(level: u32, voxels: &[[u32; K]]) -> KTree<K> {
    let rays = voxels.iter().map(|&p| Ray::new(p, p[K - 1] + 1));
    KTree::from_rays(&RaySet::from_rays(level, rays).unwrap())
}

/// Voxels at the far corner, in the middle and a 3-wide block near the middle of the largest universe of
/// each K: windows, points and the band agree with a brute force over the object's voxels and the empty
/// voxels around them, and the ball dilation by distance covers the expected count.
fn check_largest_level<const K: usize>() {
    let level = ktree::max_level(K);
    let u = Universe::<K>::new(level).unwrap();
    let far = [(u.side() - 1) as u32; K];
    let mid = (u.side() / 2) as u32;
    let mut voxels = vec![far];
    let mut at = [0u32; K];
    loop {
        voxels.push(at.map(|x| mid + x));
        let mut a = 0;
        while a < K {
            at[a] += 1;
            if at[a] < 3 {
                break;
            }
            at[a] = 0;
            a += 1;
        }
        if a == K {
            break;
        }
    }
    let tree = voxel_tree::<K>(level, &voxels);
    let truth = |p: [u32; K]| -> f64 {
        if voxels.contains(&p) {
            // The nearest empty voxel: one step out of the block or the corner.
            let d = (0..K)
                .flat_map(|a| [(a, -1i64), (a, 1)])
                .filter_map(|(a, s)| {
                    let mut q = p.map(i64::from);
                    let mut steps = 0;
                    loop {
                        q[a] += s;
                        steps += 1;
                        if q[a] < 0 || q[a] >= u.side() as i64 {
                            return None;
                        }
                        if !voxels.contains(&q.map(|x| x as u32)) {
                            return Some(steps * steps);
                        }
                    }
                })
                .min()
                .unwrap();
            -(d as f64).sqrt()
        } else {
            let d = voxels.iter().map(|&v| squared(p, v)).min().unwrap();
            (d as f64).sqrt()
        }
    };
    for (lo, shape) in [
        ([mid - 3; K], [9usize; K]),
        ([(u.side() - 4) as u32; K], [4; K]),
        ([mid - 40; K], [4; K]),
    ] {
        let field = tree.signed_distance_window(lo, shape).unwrap();
        let n: usize = shape.iter().product();
        assert_eq!(field.len(), n);
        let mut points = Vec::new();
        for (i, &value) in field.iter().enumerate() {
            let mut p = [0u32; K];
            let mut j = i;
            for a in (0..K).rev() {
                p[a] = lo[a] + (j % shape[a]) as u32;
                j /= shape[a];
            }
            assert_eq!(value, truth(p) as f32, "K = {K} at {p:?}");
            points.push(p);
        }
        let at = tree.signed_distance_at(&points).unwrap();
        for (p, v) in points.iter().zip(at) {
            assert_eq!(v, truth(*p), "K = {K} point {p:?}");
        }
    }
    let band = tree.narrow_band(2.0).unwrap();
    assert!(!band.is_empty());
    for (p, v) in band.iter() {
        assert_eq!(v, truth(p), "K = {K} band at {p:?}");
    }
    // Every voxel of the block has a neighbour outside or is its centre; the corner has K outside.
    let within_one = band.iter().filter(|(_, v)| v.abs() <= 1.0).count();
    assert!(within_one > voxels.len());
    let grown = tree.dilate_ball_by_distance(4.5).unwrap();
    grown.assert_well_formed();
    let mut reach = [mid + 2; K];
    reach[0] = mid + 6; // 4 from the block
    assert!(grown.contains(far) && grown.contains(reach));
    reach[0] = mid + 7; // 5 from it
    assert!(!grown.contains(reach));
    assert!(!grown.erode_ball_by_distance(4.5).unwrap().contains(far));
}

#[test]
fn largest_levels_do_not_overflow() {
    check_largest_level::<1>();
    check_largest_level::<2>();
    check_largest_level::<3>();
    check_largest_level::<4>();
}

#[test]
fn bad_input_is_an_error() {
    let tree = KTree::<2>::full(3).unwrap();
    assert!(tree.narrow_band(-1.0).is_err());
    assert!(tree.narrow_band(f64::NAN).is_err());
    assert!(tree.signed_distance_at(&[[8, 0]]).is_err());
    assert!(tree.signed_distance_window([4, 4], [5, 1]).is_err());
    assert!(tree.dilate_ball_by_distance(-1.0).is_err());
    // A full universe: no empty voxel anywhere.
    assert_eq!(
        tree.signed_distance_at(&[[0, 0]]).unwrap(),
        [f64::NEG_INFINITY]
    );
    let empty = KTree::<2>::empty(3).unwrap();
    assert_eq!(
        empty.signed_distance_window([0, 0], [2, 1]).unwrap(),
        [f32::INFINITY; 2]
    );
    assert!(empty.narrow_band(3.0).unwrap().is_empty());
}
