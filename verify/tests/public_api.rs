//! The public constructors take arbitrary input and answer with a value or an error, never a panic: cells,
//! ray sets, meshes, volumes, trees from raw words and levels, trees from cells, and `.ktree` bytes. Whatever
//! they accept is well formed, and the library's operations run on it without panicking.

use ktree::io::{read_ktree_any, write_ktree, write_ktree_v1};
use ktree::rays::RayError;
use ktree::solid::mesh::{MeshTransform, TriangleMesh};
use ktree::solid::volume::{Select, Volume};
use ktree::space::SpaceError;
use ktree::tree::PackedStates;
use ktree::{KTree, Ray, RaySet, Universe};
use ktree_verify::objects::object;
use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};
use std::sync::atomic::{AtomicU32, Ordering};

/// Small numbers most of the time, any `u32` sometimes.
fn coordinate() -> impl Strategy<Value = u32> {
    prop_oneof![4 => 0u32..20, 1 => any::<u32>()]
}

/// Levels where the work is small, and levels beyond every limit.
fn level() -> impl Strategy<Value = u32> {
    prop_oneof![4 => 0u32..6, 1 => 21u32..40]
}

/// Finite numbers most of the time, NaN and infinities sometimes.
fn real() -> impl Strategy<Value = f64> {
    prop_oneof![8 => -10.0..10.0f64, 1 => any::<f64>()]
}

/// Runs the read-only operations of a tree; none may panic.
fn exercise<const K: usize>(tree: &KTree<K>) {
    tree.assert_well_formed();
    let full: u128 = tree.full_cells().map(|c| c.volume()).sum();
    assert_eq!(full, tree.voxel_count());
    assert!(tree.leaves().count() as u64 <= tree.node_count());
    let _ = tree.contains([0; K]);
    let _ = tree.contains([u32::MAX; K]);
    // The queries answer on any tree, at any point, box or ray.
    assert!(!tree.contains_many(&[[0; K], [u32::MAX; K]])[1]);
    assert_eq!(tree.count([0; K], [u32::MAX; K]), tree.voxel_count());
    assert_eq!(tree.crop([0; K], [u32::MAX; K]), *tree);
    assert_eq!(tree.bounding_box().is_some(), tree.voxel_count() > 0);
    assert_eq!(
        tree.nearest([u32::MAX; K]).is_some(),
        tree.voxel_count() > 0
    );
    for (o, d) in [(-1e300, 1.0), (0.5, -1e-300), (1e9, -1e9), (0.0, 0.0)] {
        let _ = tree.cast_ray([o; K], [d; K], f64::MAX).unwrap();
    }
    let not = !tree;
    not.assert_well_formed();
    let union = (tree | &not).unwrap();
    assert_eq!(union, KTree::full(tree.level()).unwrap());
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    let back = read_ktree_any(&bytes, "tree.ktree")
        .unwrap()
        .into_dim::<K>();
    assert_eq!(back.ok().as_ref(), Some(tree));
}

/// The largest universe level for K = 3.
const MAX_LEVEL: u32 = ktree::max_level(3);

/// A valid cell: a universe level, a cell level no deeper than it, and an origin on the cell grid inside it.
fn valid_cell() -> impl Strategy<Value = (u32, u32, [u32; 3])> {
    (0..=MAX_LEVEL)
        .prop_flat_map(|universe| (Just(universe), 0..=universe))
        .prop_flat_map(|(universe, at)| {
            let cells_per_axis = 1u32 << at;
            let side = 1u32 << (universe - at);
            (
                Just(universe),
                Just(at),
                prop::array::uniform3(0..cells_per_axis),
            )
                .prop_map(move |(u, a, index)| (u, a, index.map(|i| i * side)))
        })
}

/// A cell with one thing wrong, and the error it must get.
#[derive(Debug, Clone, Copy)]
enum BadCell {
    /// The universe level is beyond `max_level(3)`.
    UniverseTooLarge,
    /// The cell level is deeper than the universe's.
    TooDeep,
    /// One origin coordinate is not a multiple of the cell's side.
    Misaligned,
    /// One origin coordinate is outside the universe.
    Outside,
}

