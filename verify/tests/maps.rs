//! Occupancy maps: the key traversal against the geometry of the segment, the map's integration against
//! a naive reference (a hash map of voxels updated ray by ray), K = 2 and 3, and OctoMap itself on its
//! own real scan (`scan.dat` of Debian's liboctomap-dev), on synthetic scans with a maximum range, and on
//! rays inserted one at a time (`insertRay`, its unit test's sphere of rays among them).

use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use ktree::map::{key_ray, MapGrid, OccupancyMap, SensorModel, VoxelState};
use ktree::space::morton_decode;
use ktree::KTree;
use ktree_verify::tools;
use proptest::prelude::*;

#[path = "maps/colours.rs"]
mod colours;

/// The smallest and largest world coordinates of voxel `key` along an axis.
fn bounds(grid: &MapGrid, key: u32) -> (f64, f64) {
    let lo = grid.corner() + f64::from(key) * grid.resolution();
    (lo, lo + grid.resolution())
}

/// Whether the segment from `a` to `b` passes within `slack` of voxel `key` (slab test).
fn segment_meets<const K: usize>(
    grid: &MapGrid,
    a: [f32; K],
    b: [f32; K],
    key: [u32; K],
    slack: f64,
) -> bool {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for i in 0..K {
        let (lo, hi) = bounds(grid, key[i]);
        let (lo, hi) = (lo - slack, hi + slack);
        let (p, d) = (f64::from(a[i]), f64::from(b[i]) - f64::from(a[i]));
        if d == 0.0 {
            if p < lo || p > hi {
                return false;
            }
        } else {
            let (u, v) = ((lo - p) / d, (hi - p) / d);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
    }
    t0 <= t1
}

fn check_ray<const K: usize>(res: f64, a: [f32; K], b: [f32; K]) -> Result<(), TestCaseError> {
    let grid = MapGrid::new(res).unwrap();
    let mut keys = Vec::new();
    prop_assert!(key_ray(&grid, a, b, &mut keys));
    let (ka, kb) = (grid.keys(a).unwrap(), grid.keys(b).unwrap());
    if ka == kb {
        prop_assert!(keys.is_empty());
        return Ok(());
    }
    prop_assert_eq!(keys[0], ka);
    prop_assert!(!keys.contains(&kb), "the end's voxel is not crossed");
    for w in keys.windows(2) {
        let steps: u32 = (0..K).map(|i| w[0][i].abs_diff(w[1][i])).sum();
        prop_assert_eq!(steps, 1, "consecutive voxels share a face: {:?}", w);
    }
    for &k in &keys {
        prop_assert!(
            segment_meets(&grid, a, b, k, res * 1e-4),
            "{:?} is off the segment",
            k
        );
    }
    // The last voxel crossed touches the end's (or the traversal stopped at the end's distance).
    let last = *keys.last().unwrap();
    let gap: u32 = (0..K).map(|i| last[i].abs_diff(kb[i])).sum();
    prop_assert!(
        gap <= K as u32,
        "the ray stops near its end: {:?} {:?}",
        last,
        kb
    );
    Ok(())
}

fn coord() -> impl Strategy<Value = f32> {
    -40.0f32..40.0
}

proptest! {
    #![proptest_config(ktree_verify::config(256))]
    #[test]
    fn key_rays_follow_the_segment_k2(a in [coord(), coord()], b in [coord(), coord()], res in 0.05f64..2.0) {
        check_ray::<2>(res, a, b)?;
    }
    #[test]
    fn key_rays_follow_the_segment_k3(a in [coord(), coord(), coord()], b in [coord(), coord(), coord()], res in 0.05f64..2.0) {
        check_ray::<3>(res, a, b)?;
    }
}

/// The naive map: a hash map from keys to log-odds, each scan's hits and misses gathered point by point
/// into sets and applied one voxel at a time.
fn reference<const K: usize>(
    grid: &MapGrid,
    model: &SensorModel,
    scans: &[(Vec<[f32; K]>, [f32; K])],
    max_range: Option<f64>,
) -> HashMap<[u32; K], f32> {
    let mut map = HashMap::new();
    for (points, origin) in scans {
        let (mut hits, mut misses) = (HashSet::new(), HashSet::new());
        for &p in points {
            let d: f32 = (0..K)
                .map(|i| (p[i] - origin[i]) * (p[i] - origin[i]))
                .sum();
            let within = max_range.is_none_or(|m| f64::from(d).sqrt() <= m);
            let end = if within {
                p
            } else {
                ktree::map::clipped_end(*origin, p, max_range.unwrap())
            };
            let mut ray = Vec::new();
            key_ray(grid, *origin, end, &mut ray);
            misses.extend(ray);
            if within {
                if let Some(k) = grid.keys(p) {
                    hits.insert(k);
                }
            }
        }
        for k in misses.difference(&hits) {
            let l = map.entry(*k).or_insert(0.0);
            *l = model.update(*l, false);
        }
        for k in hits {
            let l = map.entry(k).or_insert(0.0);
            *l = model.update(*l, true);
        }
    }
    map
}

/// Every voxel of the map's tree with its log-odds.
fn voxels<const K: usize>(tree: &KTree<K, f32>) -> HashMap<[u32; K], f32> {
    let mut out = HashMap::new();
    for (cell, value) in tree.value_leaves() {
        let Some(v) = value else { continue };
        let base = cell.morton();
        let n = 1u64 << (K as u64 * cell.side().trailing_zeros() as u64);
        assert!(n <= 1 << 20, "a leaf of {n} voxels in a test map");
        for i in 0..n {
            out.insert(morton_decode::<K>(base + i), v);
        }
    }
    out
}

/// The map's voxels are `expected`'s, with the same log-odds bit for bit.
fn same_voxels<const K: usize>(
    tree: &KTree<K, f32>,
    expected: &HashMap<[u32; K], f32>,
) -> Result<(), TestCaseError> {
    let got = voxels(tree);
    prop_assert_eq!(got.len(), expected.len());
    for (k, v) in expected {
        prop_assert_eq!(
            got.get(k).map(|g| g.to_bits()),
            Some(v.to_bits()),
            "voxel {:?}",
            k
        );
    }
    Ok(())
}

fn check_map<const K: usize>(
    res: f64,
    scans: Vec<(Vec<[f32; K]>, [f32; K])>,
    max_range: Option<f64>,
) -> Result<(), TestCaseError> {
    let mut map = OccupancyMap::<K>::new(res).unwrap();
    for (points, origin) in &scans {
        map.insert(points, *origin, max_range).unwrap();
    }
    map.log_odds().assert_well_formed();
    let expected = reference(map.grid(), map.model(), &scans, max_range);
    same_voxels(map.log_odds(), &expected)?;
    // The three parts partition the map, and states agree with them.
    let (occupied, free) = (map.occupied(), map.free());
    prop_assert_eq!((&occupied & &free).unwrap().voxel_count(), 0);
    prop_assert_eq!(
        occupied.voxel_count() + free.voxel_count() + map.unknown().voxel_count(),
        1u128 << (16 * K)
    );
    let probes: Vec<[f32; K]> = scans.iter().flat_map(|(p, _)| p.iter().copied()).collect();
    for (p, s) in probes.iter().zip(map.states(&probes)) {
        let want = match map.grid().keys(*p).and_then(|k| expected.get(&k)) {
            None => VoxelState::Unknown,
            Some(&l) if map.model().is_occupied(l) => VoxelState::Occupied,
            Some(_) => VoxelState::Free,
        };
        prop_assert_eq!(s, want);
    }
    Ok(())
}

fn scan<const K: usize>() -> impl Strategy<Value = (Vec<[f32; K]>, [f32; K])> {
    (
        prop::collection::vec(prop::array::uniform::<_, K>(-3.0f32..3.0), 0..24),
        prop::array::uniform::<_, K>(-1.0f32..1.0),
    )
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]
    #[test]
    fn maps_match_the_naive_reference_k2(scans in prop::collection::vec(scan::<2>(), 1..5), res in 0.1f64..0.7, range in prop::option::of(0.5f64..4.0)) {
        check_map::<2>(res, scans, range)?;
    }
    #[test]
    fn maps_match_the_naive_reference_k3(scans in prop::collection::vec(scan::<3>(), 1..4), res in 0.2f64..0.7, range in prop::option::of(0.5f64..4.0)) {
        check_map::<3>(res, scans, range)?;
    }
}

