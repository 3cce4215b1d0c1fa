//! Shape operations against dense references in K = 1 … 4: morphology by brute force over all offsets of
//! the element (the closing in a padded array), components by flood fill, the surface area by counting
//! faces, the Euler number by counting the cells of the cubical complex; plus the laws (idempotence,
//! duality under complement) and trees at the largest level of each K; every operation on a `.ktree` file
//! read in place gives what it gives on the tree in memory; the surface area of the whole universe at the
//! largest levels.

use ktree::io::{write_ktree, KtreeView, MappedTree};
use ktree::shape::{self, Element, ShapeError};
use ktree::tree::sink::{LevelSink, MemorySink};
use ktree::{ops, KTree, NodeState, Ray, RaySet, Universe};
use ktree_verify::objects::{obj_at, Obj};
use proptest::prelude::*;

/// Levels small enough for brute force over every offset of every voxel.
const fn top_level(k: usize) -> u32 {
    match k {
        1 => 6,
        2 => 5,
        3 => 4,
        _ => 3,
    }
}

fn obj<const K: usize>() -> impl Strategy<Value = Obj<K>> {
    (0..=top_level(K)).prop_flat_map(obj_at::<K>)
}

fn element() -> impl Strategy<Value = Element> {
    prop::sample::select(Element::ALL.to_vec())
}

/// Radii with fractional parts, including values just at and past integer and √n thresholds.
fn radius() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        0.0,
        0.5,
        1.0,
        1.2,
        1.5,
        2.0,
        2.0f64.sqrt(),
        2.5,
        5.0f64.sqrt(),
        3.0,
    ])
}

/// A dense cube of side `side` whose first corner is at `lo` on every axis, axis 0 fastest.
#[derive(Clone, PartialEq, Debug)]
struct Grid<const K: usize> {
    lo: i64,
    side: i64,
    data: Vec<bool>,
}

impl<const K: usize> Grid<K> {
    fn new(lo: i64, side: i64) -> Self {
        Self {
            lo,
            side,
            data: vec![false; (side as usize).pow(K as u32)],
        }
    }
    fn of(level: u32, dense: &[bool]) -> Self {
        Self {
            lo: 0,
            side: 1 << level,
            data: dense.to_vec(),
        }
    }
    fn index(&self, p: [i64; K]) -> Option<usize> {
        let mut i = 0usize;
        for &c in p.iter().rev() {
            let x = c - self.lo;
            if x < 0 || x >= self.side {
                return None;
            }
            i = i * self.side as usize + x as usize;
        }
        Some(i)
    }
    fn point(&self, mut i: usize) -> [i64; K] {
        let mut p = [0i64; K];
        for c in p.iter_mut() {
            *c = (i % self.side as usize) as i64 + self.lo;
            i /= self.side as usize;
        }
        p
    }
    fn get(&self, p: [i64; K]) -> bool {
        self.index(p).is_some_and(|i| self.data[i])
    }
    /// The same voxels in another cube (outside it dropped).
    fn moved(&self, lo: i64, side: i64) -> Self {
        let mut out = Self::new(lo, side);
        for i in 0..out.data.len() {
            out.data[i] = self.get(out.point(i));
        }
        out
    }
}

/// All offsets of the element (the definition, `Element::contains`), reach ⌊r⌋ on each axis.
fn offsets<const K: usize>(element: Element, r: f64) -> Vec<[i64; K]> {
    let e = r.floor() as i64;
    let w = 2 * e + 1;
    (0..w.pow(K as u32))
        .map(|mut i| {
            let mut d = [0i64; K];
            for c in d.iter_mut() {
                *c = i % w - e;
                i /= w;
            }
            d
        })
        .filter(|&d| element.contains(d, r))
        .collect()
}

fn dilate_ref<const K: usize>(a: &Grid<K>, element: Element, r: f64) -> Grid<K> {
    let ds = offsets::<K>(element, r);
    let mut out = Grid::new(a.lo, a.side);
    for i in 0..out.data.len() {
        let p = out.point(i);
        out.data[i] = ds
            .iter()
            .any(|d| a.get(std::array::from_fn(|k| p[k] - d[k])));
    }
    out
}

