//! The operations and the file formats at the largest level of each K (`ktree::max_level`: 31, 31, 21, 16
//! for K = 1 … 4), where coordinates, voxel counts and moments need the 64- and 128-bit paths. The objects
//! are a few boxes placed anywhere ([`sparse`]); each result is checked against a reference computed on
//! the boxes themselves: membership at the boxes' corners, just outside their faces and at random points,
//! exact voxel counts, bounding boxes and first moments.

use ktree_verify::sparse;

use ktree::io::{read_ktree, read_rays, write_ktree, write_rays};
use ktree::ops::{self, AxisMap, BoolOp};
use ktree::stacking::paper::stack;
use ktree::AnyRaySet;
use ktree::{KTree, RaySet};
use proptest::prelude::*;
use sparse::{boxes, point, union_volume, Boxes, Cuboid};

/// The tree of `b`, built by stacking its rays, after checking it is well formed.
fn tree<const K: usize>(b: &Boxes<K>) -> Result<KTree<K>, TestCaseError> {
    let t = stack(&b.rays());
    t.check().map_err(|e| TestCaseError::fail(e.to_string()))?;
    Ok(t)
}

fn to_u32<const K: usize>(p: [u64; K]) -> [u32; K] {
    p.map(|v| u32::try_from(v).expect("a voxel of the universe"))
}

/// `out` holds exactly the voxels `expect` says at every probe point.
fn same_at<const K: usize>(
    out: &KTree<K>,
    probes: impl IntoIterator<Item = [u64; K]>,
    expect: impl Fn([u64; K]) -> bool,
) -> Result<(), TestCaseError> {
    for p in probes {
        prop_assert_eq!(out.contains(to_u32(p)), expect(p), "at {:?}", p);
    }
    Ok(())
}

/// The universe's voxel count `U^K`.
fn universe_volume<const K: usize>(level: u32) -> u128 {
    1u128 << (level as usize * K)
}

fn check_build<const K: usize>(a: &Boxes<K>, p: [u64; K]) -> Result<(), TestCaseError> {
    let t = tree(a)?;
    prop_assert_eq!(t.level(), ktree::max_level(K));
    prop_assert_eq!(t.voxel_count(), a.voxel_count());
    prop_assert_eq!(a.rays().voxel_count(), a.voxel_count());
    same_at(&t, a.probe_points().into_iter().chain([p]), |q| {
        a.contains(q)
    })?;
    let bx = t
        .bounding_box()
        .map(|(lo, hi)| (lo.map(u64::from), hi.map(u64::from)));
    prop_assert_eq!(bx, a.bounding_box());
    Ok(())
}

fn check_booleans<const K: usize>(
    a: &Boxes<K>,
    b: &Boxes<K>,
    p: [u64; K],
) -> Result<(), TestCaseError> {
    let (ta, tb) = (tree(a)?, tree(b)?);
    let pairs: Vec<Cuboid<K>> = a
        .boxes
        .iter()
        .flat_map(|x| b.boxes.iter().map(move |y| x.meet(y)))
        .collect();
    let (na, nb, both) = (a.voxel_count(), b.voxel_count(), union_volume(&pairs));
    let probes: Vec<[u64; K]> = a
        .probe_points()
        .into_iter()
        .chain(b.probe_points())
        .chain([p])
        .collect();
    for op in BoolOp::ALL {
        let (count, rule): (u128, fn(bool, bool) -> bool) = match op {
            BoolOp::Union => (na + nb - both, |x, y| x || y),
            BoolOp::Intersection => (both, |x, y| x && y),
            BoolOp::Difference => (na - both, |x, y| x && !y),
            BoolOp::SymmetricDifference => (na + nb - 2 * both, |x, y| x != y),
        };
        let out = ops::boolean(&ta, &tb, op).map_err(|e| TestCaseError::fail(e.to_string()))?;
        out.check()
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(out.voxel_count(), count, "{:?}", op);
        same_at(&out, probes.iter().copied(), |q| {
            rule(a.contains(q), b.contains(q))
        })?;
    }
    // The complement holds nearly the whole universe: 2^64 voxels for K = 4 need 128 bits.
    let not_a = ops::complement(&ta);
    not_a
        .check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(not_a.voxel_count(), universe_volume::<K>(a.level) - na);
    same_at(&not_a, probes.iter().copied(), |q| !a.contains(q))?;
    prop_assert_eq!(
        ops::mass_properties(&not_a).unwrap().volume,
        universe_volume::<K>(a.level) - na
    );
    // The ray sets' own Booleans agree with the trees'.
    let ray_union = a
        .rays()
        .union(&b.rays())
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(stack(&ray_union), ops::union(&ta, &tb).unwrap());
    Ok(())
}