/// A map forgets the voxels whose centres lie farther than the radius from the centre, and keeps the
/// others' log-odds, voxel for voxel against the map before.
fn check_forgetting<const K: usize>(
    res: f64,
    scans: Vec<(Vec<[f32; K]>, [f32; K])>,
    centre: [f64; K],
    radius: f64,
) -> Result<(), TestCaseError> {
    let mut map = OccupancyMap::<K>::new(res).unwrap();
    for (points, origin) in &scans {
        map.insert(points, *origin, None).unwrap();
    }
    let before = voxels(map.log_odds());
    map.forget_outside(centre, radius).unwrap();
    map.log_odds().assert_well_formed();
    let g = *map.grid();
    let expected: HashMap<[u32; K], f32> = before
        .into_iter()
        .filter(|(k, _)| {
            let d2: f64 = (0..K).map(|a| (g.centre(k[a]) - centre[a]).powi(2)).sum();
            d2 <= radius * radius
        })
        .collect();
    same_voxels(map.log_odds(), &expected)?;
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(48))]
    #[test]
    fn a_map_forgets_what_lies_outside_a_ball_k2(scans in prop::collection::vec(scan::<2>(), 1..4), res in 0.1f64..0.7, centre in prop::array::uniform2(-3.0f64..3.0), radius in 0.0f64..4.0) {
        check_forgetting::<2>(res, scans, centre, radius)?;
    }
    #[test]
    fn a_map_forgets_what_lies_outside_a_ball_k3(scans in prop::collection::vec(scan::<3>(), 1..3), res in 0.2f64..0.7, centre in prop::array::uniform3(-3.0f64..3.0), radius in 0.0f64..4.0) {
        check_forgetting::<3>(res, scans, centre, radius)?;
    }
}

