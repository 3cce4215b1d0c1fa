//! Analysis operations against dense references in K = 1 … 4: mass properties (volume, centroid, second
//! moments) from voxel sums, the progressive bounds, first contact in space-time, and the complexity
//! normalisations.

use ktree_verify::objects;

use ktree::ops;
use ktree::{KTree, Universe};
use objects::{object, pair, Obj};
use proptest::prelude::*;

fn close(x: f64, y: f64) -> bool {
    (x - y).abs() <= 1e-6 * (1.0 + x.abs().max(y.abs()))
}

fn check_mass<const K: usize>(a: &Obj<K>) -> Result<(), TestCaseError> {
    let tree = a.tree();
    let dense = a.dense();
    let u = a.universe();
    let pts: Vec<[f64; K]> = (0..dense.len())
        .filter(|&i| dense[i])
        .map(|i| u.dense_point(i).map(|c| f64::from(c) + 0.5))
        .collect();
    let m = ops::mass_properties(&tree).unwrap();
    prop_assert_eq!(m.volume, pts.len() as u128);
    if !pts.is_empty() {
        let n = pts.len() as f64;
        let c: [f64; K] = std::array::from_fn(|k| pts.iter().map(|p| p[k]).sum::<f64>() / n);
        for k in 0..K {
            prop_assert!(
                close(m.centroid[k], c[k]),
                "centroid {:?} vs {:?}",
                m.centroid,
                c
            );
            for l in 0..K {
                // A unit cube about its centre adds 1/12 on the diagonal.
                let own = if k == l { n / 12.0 } else { 0.0 };
                let expect = pts
                    .iter()
                    .map(|p| (p[k] - c[k]) * (p[l] - c[l]))
                    .sum::<f64>()
                    + own;
                prop_assert!(
                    close(m.central_moments[k][l], expect),
                    "moment {k}{l}: {} vs {expect}",
                    m.central_moments[k][l]
                );
            }
        }
    }
    // Progressive bounds hold at every level and tolerance 0 is exact.
    for tol in [0.0, 0.1, 0.5] {
        let p = ops::mass_progressive(&tree, tol).unwrap();
        prop_assert!(p.met);
        let mut last_touched = 0;
        for lb in &p.levels {
            prop_assert!(lb.lower <= m.volume && m.volume <= lb.upper);
            prop_assert!(lb.nodes_touched >= last_touched);
            last_touched = lb.nodes_touched;
            if m.volume > 0 {
                for k in 0..K {
                    let (lo, hi) = lb.centroid_bounds[k];
                    prop_assert!(lo <= m.centroid[k] + 1e-9 && m.centroid[k] <= hi + 1e-9);
                }
            }
        }
        let last = p.levels.last().unwrap();
        prop_assert!((last.upper - last.lower) as f64 <= tol * p.estimate + 1e-9);
        if tol == 0.0 {
            prop_assert_eq!(p.estimate, m.volume as f64);
            prop_assert_eq!(last.nodes_touched, tree.node_count());
        }
    }
    // The bounding box and normalisation to the origin.
    let bx = tree.bounding_box();
    if pts.is_empty() {
        prop_assert!(bx.is_none());
    } else {
        let (lo, hi) = bx.unwrap();
        for k in 0..K {
            let first = pts.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min) - 0.5;
            let last = pts.iter().map(|p| p[k]).fold(0.0, f64::max) - 0.5;
            prop_assert_eq!((f64::from(lo[k]), f64::from(hi[k])), (first, last + 1.0));
        }
        let norm = ops::normalise_to_origin(&tree).unwrap();
        prop_assert_eq!(norm.voxel_count(), tree.voxel_count());
        prop_assert!(norm.bounding_box().unwrap().0.iter().all(|&v| v == 0));
    }
    Ok(())
}

/// First contact along the last axis (time) against scanning slices of the dense arrays.
fn check_first_contact<const K: usize>(a: &Obj<K>, b: &Obj<K>) -> Result<(), TestCaseError> {
    let (da, db) = (a.dense(), b.dense());
    let u = a.universe();
    let expect = (0..da.len())
        .filter(|&i| da[i] && db[i])
        .map(|i| u.dense_point(i)[K - 1])
        .min();
    prop_assert_eq!(
        ops::first_contact(&a.tree(), &b.tree(), K - 1).unwrap(),
        expect
    );
    let expect0 = (0..da.len())
        .filter(|&i| da[i] && db[i])
        .map(|i| u.dense_point(i)[0])
        .min();
    prop_assert_eq!(
        ops::first_contact(&a.tree(), &b.tree(), 0).unwrap(),
        expect0
    );
    Ok(())
}

/// Minimum separation against all pairs of voxel centres.
fn check_separation<const K: usize>(a: &Obj<K>, b: &Obj<K>) -> Result<(), TestCaseError> {
    let (da, db) = (a.dense(), b.dense());
    let u = a.universe();
    let pa: Vec<[u32; K]> = (0..da.len())
        .filter(|&i| da[i])
        .map(|i| u.dense_point(i))
        .collect();
    let pb: Vec<[u32; K]> = (0..db.len())
        .filter(|&i| db[i])
        .map(|i| u.dense_point(i))
        .collect();
    let mut best: Option<i64> = None;
    for p in &pa {
        for q in &pb {
            let d: i64 = (0..K)
                .map(|k| (i64::from(p[k]) - i64::from(q[k])).pow(2))
                .sum();
            best = Some(best.map_or(d, |b| b.min(d)));
        }
    }
    let got = ops::min_separation(&a.tree(), &b.tree()).unwrap();
    prop_assert_eq!(got, best.map(|d| (d as f64).sqrt()));
    Ok(())
}

