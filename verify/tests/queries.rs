//! The questions asked of a map ([`ktree::query`]) against the simplest references, for K = 1 … 4:
//! point queries, counts, boxes and crops against the dense array; ray casts against a brute-force march
//! over every full voxel in exact rational arithmetic; nearest voxels against brute force over every full
//! voxel; the same at the largest level of each K (references computed on the boxes themselves); and a
//! `.ktree` file read through its map answers as the tree in memory does.

// Per-axis code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use ktree::io::{write_ktree, KtreeView, MappedTree};
use ktree::query::{self, Face, Query, RayCast, RayHit};
use ktree::space::morton_encode;
use ktree::tree::storage::TreeStorage;
use ktree::{KTree, NodeState, Universe};
use ktree_verify::objects::{object, Obj};
use ktree_verify::sparse::{boxes, point, union_volume, Boxes, Cuboid};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------------
// Dense references.

/// Whether `p` is a full voxel of `dense` (outside the universe: no).
fn dense_at<const K: usize>(u: &Universe<K>, dense: &[bool], p: [u32; K]) -> bool {
    u.check_point(p).is_ok() && dense[u.dense_index(p)]
}

/// Every full voxel of `dense`.
fn full_voxels<const K: usize>(u: &Universe<K>, dense: &[bool]) -> Vec<[u32; K]> {
    (0..dense.len())
        .filter(|&i| dense[i])
        .map(|i| u.dense_point(i))
        .collect()
}

/// Points in and around the universe: up to twice its side on every axis.
fn probes<const K: usize>(level: u32) -> impl Strategy<Value = Vec<[u32; K]>> {
    let side = 1u32 << level;
    prop::collection::vec(prop::array::uniform::<_, K>(0..2 * side), 1..40)
}

/// A box `[lo, hi)` in and around the universe, possibly empty.
fn a_box<const K: usize>(level: u32) -> impl Strategy<Value = ([u32; K], [u32; K])> {
    let side = 1u32 << level;
    (
        prop::array::uniform::<_, K>(0..side + 2),
        prop::array::uniform::<_, K>(0..side + 3),
    )
}

fn obj_and<const K: usize, S: Strategy>(
    f: impl Fn(u32) -> S,
) -> impl Strategy<Value = (Obj<K>, S::Value)> {
    object::<K>().prop_flat_map(move |o| {
        let level = o.level;
        (Just(o), f(level))
    })
}

fn check_points<const K: usize>(o: &Obj<K>, points: &[[u32; K]]) -> Result<(), TestCaseError> {
    let (u, dense, tree) = (o.universe(), o.dense(), o.tree());
    let expect: Vec<bool> = points.iter().map(|&p| dense_at(&u, &dense, p)).collect();
    prop_assert_eq!(tree.contains_many(points), expect.clone());
    // Many points inside the universe (and the others): enough for the table of the top levels, several
    // runs, on all threads.
    let inside: Vec<[u32; K]> = points
        .iter()
        .copied()
        .filter(|&p| u.check_point(p).is_ok())
        .collect();
    let many: Vec<[u32; K]> = inside
        .iter()
        .cycle()
        .take(70_000)
        .chain(points)
        .copied()
        .collect();
    let expect_many: Vec<bool> = many.iter().map(|&p| dense_at(&u, &dense, p)).collect();
    prop_assert_eq!(tree.contains_many(&many), expect_many);
    // The same points given signed, some coordinates moved below 0 or past 2^32 - 1 (outside).
    let signed: Vec<[i64; K]> = many
        .iter()
        .enumerate()
        .map(|(i, p)| {
            std::array::from_fn(|a| match (i + a) % 7 {
                0 => -1 - i64::from(p[a]),
                1 => i64::from(p[a]) + (1 << 32),
                _ => i64::from(p[a]),
            })
        })
        .collect();
    let expect_signed: Vec<bool> = signed
        .iter()
        .map(|p| {
            let voxel: Option<Vec<u32>> = p.iter().map(|&c| u32::try_from(c).ok()).collect();
            voxel.is_some_and(|v| dense_at(&u, &dense, std::array::from_fn(|a| v[a])))
        })
        .collect();
    prop_assert_eq!(
        query::contains_many_signed(&tree, &signed),
        Ok(expect_signed)
    );
    // A cursor on a random walk (neighbour after neighbour) and on the points as given.
    let mut cursor = tree.cursor();
    let mut p = points[0];
    for (step, q) in points.iter().enumerate() {
        prop_assert_eq!(cursor.contains(*q).unwrap(), dense_at(&u, &dense, *q));
        let axis = step % K;
        p[axis] = if q[axis] % 2 == 0 {
            p[axis].saturating_add(1)
        } else {
            p[axis].saturating_sub(1)
        };
        prop_assert_eq!(
            cursor.contains(p).unwrap(),
            dense_at(&u, &dense, p),
            "at {:?}",
            p
        );
    }
    prop_assert_eq!(
        tree.voxel_count(),
        dense.iter().filter(|&&b| b).count() as u128
    );
    Ok(())
}