#[test]
fn a_map_refuses_to_forget_around_a_centre_or_radius_that_is_not_a_number() {
    let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    map.insert(&[[1.0, 0.0, 0.0]], [0.0; 3], None).unwrap();
    let before = map.clone();
    assert!(map
        .forget_outside([f64::NAN, 0.0, 0.0], 1.0)
        .unwrap_err()
        .contains("centre"));
    assert!(map
        .forget_outside([0.0; 3], -1.0)
        .unwrap_err()
        .contains("radius"));
    assert!(map.forget_outside([0.0; 3], f64::INFINITY).is_err());
    assert_eq!(map, before);
}

/// Scans of thousands of rays, each crossing hundreds of voxels (a pseudo-random cloud of `n` points in
/// a ball of radius 3 around the sensor, which moves a little between scans).
fn big_scans<const K: usize>(n: usize, scans: usize) -> Vec<(Vec<[f32; K]>, [f32; K])> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0
    };
    (0..scans)
        .map(|s| {
            let origin = std::array::from_fn(|a| 0.3 * s as f32 * (a as f32 - 0.5));
            let points = (0..n)
                .map(|_| std::array::from_fn(|a| origin[a] + 3.0 * uniform()))
                .collect();
            (points, origin)
        })
        .collect()
}

/// Updates of hundreds of thousands of voxels, whose cells' children are merged into the map on
/// several threads, give the naive reference's map, K = 2 and 3, with and without a maximum range.
#[test]
fn large_updates_merged_on_several_threads_match_the_naive_reference() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .unwrap();
    pool.install(|| {
        for range in [None, Some(2.0)] {
            check_map::<2>(0.004, big_scans::<2>(1500, 3), range).unwrap();
            check_map::<3>(0.02, big_scans::<3>(1500, 2), range).unwrap();
        }
    });
}