fn small_pair<const K: usize>() -> impl Strategy<Value = (Obj<K>, Obj<K>)> {
    pair::<K>().prop_filter("few voxels for the all-pairs reference", |(a, _)| {
        a.level <= 4
    })
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test] fn separation_k1((a, b) in small_pair::<1>()) { check_separation(&a, &b)?; }
    #[test] fn separation_k2((a, b) in small_pair::<2>()) { check_separation(&a, &b)?; }
    #[test] fn separation_k3((a, b) in small_pair::<3>()) { check_separation(&a, &b)?; }
    #[test] fn separation_k4((a, b) in small_pair::<4>()) { check_separation(&a, &b)?; }
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test] fn mass_k1(a in object::<1>()) { check_mass(&a)?; }
    #[test] fn mass_k2(a in object::<2>()) { check_mass(&a)?; }
    #[test] fn mass_k3(a in object::<3>()) { check_mass(&a)?; }
    #[test] fn mass_k4(a in object::<4>()) { check_mass(&a)?; }
    #[test] fn first_contact_k1((a, b) in pair::<1>()) { check_first_contact(&a, &b)?; }
    #[test] fn first_contact_k2((a, b) in pair::<2>()) { check_first_contact(&a, &b)?; }
    #[test] fn first_contact_k3((a, b) in pair::<3>()) { check_first_contact(&a, &b)?; }
    #[test] fn first_contact_k4((a, b) in pair::<4>()) { check_first_contact(&a, &b)?; }
}

#[test]
fn complexity_over_translations_counts_each_placement() {
    // A 3×3 square in a 16×16 quadtree: 4 placements per axis (bits = 2).
    let u = Universe::<2>::new(4).unwrap();
    let dense: Vec<bool> = (0..256)
        .map(|i| {
            let p = u.dense_point(i);
            (5..8).contains(&p[0]) && (9..12).contains(&p[1])
        })
        .collect();
    let tree = KTree::<2>::from_dense(4, &dense).unwrap();
    let n = ops::over_translations(&tree, 2).unwrap();
    assert_eq!(n.counts.len(), 16);
    assert_eq!(n.clipped, 0);
    // Each count is the node count of the square at that offset, built independently.
    for (i, &count) in n.counts.iter().enumerate() {
        let (tx, ty) = ((i & 3) as u32, (i >> 2) as u32);
        let d: Vec<bool> = (0..256)
            .map(|j| {
                let p = u.dense_point(j);
                (tx..tx + 3).contains(&p[0]) && (ty..ty + 3).contains(&p[1])
            })
            .collect();
        assert_eq!(count, KTree::<2>::from_dense(4, &d).unwrap().node_count());
    }
    assert!(n.min as f64 <= n.mean && n.mean <= n.max as f64);
    assert!(n.min < n.max, "placement changes the count of a 3×3 square");
    assert!(ops::over_translations(&tree, 9).is_err());
}

#[test]
fn placements_rebuild_the_object_at_each_offset() {
    // A ball at the 2^3 half-voxel placements of its centre.
    let n = ops::over_placements::<3, ops::OpsError>(2, |o| {
        let c = [
            20 + i64::from(o[0]),
            20 + i64::from(o[1]),
            20 + i64::from(o[2]),
        ];
        Ok(ktree::stacking::paper::stack(
            &ktree::rays::ball_rays::<3>(5, c, 13).expect("valid level"),
        ))
    })
    .unwrap();
    assert_eq!(n.counts.len(), 8);
    let direct =
        ktree::stacking::paper::stack(&ktree::rays::ball_rays::<3>(5, [21, 20, 21], 13).unwrap());
    assert_eq!(n.counts[0b101], direct.node_count());
    assert!(n.min <= n.max);
}

#[test]
fn four_d_space_time_collision_matches_stepping_through_time() {
    // Two balls moving towards each other in a 16³ universe over 16 time steps, as 4-D trees (x, y, z, t).
    let level = 4;
    let u4 = Universe::<4>::new(level).unwrap();
    let centre = |start: f64, v: f64, t: u32| start + v * f64::from(t);
    let inside = |p: [u32; 4], sx: f64, v: f64| {
        let c = centre(sx, v, p[3]);
        let d = |x: u32, c: f64| (f64::from(x) + 0.5 - c).powi(2);
        d(p[0], c) + d(p[1], 8.0) + d(p[2], 8.0) <= 2.5f64.powi(2)
    };
    let dense_a: Vec<bool> = (0..u4.voxels() as usize)
        .map(|i| inside(u4.dense_point(i), 2.0, 0.5))
        .collect();
    let dense_b: Vec<bool> = (0..u4.voxels() as usize)
        .map(|i| inside(u4.dense_point(i), 14.0, -0.5))
        .collect();
    let a = KTree::<4>::from_dense(level, &dense_a).unwrap();
    let b = KTree::<4>::from_dense(level, &dense_b).unwrap();
    let first = ops::first_contact(&a, &b, 3).unwrap();
    // Stepping through time with 3-D trees.
    let u3 = Universe::<3>::new(level).unwrap();
    let mut stepped = None;
    for t in 0..16u32 {
        let slice = |d: &[bool]| {
            let s: Vec<bool> = (0..u3.voxels() as usize)
                .map(|i| {
                    let p = u3.dense_point(i);
                    d[u4.dense_index([p[0], p[1], p[2], t])]
                })
                .collect();
            KTree::<3>::from_dense(level, &s).unwrap()
        };
        if ops::interferes(&slice(&dense_a), &slice(&dense_b)).unwrap() {
            stepped = Some(t);
            break;
        }
    }
    assert!(first.is_some());
    assert_eq!(first, stepped);
    assert!(ops::interferes(&a, &b).unwrap());
}