/// A cell of the given kind of wrong: `(kind, universe level, cell level, origin)`.
fn bad_cell() -> impl Strategy<Value = (BadCell, u32, u32, [u32; 3])> {
    let valid = valid_cell();
    prop_oneof![
        (
            MAX_LEVEL + 1..=u32::MAX,
            any::<u32>(),
            prop::array::uniform3(coordinate())
        )
            .prop_map(|(u, a, o)| (BadCell::UniverseTooLarge, u, a, o)),
        (valid_cell(), 1..=u32::MAX - MAX_LEVEL).prop_map(|((u, _, o), deeper)| (
            BadCell::TooDeep,
            u,
            u + deeper,
            o
        )),
        // A cell of side 2 or more, with one coordinate moved off its grid (but inside the universe).
        (
            valid.prop_filter("side > 1", |&(u, a, _)| a < u),
            0usize..3,
            any::<u32>()
        )
            .prop_map(|((u, a, mut o), axis, shift)| {
                let side = 1u32 << (u - a);
                o[axis] += 1 + shift % (side - 1);
                (BadCell::Misaligned, u, a, o)
            }),
        (valid_cell(), 0usize..3, any::<u32>()).prop_map(|((u, a, mut o), axis, value)| {
            let side = 1u64 << u;
            o[axis] = (side + u64::from(value) % ((1u64 << 32) - side)) as u32;
            (BadCell::Outside, u, a, o)
        }),
    ]
}

/// A valid run in a level-`level` universe of K = 3.
fn valid_ray(level: u32) -> impl Strategy<Value = Ray<3>> {
    let side = 1u32 << level;
    (0..side, 0..side, 0..side)
        .prop_flat_map(move |(x, y, z1)| (Just([x, y, z1]), z1 + 1..=side))
        .prop_map(|(start, z2)| Ray::new(start, z2))
}

/// A level and up to 12 valid runs in it.
fn valid_rays() -> impl Strategy<Value = (u32, Vec<Ray<3>>)> {
    (0u32..6).prop_flat_map(|level| (Just(level), prop::collection::vec(valid_ray(level), 0..12)))
}

/// A run with one thing wrong.
#[derive(Debug, Clone, Copy)]
enum BadRay {
    /// A column coordinate outside the universe.
    ColumnOutside,
    /// `z1` or `z2` beyond the universe's side.
    RunOutside,
    /// `z2 ≤ z1`.
    EmptyRun,
}

/// A bad run of the given kind in a level-`level` universe.
fn bad_ray(level: u32) -> impl Strategy<Value = (BadRay, Ray<3>)> {
    let side = 1u32 << level;
    prop_oneof![
        (valid_ray(level), 0usize..2, side..=u32::MAX).prop_map(|(mut r, axis, value)| {
            r.start[axis] = value;
            (BadRay::ColumnOutside, r)
        }),
        (valid_ray(level), any::<bool>(), side + 1..=u32::MAX).prop_map(
            move |(mut r, at_start, value)| {
                if at_start {
                    r.start[2] = value;
                } else {
                    r.z2 = value;
                }
                (BadRay::RunOutside, r)
            }
        ),
        (0..=side)
            .prop_flat_map(move |z1| (valid_ray(level), Just(z1), 0..=z1))
            .prop_map(|(mut r, z1, z2)| {
                r.start[2] = z1;
                r.z2 = z2;
                (BadRay::EmptyRun, r)
            }),
    ]
}

/// Valid runs with one bad run inserted among them: `(level, runs, where the bad one is, its kind)`.
fn rays_with_one_bad() -> impl Strategy<Value = (u32, Vec<Ray<3>>, usize, BadRay)> {
    valid_rays()
        .prop_flat_map(|(level, rays)| {
            let n = rays.len();
            (Just(level), Just(rays), 0..=n, bad_ray(level))
        })
        .prop_map(|(level, mut rays, at, (kind, bad))| {
            rays.insert(at, bad);
            (level, rays, at, kind)
        })
}

