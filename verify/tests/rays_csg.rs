//! Boolean operations and translation on ray sets = the same operations on dense boolean arrays, K = 1 … 4;
//! results are canonical ray sets and stack into the dense reference tree.

use ktree::stacking::paper::stack;
use ktree::{KTree, Ray, RaySet, Universe};
use proptest::prelude::*;

fn max_level(k: usize) -> u32 {
    if k <= 3 {
        5
    } else {
        3
    }
}

/// Random runs plus random boxes (so that columns share runs, touch and nest).
fn runs<const K: usize>(level: u32) -> impl Strategy<Value = Vec<Ray<K>>> {
    let side = 1u32 << level;
    let ray = (prop::array::uniform::<_, K>(0..side), 1..=side)
        .prop_map(move |(start, len)| Ray::new(start, (start[K - 1] + len).min(side)));
    let boxes = prop::collection::vec(prop::array::uniform::<_, K>((0..side, 1..=side)), 0..3)
        .prop_map(move |bs| {
            let mut out = Vec::new();
            for b in bs {
                let lo: [u32; K] = std::array::from_fn(|i| b[i].0);
                let hi: [u32; K] = std::array::from_fn(|i| (b[i].0 + b[i].1).min(side));
                let mut col = lo;
                'cols: loop {
                    out.push(Ray::new(col, hi[K - 1]));
                    let mut a = 0;
                    loop {
                        if a + 1 >= K {
                            break 'cols;
                        }
                        col[a] += 1;
                        if col[a] < hi[a] {
                            break;
                        }
                        col[a] = lo[a];
                        a += 1;
                    }
                }
            }
            out
        });
    (prop::collection::vec(ray, 0..20), boxes).prop_map(|(mut a, b)| {
        a.extend(b);
        a
    })
}

fn with_normals<const K: usize>(level: u32, rays: Vec<Ray<K>>) -> RaySet<K> {
    RaySet::from_rays_with_normals(
        level,
        rays.into_iter().map(|r| {
            let mut n1 = [0.0; K];
            n1[K - 1] = -1.0;
            let mut n2 = [0.0; K];
            n2[K - 1] = 1.0;
            (r, [n1, n2])
        }),
    )
    .unwrap()
}

fn pair<const K: usize>() -> impl Strategy<Value = (RaySet<K>, RaySet<K>, [i64; K])> {
    (0..=max_level(K)).prop_flat_map(|level| {
        let side = 1i64 << level;
        (
            runs::<K>(level),
            runs::<K>(level),
            prop::array::uniform::<_, K>(-side..=side),
            any::<bool>(),
        )
            .prop_map(move |(a, b, off, normals)| {
                let a = if normals {
                    with_normals(level, a)
                } else {
                    RaySet::from_rays(level, a).unwrap()
                };
                (a, with_normals(level, b), off)
            })
    })
}

fn dense<const K: usize>(set: &RaySet<K>) -> Vec<bool> {
    let u = set.universe();
    (0..u.voxels() as usize)
        .map(|i| set.contains(u.dense_point(i)))
        .collect()
}

fn check<const K: usize>(got: &RaySet<K>, want: &[bool], what: &str) -> Result<(), TestCaseError> {
    prop_assert_eq!(
        &dense(got),
        want,
        "{} differs from the dense reference",
        what
    );
    let canonical = RaySet::<K>::from_rays(got.level(), got.iter()).unwrap();
    prop_assert_eq!(canonical.runs(), got.runs(), "{} is not canonical", what);
    prop_assert_eq!(canonical.column_keys(), got.column_keys());
    let tree = stack(got);
    tree.assert_well_formed();
    prop_assert_eq!(tree, KTree::<K>::from_dense(got.level(), want).unwrap());
    Ok(())
}

fn agrees<const K: usize>(
    a: &RaySet<K>,
    b: &RaySet<K>,
    off: [i64; K],
) -> Result<(), TestCaseError> {
    let (da, db) = (dense(a), dense(b));
    let zip = |f: fn(bool, bool) -> bool| {
        da.iter()
            .zip(&db)
            .map(|(&x, &y)| f(x, y))
            .collect::<Vec<_>>()
    };
    let u = a.universe();
    let union = a.union(b).unwrap();
    check(&union, &zip(|x, y| x || y), "union")?;
    prop_assert_eq!(union.has_normals(), a.has_normals() && b.has_normals());
    check(
        &a.intersection(b).unwrap(),
        &zip(|x, y| x && y),
        "intersection",
    )?;
    check(
        &a.difference(b).unwrap(),
        &zip(|x, y| x && !y),
        "difference",
    )?;
    check(
        &a.complement().unwrap(),
        &da.iter().map(|x| !x).collect::<Vec<_>>(),
        "complement",
    )?;
    let moved = a.translated(off);
    let side = u.side() as i64;
    let want: Vec<bool> = (0..u.voxels() as usize)
        .map(|i| {
            let p = u.dense_point(i);
            let mut q = [0u32; K];
            for k in 0..K {
                let c = i64::from(p[k]) - off[k];
                if !(0..side).contains(&c) {
                    return false;
                }
                q[k] = c as u32;
            }
            da[u.dense_index(q)]
        })
        .collect();
    check(&moved, &want, "translation")?;
    // De Morgan through the ray operations alone.
    let lhs = a.union(b).unwrap().complement().unwrap();
    let rhs = a
        .complement()
        .unwrap()
        .intersection(&b.complement().unwrap())
        .unwrap();
    prop_assert_eq!(lhs.runs(), rhs.runs());
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn csg_k1((a, b, off) in pair::<1>()) { agrees(&a, &b, off)?; }
    #[test]
    fn csg_k2((a, b, off) in pair::<2>()) { agrees(&a, &b, off)?; }
    #[test]
    fn csg_k3((a, b, off) in pair::<3>()) { agrees(&a, &b, off)?; }
    #[test]
    fn csg_k4((a, b, off) in pair::<4>()) { agrees(&a, &b, off)?; }
}

