//! Operations on valued trees against the same operation on dense arrays of values, K = 1 … 4 and several
//! value types: select (a value, a range), mask, combine by every rule, overlay, map and relabel, and the
//! per-value statistics, the transforms, and growing and zooming through the root. Every result is well
//! formed and minimal (equal, node for node, to the tree of its dense reference).

use std::collections::{BTreeMap, HashMap};

use ktree::ops::values::Rule;
use ktree::ops::{self, Affine, AxisMap};
use ktree::tree::{Rgb, Value};
use ktree::{KTree, Universe};
use ktree_verify::labels::{painted_at, Painted, Palette};
use proptest::prelude::*;

fn tree_of<const K: usize, V: Value>(level: u32, dense: &[Option<V>]) -> KTree<K, V> {
    KTree::<K, V>::from_dense_values(level, dense).unwrap()
}

fn binary_of<const K: usize>(level: u32, dense: &[bool]) -> KTree<K> {
    KTree::<K>::from_dense(level, dense).unwrap()
}

fn same<const K: usize, V: Value>(
    got: &KTree<K, V>,
    want: &KTree<K, V>,
) -> Result<(), TestCaseError> {
    got.assert_well_formed();
    prop_assert!(
        got == want,
        "got {:?}\nwant {:?}",
        got.to_dense_values(),
        want.to_dense_values()
    );
    Ok(())
}

/// Voxels, box `[lo, hi)` and the sums of the centres of one value, counted on the dense array.
type Measured<const K: usize> = (u128, [u32; K], [u32; K], [f64; K]);

