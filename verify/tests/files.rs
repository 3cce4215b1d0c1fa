//! Round trips through the file formats for K = 1 … 4: `.ktree` files give back the same tree node for
//! node, ray text files give back the same ray set; damaged files are rejected, never accepted or panicked on.

use ktree_verify::cases;

use cases::{ray_sets, Case};
use ktree::io::{read_ktree, read_ktree_any, read_rays, write_ktree_v1, write_rays};
use ktree::stacking::paper::stack;
use ktree::AnyRaySet;
use proptest::prelude::*;

fn round_trips<const K: usize>(
    case: &Case<K>,
    damage_at: usize,
    damage_bit: u8,
) -> Result<(), TestCaseError>
where
    AnyRaySet: From<ktree::RaySet<K>>,
{
    let tree = stack(&case.rays);
    let mut bytes = Vec::new();
    write_ktree_v1(&mut bytes, &tree).unwrap();
    prop_assert_eq!(
        bytes.len() as u64,
        40 + 8 * tree.depth_count() as u64 + tree.bytes_at_two_bits() + 4
    );
    let back = read_ktree::<K>(&bytes, "mem").map_err(|e| TestCaseError::fail(e.to_string()))?;
    back.assert_well_formed();
    prop_assert!(back == tree, "tree changed through a .ktree round trip");
    // Any single flipped bit and any truncation is an error, not a panic or a different tree.
    let mut bad = bytes.clone();
    let at = damage_at % bad.len();
    bad[at] ^= 1 << (damage_bit % 8);
    prop_assert!(
        read_ktree_any(&bad, "bad").is_err(),
        "bit flip at byte {} accepted",
        at
    );
    prop_assert!(
        read_ktree_any(&bytes[..at], "cut").is_err(),
        "truncation at {} accepted",
        at
    );
    // Ray text.
    let mut text = Vec::new();
    write_rays(&mut text, &case.rays).unwrap();
    let rays = read_rays(&text[..], "mem").map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(
        rays == AnyRaySet::from(case.rays.clone()),
        "rays changed through the text format"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(128))]

    #[test]
    fn files_round_trip_k1(case in ray_sets::<1>(), at in any::<usize>(), bit in any::<u8>()) { round_trips(&case, at, bit)?; }

    #[test]
    fn files_round_trip_k2(case in ray_sets::<2>(), at in any::<usize>(), bit in any::<u8>()) { round_trips(&case, at, bit)?; }

    #[test]
    fn files_round_trip_k3(case in ray_sets::<3>(), at in any::<usize>(), bit in any::<u8>()) { round_trips(&case, at, bit)?; }

    #[test]
    fn files_round_trip_k4(case in ray_sets::<4>(), at in any::<usize>(), bit in any::<u8>()) { round_trips(&case, at, bit)?; }

    /// Arbitrary text never panics the ray reader.
    #[test]
    fn ray_reader_never_panics(text in "(#[^\n]*\n|[0-9 x-]{0,12}\n){0,6}") {
        let _ = read_rays(text.as_bytes(), "fuzz");
    }

    /// Arbitrary bytes after a valid header never panic the tree reader.
    #[test]
    fn tree_reader_never_panics(tail in prop::collection::vec(any::<u8>(), 0..64), k in 0u8..6, l in 0u8..24, version in 1u16..=2) {
        let mut bytes = ktree::io::MAGIC.to_vec();
        bytes.extend_from_slice(&version.to_le_bytes());
        bytes.extend_from_slice(&[k, l, 0, 0]);
        bytes.extend_from_slice(&tail);
        let _ = read_ktree_any(&bytes, "fuzz");
    }
}
