//! Geometric operations against brute-force references in K = 1 … 4: translation (integer and at a finer
//! level), rotations and reflections by reordering (and the group's laws), arbitrary affine maps (every
//! target voxel centre mapped back), rational scaling, and scaling by powers of two through the root.

use ktree_verify::objects;

use ktree::ops::{self, Affine, AxisMap};
use ktree::{KTree, Universe};
use objects::{object, Obj};
use proptest::prelude::*;

/// Brute force: target voxel q is full iff `source(q)` is a full voxel inside the universe.
fn resample_dense<const K: usize>(
    level: u32,
    dense: &[bool],
    source: impl Fn([u32; K]) -> [i64; K],
) -> Vec<bool> {
    let u = Universe::<K>::new(level).unwrap();
    let side = u.side() as i64;
    (0..dense.len())
        .map(|i| {
            let s = source(u.dense_point(i));
            s.iter().all(|&c| (0..side).contains(&c)) && dense[u.dense_index(s.map(|c| c as u32))]
        })
        .collect()
}

fn same<const K: usize>(out: &KTree<K>, level: u32, expect: &[bool]) -> Result<(), TestCaseError> {
    out.check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(out.to_dense().unwrap(), expect.to_vec());
    prop_assert_eq!(out, &KTree::from_dense(level, expect).unwrap());
    Ok(())
}

fn check_translate<const K: usize>(a: &Obj<K>, t: [i64; K]) -> Result<(), TestCaseError> {
    let (tree, dense) = (a.tree(), a.dense());
    let out = ops::translate(&tree, t).unwrap();
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| {
        std::array::from_fn(|i| i64::from(q[i]) - t[i])
    });
    same(&out, a.level, &expect)?;
    // translate(−t) ∘ translate(t) = the part that stayed inside.
    let back = ops::translate(&out, t.map(|v| -v)).unwrap();
    let side = 1i64 << a.level;
    let u = a.universe();
    let kept: Vec<bool> = (0..dense.len())
        .map(|i| {
            let p = u.dense_point(i);
            dense[i] && (0..K).all(|k| (0..side).contains(&(i64::from(p[k]) + t[k])))
        })
        .collect();
    same(&back, a.level, &kept)?;
    // A finer-level vector is the whole-voxel shift of `fine_shift`, which is the voxel-centre rule.
    let sub = 2;
    let fine: [i64; K] = t.map(|v| v * 4 + (v.rem_euclid(4)));
    let by_fine = ops::translate_fine(&tree, fine, sub).unwrap();
    let by_affine =
        ops::transform(&tree, &Affine::translation(fine.map(|v| v as f64 / 4.0))).unwrap();
    prop_assert_eq!(by_fine, by_affine);
    Ok(())
}

fn check_axis_maps<const K: usize>(a: &Obj<K>, pick: usize) -> Result<(), TestCaseError> {
    let (tree, dense) = (a.tree(), a.dense());
    let group = AxisMap::<K>::all();
    let g = group[pick % group.len()];
    let out = ops::rotate_axes(&tree, &g).unwrap();
    let side = 1u32 << a.level;
    let inv = g.inverse();
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| {
        inv.map_point(q, side).map(i64::from)
    });
    same(&out, a.level, &expect)?;
    prop_assert_eq!(out.counts_per_level(), tree.counts_per_level());
    // Composition acts like applying in turn; the inverse undoes.
    let h = group[(pick * 7 + 3) % group.len()];
    prop_assert_eq!(
        ops::rotate_axes(&out, &h).unwrap(),
        ops::rotate_axes(&tree, &h.compose(&g)).unwrap()
    );
    prop_assert_eq!(ops::rotate_axes(&out, &inv).unwrap(), tree.clone());
    // Four quarter turns are the identity.
    if K >= 2 {
        let q = AxisMap::<K>::quarter_turn(0, K - 1).unwrap();
        let mut r = tree.clone();
        for _ in 0..4 {
            r = ops::rotate_axes(&r, &q).unwrap();
        }
        prop_assert_eq!(r, tree.clone());
        // A quarter turn by reordering equals the affine rotation by 90° about the centre.
        let m =
            Affine::rotation_about(0, K - 1, 90.0, Affine::<K>::universe_centre(a.level)).unwrap();
        prop_assert_eq!(
            ops::rotate_axes(&tree, &q).unwrap(),
            ops::transform(&tree, &m).unwrap()
        );
    }
    Ok(())
}

