//! The toolkit for runs and columns against the simplest references: the merge of two lists of runs
//! against a dense boolean line for every one of the sixteen truth tables (the ends' causes included), the
//! column keys' round trip and order at every level of every K, the one tree → runs on a `.ktree` file
//! read in place against the tree in memory and against the dense array, and the dense window against
//! point queries, for K = 1 … 4.

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use ktree::io::{write_ktree, KtreeView, MappedTree};
use ktree::query::{dense_window, DenseOrder, Query};
use ktree::rays::{
    join_columns, joined, merge_runs, stretches, Cause, ColumnKeys, SignedColumnKeys, TruthTable,
};
use ktree::shape::{faces_per_axis, run_count};
use ktree::tree::{rays_of, TreeStorage};
use ktree::{max_level, KTree, Ray, RaySet, Universe};
use ktree_verify::objects::{object, Obj};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------------
// The merge.

/// A line of up to 48 voxels as booleans.
fn line() -> impl Strategy<Value = Vec<bool>> {
    prop::collection::vec(prop::bool::weighted(0.45), 0..48)
}

/// The maximal runs of a dense line, moved by `shift`: sorted, disjoint, not touching.
fn runs_of_line(line: &[bool], shift: i64) -> Vec<(i64, i64)> {
    let mut out = Vec::new();
    let mut z = 0;
    while z < line.len() {
        if !line[z] {
            z += 1;
            continue;
        }
        let start = z;
        while z < line.len() && line[z] {
            z += 1;
        }
        out.push((start as i64 + shift, z as i64 + shift));
    }
    out
}

/// Whether voxel `z` is in `runs`.
fn inside(runs: &[(i64, i64)], z: i64) -> bool {
    runs.iter().any(|r| r.0 <= z && z < r.1)
}

/// Checks `merge_runs` of two lines for every table: the output against the dense line, its form, and
/// each end's cause (an end of the input named, the first input's where both have one).
fn check_merge(a: &[bool], b: &[bool], shift: i64) -> Result<(), TestCaseError> {
    let n = a.len().max(b.len()) as i64;
    let (ra, rb) = (runs_of_line(a, shift), runs_of_line(b, shift));
    let span = shift..shift + n;
    let end_of = |runs: &[(i64, i64)], run: usize, exit: bool| {
        let r = runs[run];
        if exit {
            r.1
        } else {
            r.0
        }
    };
    let has_end = |runs: &[(i64, i64)], z: i64| runs.iter().any(|r| r.0 == z || r.1 == z);
    for table in TruthTable::ALL {
        let mut out: Vec<(i64, i64, Cause, Cause)> = Vec::new();
        merge_runs(
            ra.clone(),
            rb.clone(),
            table,
            span.clone(),
            |z1, z2, s, e| out.push((z1, z2, s, e)),
        );
        let runs: Vec<(i64, i64)> = out.iter().map(|o| (o.0, o.1)).collect();
        for w in runs.windows(2) {
            prop_assert!(w[0].1 < w[1].0, "{:?}: sorted, apart: {:?}", table, runs);
        }
        prop_assert!(runs.iter().all(|r| r.0 < r.1), "{:?}: not empty", table);
        for z in span.clone() {
            let want = table.apply(inside(&ra, z), inside(&rb, z));
            prop_assert_eq!(inside(&runs, z), want, "{:?} at {}", table, z);
        }
        for &(z1, z2, start, end) in &out {
            for (z, cause, exit) in [(z1, start, false), (z2, end, true)] {
                match cause {
                    Cause::First { run, exit: e } => prop_assert_eq!(end_of(&ra, run, e), z),
                    Cause::Second { run, exit: e } => {
                        prop_assert_eq!(end_of(&rb, run, e), z);
                        prop_assert!(!has_end(&ra, z), "the first input's end comes first");
                    }
                    Cause::Span => prop_assert_eq!(z, if exit { span.end } else { span.start }),
                }
            }
        }
    }
    // The stretches: contiguous, each of one membership, from the first end to the last.
    let s: Vec<_> = stretches(&ra, &rb).collect();
    for w in s.windows(2) {
        prop_assert_eq!(w[0].z2, w[1].z1);
    }
    for st in &s {
        for z in st.z1..st.z2 {
            prop_assert_eq!((inside(&ra, z), inside(&rb, z)), (st.first, st.second));
        }
    }
    let first = ra.iter().chain(&rb).map(|r| r.0).min();
    let last = ra.iter().chain(&rb).map(|r| r.1).max();
    prop_assert_eq!(s.first().map(|s| s.z1), first);
    prop_assert_eq!(s.last().map(|s| s.z2), last);
    Ok(())
}

