//! An occupancy map read in place from its `.ktree` file ([`MappedMap`]) answers as the map in memory:
//! the same states at points, the same ray casts (OctoMap's `castRay`, with and without unknown voxels
//! stopping rays, with and without a range) and the same occupied, free and unknown parts; a damaged file
//! is an error naming it, and a tree that is not a map is refused.

use ktree::io::ktree::{read_map_ktree, write_map_ktree_file, MappedMap};
use ktree::map::{OccupancyMap, SensorModel};
use proptest::prelude::*;

/// A map of a few scans of random points around the origin, each from its own sensor origin.
fn map_of(resolution: f64, scans: &[(Vec<[f32; 3]>, [f32; 3])]) -> OccupancyMap<3> {
    let mut map = OccupancyMap::<3>::new(resolution).unwrap();
    for (points, origin) in scans {
        map.insert(points, *origin, Some(3.0)).unwrap();
    }
    map
}

fn point() -> impl Strategy<Value = [f32; 3]> {
    prop::array::uniform3(-2.0f32..2.0)
}

fn scans() -> impl Strategy<Value = Vec<(Vec<[f32; 3]>, [f32; 3])>> {
    prop::collection::vec(
        (
            prop::collection::vec(point(), 1..60),
            prop::array::uniform3(-0.5f32..0.5),
        ),
        1..4,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn a_mapped_map_answers_as_the_map_in_memory(
        resolution in prop::sample::select(vec![0.05, 0.1, 0.25]),
        scans in scans(),
        probes in prop::collection::vec(point(), 1..200),
        directions in prop::collection::vec(prop::array::uniform3(-1.0f32..1.0), 1..40),
    ) {
        let map = map_of(resolution, &scans);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.ktree");
        write_map_ktree_file(&path, &map).unwrap();
        let mapped = MappedMap::open(&path, SensorModel::default()).unwrap();
        let view = mapped.view();
        prop_assert_eq!(view.grid(), map.grid());
        prop_assert_eq!(view.states(&probes).unwrap(), map.states(&probes));
        for (origin, direction) in probes.iter().zip(&directions) {
            for (ignore_unknown, range) in [(false, -1.0), (true, -1.0), (true, 1.5)] {
                prop_assert_eq!(
                    view.cast_ray(*origin, *direction, ignore_unknown, range).unwrap(),
                    map.cast_ray(*origin, *direction, ignore_unknown, range)
                );
            }
        }
        prop_assert_eq!(view.occupied().unwrap(), map.occupied());
        prop_assert_eq!(view.free().unwrap(), map.free());
        prop_assert_eq!(view.unknown().unwrap(), map.unknown());
        let bytes = std::fs::read(&path).unwrap();
        prop_assert_eq!(read_map_ktree(&bytes, "map.ktree", SensorModel::default()).unwrap(), map);
    }
}

#[test]
fn a_damaged_map_file_or_a_tree_that_is_no_map_is_an_error_naming_the_file() {
    let map = map_of(0.1, &[(vec![[1.0, 0.5, 0.2], [-1.0, 0.3, 0.9]], [0.0; 3])]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.ktree");
    write_map_ktree_file(&path, &map).unwrap();
    let good = std::fs::read(&path).unwrap();
    // Every cut of the file is refused when opened (its length and checksums are checked).
    for cut in [1, 17, good.len() / 2, good.len() - 1] {
        let short = dir.path().join(format!("cut{cut}.ktree"));
        std::fs::write(&short, &good[..cut]).unwrap();
        let e = MappedMap::open(&short, SensorModel::default()).unwrap_err();
        assert!(e.to_string().contains(&format!("cut{cut}.ktree")), "{e}");
    }
    // The log-odds of a map in another frame (unit voxels at the origin) are no map.
    let plain = dir.path().join("plain.ktree");
    ktree::io::ktree::v3::write_valued_ktree_file(&plain, map.log_odds()).unwrap();
    let e = MappedMap::open(&plain, SensorModel::default()).unwrap_err();
    assert!(e.to_string().contains("not an occupancy map"), "{e}");
    let e = read_map_ktree(
        &std::fs::read(&plain).unwrap(),
        "plain.ktree",
        SensorModel::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("not an occupancy map"), "{e}");
}