#[allow(clippy::needless_range_loop)] // Loops over the axes index several arrays.
fn check<const K: usize, V: Palette>(a: &Painted<K>, b: &Painted<K>) -> Result<(), TestCaseError> {
    let level = a.level;
    let (da, db) = (a.dense::<V>(), b.dense::<V>());
    let (ta, tb) = (tree_of::<K, V>(level, &da), tree_of::<K, V>(level, &db));
    let p = V::PALETTE;

    // Select one value, and a range.
    let want: Vec<bool> = da.iter().map(|v| v.is_some_and(|v| v.same(p[2]))).collect();
    let got = ta.select(p[2]);
    got.assert_well_formed();
    prop_assert_eq!(&got, &binary_of::<K>(level, &want));
    let (lo, hi) = (p[0].min_value(p[1]), p[0].max_value(p[1]));
    let want: Vec<bool> = da
        .iter()
        .map(|v| v.is_some_and(|v| v.in_range(lo, hi)))
        .collect();
    prop_assert_eq!(&ta.select_range(lo, hi), &binary_of::<K>(level, &want));

    // Mask by the other's shape.
    let mask: Vec<bool> = db.iter().map(Option::is_some).collect();
    let want: Vec<Option<V>> = da
        .iter()
        .zip(&mask)
        .map(|(v, &m)| v.filter(|_| m))
        .collect();
    same(
        &ta.mask(&binary_of::<K>(level, &mask)),
        &tree_of::<K, V>(level, &want),
    )?;

    // Combine by every rule, and overlay.
    for rule in [Rule::First, Rule::Min, Rule::Max, Rule::Sum] {
        let want: Vec<Option<V>> = da
            .iter()
            .zip(&db)
            .map(|(x, y)| match (x, y) {
                (Some(x), Some(y)) => Some(rule.apply(*x, *y)),
                (x, y) => x.or(*y),
            })
            .collect();
        same(
            &ta.combine(&tb, rule).unwrap(),
            &tree_of::<K, V>(level, &want),
        )?;
    }
    let want: Vec<Option<V>> = da.iter().zip(&db).map(|(x, y)| y.or(*x)).collect();
    same(&ta.overlay(&tb).unwrap(), &tree_of::<K, V>(level, &want))?;

    // Relabel: the second palette value becomes the first, the third is erased.
    let table: HashMap<V::Key, Option<V>> =
        HashMap::from([(p[1].key(), Some(p[0])), (p[2].key(), None)]);
    let want: Vec<Option<V>> = da
        .iter()
        .map(|v| v.and_then(|v| table.get(&v.key()).copied().unwrap_or(Some(v))))
        .collect();
    same(&ta.relabel(&table).unwrap(), &tree_of::<K, V>(level, &want))?;
    // A threshold to a binary tree.
    let want: Vec<bool> = da
        .iter()
        .map(|v| v.is_some_and(|v| !v.same(p[3])))
        .collect();
    let got: KTree<K> = ta.map_values(|v| (!v.same(p[3])).then_some(())).unwrap();
    got.assert_well_formed();
    prop_assert_eq!(&got, &binary_of::<K>(level, &want));

    // Values at points, the runs and back, a translation.
    let u = Universe::<K>::new(level).unwrap();
    let points: Vec<[u32; K]> = (0..da.len()).map(|i| u.dense_point(i)).collect();
    let got = ta.values_at(&points);
    for (g, w) in got.iter().zip(&da) {
        prop_assert_eq!(g.map(Value::key), w.map(Value::key));
    }
    // A batch large enough to be answered through the table of the top levels, with points outside.
    let many: Vec<[u32; K]> = (0..70_000usize)
        .map(|i| {
            let p = u.dense_point(i.wrapping_mul(7919) % da.len());
            if i % 97 == 0 {
                std::array::from_fn(|a| p[a] + if a == i % K { u.side() as u32 } else { 0 })
            } else {
                p
            }
        })
        .collect();
    let got = ta.values_at(&many);
    for (g, p) in got.iter().zip(&many) {
        let want = u.check_point(*p).ok().and_then(|()| da[u.dense_index(*p)]);
        prop_assert_eq!(g.map(Value::key), want.map(Value::key), "at {:?}", p);
    }
    // The first value along rays parallel to axis 0, from outside, through every row of voxels: the
    // first voxel of the row holding a value.
    let rows: Vec<[u32; K]> = points.iter().copied().filter(|p| p[0] == 0).collect();
    let rays: Vec<ktree::query::RayCast<K>> = rows
        .iter()
        .map(|p| {
            let origin = std::array::from_fn(|a| if a == 0 { -0.5 } else { f64::from(p[a]) + 0.5 });
            let direction = std::array::from_fn(|a| if a == 0 { 1.0 } else { 0.0 });
            ktree::query::RayCast::new(origin, direction, f64::INFINITY).unwrap()
        })
        .collect();
    let hits = ktree::query::first_values(&ta, &rays);
    for (row, hit) in rows.iter().zip(&hits) {
        let want = (0..u.side() as u32).find_map(|x| {
            let mut q = *row;
            q[0] = x;
            da[u.dense_index(q)].map(|v| (q, v.key()))
        });
        prop_assert_eq!(hit.map(|(h, v)| (h.voxel, v.key())), want);
    }
    same(&KTree::from_value_runs(&ta.to_value_runs()), &ta)?;
    let side = u.side() as i64;
    let t: [i64; K] = std::array::from_fn(|a| {
        [1, -2, 3, -1][a] % side.max(1) * if level.is_multiple_of(2) { 1 } else { -1 }
    });
    let mut moved = vec![None; da.len()];
    for (i, v) in da.iter().enumerate() {
        let q = u.dense_point(i);
        let r: [i64; K] = std::array::from_fn(|a| i64::from(q[a]) + t[a]);
        if r.iter().all(|&c| (0..side).contains(&c)) {
            moved[u.dense_index(std::array::from_fn(|a| r[a] as u32))] = *v;
        }
    }
    same(&ta.translate_values(t), &tree_of::<K, V>(level, &moved))?;

    // Quarter turns and reflections, rational scales and an affine turn carry every voxel's value.
    let maps = AxisMap::<K>::all();
    let map = maps[(level as usize * 7 + da.len()) % maps.len()];
    let mut turned = vec![None; da.len()];
    for (i, v) in da.iter().enumerate() {
        turned[u.dense_index(map.map_point(u.dense_point(i), u.side() as u32))] = *v;
    }
    same(
        &ops::rotate_values(&ta, &map).unwrap(),
        &tree_of::<K, V>(level, &turned),
    )?;
    for (num, den) in [(3u32, 2u32), (1, 2), (2, 1)] {
        let back =
            |q: u32| ((2 * i64::from(q) + 1) * i64::from(den)).div_euclid(2 * i64::from(num));
        let want = resampled(&da, u, |q| q.map(back));
        same(
            &ops::scale_values(&ta, num, den).unwrap(),
            &tree_of::<K, V>(level, &want),
        )?;
    }
    let centre = Affine::<K>::universe_centre(level);
    let m = if K >= 2 {
        Affine::rotation_about(0, 1, 30.0, centre).unwrap()
    } else {
        Affine::scaling_about(0.75, centre)
    };
    let inverse = m.inverse().unwrap();
    let want = resampled(&da, u, |q| inverse.source_voxel(q));
    let got = ops::transform_values(&ta, &m).unwrap();
    same(&got, &tree_of::<K, V>(level, &want))?;
    prop_assert_eq!(got.shape(), ops::transform(&ta.shape(), &m).unwrap());

    // Grow and zoom by powers of two through the root: the old universe is the cell of `path`.
    let path: Vec<usize> = (0..2)
        .map(|d| (level as usize + 3 * d) % (1 << K))
        .collect();
    let corner = |path: &[usize], level: u32| -> [i64; K] {
        std::array::from_fn(|a| {
            let bit = |d: usize| (path[d] >> a & 1) as i64;
            (0..path.len())
                .map(|d| bit(d) << (level - 1 - d as u32))
                .sum()
        })
    };
    let grown = Universe::<K>::new(level + 2).unwrap();
    let at = corner(&path, level + 2);
    let want: Vec<Option<V>> = (0..grown.side().pow(K as u32) as usize)
        .map(|i| {
            let q = grown.dense_point(i);
            let p: [i64; K] = std::array::from_fn(|a| i64::from(q[a]) - at[a]);
            let inside = p.iter().all(|&c| (0..u.side() as i64).contains(&c));
            inside
                .then(|| da[u.dense_index(p.map(|c| c as u32))])
                .flatten()
        })
        .collect();
    let g = ops::grow_values(&ta, &path).unwrap();
    same(&g, &tree_of::<K, V>(level + 2, &want))?;
    same(&ops::zoom_values(&g, &path).unwrap(), &ta)?;
    prop_assert_eq!(g.shape(), ops::grow(&ta.shape(), &path).unwrap());
    let n = (level as usize).min(2);
    let zoomed = Universe::<K>::new(level - n as u32).unwrap();
    let at = corner(&path[..n], level);
    let want = resampled(&da, u, |q| std::array::from_fn(|a| i64::from(q[a]) + at[a]));
    let want: Vec<Option<V>> = (0..zoomed.side().pow(K as u32) as usize)
        .map(|i| want[u.dense_index(zoomed.dense_point(i))])
        .collect();
    same(
        &ops::zoom_values(&ta, &path[..n]).unwrap(),
        &tree_of::<K, V>(level - n as u32, &want),
    )?;

    // Per-value statistics against a count over the dense array.
    let mut want: BTreeMap<V::Key, Measured<K>> = BTreeMap::new();
    for (i, v) in da.iter().enumerate() {
        let Some(v) = v else { continue };
        let q = u.dense_point(i);
        let e = want
            .entry(v.key())
            .or_insert((0, [u32::MAX; K], [0; K], [0.0; K]));
        e.0 += 1;
        for a in 0..K {
            e.1[a] = e.1[a].min(q[a]);
            e.2[a] = e.2[a].max(q[a] + 1);
            e.3[a] += f64::from(q[a]) + 0.5;
        }
    }
    let stats = ta.value_stats();
    prop_assert_eq!(stats.len(), want.len());
    for (key, (voxels, lo, hi, sums)) in &want {
        let s = &stats[key];
        prop_assert_eq!(s.voxels, *voxels);
        prop_assert_eq!(s.bounding_box, (*lo, *hi));
        for a in 0..K {
            prop_assert!((s.centroid[a] - sums[a] / *voxels as f64).abs() < 1e-9);
        }
        // Faces between a voxel of the value and one without it, counted on the dense array.
        let mut faces = 0u128;
        for (i, v) in da.iter().enumerate() {
            if v.map(Value::key) != Some(*key) {
                continue;
            }
            let q = u.dense_point(i);
            for a in 0..K {
                for step in [-1i64, 1] {
                    let n = i64::from(q[a]) + step;
                    let mut r = q;
                    let outside = n < 0 || n >= u.side() as i64;
                    if !outside {
                        r[a] = n as u32;
                    }
                    if outside || da[u.dense_index(r)].map(Value::key) != Some(*key) {
                        faces += 1;
                    }
                }
            }
        }
        prop_assert_eq!(s.surface_area, faces);
    }
    Ok(())
}