proptest! {
    #[test]
    fn valid_cells_are_accepted((universe, at, origin) in valid_cell()) {
        let u = Universe::<3>::new(universe).unwrap();
        let c = u.cell(origin, at).unwrap();
        prop_assert_eq!(c.universe_level(), universe);
        prop_assert_eq!(c.level(), at);
        prop_assert_eq!(c.origin(), origin);
        prop_assert_eq!(c.side(), 1u64 << (universe - at));
        prop_assert!(c.origin().iter().all(|&o| u64::from(o) % c.side() == 0));
        prop_assert!(c.origin().iter().all(|&o| u64::from(o) < u.side()));
        prop_assert!(c.contains(origin));
    }

    #[test]
    fn bad_cells_are_rejected_with_their_error((kind, universe, at, origin) in bad_cell()) {
        match kind {
            BadCell::UniverseTooLarge => {
                let e = Universe::<3>::new(universe).unwrap_err();
                prop_assert!(matches!(e, SpaceError::LevelTooLarge { k: 3, level, max: MAX_LEVEL } if level == universe), "{e:?}");
            }
            BadCell::TooDeep | BadCell::Misaligned => {
                let e = Universe::<3>::new(universe).unwrap().cell(origin, at).unwrap_err();
                prop_assert!(matches!(&e, SpaceError::Misaligned { origin: o, level, universe_level } if o[..] == origin[..] && *level == at && *universe_level == universe), "{e:?}");
            }
            BadCell::Outside => {
                let e = Universe::<3>::new(universe).unwrap().cell(origin, at).unwrap_err();
                let axis = origin.iter().position(|&o| u64::from(o) >= 1u64 << universe).unwrap();
                prop_assert_eq!(e, SpaceError::OutOfUniverse { axis, value: origin[axis].into(), side: 1u64 << universe });
            }
        }
    }

    #[test]
    fn valid_ray_sets_are_accepted((level, rays) in valid_rays()) {
        let set = RaySet::<3>::from_rays(level, rays.iter().copied()).unwrap();
        // The dumbest reference: the set of voxels the runs cover.
        let voxels: std::collections::BTreeSet<[u32; 3]> = rays
            .iter()
            .flat_map(|r| (r.z1()..r.z2).map(move |z| [r.start[0], r.start[1], z]))
            .collect();
        prop_assert_eq!(set.voxel_count(), voxels.len() as u128);
        let tree = KTree::from_rays(&set);
        prop_assert_eq!(tree.voxel_count(), voxels.len() as u128);
        for &v in &voxels {
            prop_assert!(tree.contains(v));
        }
        exercise(&tree);
    }

    #[test]
    fn bad_ray_sets_are_rejected_with_their_error((level, rays, at, kind) in rays_with_one_bad()) {
        let e = RaySet::<3>::from_rays(level, rays.iter().copied()).unwrap_err();
        let bad = rays[at];
        let side = 1u64 << level;
        match kind {
            BadRay::ColumnOutside => {
                let axis = bad.start[..2].iter().position(|&c| u64::from(c) >= side).unwrap();
                prop_assert_eq!(e, RayError::ColumnOutside { index: at, axis, value: bad.start[axis], side });
            }
            BadRay::RunOutside => {
                prop_assert_eq!(e, RayError::RunOutside { index: at, z1: bad.z1(), z2: bad.z2, side });
            }
            BadRay::EmptyRun => {
                prop_assert_eq!(e, RayError::EmptyRun { index: at, z1: bad.z1(), z2: bad.z2 });
            }
        }
    }

    #[test]
    fn ray_sets_beyond_the_largest_level_are_rejected(level in MAX_LEVEL + 1..=u32::MAX, (_, rays) in valid_rays()) {
        let e = RaySet::<3>::from_rays(level, rays).unwrap_err();
        prop_assert!(matches!(e, RayError::Space(SpaceError::LevelTooLarge { level: l, .. }) if l == level), "{e:?}");
    }
}