fn check_affine<const K: usize>(a: &Obj<K>, entries: Vec<f64>) -> Result<(), TestCaseError> {
    let (tree, dense) = (a.tree(), a.dense());
    let side = (1u64 << a.level) as f64;
    let mut m = Affine::<K>::identity();
    for i in 0..K {
        for j in 0..K {
            m.a[i][j] = entries[i * K + j] + if i == j { 1.0 } else { 0.0 };
        }
        m.b[i] = entries[K * K + i] * side;
    }
    let inv = m.inverse();
    prop_assume!(inv.is_ok(), "singular matrix");
    let inv = inv.unwrap();
    let out = ops::transform(&tree, &m).unwrap();
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| inv.source_voxel(q));
    same(&out, a.level, &expect)
}

fn check_fixed<const K: usize>(a: &Obj<K>, entries: Vec<f64>) -> Result<(), TestCaseError> {
    let (tree, dense) = (a.tree(), a.dense());
    let side = (1u64 << a.level) as f64;
    let mut m = Affine::<K>::identity();
    for i in 0..K {
        for j in 0..K {
            m.a[i][j] = entries[i * K + j] + if i == j { 1.0 } else { 0.0 };
        }
        m.b[i] = entries[K * K + i] * side;
    }
    let map = ops::FixedAffine::new(&m, 32);
    prop_assume!(map.is_ok(), "singular matrix");
    let map = map.unwrap();
    let out = ops::transform_fixed(&tree, &m, 32).unwrap();
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| map.source_voxel(q));
    same(&out, a.level, &expect)?;
    // Coarse fixed point (8 bits) is still exact with respect to its own rounded matrix.
    let coarse = ops::FixedAffine::new(&m, 8).unwrap();
    let out8 = ops::transform_fixed(&tree, &m, 8).unwrap();
    let expect8 = resample_dense::<K>(a.level, &dense, |q: [u32; K]| coarse.source_voxel(q));
    same(&out8, a.level, &expect8)
}

fn check_rotation<const K: usize>(
    a: &Obj<K>,
    degrees: f64,
    shift: f64,
) -> Result<(), TestCaseError> {
    prop_assume!(K >= 2, "rotations need two axes");
    let (tree, dense) = (a.tree(), a.dense());
    let centre = Affine::<K>::universe_centre(a.level);
    let r = Affine::rotation_about(0, 1, degrees, centre).unwrap();
    let r2 = Affine::rotation_about(K - 1, 0, degrees / 2.0, centre).unwrap();
    let m = Affine::translation([shift; K]).after(&r2.after(&r));
    let out = ops::transform(&tree, &m).unwrap();
    let inv = m.inverse().unwrap();
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| inv.source_voxel(q));
    same(&out, a.level, &expect)
}

fn check_projective<const K: usize>(a: &Obj<K>, e: Vec<f64>) -> Result<(), TestCaseError> {
    let (tree, dense) = (a.tree(), a.dense());
    let u = (1u64 << a.level) as f64;
    let n = K + 1;
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let id = if i == j { 1.0 } else { 0.0 };
            m[i * n + j] = id
                + if i == K && j < K {
                    e[i * n + j] * 0.2 / u // mild projective row
                } else if j == K && i < K {
                    e[i * n + j] * u / 4.0
                } else if i < K && j < K {
                    e[i * n + j] * 0.5
                } else {
                    0.0
                };
        }
    }
    let p = ops::Projective::<K>::from_homogeneous(&m).unwrap();
    let out = ops::transform_projective(&tree, &p);
    // Singular, or sends part of the universe to infinity: rejected with an error, and not counted.
    prop_assume!(out.is_ok(), "projective map rejected");
    let out = out.unwrap();
    let inv = p.inverse().unwrap();
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| {
        inv.source_voxel(q).unwrap_or([-1; K])
    });
    same(&out, a.level, &expect)?;
    // An affine matrix through the projective path agrees with the affine path.
    let r = Affine::rotation_about(0, K - 1, 37.0, Affine::<K>::universe_centre(a.level)).unwrap();
    prop_assert_eq!(
        ops::transform_projective(&tree, &ops::Projective::from_affine(&r)).unwrap(),
        ops::transform(&tree, &r).unwrap()
    );
    Ok(())
}

fn check_scale<const K: usize>(a: &Obj<K>, num: u32, den: u32) -> Result<(), TestCaseError> {
    let (tree, dense) = (a.tree(), a.dense());
    let out = ops::scale(&tree, num, den).unwrap();
    let back = |q: u32| ((2 * i64::from(q) + 1) * i64::from(den)).div_euclid(2 * i64::from(num));
    let expect = resample_dense::<K>(a.level, &dense, |q: [u32; K]| q.map(back));
    same(&out, a.level, &expect)
}