fn check_boxes<const K: usize>(
    o: &Obj<K>,
    (lo, hi): ([u32; K], [u32; K]),
) -> Result<(), TestCaseError> {
    let (u, dense, tree) = (o.universe(), o.dense(), o.tree());
    let full = full_voxels(&u, &dense);
    let expect_box = (!full.is_empty()).then(|| {
        let lo: [u32; K] = std::array::from_fn(|a| full.iter().map(|v| v[a]).min().unwrap());
        let hi: [u32; K] = std::array::from_fn(|a| full.iter().map(|v| v[a] + 1).max().unwrap());
        (lo, hi)
    });
    prop_assert_eq!(tree.bounding_box(), expect_box);
    let inside = |v: &[u32; K]| (0..K).all(|a| lo[a] <= v[a] && v[a] < hi[a]);
    prop_assert_eq!(
        tree.count(lo, hi),
        full.iter().filter(|v| inside(v)).count() as u128
    );
    let cut = tree.crop(lo, hi);
    cut.assert_well_formed();
    let expect: Vec<bool> = (0..dense.len())
        .map(|i| dense[i] && inside(&u.dense_point(i)))
        .collect();
    prop_assert_eq!(cut.to_dense().unwrap(), expect);
    Ok(())
}

// ---------------------------------------------------------------------------------------------------
// Rays: the reference in exact rational arithmetic.

/// Ray coordinates in exact units: the origin in 1/256 voxel, the direction in 1/64, `max_t` in 1/16
/// (`None`: no limit). Every value is exact in `f64`.
#[derive(Debug, Clone, Copy)]
struct ExactRay<const K: usize> {
    origin: [i64; K],
    direction: [i64; K],
    max_t: Option<i64>,
}

impl<const K: usize> ExactRay<K> {
    fn cast(&self) -> RayCast<K> {
        RayCast::new(
            self.origin.map(|v| v as f64 / 256.0),
            self.direction.map(|v| v as f64 / 64.0),
            self.max_t.map_or(f64::INFINITY, |m| m as f64 / 16.0),
        )
        .unwrap()
    }
}

/// A non-negative-denominator fraction.
#[derive(Debug, Clone, Copy)]
struct Q(i128, i128);

impl Q {
    fn lt(self, o: Q) -> bool {
        self.0 * o.1 < o.0 * self.1
    }
    fn eq(self, o: Q) -> bool {
        self.0 * o.1 == o.0 * self.1
    }
    fn f64(self) -> f64 {
        self.0 as f64 / self.1 as f64
    }
}

