//! Quadrics and boxes to rays = brute-force exact evaluation at every voxel, K = 1 … 4; then stacked into a
//! well-formed tree equal to the dense reference.

use ktree::solid::{BoxSolid, Frame, Quadric, Rational, Sample, Solid};
use ktree::stacking::paper::stack;
use ktree::{KTree, RaySet, Universe};
use proptest::prelude::*;

fn max_level(k: usize) -> u32 {
    if k <= 3 {
        5
    } else {
        3
    }
}

/// Rays equal the brute-force test voxel by voxel, the tree built from them equals the dense tree.
fn agrees<const K: usize>(
    solid: &Solid<K>,
    level: u32,
    sample: Sample,
) -> Result<(), TestCaseError> {
    let rays = solid.to_rays(level, sample, true).unwrap();
    let u = Universe::<K>::new(level).unwrap();
    let n = u.voxels() as usize;
    let mut dense = vec![false; n];
    for (i, d) in dense.iter_mut().enumerate() {
        let p = u.dense_point(i);
        *d = solid.contains(level, sample, p);
        prop_assert_eq!(rays.contains(p), *d, "voxel {:?}", p);
    }
    // The generated set is in canonical form: rebuilding it through the validating path gives the same.
    let again = RaySet::<K>::from_rays(level, rays.iter()).unwrap();
    prop_assert_eq!(again.runs(), rays.runs());
    prop_assert_eq!(again.column_keys(), rays.column_keys());
    for i in 0..rays.len() {
        let [a, b] = rays.normals(i).unwrap();
        for nrm in [a, b] {
            let len: f32 = nrm.iter().map(|x| x * x).sum();
            prop_assert!((len - 1.0).abs() < 1e-3, "normal {:?}", nrm);
        }
    }
    let tree = stack(&rays);
    tree.assert_well_formed();
    prop_assert_eq!(tree, KTree::<K>::from_dense(level, &dense).unwrap());
    Ok(())
}

fn sample() -> impl Strategy<Value = Sample> {
    prop_oneof![Just(Sample::Centre), Just(Sample::Corner)]
}

fn frame() -> impl Strategy<Value = Frame> {
    prop_oneof![Just(Frame::Voxel), Just(Frame::UnitCube)]
}

/// Random symmetric integer matrices (any signature: ellipsoids, hyperboloids, cylinders, slabs, planes).
fn matrices<const K: usize>() -> impl Strategy<Value = Quadric<K>> {
    (
        prop::collection::vec(-40i128..=40, (K + 1) * (K + 1)),
        frame(),
    )
        .prop_filter_map("zero", |(v, frame)| {
            let m: Vec<Vec<i128>> = (0..=K)
                .map(|i| (0..=K).map(|j| v[i.min(j) * (K + 1) + i.max(j)]).collect())
                .collect();
            Quadric::from_matrix(&m, frame).ok()
        })
}

fn rational() -> impl Strategy<Value = Rational> {
    (
        -20i64..=60,
        prop_oneof![Just(1i64), Just(2), Just(3), Just(4), Just(10)],
    )
        .prop_map(|(n, d)| Rational::new(n, d).unwrap())
}

fn positive() -> impl Strategy<Value = Rational> {
    (
        1i64..=40,
        prop_oneof![Just(1i64), Just(2), Just(4), Just(5)],
    )
        .prop_map(|(n, d)| Rational::new(n, d).unwrap())
}

/// Named solids in voxel coordinates, with parameters around a universe of side ≤ 32.
fn named<const K: usize>() -> impl Strategy<Value = Solid<K>> {
    let centre = prop::array::uniform::<_, K>(rational());
    let radii = prop::array::uniform::<_, K>(positive());
    (0usize..7, centre, radii, positive(), positive(), 0..K).prop_filter_map(
        "bad parameters",
        |(kind, c, r, a, b, axis)| {
            let f = Frame::Voxel;
            let q = match kind {
                0 => Quadric::ball(c, a, f),
                1 => Quadric::ellipsoid(c, r, f),
                2 => Quadric::paraboloid(c, a, b, f),
                3 => Quadric::cylinder(axis, c, a, f),
                4 => Quadric::cone(axis, c, a, b, f),
                5 => Quadric::half_space(
                    r.map(|x| Rational::new(x.num() - 10, x.den()).unwrap()),
                    a,
                    f,
                ),
                _ => {
                    let hi: [Rational; K] = std::array::from_fn(|i| {
                        Rational::new(
                            c[i].num() * r[i].den() + r[i].num() * c[i].den(),
                            c[i].den() * r[i].den(),
                        )
                        .unwrap()
                    });
                    return BoxSolid::new(c, hi, f).ok().map(Solid::Box);
                }
            };
            q.ok().map(Solid::Quadric)
        },
    )
}

macro_rules! quadric_tests {
    ($k:literal, $raw:ident, $named:ident) => {
        proptest! {
            #![proptest_config(ktree_verify::config(48))]
            #[test]
            fn $raw(q in matrices::<$k>(), level in 0..=max_level($k), s in sample()) {
                agrees(&Solid::Quadric(q), level, s)?;
            }
            #[test]
            fn $named(solid in named::<$k>(), level in 0..=max_level($k), s in sample()) {
                agrees(&solid, level, s)?;
            }
        }
    };
}

quadric_tests!(1, raw_quadric_k1, named_solid_k1);
quadric_tests!(2, raw_quadric_k2, named_solid_k2);
quadric_tests!(3, raw_quadric_k3, named_solid_k3);
quadric_tests!(4, raw_quadric_k4, named_solid_k4);