/// Runs `check` on the cases of `strategy` (256, or `PROPTEST_CASES`); `check` answers whether the case was
/// accepted and so reached the checks. Panics with proptest's report if a check fails; returns how many
/// cases were accepted, and of how many.
fn accepted_of<S: Strategy>(
    strategy: S,
    check: impl Fn(S::Value) -> Result<bool, TestCaseError>,
) -> (u32, u32) {
    let config = ktree_verify::config(256);
    let cases = config.cases;
    let accepted = AtomicU32::new(0);
    let mut runner = TestRunner::new(config);
    if let Err(e) = runner.run(&strategy, |value| {
        if check(value)? {
            accepted.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    }) {
        panic!("{e}");
    }
    (accepted.into_inner(), cases)
}

/// Asserts that at least `1 / one_in` of the cases of a property were accepted, so that the checks behind
/// the acceptance ran (the strategies are built so that many more are).
fn assert_accepted((accepted, cases): (u32, u32), one_in: u32) {
    assert!(
        accepted >= cases / one_in,
        "only {accepted} of {cases} cases reached the checks (at least 1 in {one_in} expected)"
    );
}

#[test]
fn meshes_are_checked() {
    // Arbitrary vertices and indices, or a well-formed mesh: finite vertices, indices among them.
    let well_formed = (3usize..8)
        .prop_flat_map(|n| {
            (
                prop::collection::vec(prop::array::uniform3(-10.0..10.0f64), n),
                prop::collection::vec(prop::array::uniform3(0..n as u32), 1..8),
            )
        })
        .boxed();
    let arbitrary = (
        prop::collection::vec(prop::array::uniform3(real()), 0..8),
        prop::collection::vec(
            prop::array::uniform3(prop_oneof![0u32..8, any::<u32>()]),
            0..8,
        ),
    )
        .boxed();
    let strategy = (
        prop_oneof![arbitrary, well_formed],
        2u32..6,
        real(),
        prop::array::uniform3(real()),
    )
        .prop_map(|((v, t), level, scale, translate)| (v, t, level, scale, translate));
    let counts = accepted_of(
        strategy,
        |(vertices, triangles, level, scale, translate)| {
            let Ok(mesh) = TriangleMesh::new(vertices, triangles) else {
                return Ok(false);
            };
            let _ = (
                mesh.bounds(),
                mesh.signed_volume(),
                mesh.surface_area(),
                mesh.open_edges(),
            );
            let placements = [
                MeshTransform::fit(&mesh, level).ok(),
                Some(MeshTransform { scale, translate }),
            ];
            let mut voxelized = false;
            for p in placements.iter().flatten() {
                if let Ok(r) = mesh.to_rays(level, p) {
                    exercise(&KTree::from_rays(&r.rays));
                    voxelized = true;
                }
            }
            Ok(voxelized)
        },
    );
    println!("meshes voxelized: {counts:?}");
    assert_accepted(counts, 8);
}

#[test]
fn volumes_are_checked() {
    // Arbitrary shapes, levels and offsets, or a volume that fits its universe: sides 1 to 4, a level of
    // at least 3 and an offset that keeps it inside.
    let arbitrary = (
        prop::array::uniform3(prop_oneof![8 => 0usize..5, 1 => any::<usize>()]),
        prop_oneof![3 => Just(0usize), 1 => 0usize..3],
        level(),
        prop::array::uniform3(coordinate()),
    )
        .boxed();
    let fitting = (
        prop::array::uniform3(1usize..5),
        3u32..6,
        prop::array::uniform3(0u32..5),
    )
        .prop_map(|(shape, level, offset)| (shape, 0, level, offset))
        .boxed();
    let strategy = (
        prop_oneof![arbitrary, fitting],
        prop::collection::vec(real(), 130),
        any::<bool>(),
    )
        .prop_map(|((shape, short, level, offset), samples, label)| {
            (shape, samples, short, level, offset, label)
        });
    let counts = accepted_of(strategy, |(shape, samples, short, level, offset, label)| {
        // Mostly as many samples as the shape has voxels, sometimes fewer.
        let n = shape
            .iter()
            .try_fold(1usize, |p, &s| p.checked_mul(s))
            .unwrap_or(usize::MAX);
        let values = samples[..n.min(samples.len()).saturating_sub(short)].to_vec();
        let Ok(volume) = Volume::new(shape, values, [1.0; 3]) else {
            return Ok(false);
        };
        let select = if label {
            Select::Label(1.0)
        } else {
            Select::AtLeast(0.0)
        };
        let _ = volume.fitting_level();
        let Ok(rays) = volume.to_rays(level, offset, select) else {
            return Ok(false);
        };
        prop_assert_eq!(rays.voxel_count(), volume.count(select) as u128);
        exercise(&KTree::from_rays(&rays));
        Ok(true)
    });
    println!("volumes voxelized: {counts:?}");
    assert_accepted(counts, 8);
}

#[test]
fn trees_from_raw_words_are_checked() {
    // Arbitrary words, or the words of a real tree (which must be accepted).
    let arbitrary = (
        level(),
        prop::collection::vec(
            (prop::collection::vec(any::<u64>(), 0..3), 0usize..70),
            0..4,
        ),
    )
        .boxed();
    let real_tree = object::<2>()
        .prop_map(|obj| {
            let tree = obj.tree();
            let levels = (0..tree.depth_count())
                .map(|d| {
                    (
                        tree.level_states(d).words().to_vec(),
                        tree.level_states(d).len(),
                    )
                })
                .collect::<Vec<_>>();
            (obj.level, levels)
        })
        .boxed();
    let strategy = prop_oneof![arbitrary, real_tree];
    let counts = accepted_of(strategy, |(level, raw)| {
        let levels: Result<Vec<PackedStates>, _> = raw
            .into_iter()
            .map(|(words, len)| PackedStates::from_words(words, len))
            .collect();
        let Ok(Ok(tree)) = levels.map(|levels| KTree::<2>::from_level_states(level, levels)) else {
            return Ok(false);
        };
        exercise(&tree);
        Ok(true)
    });
    println!("trees from raw words: {counts:?}");
    assert_accepted(counts, 4);
}

#[test]
fn trees_from_changed_levels_are_checked() {
    let strategy = (
        object::<2>(),
        any::<prop::sample::Index>(),
        any::<prop::sample::Index>(),
    );
    let counts = accepted_of(strategy, |(obj, depth, bit)| {
        // A real tree with one bit of one level flipped: sometimes still a tree, mostly not.
        let tree = obj.tree();
        let mut levels: Vec<(Vec<u64>, usize)> = (0..tree.depth_count())
            .map(|d| {
                (
                    tree.level_states(d).words().to_vec(),
                    tree.level_states(d).len(),
                )
            })
            .collect();
        let d = depth.index(levels.len());
        let bits = levels[d].0.len() * 64;
        if bits == 0 {
            return Ok(false);
        }
        let b = bit.index(bits);
        levels[d].0[b / 64] ^= 1 << (b % 64);
        let levels: Result<Vec<PackedStates>, _> = levels
            .into_iter()
            .map(|(words, len)| PackedStates::from_words(words, len))
            .collect();
        let Ok(Ok(changed)) = levels.map(|levels| KTree::<2>::from_level_states(obj.level, levels))
        else {
            return Ok(false);
        };
        exercise(&changed);
        Ok(true)
    });
    println!("trees from changed levels: {counts:?}");
    assert_accepted(counts, 128);
}

#[test]
fn trees_from_cells_are_checked() {
    let strategy = (
        0u32..5,
        prop::collection::vec((prop::array::uniform2(0u32..16), 0u32..5), 0..12),
    );
    let counts = accepted_of(strategy, |(level, cells)| {
        let u = Universe::<2>::new(level).unwrap();
        let cells: Vec<_> = cells
            .into_iter()
            .filter_map(|(o, l)| u.cell(o, l).ok())
            .collect();
        let Ok(tree) = KTree::from_cells(u, &cells) else {
            return Ok(false);
        };
        let given: u128 = cells.iter().map(|c| c.volume()).sum();
        prop_assert_eq!(tree.voxel_count(), given);
        for c in &cells {
            prop_assert!(tree.contains(c.origin()));
        }
        exercise(&tree);
        Ok(true)
    });
    println!("trees from cells: {counts:?}");
    assert_accepted(counts, 8);
}

/// Arbitrary bytes, or a real `.ktree` file whole or cut.
fn ktree_bytes() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..120),
        (object::<3>(), any::<prop::sample::Index>(), any::<bool>()).prop_map(
            |(obj, cut, whole)| {
                let mut bytes = Vec::new();
                write_ktree(&mut bytes, &obj.tree()).unwrap();
                if !whole {
                    bytes.truncate(cut.index(bytes.len()));
                }
                bytes
            }
        ),
    ]
}