/// The entry parameter of the ray into voxel `v` (the infimum of the parameters `0 ≤ t ≤ max_t` at which
/// `p(t)` is in `[v, v + 1)`) and the axes whose face gives it, or `None` if the ray never is in `v`.
fn exact_entry<const K: usize>(r: &ExactRay<K>, v: [u32; K]) -> Option<(Q, Vec<usize>)> {
    // (value, open, axis)
    let mut lows: Vec<(Q, bool, Option<usize>)> = vec![(Q(0, 1), false, None)];
    let mut highs: Vec<(Q, bool)> = r
        .max_t
        .map(|m| (Q(m as i128, 16), false))
        .into_iter()
        .collect();
    for a in 0..K {
        let (o, d) = (r.origin[a] as i128, r.direction[a] as i128);
        let (lo, hi) = (256 * v[a] as i128 - o, 256 * (v[a] as i128 + 1) - o);
        // t = (256 c − o) / (4 d) for the plane at c.
        match d.signum() {
            1 => {
                lows.push((Q(lo, 4 * d), false, Some(a)));
                highs.push((Q(hi, 4 * d), true));
            }
            -1 => {
                lows.push((Q(-hi, -4 * d), true, Some(a)));
                highs.push((Q(-lo, -4 * d), false));
            }
            _ if lo <= 0 && 0 < hi => {}
            _ => return None,
        }
    }
    let low = lows.iter().fold(lows[0], |m, &l| {
        if m.0.lt(l.0) || (m.0.eq(l.0) && l.1 && !m.1) {
            l
        } else {
            m
        }
    });
    let met = highs
        .iter()
        .all(|&(h, open)| low.0.lt(h) || (low.0.eq(h) && !open && !low.1));
    if !met {
        return None;
    }
    let axes = lows
        .iter()
        .filter(|l| l.0.eq(low.0) && l.2.is_some())
        .map(|l| l.2.unwrap())
        .collect();
    Some((low.0, if low.2.is_none() { Vec::new() } else { axes }))
}

/// The cast checked against the brute-force march over every full voxel: a hit iff some full voxel is
/// entered; then the voxel is one entered first, at the same `t`, through a face of the same parameter.
fn check_ray<const K: usize>(
    u: &Universe<K>,
    dense: &[bool],
    hit: Option<RayHit<K>>,
    r: &ExactRay<K>,
) -> Result<(), TestCaseError> {
    let entries: Vec<([u32; K], Q, Vec<usize>)> = full_voxels(u, dense)
        .into_iter()
        .filter_map(|v| exact_entry(r, v).map(|(t, axes)| (v, t, axes)))
        .collect();
    let first = entries
        .iter()
        .map(|e| e.1)
        .reduce(|a, b| if b.lt(a) { b } else { a });
    match (hit, first) {
        (None, None) => {}
        (Some(h), Some(t)) => {
            prop_assert!(
                (h.t - t.f64()).abs() <= 1e-9 * t.f64().abs().max(1.0),
                "t {} against {:?} for {:?}",
                h.t,
                t,
                r
            );
            let mine = entries.iter().find(|e| e.0 == h.voxel);
            prop_assert!(
                mine.is_some_and(|e| e.1.eq(t)),
                "{:?} is not a voxel entered first ({:?}) by {:?}",
                h,
                t,
                r
            );
            let axes = &mine.unwrap().2;
            match h.face {
                None => prop_assert!(axes.is_empty(), "{:?}: entered through {:?}", h, axes),
                Some(Face { axis, sign }) => {
                    prop_assert!(axes.contains(&axis), "{:?}: entered through {:?}", h, axes);
                    prop_assert_eq!(sign, if r.direction[axis] > 0 { -1 } else { 1 });
                }
            }
        }
        (h, t) => prop_assert!(false, "cast {:?}, reference {:?} for {:?}", h, t, r),
    }
    Ok(())
}

/// Random rays from in and around the universe; each direction component is 0 with probability 1/5.
fn rays<const K: usize>(level: u32) -> impl Strategy<Value = Vec<ExactRay<K>>> {
    let side = 256i64 << level;
    let component = prop_oneof![1 => Just(0i64), 4 => -200i64..=200];
    let ray = (
        prop::array::uniform::<_, K>(-side / 2..side * 3 / 2),
        prop::array::uniform::<_, K>(component),
        prop::option::of(0i64..(64 << level)),
    )
        .prop_map(|(origin, direction, max_t)| ExactRay {
            origin,
            direction,
            max_t,
        });
    prop::collection::vec(ray, 1..8)
}