fn check_translate<const K: usize>(
    a: &Boxes<K>,
    shift: [i64; K],
    p: [u64; K],
) -> Result<(), TestCaseError> {
    let side = a.side() as i64;
    let moved = Boxes {
        level: a.level,
        boxes: a
            .boxes
            .iter()
            .map(|b| Cuboid {
                lo: std::array::from_fn(|i| (b.lo[i] as i64 + shift[i]).clamp(0, side) as u64),
                hi: std::array::from_fn(|i| (b.hi[i] as i64 + shift[i]).clamp(0, side) as u64),
            })
            .collect(),
    };
    let out = ops::translate(&tree(a)?, shift).unwrap();
    out.check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(out.voxel_count(), moved.voxel_count());
    let probes = moved.probe_points().into_iter().chain([p]);
    same_at(&out, probes, |q| moved.contains(q))?;
    // Translating back restores every voxel that stayed inside.
    let back = ops::translate(&out, shift.map(|v| -v)).unwrap();
    prop_assert_eq!(back.voxel_count(), moved.voxel_count());
    same_at(&back, a.probe_points(), |q| {
        a.contains(q) && moved.contains(std::array::from_fn(|i| (q[i] as i64 + shift[i]) as u64))
    })?;
    Ok(())
}

fn check_axis_map<const K: usize>(
    a: &Boxes<K>,
    pick: usize,
    p: [u64; K],
) -> Result<(), TestCaseError> {
    let all = AxisMap::<K>::all();
    let map = all[pick % all.len()];
    let side = a.side();
    let image = |q: [u64; K]| -> [u64; K] { map.map_point(to_u32(q), side as u32).map(u64::from) };
    let mapped = Boxes {
        level: a.level,
        boxes: a
            .boxes
            .iter()
            .map(|b| {
                let (x, y) = (image(b.lo), image(b.hi.map(|v| v - 1)));
                Cuboid {
                    lo: std::array::from_fn(|i| x[i].min(y[i])),
                    hi: std::array::from_fn(|i| x[i].max(y[i]) + 1),
                }
            })
            .collect(),
    };
    let out = ops::rotate_axes(&tree(a)?, &map).unwrap();
    out.check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(out.voxel_count(), a.voxel_count());
    let probes = mapped.probe_points().into_iter().chain([p]);
    same_at(&out, probes, |q| mapped.contains(q))?;
    // Every probe of the source lands where the map sends it.
    for q in a.probe_points() {
        prop_assert_eq!(out.contains(to_u32(image(q))), a.contains(q));
    }
    Ok(())
}

/// The voxels `q` of the scaled object whose source voxel `(q + ½)·den/num` lies in `[lo, hi)` along one
/// axis: an interval, since the source voxel grows with `q`.
fn scaled_interval(lo: u64, hi: u64, num: u64, den: u64, side: u64) -> (u64, u64) {
    let source = |q: u64| (2 * u128::from(q) + 1) * u128::from(den) / (2 * u128::from(num));
    let first_at_least = |v: u64| -> u64 {
        // The smallest q in [0, side] with source(q) >= v (side when none).
        let (mut a, mut b) = (0u64, side);
        while a < b {
            let m = a + (b - a) / 2;
            if source(m) >= u128::from(v) {
                b = m;
            } else {
                a = m + 1;
            }
        }
        a
    };
    (first_at_least(lo), first_at_least(hi))
}