#[test]
fn ktree_bytes_are_checked() {
    let counts = accepted_of(ktree_bytes(), |bytes| {
        let Ok(tree) = read_ktree_any(&bytes, "any.ktree") else {
            return Ok(false);
        };
        ktree::with_dim!(&tree, AnyTree, t => exercise(t));
        Ok(true)
    });
    println!("ktree bytes read: {counts:?}");
    assert_accepted(counts, 16);
}

#[test]
fn changed_ktree_files_with_a_fixed_checksum_are_checked() {
    // A byte changed, or (one case in four) none: the file as written, which must be read.
    let change = prop_oneof![1 => Just(None), 3 => any::<u8>().prop_map(Some)];
    let strategy = (object::<3>(), any::<prop::sample::Index>(), change);
    let counts = accepted_of(strategy, |(obj, at, value)| {
        // Change one byte, then make the checksum agree, so that the structural checks must catch it.
        let mut bytes = Vec::new();
        write_ktree_v1(&mut bytes, &obj.tree()).unwrap();
        let crc_at = bytes.len() - 4;
        if let Some(value) = value {
            bytes[at.index(crc_at)] = value;
        }
        let crc = crc_of(&bytes[..crc_at]);
        bytes[crc_at..].copy_from_slice(&crc.to_le_bytes());
        let read = read_ktree_any(&bytes, "changed.ktree");
        prop_assert!(
            value.is_some() || read.is_ok(),
            "an unchanged file is refused: {read:?}"
        );
        let Ok(tree) = read else {
            return Ok(false);
        };
        ktree::with_dim!(&tree, AnyTree, t => exercise(t));
        Ok(true)
    });
    println!("changed ktree files read: {counts:?}");
    assert_accepted(counts, 8);
}

/// CRC-32 (IEEE), bit by bit: the checksum of `.ktree` files.
fn crc_of(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}