/// Runs sorted by their starts that may overlap or touch (up to 12, in `0..60`).
fn overlapping() -> impl Strategy<Value = Vec<(i64, i64)>> {
    prop::collection::vec((0i64..50, 1i64..10), 0..12).prop_map(|mut v| {
        v.sort_unstable();
        v.into_iter().map(|(z, len)| (z, z + len)).collect()
    })
}

proptest! {
    #![proptest_config(ktree_verify::config(256))]
    #[test]
    fn merges_match_the_dense_line(a in line(), b in line(), shift in -100i64..100) {
        check_merge(&a, &b, shift)?;
    }

    /// A union takes inputs whose runs overlap; `joined` makes such runs disjoint.
    #[test]
    fn unions_take_overlapping_runs(a in overlapping(), b in overlapping()) {
        let mut out = Vec::new();
        merge_runs(a.clone(), b.clone(), TruthTable::UNION, 0..64, |z1, z2, _, _| out.push((z1, z2)));
        for z in -1..70 {
            let want = inside(&a, z) || inside(&b, z);
            prop_assert_eq!(inside(&out, z), want);
        }
        for w in out.windows(2) {
            prop_assert!(w[0].1 < w[1].0);
        }
        // `joined` of one sorted list: the union of its runs, disjoint and apart.
        let sorted: Vec<(i64, i64)> = {
            let mut v = a.clone();
            v.extend(&b);
            v.sort_unstable();
            v
        };
        let j2: Vec<_> = joined(sorted.iter().copied()).collect();
        for w in j2.windows(2) {
            prop_assert!(w[0].1 < w[1].0);
        }
        for z in -1..70 {
            prop_assert_eq!(inside(&j2, z), inside(&a, z) || inside(&b, z));
        }
    }
}

// ---------------------------------------------------------------------------------------------------
// Column keys.

/// Columns of a universe of level `level`: the first K − 1 coordinates, the last 0.
fn columns<const K: usize>() -> impl Strategy<Value = (u32, Vec<[u32; K]>)> {
    (0..=max_level(K)).prop_flat_map(|level| {
        let side = 1u64 << level;
        let column = prop::array::uniform::<_, K>(0..side).prop_map(|c| {
            let mut c = c.map(|x| x as u32);
            c[K - 1] = 0;
            c
        });
        (Just(level), prop::collection::vec(column, 1..12))
    })
}