/// Builds `octomap_insert` against the installed OctoMap into `dir`; `None` after [`tools::missing`]
/// without `g++` or OctoMap's headers.
fn octomap_insert(dir: &Path) -> Option<PathBuf> {
    octomap_program(dir, "octomap_insert")
}

/// Builds the checker `name` (`tests/maps/NAME.cpp`) against the installed OctoMap into `dir`.
fn octomap_program(dir: &Path, name: &str) -> Option<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/maps/{name}.cpp"));
    tools::build_octomap_program(dir, &src)
}

/// OctoMap's map of `scans` (each its points and origin) as a valued tree at OctoMap's keys.
fn octomap_map(
    exe: &Path,
    res: f64,
    max_range: Option<f64>,
    scans: &[(Vec<[f32; 3]>, [f32; 3])],
) -> KTree<3, f32> {
    let mut cmd = Command::new(exe);
    cmd.arg(res.to_string());
    if let Some(m) = max_range {
        cmd.arg(m.to_string());
    }
    let out = run_with_input(&mut cmd, scans_text(scans));
    leaves_tree(&out)
}

/// Scans as the checkers read them: `scan ox oy oz`, then the points.
fn scans_text(scans: &[(Vec<[f32; 3]>, [f32; 3])]) -> String {
    let mut input = String::new();
    for (points, o) in scans {
        // Rust prints the shortest text that reads back as the same f32: OctoMap reads the same floats.
        input += &format!("scan {} {} {}\n", o[0], o[1], o[2]);
        for p in points {
            input += &format!("{} {} {}\n", p[0], p[1], p[2]);
        }
    }
    input
}

/// Runs `cmd` with `input` on its standard input; its standard output.
fn run_with_input(cmd: &mut Command, input: String) -> String {
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the checker runs");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let out = child.wait_with_output().expect("the checker finishes");
    writer.join().unwrap().unwrap();
    assert!(out.status.success(), "the checker failed");
    String::from_utf8(out.stdout).unwrap()
}

/// The valued tree of a checker's `leaf kx ky kz side bits` lines.
fn leaves_tree(text: &str) -> KTree<3, f32> {
    let mut runs = Vec::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f[0], "leaf");
        let k: Vec<u32> = f[1..5].iter().map(|s| s.parse().unwrap()).collect();
        let l = f32::from_bits(u32::from_str_radix(f[5], 16).unwrap());
        for x in k[0]..k[0] + k[3] {
            for y in k[1]..k[1] + k[3] {
                runs.push((ktree::Ray::new([x, y, k[2]], k[2] + k[3]), l));
            }
        }
    }
    KTree::from_value_runs(&ktree::rays::ValueRuns::from_runs(16, runs).unwrap())
}

/// The voxels where two maps differ: in one only, or with other log-odds.
fn differences(a: &KTree<3, f32>, b: &KTree<3, f32>) -> u128 {
    let shapes = (&a.shape() ^ &b.shape()).unwrap().voxel_count();
    let both = (&a.shape() & &b.shape()).unwrap();
    let a_in = a.mask(&both);
    let b_in = b.mask(&both);
    let same = ktree::ops::values::select_where(
        &a_in
            .combine(
                &b_in.map_values(|v| Some(-v)).unwrap(),
                ktree::ops::values::Rule::Sum,
            )
            .unwrap(),
        |d: f32| d == 0.0,
    )
    .unwrap()
    .voxel_count();
    shapes + (both.voxel_count() - same)
}