fn check_grow_zoom<const K: usize>(a: &Obj<K>, path: Vec<usize>) -> Result<(), TestCaseError> {
    let tree = a.tree();
    let path: Vec<usize> = path.into_iter().map(|c| c % (1 << K)).collect();
    let g = ops::grow(&tree, &path).unwrap();
    g.check().map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(g.voxel_count(), tree.voxel_count());
    prop_assert_eq!(ops::zoom(&g, &path).unwrap(), tree.clone());
    // Every voxel lands at the cell the path names.
    let mut offset = [0u32; K];
    for (d, &c) in path.iter().enumerate() {
        for (i, o) in offset.iter_mut().enumerate() {
            if c >> i & 1 == 1 {
                *o += 1 << (a.level as usize + path.len() - 1 - d);
            }
        }
    }
    let u = a.universe();
    for (i, &full) in a.dense().iter().enumerate() {
        let p = u.dense_point(i);
        let q: [u32; K] = std::array::from_fn(|k| p[k] + offset[k]);
        prop_assert_eq!(g.contains(q), full);
    }
    Ok(())
}

fn shift<const K: usize>() -> impl Strategy<Value = [i64; K]> {
    prop::array::uniform::<_, K>(-40i64..40)
}

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    #[test] fn translate_k1(a in object::<1>(), t in shift::<1>()) { check_translate(&a, t)?; }
    #[test] fn translate_k2(a in object::<2>(), t in shift::<2>()) { check_translate(&a, t)?; }
    #[test] fn translate_k3(a in object::<3>(), t in shift::<3>()) { check_translate(&a, t)?; }
    #[test] fn translate_k4(a in object::<4>(), t in prop::array::uniform::<_, 4>(-9i64..9)) { check_translate(&a, t)?; }

    #[test] fn axis_maps_k1(a in object::<1>(), g in 0usize..1000) { check_axis_maps(&a, g)?; }
    #[test] fn axis_maps_k2(a in object::<2>(), g in 0usize..1000) { check_axis_maps(&a, g)?; }
    #[test] fn axis_maps_k3(a in object::<3>(), g in 0usize..1000) { check_axis_maps(&a, g)?; }
    #[test] fn axis_maps_k4(a in object::<4>(), g in 0usize..1000) { check_axis_maps(&a, g)?; }

    #[test] fn affine_k1(a in object::<1>(), e in prop::collection::vec(-0.9f64..0.9, 2)) { check_affine(&a, e)?; }
    #[test] fn affine_k2(a in object::<2>(), e in prop::collection::vec(-0.9f64..0.9, 6)) { check_affine(&a, e)?; }
    #[test] fn affine_k3(a in object::<3>(), e in prop::collection::vec(-0.9f64..0.9, 12)) { check_affine(&a, e)?; }
    #[test] fn affine_k4(a in object::<4>(), e in prop::collection::vec(-0.9f64..0.9, 20)) { check_affine(&a, e)?; }

    #[test] fn fixed_k1(a in object::<1>(), e in prop::collection::vec(-0.9f64..0.9, 2)) { check_fixed(&a, e)?; }
    #[test] fn fixed_k2(a in object::<2>(), e in prop::collection::vec(-0.9f64..0.9, 6)) { check_fixed(&a, e)?; }
    #[test] fn fixed_k3(a in object::<3>(), e in prop::collection::vec(-0.9f64..0.9, 12)) { check_fixed(&a, e)?; }
    #[test] fn fixed_k4(a in object::<4>(), e in prop::collection::vec(-0.9f64..0.9, 20)) { check_fixed(&a, e)?; }

    #[test] fn rotation_k2(a in object::<2>(), d in -180f64..180.0, s in -3f64..3.0) { check_rotation(&a, d, s)?; }
    #[test] fn rotation_k3(a in object::<3>(), d in -180f64..180.0, s in -3f64..3.0) { check_rotation(&a, d, s)?; }
    #[test] fn rotation_k4(a in object::<4>(), d in -180f64..180.0, s in -3f64..3.0) { check_rotation(&a, d, s)?; }

    #[test] fn projective_k2(a in object::<2>(), e in prop::collection::vec(-1f64..1.0, 9)) { check_projective(&a, e)?; }
    #[test] fn projective_k3(a in object::<3>(), e in prop::collection::vec(-1f64..1.0, 16)) { check_projective(&a, e)?; }
    #[test] fn projective_k4(a in object::<4>(), e in prop::collection::vec(-1f64..1.0, 25)) { check_projective(&a, e)?; }

    #[test] fn scale_k1(a in object::<1>(), n in 1u32..6, d in 1u32..6) { check_scale(&a, n, d)?; }
    #[test] fn scale_k2(a in object::<2>(), n in 1u32..6, d in 1u32..6) { check_scale(&a, n, d)?; }
    #[test] fn scale_k3(a in object::<3>(), n in 1u32..6, d in 1u32..6) { check_scale(&a, n, d)?; }
    #[test] fn scale_k4(a in object::<4>(), n in 1u32..6, d in 1u32..6) { check_scale(&a, n, d)?; }

    #[test] fn grow_zoom_k1(a in object::<1>(), p in prop::collection::vec(0usize..16, 0..3)) { check_grow_zoom(&a, p)?; }
    #[test] fn grow_zoom_k2(a in object::<2>(), p in prop::collection::vec(0usize..16, 0..3)) { check_grow_zoom(&a, p)?; }
    #[test] fn grow_zoom_k3(a in object::<3>(), p in prop::collection::vec(0usize..16, 0..3)) { check_grow_zoom(&a, p)?; }
    #[test] fn grow_zoom_k4(a in object::<4>(), p in prop::collection::vec(0usize..16, 0..3)) { check_grow_zoom(&a, p)?; }
}