fn check_keys<const K: usize>(level: u32, cols: &[[u32; K]]) -> Result<(), TestCaseError> {
    let keys = ColumnKeys::<K>::new(level);
    let side = 1i64 << level;
    for a in cols {
        let key = keys.pack(*a);
        prop_assert_eq!(keys.unpack(key), *a);
        for axis in 0..K - 1 {
            prop_assert_eq!(keys.axis(key, axis), a[axis]);
        }
        // The last coordinate is not part of the key.
        let mut with_z = *a;
        with_z[K - 1] = 7;
        prop_assert_eq!(keys.pack(with_z), key);
        // The signed twin holds the column too, and converts back.
        let signed = SignedColumnKeys::<K>::of_unsigned(keys, key);
        prop_assert_eq!(SignedColumnKeys::<K>::unpack(signed), a.map(i64::from));
        prop_assert_eq!(SignedColumnKeys::<K>::to_unsigned(keys, signed), Some(key));
        if K > 1 {
            // The slab of its first coordinate holds it.
            prop_assert!(keys.slab(a[0]..a[0] + 1).contains(&key));
        }
        for b in cols {
            let other = keys.pack(*b);
            prop_assert_eq!(key.cmp(&other), a.cmp(b), "keys sort as the columns");
            let sa = SignedColumnKeys::<K>::of_unsigned(keys, key);
            let sb = SignedColumnKeys::<K>::of_unsigned(keys, other);
            prop_assert_eq!(sa.cmp(&sb), a.cmp(b), "signed keys sort as the columns");
            // Moving by the difference lands on the other column, in either key.
            let by: [i64; K] = std::array::from_fn(|i| i64::from(b[i]) - i64::from(a[i]));
            prop_assert_eq!(keys.moved(key, by), Some(other));
            prop_assert_eq!(sa.wrapping_add(SignedColumnKeys::<K>::offset(by)), sb);
            // Past the universe on the first axis: no key.
            if K > 1 {
                let mut out = by;
                out[0] = side - i64::from(a[0]);
                prop_assert_eq!(keys.moved(key, out), None);
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(128))]
    #[test]
    fn column_keys_k1((level, cols) in columns::<1>()) { check_keys(level, &cols)?; }
    #[test]
    fn column_keys_k2((level, cols) in columns::<2>()) { check_keys(level, &cols)?; }
    #[test]
    fn column_keys_k3((level, cols) in columns::<3>()) { check_keys(level, &cols)?; }
    #[test]
    fn column_keys_k4((level, cols) in columns::<4>()) { check_keys(level, &cols)?; }
}

/// Every level of every K: the largest column's key round-trips and is the largest key.
#[test]
fn column_keys_at_every_level() {
    fn all<const K: usize>() {
        for level in 0..=max_level(K) {
            let keys = ColumnKeys::<K>::new(level);
            let top = [((1u64 << level) - 1) as u32; K];
            let mut top_column = top;
            top_column[K - 1] = 0;
            let key = keys.pack(top);
            assert_eq!(keys.unpack(key), top_column, "K = {K}, L = {level}");
            let fields = level as u64 * (K as u64 - 1);
            assert_eq!(
                u128::from(key),
                (1u128 << fields) - 1,
                "K = {K}, L = {level}"
            );
            let signed = SignedColumnKeys::<K>::of_unsigned(keys, key);
            assert_eq!(SignedColumnKeys::<K>::to_unsigned(keys, signed), Some(key));
        }
    }
    all::<1>();
    all::<2>();
    all::<3>();
    all::<4>();
}

#[test]
fn columns_join_side_by_side() {
    let joined_keys: Vec<_> = join_columns(&[0, 2, 2, 5], &[1, 2, 6], 0).collect();
    assert_eq!(
        joined_keys,
        [
            (0, 0..1, 0..0),
            (1, 1..1, 0..1),
            (2, 1..3, 1..2),
            (5, 3..4, 2..2),
            (6, 4..4, 2..3)
        ]
    );
    // The second list moved by 1 (wrapping): its keys become 2, 3, 7.
    let moved: Vec<u64> = join_columns(&[2], &[1, 2, 6], 1).map(|j| j.0).collect();
    assert_eq!(moved, [2, 3, 7]);
}

// ---------------------------------------------------------------------------------------------------
// Tree → runs and the dense window, on a tree in memory and on a file read in place.

fn view_of<const K: usize>(tree: &KTree<K>) -> KtreeView {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    KtreeView::from_bytes(bytes, "mem").unwrap()
}

/// The runs of a dense array: one ray per full voxel, joined by the ray set.
fn dense_rays<const K: usize>(u: &Universe<K>, dense: &[bool]) -> RaySet<K> {
    let rays = (0..dense.len()).filter(|&i| dense[i]).map(|i| {
        let p = u.dense_point(i);
        Ray::new(p, p[K - 1] + 1)
    });
    RaySet::from_rays(u.level(), rays).unwrap()
}

/// A box in and around the universe, possibly empty or inverted.
fn a_box<const K: usize>(level: u32) -> impl Strategy<Value = ([i64; K], [i64; K])> {
    let side = 1i64 << level;
    (
        prop::array::uniform::<_, K>(-2..side + 1),
        prop::array::uniform::<_, K>(-1..side + 3),
    )
}

fn obj_and_box<const K: usize>() -> impl Strategy<Value = (Obj<K>, ([i64; K], [i64; K]))> {
    object::<K>().prop_flat_map(|o| {
        let level = o.level;
        (Just(o), a_box::<K>(level))
    })
}

fn check_runs_and_windows<const K: usize>(
    o: &Obj<K>,
    (lo, hi): ([i64; K], [i64; K]),
) -> Result<(), TestCaseError> {
    let (u, dense, tree) = (o.universe(), o.dense(), o.tree());
    let view = view_of(&tree);
    let mapped = MappedTree::<K>::new(&view).unwrap();
    let want = dense_rays(&u, &dense);
    prop_assert_eq!(&tree.to_rays(), &want);
    prop_assert_eq!(rays_of(&mapped).unwrap(), want.clone());
    prop_assert_eq!(run_count(&tree), Ok(want.len() as u128));
    prop_assert_eq!(run_count(&mapped).unwrap(), want.len() as u128);
    prop_assert_eq!(
        faces_per_axis(&mapped).unwrap(),
        faces_per_axis(&tree).unwrap()
    );
    // The dense window in both orders against point queries.
    let dims: [usize; K] = std::array::from_fn(|a| (hi[a] - lo[a]).max(0) as usize);
    for order in [DenseOrder::FirstAxisFastest, DenseOrder::LastAxisFastest] {
        let got = dense_window(&tree, lo, hi, order).unwrap();
        let from_file = Query::dense_window(&mapped, lo, hi, order).unwrap();
        prop_assert_eq!(&got, &from_file);
        prop_assert_eq!(got.len(), dims.iter().product::<usize>());
        for (i, &v) in got.iter().enumerate() {
            // The voxel at index i in `order`.
            let mut p = [0i64; K];
            let mut rest = i;
            let axes: Vec<usize> = match order {
                DenseOrder::FirstAxisFastest => (0..K).collect(),
                DenseOrder::LastAxisFastest => (0..K).rev().collect(),
            };
            for &a in &axes {
                p[a] = lo[a] + (rest % dims[a]) as i64;
                rest /= dims[a];
            }
            let want = p.iter().all(|&c| c >= 0 && c < u.side() as i64)
                && tree.contains(p.map(|c| c as u32));
            prop_assert_eq!(v, want, "{:?} at {:?}", order, p);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn runs_and_windows_k1((o, b) in obj_and_box::<1>()) { check_runs_and_windows(&o, b)?; }
    #[test]
    fn runs_and_windows_k2((o, b) in obj_and_box::<2>()) { check_runs_and_windows(&o, b)?; }
    #[test]
    fn runs_and_windows_k3((o, b) in obj_and_box::<3>()) { check_runs_and_windows(&o, b)?; }
    #[test]
    fn runs_and_windows_k4((o, b) in obj_and_box::<4>()) { check_runs_and_windows(&o, b)?; }
}

/// The whole universe of `to_dense` is the dense window of the universe, and the dense array.
#[test]
fn to_dense_is_the_universe_window() {
    let dense: Vec<bool> = (0..512u32).map(|i| (i * 37 + i / 7) % 5 < 2).collect();
    let tree = KTree::<3>::from_dense(3, &dense).unwrap();
    assert_eq!(tree.to_dense().unwrap(), dense);
    assert_eq!(
        dense_window(&tree, [0; 3], [8; 3], DenseOrder::FirstAxisFastest).unwrap(),
        dense
    );
    // Too large a window is refused before anything is allocated.
    let big = KTree::<3>::full(21).unwrap();
    assert!(dense_window(&big, [0; 3], [1 << 20; 3], DenseOrder::LastAxisFastest).is_err());
    assert_eq!(TreeStorage::voxel_count(&big), 1 << 63);
}