#[test]
fn different_levels_are_an_error() {
    let a = RaySet::<3>::full(2).unwrap();
    let b = RaySet::<3>::full(3).unwrap();
    assert!(a.union(&b).is_err());
    assert!(a.difference(&b).is_err());
}

/// Normals: the subtracted set's normals are negated where they bound the result.
#[test]
fn difference_negates_the_subtracted_normals() {
    let a = with_normals::<2>(3, vec![Ray::new([1, 0], 8)]);
    let b = with_normals::<2>(3, vec![Ray::new([1, 3], 5)]);
    let d = a.difference(&b).unwrap();
    assert_eq!(d.runs(), [(0, 3), (5, 8)]);
    assert_eq!(d.normals(0).unwrap()[1], [0.0, 1.0]); // b's entry normal (−z) negated
    assert_eq!(d.normals(1).unwrap()[0], [0.0, -1.0]);
    let _ = Universe::<2>::new(3).unwrap();
}

/// A normal naming its set, run and end (negated where an operation turns it around).
fn label<const K: usize>(set: f32, run: usize, exit: bool) -> [f32; K] {
    let mut n = [0.0; K];
    n[0] = 10.0 + 10_000.0 * set + 2.0 * run as f32 + f32::from(u8::from(exit));
    n
}

/// `set` with a normal of its own at each end of each run.
fn labelled<const K: usize>(set: &RaySet<K>, id: f32) -> RaySet<K> {
    RaySet::from_rays_with_normals(
        set.level(),
        set.iter()
            .enumerate()
            .map(|(i, r)| (r, [label(id, i, false), label(id, i, true)])),
    )
    .unwrap()
}

/// The normal a result's end at `z` of column `key` (its start, or its end if `exit`) carries: that of the
/// first operand's run end there, else the second's, negated where the operand's membership changes the
/// other way; `∓z` at the universe's ends.
fn expected_normal<const K: usize>(
    operands: &[&RaySet<K>],
    key: u64,
    z: u32,
    exit: bool,
) -> [f32; K] {
    for set in operands {
        for i in 0..set.len() {
            if set.column_keys()[i] != key {
                continue;
            }
            let (z1, z2) = set.runs()[i];
            for (at, end_exit) in [(z1, false), (z2, true)] {
                if at == z {
                    let n = set.normals(i).unwrap()[usize::from(end_exit)];
                    return if end_exit == exit { n } else { n.map(|x| -x) };
                }
            }
        }
    }
    let mut n = [0.0; K];
    n[K - 1] = if exit { 1.0 } else { -1.0 };
    n
}

fn check_normals<const K: usize>(a: &RaySet<K>, b: &RaySet<K>) -> Result<(), TestCaseError> {
    let (a, b) = (labelled(a, 1.0), labelled(b, 2.0));
    let results = [
        (a.union(&b).unwrap(), vec![&a, &b]),
        (a.intersection(&b).unwrap(), vec![&a, &b]),
        (a.difference(&b).unwrap(), vec![&a, &b]),
        (a.complement().unwrap(), vec![&a]),
    ];
    for (what, (got, operands)) in ["union", "intersection", "difference", "complement"]
        .iter()
        .zip(&results)
    {
        // A set of no run carries no normals (nor does a result made with it).
        if operands.iter().any(|o| o.is_empty()) {
            continue;
        }
        prop_assert!(got.has_normals(), "{}", what);
        for i in 0..got.len() {
            let key = got.column_keys()[i];
            let (z1, z2) = got.runs()[i];
            let n = got.normals(i).unwrap();
            prop_assert_eq!(
                n[0],
                expected_normal(operands, key, z1, false),
                "{} start",
                what
            );
            prop_assert_eq!(
                n[1],
                expected_normal(operands, key, z2, true),
                "{} end",
                what
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    /// Normals ride with the run ends they bound, turned around where the membership turns.
    #[test]
    fn normals_ride_with_their_ends_k1((a, b, _) in pair::<1>()) { check_normals(&a, &b)?; }
    #[test]
    fn normals_ride_with_their_ends_k2((a, b, _) in pair::<2>()) { check_normals(&a, &b)?; }
    #[test]
    fn normals_ride_with_their_ends_k3((a, b, _) in pair::<3>()) { check_normals(&a, &b)?; }
}