fn check_scale<const K: usize>(
    a: &Boxes<K>,
    num: u32,
    den: u32,
    p: [u64; K],
) -> Result<(), TestCaseError> {
    let side = a.side();
    let scaled = Boxes {
        level: a.level,
        boxes: a
            .boxes
            .iter()
            .map(|b| {
                let ranges: [(u64, u64); K] = std::array::from_fn(|i| {
                    scaled_interval(b.lo[i], b.hi[i], u64::from(num), u64::from(den), side)
                });
                Cuboid {
                    lo: ranges.map(|r| r.0),
                    hi: ranges.map(|r| r.1),
                }
            })
            .collect(),
    };
    let out = ops::scale(&tree(a)?, num, den).map_err(|e| TestCaseError::fail(e.to_string()))?;
    out.check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(out.voxel_count(), scaled.voxel_count());
    let back = |q: u64| (2 * q + 1) * u64::from(den) / (2 * u64::from(num));
    let probes = scaled.probe_points().into_iter().chain([p]);
    same_at(&out, probes, |q| a.contains(q.map(back)))?;
    Ok(())
}

fn check_zoom<const K: usize>(a: &Boxes<K>, path: Vec<usize>) -> Result<(), TestCaseError> {
    let path: Vec<usize> = path.into_iter().map(|c| c % (1 << K)).collect();
    let level = a.level - path.len() as u32;
    let mut offset = [0u64; K];
    for (d, &c) in path.iter().enumerate() {
        for (i, o) in offset.iter_mut().enumerate() {
            if c >> i & 1 == 1 {
                *o += 1 << (a.level as usize - 1 - d);
            }
        }
    }
    let cell = Cuboid {
        lo: offset,
        hi: offset.map(|o| o + (1 << level)),
    };
    let kept = Boxes {
        level,
        boxes: a
            .boxes
            .iter()
            .map(|b| {
                let m = b.meet(&cell);
                if m.is_empty() {
                    Cuboid {
                        lo: [0; K],
                        hi: [0; K],
                    }
                } else {
                    Cuboid {
                        lo: std::array::from_fn(|i| m.lo[i] - offset[i]),
                        hi: std::array::from_fn(|i| m.hi[i] - offset[i]),
                    }
                }
            })
            .collect(),
    };
    let out = ops::zoom(&tree(a)?, &path).map_err(|e| TestCaseError::fail(e.to_string()))?;
    out.check()
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(out.level(), level);
    prop_assert_eq!(out.voxel_count(), kept.voxel_count());
    same_at(&out, kept.probe_points(), |q| kept.contains(q))?;
    Ok(())
}

fn check_mass<const K: usize>(a: &Boxes<K>) -> Result<(), TestCaseError> {
    let m = ops::mass_properties(&tree(a)?).unwrap();
    let volume = a.voxel_count();
    prop_assert_eq!(m.volume, volume);
    for axis in 0..K {
        let expect = a.doubled_first_moment(axis) as f64 / (2.0 * volume as f64);
        let err = (m.centroid[axis] - expect).abs();
        prop_assert!(
            err <= 1e-9 * expect.abs().max(1.0),
            "centroid axis {}: {} vs {}",
            axis,
            m.centroid[axis],
            expect
        );
        // Every voxel contributes at least its own 1/12 about its centre, whatever the object's shape.
        let least = volume as f64 / 12.0;
        prop_assert!(
            m.central_moments[axis][axis] >= least * (1.0 - 1e-9),
            "central moment axis {}: {} < {}",
            axis,
            m.central_moments[axis][axis],
            least
        );
    }
    Ok(())
}

/// The smallest distance between voxel centres of two boxes.
fn box_distance<const K: usize>(x: &Cuboid<K>, y: &Cuboid<K>) -> f64 {
    let squared: u128 = (0..K)
        .map(|i| {
            let gap = if y.lo[i] >= x.hi[i] {
                y.lo[i] - (x.hi[i] - 1)
            } else if x.lo[i] >= y.hi[i] {
                x.lo[i] - (y.hi[i] - 1)
            } else {
                0
            };
            u128::from(gap) * u128::from(gap)
        })
        .sum();
    (squared as f64).sqrt()
}