/// Tie points: a disk of radius 5 centred at a voxel centre has centres exactly on its circle (3-4-5).
#[test]
fn ties_on_the_surface_are_inside() {
    let c = [Rational::new(21, 2).unwrap(), Rational::new(21, 2).unwrap()];
    let q = Quadric::<2>::ball(c, 5.into(), Frame::Voxel).unwrap();
    let rays = q.to_rays(5, Sample::Centre, false).unwrap();
    // Centres (10.5 ± 3, 10.5 ± 4) lie exactly on the circle: voxel (13, 14) must be inside, (13, 15) not.
    assert!(rays.contains([13, 14]) && rays.contains([10, 15]) && !rays.contains([13, 15]));
    assert!(!rays.contains([10, 16]));
    // The complement shares the boundary voxels.
    let out = q.negated().to_rays(5, Sample::Centre, false).unwrap();
    assert!(out.contains([13, 14]) && out.contains([10, 15]) && !out.contains([10, 12]));
}

/// The unit-cube frame: the paper's 1/8 sphere of radius 1 at the corner is the quarter disk at any level.
#[test]
fn unit_cube_frame_scales_with_level() {
    let q = Quadric::<2>::ball([0.into(), 0.into()], 1.into(), Frame::UnitCube).unwrap();
    for level in 1..8u32 {
        let side = 1u64 << level;
        let expect = (0..side)
            .flat_map(|x| (0..side).map(move |y| (x, y)))
            .filter(|&(x, y)| (2 * x + 1).pow(2) + (2 * y + 1).pow(2) <= 4 * side * side)
            .count();
        assert_eq!(
            q.to_rays(level, Sample::Centre, false)
                .unwrap()
                .voxel_count(),
            expect as u128
        );
    }
}

/// Bad parameters are errors, not panics.
#[test]
fn bad_parameters_are_errors() {
    let z = [Rational::int(0); 3];
    assert!(Quadric::<3>::ball(z, 0.into(), Frame::Voxel).is_err());
    assert!(Quadric::<3>::cylinder(3, z, 1.into(), Frame::Voxel).is_err());
    assert!(Quadric::<3>::half_space(z, 1.into(), Frame::Voxel).is_err());
    assert!(Quadric::<2>::from_matrix(
        &[vec![1, 2, 0], vec![0, 1, 0], vec![0, 0, -1]],
        Frame::Voxel
    )
    .is_err());
    assert!(Quadric::<2>::from_matrix(&[vec![1, 0], vec![0, 1]], Frame::Voxel).is_err());
    assert!("1.2.3".parse::<Rational>().is_err());
    assert!("1/0".parse::<Rational>().is_err());
    let big = Quadric::<3>::from_matrix(
        &[
            vec![1 << 99, 0, 0, 0],
            vec![0, 1, 0, 0],
            vec![0, 0, 1, 0],
            vec![0, 0, 0, -1],
        ],
        Frame::Voxel,
    )
    .unwrap();
    assert!(big.to_rays(20, Sample::Centre, false).is_err());
    // Too many rays: an error, not an exhausted memory.
    let h = Rational::int(1 << 5);
    let ball = Quadric::<4>::ball([h; 4], h, Frame::Voxel).unwrap();
    let n = ball.to_rays(6, Sample::Centre, false).unwrap().len();
    assert!(ball.to_rays_limited(6, Sample::Centre, false, n).is_ok());
    assert!(matches!(
        ball.to_rays_limited(6, Sample::Centre, false, n - 1),
        Err(ktree::solid::SolidError::TooManyRays { .. })
    ));
    let b = BoxSolid::<4>::new(
        [Rational::int(0); 4],
        [Rational::int(1 << 16); 4],
        Frame::Voxel,
    )
    .unwrap();
    assert!(b.to_rays(16, Sample::Centre, false).is_err());
}

proptest! {
    #![proptest_config(ktree_verify::config(24))]
    /// Parameters with large denominators give matrices too large for the 64-bit fast path: the 128-bit
    /// path must agree with the brute force too.
    #[test]
    fn large_coefficients_k3(c in prop::array::uniform3(-3_000_000i64..20_000_000), r in 1_000_000i64..12_000_000,
                             k in 0usize..3, s in sample()) {
        let d = 1_000_003;
        let centre = c.map(|x| Rational::new(x, d).unwrap());
        let radius = Rational::new(r, d).unwrap();
        let q = match k {
            0 => Quadric::<3>::ball(centre, radius, Frame::Voxel),
            1 => Quadric::<3>::cone(2, centre, radius, Rational::new(r / 2 + 1, d).unwrap(), Frame::Voxel),
            _ => Quadric::<3>::paraboloid(centre, radius, Rational::new(3 * r, d).unwrap(), Frame::Voxel),
        };
        agrees(&Solid::Quadric(q.unwrap()), 4, s)?;
    }
}

/// The general quadric ball and the core's direct ball generator (`rays::ball_rays`) agree.
#[test]
fn quadric_ball_equals_the_direct_generator() {
    for (c2, r2, level) in [
        ([16i64, 16, 16], 16i64, 4u32),
        ([3, 40, 17], 23, 5),
        ([-5, 9, 31], 30, 5),
        ([64, 64, 64], 64, 6),
        // Long rows: columns are solved by stepping each row's quadratic from column to column.
        ([1024, 1024, 1024], 1023, 10),
        ([701, 1029, 517], 611, 10),
    ] {
        let centre = c2.map(|c| Rational::new(c, 2).unwrap());
        let q = Quadric::<3>::ball(centre, Rational::new(r2, 2).unwrap(), Frame::Voxel).unwrap();
        assert_eq!(
            q.to_rays(level, Sample::Centre, false).unwrap(),
            ktree::rays::ball_rays::<3>(level, c2, r2).unwrap(),
            "{c2:?} {r2}"
        );
    }
}