fn erode_ref<const K: usize>(a: &Grid<K>, element: Element, r: f64) -> Grid<K> {
    let ds = offsets::<K>(element, r);
    let mut out = Grid::new(a.lo, a.side);
    for i in 0..out.data.len() {
        let p = out.point(i);
        out.data[i] = ds
            .iter()
            .all(|d| a.get(std::array::from_fn(|k| p[k] + d[k])));
    }
    out
}

fn check_morphology<const K: usize>(
    o: &Obj<K>,
    element: Element,
    r: f64,
) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let a = Grid::<K>::of(o.level, &o.dense());
    let side = a.side;
    let dense = |t: &KTree<K>| {
        t.assert_well_formed();
        Grid::<K>::of(o.level, &t.to_dense().unwrap())
    };
    let dil = tree.dilate(r, element).unwrap();
    prop_assert_eq!(dense(&dil), dilate_ref(&a, element, r), "dilate");
    let ero = tree.erode(r, element).unwrap();
    prop_assert_eq!(dense(&ero), erode_ref(&a, element, r), "erode");
    if element == Element::Ball {
        // Both ball paths, whichever `dilate` and `erode` chose.
        let by_distance = tree.dilate_ball_by_distance(r).unwrap();
        prop_assert_eq!(
            dense(&by_distance),
            dilate_ref(&a, element, r),
            "dilate by distance"
        );
        let by_distance = tree.erode_ball_by_distance(r).unwrap();
        prop_assert_eq!(
            dense(&by_distance),
            erode_ref(&a, element, r),
            "erode by distance"
        );
    }
    let open = tree.opening(r, element).unwrap();
    prop_assert_eq!(
        dense(&open),
        dilate_ref(&erode_ref(&a, element, r), element, r),
        "opening"
    );
    // The closing in a cube padded by the element's reach, then cropped.
    let m = r.floor() as i64;
    let padded = a.moved(-m, side + 2 * m);
    let closed_ref = erode_ref(&dilate_ref(&padded, element, r), element, r).moved(0, side);
    let close = tree.closing(r, element).unwrap();
    prop_assert_eq!(dense(&close), closed_ref, "closing");
    // Laws: idempotence, extensivity, duality (erosion = ¬ dilation of ¬A, minus the band the border erodes).
    prop_assert_eq!(&open.opening(r, element).unwrap(), &open);
    prop_assert_eq!(&close.closing(r, element).unwrap(), &close);
    prop_assert_eq!(&ops::intersection(&close, &tree).unwrap(), &tree);
    prop_assert_eq!(&ops::intersection(&open, &tree).unwrap(), &open);
    let e = m.min(side) as u32;
    let inner = if 2 * i64::from(e) < side {
        let s = side as u32;
        let rays = (0..s.pow(K as u32 - 1)).filter_map(|i| {
            let mut start = [0u32; K];
            let mut i = i;
            for c in start[..K - 1].iter_mut() {
                *c = i % s;
                i /= s;
            }
            let inside = start[..K - 1].iter().all(|&c| c >= e && c < s - e);
            start[K - 1] = e;
            inside.then(|| Ray::new(start, s - e))
        });
        KTree::from_rays(&RaySet::from_rays(o.level, rays).unwrap())
    } else {
        KTree::empty(o.level).unwrap()
    };
    let dual = ops::intersection(
        &ops::complement(&ops::complement(&tree).dilate(r, element).unwrap()),
        &inner,
    )
    .unwrap();
    prop_assert_eq!(&dual, &ero, "duality");
    Ok(())
}

fn neighbours<const K: usize>(connectivity: usize) -> Vec<[i64; K]> {
    offsets::<K>(Element::Box, 1.0)
        .into_iter()
        .filter(|d| {
            let m = d.iter().filter(|&&x| x != 0).count();
            m >= 1 && m <= connectivity
        })
        .collect()
}