fn check_interference<const K: usize>(a: &Boxes<K>, b: &Boxes<K>) -> Result<(), TestCaseError> {
    let (ta, tb) = (tree(a)?, tree(b)?);
    let pairs: Vec<Cuboid<K>> = a
        .boxes
        .iter()
        .flat_map(|x| b.boxes.iter().map(move |y| x.meet(y)))
        .collect();
    let both = union_volume(&pairs);
    prop_assert_eq!(ops::interferes(&ta, &tb).unwrap(), both > 0);
    let cells = ops::overlap_cells(&ta, &tb).unwrap();
    let covered: u128 = cells.iter().map(|c| c.volume()).sum();
    prop_assert_eq!(covered, both);
    for c in &cells {
        let corner = c.origin().map(u64::from);
        prop_assert!(
            a.contains(corner) && b.contains(corner),
            "overlap cell {:?}",
            c
        );
    }
    let expect = a
        .boxes
        .iter()
        .flat_map(|x| b.boxes.iter().map(move |y| box_distance(x, y)))
        .fold(f64::INFINITY, f64::min);
    let got = ops::min_separation(&ta, &tb)
        .unwrap()
        .expect("both objects are non-empty");
    prop_assert!(
        (got - expect).abs() <= 1e-9 * expect.max(1.0),
        "separation {} vs {}",
        got,
        expect
    );
    Ok(())
}

fn check_files<const K: usize>(a: &Boxes<K>, b: &Boxes<K>) -> Result<(), TestCaseError>
where
    AnyRaySet: From<RaySet<K>>,
{
    // A sparse object and a nearly full one (the complement of the other).
    let objects = [tree(a)?, ops::complement(&tree(b)?)];
    for t in objects {
        let mut bytes = Vec::new();
        write_ktree(&mut bytes, &t).unwrap();
        let back =
            read_ktree::<K>(&bytes, "mem").map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(back == t, "tree changed through a .ktree round trip");
        prop_assert_eq!(back.voxel_count(), t.voxel_count());
    }
    let rays = a.rays();
    let mut text = Vec::new();
    write_rays(&mut text, &rays).unwrap();
    let back = read_rays(&text[..], "mem").map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!(
        back == AnyRaySet::from(rays),
        "rays changed through the text format"
    );
    Ok(())
}

fn shift<const K: usize>() -> impl Strategy<Value = [i64; K]> {
    let side = 1i64 << ktree::max_level(K);
    // Small shifts, and shifts of any size up to the side in either direction.
    prop::array::uniform::<_, K>(prop_oneof![-3i64..=3, -side..=side])
}

