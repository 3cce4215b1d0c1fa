//! Booleans, complement and interference against the dense reference in K = 1 … 4, plus algebraic laws
//! (De Morgan, A∖B = A∩¬B, xor = (A∖B)∪(B∖A)) and regularization.

use ktree_verify::objects;

use ktree::ops::{self, BoolOp, OpsError};
use ktree::KTree;
use objects::{pair, Obj};
use proptest::prelude::*;

fn check_booleans<const K: usize>(a: &Obj<K>, b: &Obj<K>) -> Result<(), TestCaseError> {
    let (ta, tb) = (a.tree(), b.tree());
    let (da, db) = (a.dense(), b.dense());
    for op in BoolOp::ALL {
        let out = ops::boolean(&ta, &tb, op).unwrap();
        out.check()
            .map_err(|e| TestCaseError::fail(format!("{op:?}: {e}")))?;
        let expect: Vec<bool> = da.iter().zip(&db).map(|(&x, &y)| op.apply(x, y)).collect();
        prop_assert_eq!(out.to_dense().unwrap(), expect.clone(), "{:?}", op);
        prop_assert_eq!(
            out,
            KTree::from_dense(a.level, &expect).unwrap(),
            "{:?} node for node",
            op
        );
    }
    let not_a = ops::complement(&ta);
    not_a.assert_well_formed();
    prop_assert_eq!(
        not_a.to_dense().unwrap(),
        da.iter().map(|&x| !x).collect::<Vec<_>>()
    );
    // Laws.
    let not_b = ops::complement(&tb);
    let u = ops::union(&ta, &tb).unwrap();
    prop_assert_eq!(
        ops::complement(&u),
        ops::intersection(&not_a, &not_b).unwrap()
    );
    let i = ops::intersection(&ta, &tb).unwrap();
    prop_assert_eq!(ops::complement(&i), ops::union(&not_a, &not_b).unwrap());
    prop_assert_eq!(
        ops::difference(&ta, &tb).unwrap(),
        ops::intersection(&ta, &not_b).unwrap()
    );
    let x = ops::symmetric_difference(&ta, &tb).unwrap();
    let x2 = ops::union(
        &ops::difference(&ta, &tb).unwrap(),
        &ops::difference(&tb, &ta).unwrap(),
    )
    .unwrap();
    prop_assert_eq!(x, x2);
    prop_assert_eq!(ops::complement(&not_a), ta.clone());
    // Interference agrees with the intersection.
    let overlap = da.iter().zip(&db).any(|(&x, &y)| x && y);
    prop_assert_eq!(ops::interferes(&ta, &tb).unwrap(), overlap);
    let cells = ops::overlap_cells(&ta, &tb).unwrap();
    prop_assert_eq!(cells, i.full_cells().collect::<Vec<_>>());
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(128))]
    #[test]
    fn booleans_match_dense_k1((a, b) in pair::<1>()) { check_booleans(&a, &b)?; }
    #[test]
    fn booleans_match_dense_k2((a, b) in pair::<2>()) { check_booleans(&a, &b)?; }
    #[test]
    fn booleans_match_dense_k3((a, b) in pair::<3>()) { check_booleans(&a, &b)?; }
    #[test]
    fn booleans_match_dense_k4((a, b) in pair::<4>()) { check_booleans(&a, &b)?; }
}

#[test]
fn different_levels_are_an_error() {
    let a = KTree::<3>::full(3).unwrap();
    let b = KTree::<3>::full(4).unwrap();
    assert!(matches!(
        ops::union(&a, &b).unwrap_err(),
        OpsError::LevelMismatch { left: 3, right: 4 }
    ));
    assert!(ops::interferes(&a, &b).is_err());
}

#[test]
fn touching_objects_have_an_empty_regularized_intersection() {
    // Two 2×4×4 slabs of a 4×4×4 universe meeting along the plane x = 2.
    let u = ktree::Universe::<3>::new(2).unwrap();
    let left: Vec<bool> = (0..64).map(|i| u.dense_point(i)[0] < 2).collect();
    let right: Vec<bool> = left.iter().map(|&x| !x).collect();
    let (a, b) = (
        KTree::<3>::from_dense(2, &left).unwrap(),
        KTree::<3>::from_dense(2, &right).unwrap(),
    );
    let i = ops::intersection(&a, &b).unwrap();
    assert_eq!(i, KTree::empty(2).unwrap());
    assert!(!ops::interferes(&a, &b).unwrap());
    assert_eq!(ops::union(&a, &b).unwrap(), KTree::full(2).unwrap());
}