fn group_laws<const K: usize>() {
    let all = AxisMap::<K>::all();
    let fact: usize = (1..=K).product();
    assert_eq!(all.len(), fact << K);
    let set: std::collections::HashSet<_> = all.iter().copied().collect();
    assert_eq!(set.len(), all.len(), "elements distinct");
    for g in &all {
        assert_eq!(g.compose(&g.inverse()), AxisMap::identity());
        for h in all.iter().step_by(3) {
            assert!(set.contains(&g.compose(h)), "closed under composition");
        }
    }
    let rotations = all.iter().filter(|g| g.is_rotation()).count();
    assert_eq!(rotations, all.len() / 2);
}

#[test]
fn hyperoctahedral_group_has_k_factorial_two_to_the_k_elements_and_is_closed() {
    group_laws::<1>();
    group_laws::<2>();
    group_laws::<3>();
    group_laws::<4>();
}

#[test]
fn perspective_shrinks_far_things_more_than_near_ones() {
    // Two equal boxes side by side in x, one near (small z) and one far (large z).
    let l = 6;
    let u = Universe::<3>::new(l).unwrap();
    let dense: Vec<bool> = (0..1usize << 18)
        .map(|i| {
            let p = u.dense_point(i);
            let across = (24..40).contains(&p[0]) && (24..40).contains(&p[1]);
            across && ((2..10).contains(&p[2]) || (50..58).contains(&p[2]))
        })
        .collect();
    let t = KTree::<3>::from_dense(l, &dense).unwrap();
    let p = ops::Projective::<3>::perspective(l, 2, 32.0).unwrap();
    let out = ops::transform_projective(&t, &p).unwrap();
    out.assert_well_formed();
    let width = |zs: std::ops::Range<u32>| {
        let xs: Vec<u32> = (0..1usize << 18)
            .filter(|&i| out.contains(u.dense_point(i)) && zs.contains(&u.dense_point(i)[2]))
            .map(|i| u.dense_point(i)[0])
            .collect();
        xs.iter().max().unwrap() - xs.iter().min().unwrap() + 1
    };
    let (near, far) = (width(0..32), width(32..64));
    assert!(far < near, "near {near}, far {far}");
    // Meagher's Y' = Y·d/(z + d): the far box (z ≈ 54) is shrunk to about 32/86 of 16.
    assert!((4..=8).contains(&far), "far width {far}");
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let t = KTree::<3>::full(3).unwrap();
    assert!(ops::zoom(&t, &[8]).is_err());
    assert!(ops::zoom(&t, &[0, 0, 0, 0]).is_err());
    assert!(ops::grow(&KTree::<3>::full(21).unwrap(), &[0]).is_err());
    assert!(ops::scale(&t, 0, 1).is_err());
    assert!(Affine::<3>::from_homogeneous(&[1.0; 9]).is_err());
    let mut singular = Affine::<3>::identity();
    singular.a[2][2] = 0.0;
    assert!(ops::transform(&t, &singular).is_err());
    assert!(AxisMap::<3>::new([0, 0, 1], [false; 3]).is_err());
    assert!(AxisMap::<3>::quarter_turn(1, 1).is_err());
}