/// OctoMap's real laser scan (88 206 points, sensor at the origin), as its `scan.dat` lines.
fn octomap_scan() -> Option<Vec<[f32; 3]>> {
    let file = Path::new("/usr/share/doc/liboctomap-dev/examples/data/scan.dat.bz2");
    if !tools::require_file(
        file,
        "install Debian's liboctomap-dev (it ships scan.dat.bz2)",
    ) {
        return None;
    }
    let bzcat = tools::require(&["bzcat"], "install bzip2")?;
    let out = Command::new(bzcat).arg(file).output().expect("bzcat runs");
    let text = String::from_utf8(out.stdout).unwrap();
    Some(
        text.lines()
            .map(|l| {
                let v: Vec<f32> = l.split_whitespace().map(|s| s.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
            .collect(),
    )
}

#[test]
fn octomaps_real_scan_gives_octomaps_map() {
    let dir = tempfile::tempdir().unwrap();
    let (Some(exe), Some(points)) = (octomap_insert(dir.path()), octomap_scan()) else {
        return;
    };
    assert_eq!(points.len(), 88_206);
    let scans = vec![(points, [0.0f32; 3])];
    for res in [0.1, 0.05] {
        let mut map = OccupancyMap::<3>::new(res).unwrap();
        let update = map.insert(&scans[0].0, [0.0; 3], None).unwrap();
        assert_eq!(update.rays_outside, 0);
        let theirs = octomap_map(&exe, res, None, &scans);
        assert_eq!(differences(map.log_odds(), &theirs), 0, "at {res} m");
        assert_eq!(map.log_odds(), &theirs);
    }
}

#[test]
fn scans_from_several_poses_with_a_maximum_range_give_octomaps_map() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_insert(dir.path()) else {
        return;
    };
    let scans = room_scans();
    for (res, range) in [(0.05, Some(3.0)), (0.1, None), (0.2, Some(2.5))] {
        let mut map = OccupancyMap::<3>::new(res).unwrap();
        for (points, origin) in &scans {
            map.insert(points, *origin, range).unwrap();
        }
        let theirs = octomap_map(&exe, res, range, &scans);
        assert_eq!(
            differences(map.log_odds(), &theirs),
            0,
            "at {res} m, range {range:?}"
        );
    }
}

/// Points on the walls of a 6 × 4 × 3 m room and a box in it, seen from three poses.
fn room_scans() -> Vec<(Vec<[f32; 3]>, [f32; 3])> {
    let mut seed = 7u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut scans = Vec::new();
    for origin in [[1.0f32, 1.0, 1.2], [4.3, 2.1, 1.5], [2.5, 3.2, 0.4]] {
        let mut points = Vec::new();
        for _ in 0..4000 {
            let (u, v) = (next(), next());
            let p = match (next() * 6.0) as u32 {
                0 => [0.0, 4.0 * u, 3.0 * v],
                1 => [6.0, 4.0 * u, 3.0 * v],
                2 => [6.0 * u, 0.0, 3.0 * v],
                3 => [6.0 * u, 4.0, 3.0 * v],
                4 => [6.0 * u, 4.0 * v, 0.0],
                _ => [2.0 + u, 1.5 + v, 1.0],
            };
            points.push(p);
        }
        scans.push((points, origin));
    }
    scans
}

/// A map's maximum-likelihood form: occupied voxels at the upper clamp, free ones at the lower.
fn max_likelihood(map: &OccupancyMap<3>) -> KTree<3, f32> {
    let m = *map.model();
    map.log_odds()
        .map_values(|l| {
            Some(if m.is_occupied(l) {
                m.clamp_max
            } else {
                m.clamp_min
            })
        })
        .unwrap()
}

#[test]
fn map_files_written_by_ktree_read_in_octomap_and_octomaps_read_in_ktree() {
    let dir = tempfile::tempdir().unwrap();
    let Some(files) = octomap_program(dir.path(), "octomap_files") else {
        return;
    };
    let scans = room_scans();
    let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    for (points, origin) in &scans {
        map.insert(points, *origin, None).unwrap();
    }
    let read = |path: &Path| {
        let out = Command::new(&files).arg("read").arg(path).output().unwrap();
        assert!(out.status.success(), "OctoMap reads {}", path.display());
        leaves_tree(&String::from_utf8(out.stdout).unwrap())
    };
    // ktree writes, OctoMap reads: every log-odds in .ot, the maximum-likelihood map in .bt.
    let (ot, bt) = (dir.path().join("ktree.ot"), dir.path().join("ktree.bt"));
    let mut bytes = Vec::new();
    ktree::io::write_ot_map(&mut bytes, &map).unwrap();
    std::fs::write(&ot, &bytes).unwrap();
    assert_eq!(&read(&ot), map.log_odds());
    bytes.clear();
    ktree::io::write_bt_map(&mut bytes, &map).unwrap();
    std::fs::write(&bt, &bytes).unwrap();
    assert_eq!(read(&bt), max_likelihood(&map));
    // OctoMap writes the same scans, ktree reads.
    let (ot, bt) = (dir.path().join("octomap.ot"), dir.path().join("octomap.bt"));
    let mut cmd = Command::new(&files);
    cmd.args(["write", "0.1"]).arg(&ot).arg(&bt);
    run_with_input(&mut cmd, scans_text(&scans));
    let model = *map.model();
    let theirs = ktree::io::read_ot_map(&std::fs::read(&ot).unwrap(), "octomap.ot", model).unwrap();
    assert_eq!(theirs, map);
    let theirs = ktree::io::read_bt_map(&std::fs::read(&bt).unwrap(), "octomap.bt", model).unwrap();
    assert_eq!(theirs.log_odds(), &max_likelihood(&map));
    assert_eq!(theirs.grid().resolution(), 0.1);
}

#[test]
fn octomaps_building_map_reads_with_its_free_space() {
    let dir = tempfile::tempdir().unwrap();
    let Some(files) = octomap_program(dir.path(), "octomap_files") else {
        return;
    };
    let path = Path::new("/usr/share/doc/liboctomap-dev/examples/data/geb079.bt");
    if !tools::require_file(path, "install Debian's liboctomap-dev (it ships geb079.bt)") {
        return;
    }
    let map = ktree::io::read_bt_map(
        &std::fs::read(path).unwrap(),
        "geb079.bt",
        SensorModel::default(),
    )
    .unwrap();
    assert_eq!(map.grid().resolution(), 0.08);
    let out = Command::new(&files).arg("read").arg(path).output().unwrap();
    let theirs = leaves_tree(&String::from_utf8(out.stdout).unwrap());
    assert_eq!(map.log_odds(), &theirs);
    assert!(map.free().voxel_count() > map.occupied().voxel_count());
}

#[test]
fn ray_casts_on_a_map_stop_where_octomaps_cast_ray_stops() {
    let dir = tempfile::tempdir().unwrap();
    let Some(files) = octomap_program(dir.path(), "octomap_files") else {
        return;
    };
    let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    for (points, origin) in &room_scans() {
        map.insert(points, *origin, None).unwrap();
    }
    let ot = dir.path().join("room.ot");
    let mut bytes = Vec::new();
    ktree::io::write_ot_map(&mut bytes, &map).unwrap();
    std::fs::write(&ot, &bytes).unwrap();
    // Rays from points in and around the room in every direction.
    let mut seed = 11u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let rays: Vec<([f32; 3], [f32; 3])> = (0..1500)
        .map(|_| {
            let o = [next() * 7.0 - 0.5, next() * 5.0 - 0.5, next() * 3.0];
            let d = [next() - 0.5, next() - 0.5, next() - 0.5];
            (o, d)
        })
        .collect();
    let text: String = rays
        .iter()
        .map(|(o, d)| format!("{} {} {} {} {} {}\n", o[0], o[1], o[2], d[0], d[1], d[2]))
        .collect();
    // Passing through unknown voxels with no range, the rays that meet nothing reach the map's bounds,
    // where OctoMap's end is the last voxel inside.
    for (ignore, range) in [(false, -1.0), (true, 4.0), (false, 2.0), (true, -1.0)] {
        let mut cmd = Command::new(&files);
        cmd.arg("cast")
            .arg(&ot)
            .arg(if ignore { "1" } else { "0" })
            .arg(range.to_string());
        let out = run_with_input(&mut cmd, text.clone());
        let mut kinds = HashSet::new();
        for ((o, d), line) in rays.iter().zip(out.lines()) {
            let f: Vec<u32> = line.split(' ').map(|s| s.parse().unwrap()).collect();
            let end = map.cast_ray(*o, *d, ignore, range);
            let (hit, key) = match end {
                ktree::map::CastEnd::Occupied(k) => (1, Some(k)),
                ktree::map::CastEnd::Unknown(k)
                | ktree::map::CastEnd::Range(k)
                | ktree::map::CastEnd::Outside(Some(k)) => (0, Some(k)),
                ktree::map::CastEnd::Outside(None) => (0, None),
            };
            kinds.insert(std::mem::discriminant(&end));
            assert_eq!(f[0], hit, "ray {o:?} {d:?}: {end:?}");
            if let Some(k) = key {
                assert_eq!(f[1..4], k, "ray {o:?} {d:?}: {end:?}");
            }
        }
        assert!(
            kinds.len() >= 2,
            "rays of several outcomes ({ignore}, {range})"
        );
        if (ignore, range) == (true, -1.0) {
            assert!(
                kinds.contains(&std::mem::discriminant(&ktree::map::CastEnd::Outside(None))),
                "rays that reach the map's bounds"
            );
        }
    }
}

/// A checker's output split into its `leaf` lines (as one text) and its other lines.
fn split_leaves(text: &str) -> (String, Vec<&str>) {
    let (leaves, other): (Vec<&str>, Vec<&str>) =
        text.lines().partition(|l| l.starts_with("leaf "));
    (leaves.join("\n"), other)
}

/// The number after `name` on the line `name N` of a checker's output.
fn count(lines: &[&str], name: &str) -> u64 {
    let line = lines
        .iter()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(' '))
        .unwrap_or_else(|| panic!("the checker printed no {name}"));
    line.parse().unwrap()
}

/// octomath's `Vector3::rotate_IP(roll, pitch, yaw)`: turned about y, then z, then x, each step computed
/// in `f64` from the `f32` coordinates and rounded back.
fn rotate(p: [f32; 3], roll: f64, pitch: f64, yaw: f64) -> [f32; 3] {
    let [mut x, mut y, mut z] = p;
    let (px, pz) = (f64::from(x), f64::from(z));
    x = (pz * pitch.sin() + px * pitch.cos()) as f32;
    z = (pz * pitch.cos() - px * pitch.sin()) as f32;
    let (yx, yy) = (f64::from(x), f64::from(y));
    x = (yx * yaw.cos() - yy * yaw.sin()) as f32;
    y = (yx * yaw.sin() + yy * yaw.cos()) as f32;
    let (ry, rz) = (f64::from(y), f64::from(z));
    y = (ry * roll.cos() - rz * roll.sin()) as f32;
    z = (ry * roll.sin() + rz * roll.cos()) as f32;
    [x, y, z]
}

/// The ray ends of OctoMap's unit test InsertRay: from the sensor at (0.01, 0.01, 0.02), the point 2 m
/// away along x ((2.01, 0.01, 0.01) from it) turned by 1° about z 360 times, then by 1° about y, 360
/// times over: 129 600 rays, the sensor's coordinates added in `f32`.
fn sphere_ends(origin: [f32; 3]) -> Vec<[f32; 3]> {
    // octomath's DEG2RAD(1.): 1 · 0.01745329251994329575, the same f64 as this.
    let degree = 0.017_453_292_519_943_295_f64;
    let mut on_surface = [2.01f32, 0.01, 0.01];
    let mut ends = Vec::with_capacity(360 * 360);
    for _ in 0..360 {
        for _ in 0..360 {
            ends.push(std::array::from_fn(|i| origin[i] + on_surface[i]));
            on_surface = rotate(on_surface, 0.0, 0.0, degree);
        }
        on_surface = rotate(on_surface, 0.0, degree, 0.0);
    }
    ends
}

#[test]
fn octomaps_insert_ray_unit_test_gives_octomaps_map() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_program(dir.path(), "octomap_insert_rays") else {
        return;
    };
    let origin = [0.01f32, 0.01, 0.02];
    let ends = sphere_ends(origin);
    let out = Command::new(&exe).arg("sphere").output().unwrap();
    assert!(out.status.success(), "the checker failed");
    let text = String::from_utf8(out.stdout).unwrap();
    let (leaves, lines) = split_leaves(&text);
    // The same rays as OctoMap's test, to the bit.
    let theirs_ends: Vec<[f32; 3]> = lines
        .iter()
        .filter_map(|l| l.strip_prefix("end "))
        .map(|l| {
            let v: Vec<u32> = l
                .split(' ')
                .map(|h| u32::from_str_radix(h, 16).unwrap())
                .collect();
            [v[0], v[1], v[2]].map(f32::from_bits)
        })
        .collect();
    assert_eq!(theirs_ends.len(), 360 * 360);
    assert!(theirs_ends
        .iter()
        .zip(&ends)
        .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)));
    assert_eq!(count(&lines, "outside"), 0);
    // OctoMap's test: 50 615 nodes once the map is written as .bt (maximum likelihood, pruned).
    assert_eq!(count(&lines, "binary_size"), 50_615);

    let mut map = OccupancyMap::<3>::new(0.05).unwrap();
    assert_eq!(map.insert_rays(origin, &ends, None).unwrap(), 0);
    let theirs = leaves_tree(&leaves);
    assert_eq!(differences(map.log_odds(), &theirs), 0);
    assert_eq!(map.log_odds(), &theirs);
    let theirs = OccupancyMap::from_log_odds(*map.grid(), *map.model(), theirs).unwrap();
    assert_eq!(map.occupied(), theirs.occupied());
    assert_eq!(map.free(), theirs.free());
    assert_eq!(map.unknown(), theirs.unknown());
    assert!(map.occupied().voxel_count() > 0 && map.free().voxel_count() > 0);
    // The same node count in ktree's tree: OctoMap's nodes are the ones that are not empty.
    let c = max_likelihood(&map).counts();
    assert_eq!(c.full + c.partial, 50_615);
    // Ray by ray is not scan by scan: one scan of the same ends updates each voxel once.
    let mut scan = OccupancyMap::<3>::new(0.05).unwrap();
    scan.insert(&ends, origin, None).unwrap();
    assert_ne!(scan.log_odds(), map.log_odds());
}