/// Components by flood fill: each as a dense array, in any order.
fn components_ref<const K: usize>(a: &Grid<K>, connectivity: usize) -> Vec<Vec<bool>> {
    let ns = neighbours::<K>(connectivity);
    let mut seen = vec![false; a.data.len()];
    let mut out = Vec::new();
    for start in 0..a.data.len() {
        if !a.data[start] || seen[start] {
            continue;
        }
        let mut comp = vec![false; a.data.len()];
        let mut stack = vec![start];
        seen[start] = true;
        while let Some(i) = stack.pop() {
            comp[i] = true;
            let p = a.point(i);
            for d in &ns {
                if let Some(j) = a.index(std::array::from_fn(|k| p[k] + d[k])) {
                    if a.data[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        out.push(comp);
    }
    out
}

fn surface_ref<const K: usize>(a: &Grid<K>) -> u128 {
    let mut n = 0;
    for i in 0..a.data.len() {
        if !a.data[i] {
            continue;
        }
        let p = a.point(i);
        for axis in 0..K {
            for s in [-1, 1] {
                let mut q = p;
                q[axis] += s;
                n += u128::from(!a.get(q));
            }
        }
    }
    n
}

/// The Euler characteristic of the cubical complex, cell by cell: for connectivity 1 the blocks of `2^j`
/// full voxels, for connectivity `K` the cells of the grid touched by a full voxel.
fn euler_ref<const K: usize>(a: &Grid<K>, connectivity: usize) -> i64 {
    let side = a.side;
    let mut chi = 0i64;
    if connectivity == 1 {
        for free in 0..1usize << K {
            let sign = if free.count_ones() % 2 == 0 { 1 } else { -1 };
            for i in 0..a.data.len() {
                let p = a.point(i);
                let all = (0..1usize << K)
                    .filter(|b| b & !free == 0)
                    .all(|b| a.get(std::array::from_fn(|k| p[k] + (b >> k & 1) as i64)));
                chi += sign * i64::from(all);
            }
        }
    } else {
        // Doubled coordinates 0 ..= 2U: odd spans a voxel, even lies on a grid plane between two.
        let w = 2 * side + 1;
        for i in 0..w.pow(K as u32) {
            let mut q = [0i64; K];
            let mut t = i;
            for c in q.iter_mut() {
                *c = t % w;
                t /= w;
            }
            let dim = q.iter().filter(|&&x| x % 2 == 1).count();
            let even: Vec<usize> = (0..K).filter(|&k| q[k] % 2 == 0).collect();
            let touched = (0..1usize << even.len()).any(|b| {
                let mut p: [i64; K] = std::array::from_fn(|k| (q[k] - 1) / 2);
                for (j, &k) in even.iter().enumerate() {
                    p[k] = q[k] / 2 - 1 + (b >> j & 1) as i64;
                }
                a.get(p)
            });
            if touched {
                chi += if dim % 2 == 0 { 1 } else { -1 };
            }
        }
    }
    chi
}

fn check_measures<const K: usize>(o: &Obj<K>) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let a = Grid::<K>::of(o.level, &o.dense());
    // The runs the measures walk: one ray per full voxel, joined by the ray set.
    let voxels = (0..a.data.len()).filter(|&i| a.data[i]).map(|i| {
        let p = a.point(i).map(|c| c as u32);
        Ray::new(p, p[K - 1] + 1)
    });
    prop_assert_eq!(tree.to_rays(), RaySet::from_rays(o.level, voxels).unwrap());
    prop_assert_eq!(tree.surface_area(), surface_ref(&a));
    for connectivity in 1..=K {
        let comps = tree.components(connectivity).unwrap();
        let mut expect = components_ref(&a, connectivity);
        let sizes: Vec<u128> = comps.iter().map(|c| c.size).collect();
        prop_assert!(sizes.windows(2).all(|w| w[0] >= w[1]), "largest first");
        prop_assert_eq!(&tree.component_sizes(connectivity).unwrap(), &sizes);
        let mut got: Vec<Vec<bool>> = comps
            .iter()
            .map(|c| {
                c.tree.assert_well_formed();
                assert_eq!(c.tree.voxel_count(), c.size);
                c.tree.to_dense().unwrap()
            })
            .collect();
        got.sort();
        expect.sort();
        prop_assert_eq!(got, expect, "connectivity {}", connectivity);
        if connectivity == 1 || connectivity == K {
            prop_assert_eq!(
                tree.euler_number(connectivity).unwrap(),
                euler_ref(&a, connectivity),
                "euler, connectivity {}",
                connectivity
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn morphology_matches_dense_k1(o in obj::<1>(), e in element(), r in radius()) { check_morphology(&o, e, r)?; }
    #[test]
    fn morphology_matches_dense_k2(o in obj::<2>(), e in element(), r in radius()) { check_morphology(&o, e, r)?; }
    #[test]
    fn morphology_matches_dense_k3(o in obj::<3>(), e in element(), r in radius()) { check_morphology(&o, e, r)?; }
    #[test]
    fn morphology_matches_dense_k4(o in obj::<4>(), e in element(), r in radius()) { check_morphology(&o, e, r)?; }
    #[test]
    fn measures_match_dense_k1(o in obj::<1>()) { check_measures(&o)?; }
    #[test]
    fn measures_match_dense_k2(o in obj::<2>()) { check_measures(&o)?; }
    #[test]
    fn measures_match_dense_k3(o in obj::<3>()) { check_measures(&o)?; }
    #[test]
    fn measures_match_dense_k4(o in obj::<4>()) { check_measures(&o)?; }
}

fn voxel_tree<const K: usize>(level: u32, voxels: &[[u32; K]]) -> KTree<K> {
    let rays = voxels.iter().map(|&p| {
        let mut q = p;
        q[K - 1] += 1;
        Ray::new(p, q[K - 1])
    });
    KTree::from_rays(&RaySet::from_rays(level, rays).unwrap())
}

/// A voxel at the far corner and one in the middle of the largest universe of each K: dilation, erosion,
/// components, surface area and Euler number do not overflow.
fn check_largest_level<const K: usize>() {
    let level = ktree::max_level(K);
    let u = Universe::<K>::new(level).unwrap();
    let far = [(u.side() - 1) as u32; K];
    let mid = [(u.side() / 2) as u32; K];
    let tree = voxel_tree::<K>(level, &[far, mid]);
    assert_eq!(tree.surface_area(), 4 * K as u128);
    assert_eq!(tree.component_sizes(K).unwrap(), vec![1, 1]);
    assert_eq!(tree.euler_number(1).unwrap(), 2);
    assert_eq!(tree.euler_number(K).unwrap(), 2);
    for element in Element::ALL {
        let r = 2.5;
        let all = offsets::<K>(element, r);
        // At the corner only the offsets with every d_i ≤ 0 stay inside.
        let at_corner = all.iter().filter(|d| d.iter().all(|&x| x <= 0)).count();
        let grown = tree.dilate(r, element).unwrap();
        grown.assert_well_formed();
        assert_eq!(
            grown.voxel_count(),
            (all.len() + at_corner) as u128,
            "{element}"
        );
        // The corner's piece touches the border and erodes away; the middle one comes back.
        let back = grown.erode(r, element).unwrap();
        assert_eq!(back.voxel_count(), 1, "{element}");
        assert!(back.contains(mid));
        let closed = tree.closing(r, element).unwrap();
        assert_eq!(closed, tree, "{element}");
        assert_eq!(grown.components(1).unwrap().len(), 2);
    }
}

/// Trees of many slabs (the runs are gathered slab by slab along the first axis): the runs come back.
#[test]
fn runs_come_back_from_large_trees() {
    for level in [7, 9] {
        let c = 1i64 << (level - 1);
        let rays = ktree::rays::ball_rays::<3>(level, [c - 3, c + 1, c], c - 5).unwrap();
        assert_eq!(KTree::from_rays(&rays).to_rays(), rays, "ball, L = {level}");
        let rays = ktree::rays::ball_rays::<2>(level, [c, c - 7], c - 2).unwrap();
        assert_eq!(KTree::from_rays(&rays).to_rays(), rays, "disc, L = {level}");
    }
}

#[test]
fn largest_levels_do_not_overflow() {
    check_largest_level::<1>();
    check_largest_level::<2>();
    check_largest_level::<3>();
    check_largest_level::<4>();
}

#[test]
fn named_cases() {
    // A 5 × 5 ring around one hole in 2-D: one object, one hole.
    let level = 3;
    let mut voxels = Vec::new();
    for x in 1..6u32 {
        for y in 1..6u32 {
            if !(2..5).contains(&x) || !(2..5).contains(&y) {
                voxels.push([x, y]);
            }
        }
    }
    let ring = voxel_tree::<2>(level, &voxels);
    assert_eq!(ring.euler_number(1).unwrap(), 0);
    assert_eq!(ring.euler_number(2).unwrap(), 0);
    assert_eq!(ring.surface_area(), 4 * 5 + 4 * 3);
    // The 3 × 3 hole: a closing by a 3 × 3 box keeps it, by a 5 × 5 box fills it.
    assert_eq!(ring.closing(1.0, Element::Box).unwrap().voxel_count(), 16);
    assert_eq!(ring.closing(2.0, Element::Box).unwrap().voxel_count(), 25);
    // A hollow 3 × 3 × 3 cube in 3-D: one object, one cavity: χ = 2.
    let mut shell = Vec::new();
    for x in 0..3u32 {
        for y in 0..3u32 {
            for z in 0..3u32 {
                if [x, y, z] != [1, 1, 1] {
                    shell.push([x + 1, y + 1, z + 1]);
                }
            }
        }
    }
    let shell = voxel_tree::<3>(3, &shell);
    assert_eq!(shell.euler_number(1).unwrap(), 2);
    assert_eq!(shell.euler_number(3).unwrap(), 2);
    assert_eq!(shell.surface_area(), 54 + 6);
    assert!(matches!(
        shell.euler_number(2),
        Err(ShapeError::EulerConnectivity {
            connectivity: 2,
            k: 3
        })
    ));
    // Bad input.
    assert!(matches!(
        shell.dilate(-1.0, Element::Ball),
        Err(ShapeError::BadRadius(_))
    ));
    assert!(shell.erode(f64::NAN, Element::Box).is_err());
    assert!(shell.closing(f64::INFINITY, Element::Cross).is_err());
    assert!(matches!(
        shell.components(0),
        Err(ShapeError::Connectivity {
            connectivity: 0,
            k: 3
        })
    ));
    assert!(shell.components(4).is_err());
    // Huge radii: an answer or an error, never a panic or an overflow.
    let line = voxel_tree::<1>(4, &[[3], [9]]);
    assert_eq!(line.dilate(1e300, Element::Box).unwrap().voxel_count(), 16);
    assert!(matches!(
        line.closing(1e300, Element::Cross),
        Err(ShapeError::ClosingTooWide { side: 16, .. })
    ));
    assert_eq!(line.closing(64.0, Element::Cross).unwrap().voxel_count(), 7);
    assert_eq!(line.erode(1e300, Element::Ball).unwrap().voxel_count(), 0);
    assert_eq!(ring.dilate(1e9, Element::Ball).unwrap().voxel_count(), 64);
    for element in Element::ALL {
        assert!(ring.closing(1e9, element).is_err());
    }
    // A box closing by a radius past the object's size is its bounding box.
    assert_eq!(ring.closing(32.0, Element::Box).unwrap().voxel_count(), 25);
    // A ball dilated by a ball: the result is within the larger ball and contains the smaller.
    let ball = KTree::from_rays(&ktree::rays::ball_rays::<3>(6, [64, 64, 64], 100).unwrap());
    let grown = ball.dilate(8.0, Element::Ball).unwrap();
    assert_eq!(grown.components(1).unwrap().len(), 1);
    assert_eq!(ops::intersection(&grown, &ball).unwrap(), ball);
    let closed = ball.closing(8.0, Element::Ball).unwrap();
    assert_eq!(ops::intersection(&closed, &ball).unwrap(), ball);
}

/// Every shape operation on a `.ktree` file read in place gives what it gives on the tree in memory.
fn check_mapped<const K: usize>(o: &Obj<K>, e: Element, r: f64) -> Result<(), TestCaseError> {
    let tree = o.tree();
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, &tree).unwrap();
    let view = KtreeView::from_bytes(bytes, "mem").unwrap();
    let mapped = MappedTree::<K>::new(&view).unwrap();
    prop_assert_eq!(
        shape::dilate(&mapped, r, e).unwrap(),
        tree.dilate(r, e).unwrap()
    );
    prop_assert_eq!(
        shape::erode(&mapped, r, e).unwrap(),
        tree.erode(r, e).unwrap()
    );
    prop_assert_eq!(
        shape::opening(&mapped, r, e).unwrap(),
        tree.opening(r, e).unwrap()
    );
    prop_assert_eq!(
        shape::closing(&mapped, r, e).unwrap(),
        tree.closing(r, e).unwrap()
    );
    prop_assert_eq!(
        shape::dilate_ball_by_distance(&mapped, r).unwrap(),
        tree.dilate_ball_by_distance(r).unwrap()
    );
    prop_assert_eq!(
        shape::erode_ball_by_distance(&mapped, r).unwrap(),
        tree.erode_ball_by_distance(r).unwrap()
    );
    prop_assert_eq!(shape::surface_area(&mapped).unwrap(), tree.surface_area());
    for c in 1..=K {
        let parts = shape::components(&mapped, c).unwrap();
        prop_assert_eq!(&parts, &tree.components(c).unwrap());
        prop_assert_eq!(
            shape::component_sizes(&mapped, c).unwrap(),
            tree.component_sizes(c).unwrap()
        );
        prop_assert_eq!(
            shape::largest_component(&mapped, c).unwrap(),
            tree.largest_component(c).unwrap()
        );
        if c == 1 || c == K {
            prop_assert_eq!(
                shape::euler_number(&mapped, c).unwrap(),
                tree.euler_number(c).unwrap()
            );
        }
    }
    let side = o.universe().side() as u32;
    let points: Vec<[u32; K]> = (0..side).map(|i| [i * 5 % side; K]).collect();
    prop_assert_eq!(
        shape::signed_distance_at(&mapped, &points).unwrap(),
        tree.signed_distance_at(&points).unwrap()
    );
    let shape_of = [side as usize; K];
    prop_assert_eq!(
        shape::signed_distance_window(&mapped, [0; K], shape_of).unwrap(),
        tree.signed_distance_window([0; K], shape_of).unwrap()
    );
    prop_assert_eq!(
        shape::narrow_band(&mapped, r).unwrap(),
        tree.narrow_band(r).unwrap()
    );
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    #[test]
    fn mapped_files_k1(o in obj::<1>(), e in element(), r in radius()) { check_mapped(&o, e, r)?; }
    #[test]
    fn mapped_files_k2(o in obj::<2>(), e in element(), r in radius()) { check_mapped(&o, e, r)?; }
    #[test]
    fn mapped_files_k3(o in obj::<3>(), e in element(), r in radius()) { check_mapped(&o, e, r)?; }
    #[test]
    fn mapped_files_k4(o in obj::<4>(), e in element(), r in radius()) { check_mapped(&o, e, r)?; }
}

/// The surface area of the whole universe at the largest level of each K, and of trees whose full leaves
/// are huge, counted on the nodes (a run per column would be 2^42 runs for K = 3).
#[test]
fn surface_area_of_the_whole_universe() {
    assert_eq!(KTree::<3>::full(21).unwrap().surface_area(), 6 << 42);
    assert_eq!(KTree::<4>::full(16).unwrap().surface_area(), 8 << 48);
    assert_eq!(KTree::<2>::full(31).unwrap().surface_area(), 4 << 31);
    assert_eq!(KTree::<1>::full(31).unwrap().surface_area(), 2);
    assert_eq!(
        shape::run_count(&KTree::<3>::full(21).unwrap()),
        Ok(1 << 42)
    );
    // Half the universe (x < U/2) at the largest level: 2·U² across x, U² across y and z.
    let mut sink = MemorySink::<3>::new(Universe::new(21).unwrap());
    let kids: Vec<NodeState> = (0..8)
        .map(|c| {
            if c & 1 == 0 {
                NodeState::Full
            } else {
                NodeState::Empty
            }
        })
        .collect();
    sink.push_block(1, &kids).unwrap();
    let half = sink.finish(NodeState::Partial).unwrap();
    assert_eq!(half.voxel_count(), 1 << 62);
    assert_eq!(
        shape::faces_per_axis(&half),
        Ok([2 << 42, 1 << 42, 1 << 42])
    );
    // A huge full leaf beside a small one: the small one's faces come off the big one's.
    let mut dense = vec![false; 64];
    dense[0] = true;
    let corner = KTree::<3>::from_dense(2, &dense).unwrap();
    assert_eq!(corner.surface_area(), 6);
}