fn path<const K: usize>() -> impl Strategy<Value = Vec<usize>> {
    prop::collection::vec(0usize..16, 0..=ktree::max_level(K) as usize)
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test] fn build_k1(a in boxes::<1>(), p in point::<1>()) { check_build(&a, p)?; }
    #[test] fn build_k2(a in boxes::<2>(), p in point::<2>()) { check_build(&a, p)?; }
    #[test] fn build_k3(a in boxes::<3>(), p in point::<3>()) { check_build(&a, p)?; }
    #[test] fn build_k4(a in boxes::<4>(), p in point::<4>()) { check_build(&a, p)?; }

    #[test] fn booleans_k1(a in boxes::<1>(), b in boxes::<1>(), p in point::<1>()) { check_booleans(&a, &b, p)?; }
    #[test] fn booleans_k2(a in boxes::<2>(), b in boxes::<2>(), p in point::<2>()) { check_booleans(&a, &b, p)?; }
    #[test] fn booleans_k3(a in boxes::<3>(), b in boxes::<3>(), p in point::<3>()) { check_booleans(&a, &b, p)?; }
    #[test] fn booleans_k4(a in boxes::<4>(), b in boxes::<4>(), p in point::<4>()) { check_booleans(&a, &b, p)?; }

    #[test] fn translate_k1(a in boxes::<1>(), t in shift::<1>(), p in point::<1>()) { check_translate(&a, t, p)?; }
    #[test] fn translate_k2(a in boxes::<2>(), t in shift::<2>(), p in point::<2>()) { check_translate(&a, t, p)?; }
    #[test] fn translate_k3(a in boxes::<3>(), t in shift::<3>(), p in point::<3>()) { check_translate(&a, t, p)?; }
    #[test] fn translate_k4(a in boxes::<4>(), t in shift::<4>(), p in point::<4>()) { check_translate(&a, t, p)?; }

    #[test] fn axis_maps_k1(a in boxes::<1>(), g in 0usize..1000, p in point::<1>()) { check_axis_map(&a, g, p)?; }
    #[test] fn axis_maps_k2(a in boxes::<2>(), g in 0usize..1000, p in point::<2>()) { check_axis_map(&a, g, p)?; }
    #[test] fn axis_maps_k3(a in boxes::<3>(), g in 0usize..1000, p in point::<3>()) { check_axis_map(&a, g, p)?; }
    #[test] fn axis_maps_k4(a in boxes::<4>(), g in 0usize..1000, p in point::<4>()) { check_axis_map(&a, g, p)?; }

    #[test] fn scale_k1(a in boxes::<1>(), n in 1u32..6, d in 1u32..6, p in point::<1>()) { check_scale(&a, n, d, p)?; }
    #[test] fn scale_k2(a in boxes::<2>(), n in 1u32..6, d in 1u32..6, p in point::<2>()) { check_scale(&a, n, d, p)?; }
    #[test] fn scale_k3(a in boxes::<3>(), n in 1u32..6, d in 1u32..6, p in point::<3>()) { check_scale(&a, n, d, p)?; }
    #[test] fn scale_k4(a in boxes::<4>(), n in 1u32..6, d in 1u32..6, p in point::<4>()) { check_scale(&a, n, d, p)?; }

    #[test] fn zoom_k1(a in boxes::<1>(), path in path::<1>()) { check_zoom(&a, path)?; }
    #[test] fn zoom_k2(a in boxes::<2>(), path in path::<2>()) { check_zoom(&a, path)?; }
    #[test] fn zoom_k3(a in boxes::<3>(), path in path::<3>()) { check_zoom(&a, path)?; }
    #[test] fn zoom_k4(a in boxes::<4>(), path in path::<4>()) { check_zoom(&a, path)?; }

    #[test] fn mass_k1(a in boxes::<1>()) { check_mass(&a)?; }
    #[test] fn mass_k2(a in boxes::<2>()) { check_mass(&a)?; }
    #[test] fn mass_k3(a in boxes::<3>()) { check_mass(&a)?; }
    #[test] fn mass_k4(a in boxes::<4>()) { check_mass(&a)?; }

    #[test] fn interference_k1(a in boxes::<1>(), b in boxes::<1>()) { check_interference(&a, &b)?; }
    #[test] fn interference_k2(a in boxes::<2>(), b in boxes::<2>()) { check_interference(&a, &b)?; }
    #[test] fn interference_k3(a in boxes::<3>(), b in boxes::<3>()) { check_interference(&a, &b)?; }
    #[test] fn interference_k4(a in boxes::<4>(), b in boxes::<4>()) { check_interference(&a, &b)?; }

    #[test] fn files_k1(a in boxes::<1>(), b in boxes::<1>()) { check_files(&a, &b)?; }
    #[test] fn files_k2(a in boxes::<2>(), b in boxes::<2>()) { check_files(&a, &b)?; }
    #[test] fn files_k3(a in boxes::<3>(), b in boxes::<3>()) { check_files(&a, &b)?; }
    #[test] fn files_k4(a in boxes::<4>(), b in boxes::<4>()) { check_files(&a, &b)?; }
}