/// The dense array whose voxel `q` holds the value of voxel `source(q)` of `dense` (empty outside).
fn resampled<const K: usize, V: Value>(
    dense: &[Option<V>],
    u: Universe<K>,
    source: impl Fn([u32; K]) -> [i64; K],
) -> Vec<Option<V>> {
    let side = u.side() as i64;
    (0..dense.len())
        .map(|i| {
            let p = source(u.dense_point(i));
            if p.iter().all(|&c| (0..side).contains(&c)) {
                dense[u.dense_index(p.map(|c| c as u32))]
            } else {
                None
            }
        })
        .collect()
}

fn pair<const K: usize>() -> impl Strategy<Value = (Painted<K>, Painted<K>)> {
    (0..=ktree_verify::objects::max_level(K))
        .prop_flat_map(|l| (painted_at::<K>(l), painted_at::<K>(l)))
}

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    #[test]
    fn value_ops_k1((a, b) in pair::<1>()) { check::<1, u8>(&a, &b)?; check::<1, f32>(&a, &b)?; }
    #[test]
    fn value_ops_k2((a, b) in pair::<2>()) { check::<2, u16>(&a, &b)?; check::<2, Rgb>(&a, &b)?; }
    #[test]
    fn value_ops_k3((a, b) in pair::<3>()) { check::<3, i8>(&a, &b)?; check::<3, f32>(&a, &b)?; }
    #[test]
    fn value_ops_k4((a, b) in pair::<4>()) { check::<4, u32>(&a, &b)?; check::<4, Rgb>(&a, &b)?; }
}

#[test]
fn a_float_sum_that_is_nan_is_an_error_and_levels_must_match() {
    let a = KTree::<1, f32>::from_dense_values(1, &[Some(f32::INFINITY), None]).unwrap();
    let b = KTree::<1, f32>::from_dense_values(1, &[Some(f32::NEG_INFINITY), None]).unwrap();
    let e = a.combine(&b, Rule::Sum).unwrap_err();
    let cause = std::error::Error::source(&e)
        .expect("the value's error")
        .to_string();
    assert!(cause.contains("NaN"), "{e}: {cause}");
    let c = KTree::<1, f32>::from_dense_values(2, &[None; 4]).unwrap();
    assert!(a
        .combine(&c, Rule::Max)
        .unwrap_err()
        .to_string()
        .contains("levels"));
    // Saturating integer sums.
    let x = KTree::<1, u8>::from_dense_values(1, &[Some(200), Some(1)]).unwrap();
    let s = x.combine(&x, Rule::Sum).unwrap();
    assert_eq!(s.to_dense_values().unwrap(), [Some(255), Some(2)]);
}