#[test]
fn rays_inserted_one_by_one_give_octomaps_map() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_program(dir.path(), "octomap_insert_rays") else {
        return;
    };
    // The room's scans, each with a point beyond the map, one in the sensor's voxel and one repeated.
    let mut scans = room_scans();
    for (points, origin) in &mut scans {
        points.truncate(1500);
        points.extend([[5000.0, 1.0, 1.0], *origin, points[0]]);
    }
    for (res, range) in [(0.1, None), (0.05, Some(2.5)), (0.2, Some(4.0))] {
        let mut map = OccupancyMap::<3>::new(res).unwrap();
        let mut outside = 0;
        for (i, (points, origin)) in scans.iter().enumerate() {
            if i == 0 {
                // The first scan ray by ray, the others at once.
                for p in points {
                    outside += usize::from(!map.insert_ray(*origin, *p, range).unwrap());
                }
            } else {
                outside += map.insert_rays(*origin, points, range).unwrap();
            }
        }
        let mut cmd = Command::new(&exe);
        cmd.arg(res.to_string());
        if let Some(m) = range {
            cmd.arg(m.to_string());
        }
        let out = run_with_input(&mut cmd, scans_text(&scans));
        let (leaves, lines) = split_leaves(&out);
        assert_eq!(outside as u64, count(&lines, "outside"), "at {res} m");
        // Without a range the rays to the far point leave the map; with one they are cut inside it.
        assert_eq!(outside, if range.is_none() { 3 } else { 0 });
        let theirs = leaves_tree(&leaves);
        assert_eq!(
            differences(map.log_odds(), &theirs),
            0,
            "at {res} m, range {range:?}"
        );
    }
}