fn check_rays<const K: usize>(o: &Obj<K>, rs: &[ExactRay<K>]) -> Result<(), TestCaseError> {
    let (u, dense, tree) = (o.universe(), o.dense(), o.tree());
    let casts: Vec<RayCast<K>> = rs.iter().map(ExactRay::cast).collect();
    let hits = tree.cast_rays(&casts);
    for (r, hit) in rs.iter().zip(hits) {
        check_ray(&u, &dense, hit, r)?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------------
// Nearest: brute force over every full voxel.

fn check_nearest<const K: usize>(o: &Obj<K>, points: &[[u32; K]]) -> Result<(), TestCaseError> {
    let (u, dense, tree) = (o.universe(), o.dense(), o.tree());
    let full = full_voxels(&u, &dense);
    let got = tree.nearest_many(points);
    for (p, n) in points.iter().zip(got) {
        let expect = full
            .iter()
            .map(|v| {
                let d: u128 = (0..K).map(|a| u128::from(v[a].abs_diff(p[a])).pow(2)).sum();
                (d, morton_encode(*v), *v)
            })
            .min();
        prop_assert_eq!(
            n.map(|n| (n.squared, n.voxel)),
            expect.map(|(d, _, v)| (d, v)),
            "from {:?}",
            p
        );
        // The same point moved by −U on every axis, below the universe.
        let side = i64::from(u.side() as u32);
        let q = p.map(|v| i64::from(v) - side);
        let below = query::nearest_signed(&tree, q).unwrap();
        let expect_below = full
            .iter()
            .map(|v| {
                let d: u128 = (0..K)
                    .map(|a| u128::from(i64::from(v[a]).abs_diff(q[a])).pow(2))
                    .sum();
                (d, morton_encode(*v), *v)
            })
            .min();
        prop_assert_eq!(
            below.map(|n| (n.squared, n.voxel)),
            expect_below.map(|(d, _, v)| (d, v)),
            "from {:?}",
            q
        );
        let dist = tree.distance(*p);
        match expect {
            None => prop_assert_eq!(dist, f64::INFINITY),
            Some((d, _, _)) => prop_assert_eq!(dist, (d as f64).sqrt()),
        }
    }
    // The signed batch (Morton-ordered, each search from the previous answer) as one search at a time,
    // on points inside, below and above the universe.
    let side = i64::from(u.side() as u32);
    let signed: Vec<[i64; K]> = points
        .iter()
        .enumerate()
        .map(|(i, p)| p.map(|v| i64::from(v) + side * (i as i64 % 3 - 1)))
        .collect();
    let batch = query::nearest_many_signed(&tree, &signed).unwrap();
    for (q, n) in signed.iter().zip(batch) {
        prop_assert_eq!(n, query::nearest_signed(&tree, *q).unwrap(), "from {:?}", q);
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------------
// A file read through its map answers as the tree in memory.

fn view_of<const K: usize>(tree: &KTree<K>) -> KtreeView {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    KtreeView::from_bytes(bytes, "mem").unwrap()
}

fn check_mapped<const K: usize>(
    o: &Obj<K>,
    points: &[[u32; K]],
    rs: &[ExactRay<K>],
) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let view = view_of(&tree);
    let mapped = MappedTree::<K>::new(&view).unwrap();
    prop_assert_eq!(mapped.voxel_count(), tree.voxel_count());
    prop_assert_eq!(view.voxel_count(), tree.voxel_count());
    prop_assert_eq!(
        mapped.contains_many(points).unwrap(),
        tree.contains_many(points)
    );
    // Enough points for the table of the top levels, read through the map.
    let many: Vec<[u32; K]> = points.iter().cycle().take(70_000).copied().collect();
    prop_assert_eq!(
        mapped.contains_many(&many).unwrap(),
        tree.contains_many(&many)
    );
    prop_assert_eq!(mapped.bounding_box().unwrap(), tree.bounding_box());
    let (lo, hi) = (points[0], *points.last().unwrap());
    prop_assert_eq!(mapped.count(lo, hi).unwrap(), tree.count(lo, hi));
    prop_assert_eq!(mapped.crop(lo, hi).unwrap(), tree.crop(lo, hi));
    let casts: Vec<RayCast<K>> = rs.iter().map(ExactRay::cast).collect();
    prop_assert_eq!(mapped.cast_rays(&casts).unwrap(), tree.cast_rays(&casts));
    prop_assert_eq!(
        mapped.nearest_many(points).unwrap(),
        tree.nearest_many(points)
    );
    let mut cursor = query::PointCursor::new(&mapped).unwrap();
    for &p in points {
        prop_assert_eq!(cursor.contains(p).unwrap(), tree.contains(p));
        prop_assert_eq!(Query::contains(&mapped, p).unwrap(), tree.contains(p));
        prop_assert_eq!(Query::nearest(&mapped, p).unwrap(), tree.nearest(p));
        prop_assert_eq!(Query::distance(&mapped, p).unwrap(), tree.distance(p));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn points_k1((o, p) in obj_and::<1, _>(probes::<1>)) { check_points(&o, &p)?; }
    #[test]
    fn points_k2((o, p) in obj_and::<2, _>(probes::<2>)) { check_points(&o, &p)?; }
    #[test]
    fn points_k3((o, p) in obj_and::<3, _>(probes::<3>)) { check_points(&o, &p)?; }
    #[test]
    fn points_k4((o, p) in obj_and::<4, _>(probes::<4>)) { check_points(&o, &p)?; }

    #[test]
    fn boxes_k1((o, b) in obj_and::<1, _>(a_box::<1>)) { check_boxes(&o, b)?; }
    #[test]
    fn boxes_k2((o, b) in obj_and::<2, _>(a_box::<2>)) { check_boxes(&o, b)?; }
    #[test]
    fn boxes_k3((o, b) in obj_and::<3, _>(a_box::<3>)) { check_boxes(&o, b)?; }
    #[test]
    fn boxes_k4((o, b) in obj_and::<4, _>(a_box::<4>)) { check_boxes(&o, b)?; }

    #[test]
    fn rays_k1((o, r) in obj_and::<1, _>(rays::<1>)) { check_rays(&o, &r)?; }
    #[test]
    fn rays_k2((o, r) in obj_and::<2, _>(rays::<2>)) { check_rays(&o, &r)?; }
    #[test]
    fn rays_k3((o, r) in obj_and::<3, _>(rays::<3>)) { check_rays(&o, &r)?; }
    #[test]
    fn rays_k4((o, r) in obj_and::<4, _>(rays::<4>)) { check_rays(&o, &r)?; }

    #[test]
    fn nearest_k1((o, p) in obj_and::<1, _>(probes::<1>)) { check_nearest(&o, &p)?; }
    #[test]
    fn nearest_k2((o, p) in obj_and::<2, _>(probes::<2>)) { check_nearest(&o, &p)?; }
    #[test]
    fn nearest_k3((o, p) in obj_and::<3, _>(probes::<3>)) { check_nearest(&o, &p)?; }
    #[test]
    fn nearest_k4((o, p) in obj_and::<4, _>(probes::<4>)) { check_nearest(&o, &p)?; }
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test]
    fn mapped_k1((o, (p, r)) in obj_and::<1, _>(|l| (probes::<1>(l), rays::<1>(l)))) {
        check_mapped(&o, &p, &r)?;
    }
    #[test]
    fn mapped_k2((o, (p, r)) in obj_and::<2, _>(|l| (probes::<2>(l), rays::<2>(l)))) {
        check_mapped(&o, &p, &r)?;
    }
    #[test]
    fn mapped_k3((o, (p, r)) in obj_and::<3, _>(|l| (probes::<3>(l), rays::<3>(l)))) {
        check_mapped(&o, &p, &r)?;
    }
    #[test]
    fn mapped_k4((o, (p, r)) in obj_and::<4, _>(|l| (probes::<4>(l), rays::<4>(l)))) {
        check_mapped(&o, &p, &r)?;
    }
}

// ---------------------------------------------------------------------------------------------------
// Named rays, on one small object per K, against the same exact reference.

/// A 2^K block of full voxels at `[2, 4)^K` and the voxel `[6, …, 6]` in a universe of level 3.
fn named_object<const K: usize>() -> Obj<K> {
    Obj {
        level: 3,
        boxes: vec![([2; K], [4; K])],
        voxels: vec![[6; K]],
    }
}

fn exact<const K: usize>(origin: [f64; K], direction: [f64; K], max_t: Option<f64>) -> ExactRay<K> {
    ExactRay {
        origin: origin.map(|v| (v * 256.0) as i64),
        direction: direction.map(|v| (v * 64.0) as i64),
        max_t: max_t.map(|m| (m * 16.0) as i64),
    }
}

/// A named case's hit: voxel, `t` and face.
type Expected<const K: usize> = Option<([u32; K], f64, Option<Face>)>;

fn named_rays<const K: usize>() {
    let o = named_object::<K>();
    let (u, dense, tree) = (o.universe(), o.dense(), o.tree());
    let unit =
        |a: usize, s: f64| -> [f64; K] { std::array::from_fn(|i| if i == a { s } else { 0.0 }) };
    let at = |v: f64| -> [f64; K] { [v; K] };
    let with = |base: [f64; K], a: usize, v: f64| -> [f64; K] {
        let mut p = base;
        p[a] = v;
        p
    };
    let mut cases: Vec<(&str, ExactRay<K>, Expected<K>)> = Vec::new();
    for a in 0..K {
        // Axis-parallel, from outside the universe, up and down the axis.
        cases.push((
            "axis-parallel up, from outside",
            exact(with(at(2.5), a, -3.0), unit(a, 1.0), None),
            Some(([2; K], 5.0, Some(Face { axis: a, sign: -1 }))),
        ));
        cases.push((
            "axis-parallel down",
            exact(with(at(3.5), a, 5.5), unit(a, -2.0), None),
            Some(([3; K], 0.75, Some(Face { axis: a, sign: 1 }))),
        ));
        // Along the lower face x_a = 2 of the block (inside its voxels, half-open) and along its upper
        // face x_a = 4 (outside them).
        if K > 1 {
            let b = (a + 1) % K;
            cases.push((
                "along a lower face",
                exact(with(with(at(2.5), a, 2.0), b, 0.25), unit(b, 1.0), None),
                Some(([2; K], 1.75, Some(Face { axis: b, sign: -1 }))),
            ));
            cases.push((
                "along an upper face",
                exact(with(with(at(2.5), a, 4.0), b, 0.25), unit(b, 1.0), None),
                None,
            ));
        }
        // Stopped by max_t before the block, and just at its face.
        cases.push((
            "max_t before",
            exact(with(at(2.5), a, 0.0), unit(a, 1.0), Some(1.5)),
            None,
        ));
        cases.push((
            "max_t at the face",
            exact(with(at(2.5), a, 0.0), unit(a, 1.0), Some(2.0)),
            Some(([2; K], 2.0, Some(Face { axis: a, sign: -1 }))),
        ));
        // Pointing away.
        cases.push((
            "away",
            exact(with(at(2.5), a, 1.0), unit(a, -1.0), None),
            None,
        ));
    }
    // Inside a full voxel: that voxel at t = 0, and a zero direction.
    cases.push((
        "inside",
        exact(at(3.25), at(1.0), None),
        Some(([3; K], 0.0, None)),
    ));
    cases.push((
        "a point",
        exact(at(6.5), at(0.0), None),
        Some(([6; K], 0.0, None)),
    ));
    cases.push((
        "a point in empty space",
        exact(at(0.5), at(0.0), None),
        None,
    ));
    // The diagonal through the block's corners: the corner (2, …, 2) is entered at t = 2.
    cases.push((
        "the diagonal",
        exact(at(0.0), at(1.0), None),
        Some(([2; K], 2.0, None)),
    ));
    // Missing the universe altogether.
    cases.push((
        "outside",
        exact(with(at(-1.0), 0, -1.0), at(-1.0), None),
        None,
    ));
    for (name, r, expect) in cases {
        let hit = query::cast_ray(&tree, &r.cast()).unwrap();
        check_ray(&u, &dense, hit, &r).unwrap_or_else(|e| panic!("K = {K}, {name}: {e}"));
        match (hit, expect) {
            (None, None) => {}
            (Some(h), Some((voxel, t, face))) => {
                assert_eq!((h.voxel, h.t), (voxel, t), "K = {K}, {name}");
                // On the diagonal every axis gives the entry: any of them is right.
                if name != "the diagonal" {
                    assert_eq!(h.face, face, "K = {K}, {name}");
                } else {
                    assert!(h.face.is_some_and(|f| f.sign == -1), "K = {K}, {name}");
                }
            }
            _ => panic!("K = {K}, {name}: {hit:?}, expected {expect:?}"),
        }
    }
    // Infinite and NaN inputs are errors, never a loop.
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(tree.cast_ray(with(at(0.5), 0, bad), at(1.0), 1.0).is_err());
        assert!(tree
            .cast_ray(at(0.5), with(at(1.0), K - 1, bad), 1.0)
            .is_err());
    }
    assert!(tree.cast_ray(at(0.5), at(1.0), f64::NAN).is_err());
    assert!(tree.cast_ray(at(0.5), at(1.0), -1.0).is_err());
    // Tiny and huge directions terminate and agree with the reference where it is exact.
    let slow = tree
        .cast_ray(at(0.5), at(1e-300), f64::INFINITY)
        .unwrap()
        .unwrap();
    assert_eq!((slow.voxel, slow.t), ([2; K], 1.5e300));
    assert!(tree.cast_ray(at(0.5), at(1e-300), 1e299).unwrap().is_none());
    let far = tree
        .cast_ray(at(0.5), at(1e300), f64::INFINITY)
        .unwrap()
        .unwrap();
    assert_eq!(far.voxel, [2; K]);
}

#[test]
fn named_rays_k1_to_k4() {
    named_rays::<1>();
    named_rays::<2>();
    named_rays::<3>();
    named_rays::<4>();
}

#[test]
fn the_diagonal_through_the_block_corner_is_the_diagonal() {
    // In K = 1 the "diagonal" enters through the one axis.
    let o = named_object::<1>();
    let hit = o
        .tree()
        .cast_ray([0.0], [1.0], f64::INFINITY)
        .unwrap()
        .unwrap();
    assert_eq!(hit.face, Some(Face { axis: 0, sign: -1 }));
}

// ---------------------------------------------------------------------------------------------------
// The largest level of each K: references on the boxes themselves.

fn to_u32<const K: usize>(p: [u64; K]) -> [u32; K] {
    p.map(|v| v as u32)
}

fn check_max_level<const K: usize>(b: &Boxes<K>, p: [u64; K]) -> Result<(), TestCaseError> {
    let tree = KTree::from_rays(&b.rays());
    let side = b.side();
    prop_assert_eq!(tree.level(), ktree::max_level(K));
    prop_assert_eq!(tree.voxel_count(), b.voxel_count());
    let expect_box = b.bounding_box().map(|(lo, hi)| (to_u32(lo), to_u32(hi)));
    prop_assert_eq!(tree.bounding_box(), expect_box);
    let probes: Vec<[u64; K]> = b.probe_points().into_iter().chain([p]).collect();
    let points: Vec<[u32; K]> = probes.iter().map(|&q| to_u32(q)).collect();
    let expect: Vec<bool> = probes.iter().map(|&q| b.contains(q)).collect();
    prop_assert_eq!(tree.contains_many(&points), expect.clone());
    // Enough points for the table of the top levels, at the largest level.
    let n = 70_000;
    let many: Vec<[u32; K]> = points.iter().cycle().take(n).copied().collect();
    let expect_many: Vec<bool> = expect.iter().cycle().take(n).copied().collect();
    prop_assert_eq!(tree.contains_many(&many), expect_many);
    // Counts and crops of the box around each box and of a box from p to the top corner.
    let mut windows: Vec<Cuboid<K>> = b
        .boxes
        .iter()
        .map(|c| Cuboid {
            lo: c.lo.map(|v| v.saturating_sub(1)),
            hi: c.hi.map(|v| (v + 1).min(side)),
        })
        .collect();
    windows.push(Cuboid {
        lo: p,
        hi: [side; K],
    });
    for w in &windows {
        let meets: Vec<Cuboid<K>> = b.boxes.iter().map(|c| c.meet(w)).collect();
        let (lo, hi) = (to_u32(w.lo), to_u32(w.hi));
        prop_assert_eq!(tree.count(lo, hi), union_volume(&meets));
        let cut = tree.crop(lo, hi);
        cut.assert_well_formed();
        prop_assert_eq!(cut.voxel_count(), union_volume(&meets));
    }
    // Nearest: the box nearest p.
    let squared = |c: &Cuboid<K>| -> u128 {
        (0..K)
            .map(|a| u128::from(p[a].clamp(c.lo[a], c.hi[a] - 1).abs_diff(p[a])).pow(2))
            .sum()
    };
    let expect = b.boxes.iter().filter(|c| !c.is_empty()).map(squared).min();
    let n = tree.nearest(to_u32(p));
    prop_assert_eq!(n.map(|n| n.squared), expect);
    if let Some(n) = n {
        prop_assert!(b.contains(n.voxel.map(u64::from)));
    }
    // A ray up axis 0 from below the universe through p's line.
    let mut origin: [f64; K] = p.map(|v| v as f64 + 0.5);
    origin[0] = -1.0;
    let mut direction = [0.0; K];
    direction[0] = 1.0;
    let first = b
        .boxes
        .iter()
        .filter(|c| !c.is_empty() && (1..K).all(|a| c.lo[a] <= p[a] && p[a] < c.hi[a]))
        .map(|c| c.lo[0])
        .min();
    let hit = tree.cast_ray(origin, direction, f64::INFINITY).unwrap();
    prop_assert_eq!(hit.map(|h| h.voxel[0]), first.map(|x| x as u32));
    if let (Some(h), Some(x)) = (hit, first) {
        prop_assert_eq!(h.t, x as f64 + 1.0);
        prop_assert_eq!(&h.voxel[1..], &to_u32(p)[1..]);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test]
    fn max_level_k1(b in boxes::<1>(), p in point::<1>()) { check_max_level(&b, p)?; }
    #[test]
    fn max_level_k2(b in boxes::<2>(), p in point::<2>()) { check_max_level(&b, p)?; }
    #[test]
    fn max_level_k3(b in boxes::<3>(), p in point::<3>()) { check_max_level(&b, p)?; }
    #[test]
    fn max_level_k4(b in boxes::<4>(), p in point::<4>()) { check_max_level(&b, p)?; }
}

#[test]
fn a_full_universe_at_the_largest_level_counts_without_overflow() {
    assert_eq!(KTree::<1>::full(31).unwrap().voxel_count(), 1 << 31);
    assert_eq!(KTree::<2>::full(31).unwrap().voxel_count(), 1 << 62);
    assert_eq!(KTree::<3>::full(21).unwrap().voxel_count(), 1 << 63);
    assert_eq!(KTree::<4>::full(16).unwrap().voxel_count(), 1 << 64);
    let t = KTree::<4>::full(16).unwrap();
    assert_eq!(t.count([0; 4], [u32::MAX; 4]), 1 << 64);
    assert_eq!(t.bounding_box(), Some(([0; 4], [1 << 16; 4])));
    assert_eq!(t.nearest([u32::MAX; 4]).unwrap().voxel, [(1 << 16) - 1; 4]);
    let empty = KTree::<3>::empty(21).unwrap();
    assert_eq!(empty.distance([5, 5, 5]), f64::INFINITY);
    assert_eq!(empty.nearest([5, 5, 5]), None);
    assert_eq!(empty.bounding_box(), None);
    assert_eq!(NodeState::Empty, empty.root_state());
}
