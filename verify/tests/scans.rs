//! Scans in: OctoMap's scan graphs, scan logs and poses against liboctomap itself (the world points and
//! sensor origins of each node, bit for bit, as `insertPointCloud(const ScanNode&)` computes them), its
//! real `spherical_scan.graph` integrated into the same map as OctoMap's, scan lists of point files, and
//! bad files named at their byte or line.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use ktree::io::{
    read_scan_directory, read_scan_graph, read_scan_list, read_scan_log, read_scans, Place, Pose,
    Scan, ScanNode,
};
use ktree::map::OccupancyMap;
use ktree::KTree;
use ktree_verify::tools;
use proptest::prelude::*;

/// OctoMap's scan graph, kept in data/ (the same bytes as Debian's liboctomap-dev example).
fn spherical_scan() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/scans/spherical_scan.graph")
}

/// Builds `octomap_scans` against the installed OctoMap into `dir`; `None` after [`tools::missing`]
/// without `g++` or OctoMap's headers.
fn octomap_scans(dir: &Path) -> Option<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/maps/octomap_scans.cpp");
    tools::build_octomap_program(dir, &src)
}

/// Runs `exe` with `args`, `input` on its standard input; its standard output.
fn run(exe: &Path, args: &[&str], input: String) -> String {
    let mut child = Command::new(exe)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("octomap_scans runs");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let out = child.wait_with_output().expect("octomap_scans finishes");
    writer.join().unwrap().unwrap();
    assert!(out.status.success(), "octomap_scans {args:?} failed");
    String::from_utf8(out.stdout).unwrap()
}

fn f32_hex(hex: &str) -> f32 {
    f32::from_bits(u32::from_str_radix(hex, 16).unwrap())
}

fn bits3(p: [f32; 3]) -> [u32; 3] {
    p.map(f32::to_bits)
}

/// The scans OctoMap places from the graph `file` (`octomap_scans world`), with their node ids.
fn octomap_world(exe: &Path, file: &Path) -> Vec<(u32, Scan)> {
    let out = run(exe, &["world", file.to_str().unwrap()], String::new());
    let mut scans: Vec<(u32, Scan)> = Vec::new();
    for line in out.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f[0] == "node" {
            let origin = [f32_hex(f[3]), f32_hex(f[4]), f32_hex(f[5])];
            let scan = Scan {
                points: Vec::with_capacity(f[2].parse().unwrap()),
                origin,
            };
            scans.push((f[1].parse().unwrap(), scan));
        } else {
            let p = [f32_hex(f[0]), f32_hex(f[1]), f32_hex(f[2])];
            scans.last_mut().unwrap().1.points.push(p);
        }
    }
    scans
}

/// Asserts that ktree's scans are OctoMap's, bit for bit.
fn assert_same_scans(ours: &[Scan], theirs: &[(u32, Scan)], what: &str) {
    assert_eq!(ours.len(), theirs.len(), "{what}: scans");
    for (i, (a, (_, b))) in ours.iter().zip(theirs).enumerate() {
        assert_eq!(
            bits3(a.origin),
            bits3(b.origin),
            "{what}: scan {i}'s origin {:?} vs {:?}",
            a.origin,
            b.origin
        );
        assert_eq!(a.points.len(), b.points.len(), "{what}: scan {i}'s points");
        for (j, (p, q)) in a.points.iter().zip(&b.points).enumerate() {
            assert_eq!(
                bits3(*p),
                bits3(*q),
                "{what}: scan {i}, point {j}: {p:?} vs {q:?}"
            );
        }
    }
}

fn graph_scans(file: &Path) -> Vec<Scan> {
    let bytes = std::fs::read(file).unwrap();
    read_scan_graph(&bytes, file)
        .unwrap()
        .iter()
        .map(ScanNode::to_scan)
        .collect()
}

#[test]
fn the_spherical_scan_graph_reads_without_octomap() {
    let file = spherical_scan();
    let bytes = std::fs::read(&file).unwrap();
    let nodes = read_scan_graph(&bytes, &file).unwrap();
    assert_eq!(nodes.len(), 1);
    assert_eq!(nodes[0].points.len(), 10_201);
    // The pose is a unit quaternion; the world points are the sensor-frame points moved by it.
    let q = nodes[0].pose.rotation;
    let norm: f32 = q.iter().map(|c| c * c).sum();
    assert!((norm - 1.0).abs() < 1e-5, "{q:?}");
    let scans = read_scans(&file).unwrap();
    assert_eq!(scans, vec![nodes[0].to_scan()]);
    // The sensor is at the pose's translation, up to OctoMap's rounding.
    let (o, t) = (scans[0].origin, nodes[0].pose.translation);
    assert!((0..3).all(|a| (o[a] - t[a]).abs() < 1e-6), "{o:?} {t:?}");
}

#[test]
fn the_spherical_scan_graph_is_placed_as_octomap_places_it() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_scans(dir.path()) else {
        return;
    };
    let debian = Path::new("/usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph");
    if debian.is_file() {
        assert_eq!(
            std::fs::read(debian).unwrap(),
            std::fs::read(spherical_scan()).unwrap()
        );
    }
    let theirs = octomap_world(&exe, &spherical_scan());
    assert_eq!(theirs.len(), 1);
    assert_same_scans(
        &graph_scans(&spherical_scan()),
        &theirs,
        "spherical_scan.graph",
    );
}

/// A small random generator (fixed seeds: the cases are the same every run).
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// A node for `octomap_scans write`: translation, angles, points (sensor frame).
type NodeInput = ([f32; 3], [f64; 3], Vec<[f32; 3]>);

fn random_nodes(seed: u64, count: usize, points: usize) -> Vec<NodeInput> {
    let mut g = Lcg(seed);
    let pi = std::f64::consts::PI;
    (0..count)
        .map(|_| {
            let t = [0; 3].map(|_| g.range(-20.0, 20.0) as f32);
            let a = [
                g.range(-pi, pi),
                g.range(-pi / 2.0, pi / 2.0),
                g.range(-4.0, 4.0),
            ];
            let p = (0..points)
                .map(|_| [0; 3].map(|_| g.range(-10.0, 10.0) as f32))
                .collect();
            (t, a, p)
        })
        .collect()
}

/// The input of `octomap_scans write` for `nodes`.
fn write_input(nodes: &[NodeInput]) -> String {
    let mut s = String::new();
    for (t, a, points) in nodes {
        s += &format!(
            "node {:x} {:x} {:x} {:x} {:x} {:x}\n",
            t[0].to_bits(),
            t[1].to_bits(),
            t[2].to_bits(),
            a[0].to_bits(),
            a[1].to_bits(),
            a[2].to_bits()
        );
        for p in points {
            s += &format!(
                "{:x} {:x} {:x}\n",
                p[0].to_bits(),
                p[1].to_bits(),
                p[2].to_bits()
            );
        }
    }
    s
}

#[test]
fn graphs_with_random_poses_written_by_octomap_read_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_scans(dir.path()) else {
        return;
    };
    for (seed, count, points) in [(1, 1, 0), (2, 1, 50), (3, 3, 40), (4, 6, 25), (5, 12, 10)] {
        let nodes = random_nodes(seed, count, points);
        let file = dir.path().join(format!("g{seed}.graph"));
        run(
            &exe,
            &["write", file.to_str().unwrap()],
            write_input(&nodes),
        );
        let read = read_scan_graph(&std::fs::read(&file).unwrap(), &file).unwrap();
        // The file holds the poses OctoMap made from the angles: ktree makes the same from them.
        for (node, (t, a, p)) in read.iter().zip(&nodes) {
            assert_eq!(
                node.pose,
                Pose::from_xyz_rpy(t[0], t[1], t[2], a[0], a[1], a[2])
            );
            assert_eq!(&node.points, p);
        }
        let ours: Vec<Scan> = read.iter().map(ScanNode::to_scan).collect();
        let theirs = octomap_world(&exe, &file);
        assert_eq!(
            read.iter().map(|n| n.id).collect::<Vec<_>>(),
            theirs.iter().map(|(id, _)| *id).collect::<Vec<_>>()
        );
        assert_same_scans(&ours, &theirs, &format!("graph {seed}"));
    }
}

#[test]
fn logs_read_as_log2graph_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_scans(dir.path()) else {
        return;
    };
    let Some(log2graph) = tools::require(&["log2graph"], "install Debian's octomap-tools") else {
        return;
    };
    // Printed as Rust prints floats (the shortest text that reads back as the same f32), with a comment,
    // an empty line and a node without points.
    let mut g = Lcg(11);
    let mut text = String::from("# a log for the test\n\n");
    for node in 0..5 {
        let v: Vec<f32> = (0..6).map(|_| g.range(-6.0, 6.0) as f32).collect();
        text += &format!(
            "NODE {} {} {} {} {} {}\n",
            v[0], v[1], v[2], v[3], v[4], v[5]
        );
        for _ in 0..(node * 17 % 40) {
            let p: Vec<f32> = (0..3).map(|_| g.range(-8.0, 8.0) as f32).collect();
            text += &format!("{} {} {}\n", p[0], p[1], p[2]);
        }
    }
    let log = dir.path().join("scans.log");
    let graph = dir.path().join("scans.graph");
    std::fs::write(&log, &text).unwrap();
    let status = Command::new(log2graph)
        .arg(&log)
        .arg(&graph)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let from_log: Vec<Scan> = read_scan_log(text.as_bytes(), &log)
        .unwrap()
        .iter()
        .map(ScanNode::to_scan)
        .collect();
    assert_eq!(from_log.len(), 5);
    let theirs = octomap_world(&exe, &graph);
    assert_same_scans(&from_log, &theirs, "the log");
    assert_same_scans(&graph_scans(&graph), &theirs, "log2graph's graph");
    assert_eq!(read_scans(&log).unwrap(), from_log);
}

fn angle() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -7.0f64..7.0,
        1 => prop::sample::select(vec![
            0.0,
            -0.0,
            std::f64::consts::PI,
            -std::f64::consts::PI,
            std::f64::consts::FRAC_PI_2,
            -std::f64::consts::FRAC_PI_2,
            1e-9,
            100.0,
        ]),
    ]
}

type PoseCase = ([f32; 3], [f64; 3], [f32; 3]);

fn pose_case() -> impl Strategy<Value = PoseCase> {
    (
        prop::array::uniform3(-50.0f32..50.0),
        prop::array::uniform3(angle()),
        prop::array::uniform3(-50.0f32..50.0),
    )
}

fn check_poses(exe: &Path, cases: &[PoseCase]) -> Result<(), TestCaseError> {
    let mut input = String::new();
    for (t, a, p) in cases {
        let f: Vec<String> = t
            .iter()
            .map(|x| format!("{:x}", x.to_bits()))
            .chain(a.iter().map(|x| format!("{:x}", x.to_bits())))
            .chain(p.iter().map(|x| format!("{:x}", x.to_bits())))
            .collect();
        input += &(f.join(" ") + "\n");
    }
    let out = run(exe, &["pose"], input);
    let lines: Vec<&str> = out.lines().collect();
    prop_assert_eq!(lines.len(), cases.len());
    for ((t, a, p), line) in cases.iter().zip(lines) {
        let theirs: Vec<u32> = line
            .split_whitespace()
            .map(|h| u32::from_str_radix(h, 16).unwrap())
            .collect();
        let pose = Pose::from_xyz_rpy(t[0], t[1], t[2], a[0], a[1], a[2]);
        let ours: Vec<u32> = pose
            .rotation
            .iter()
            .chain(&pose.transform(*p))
            .chain(&pose.inverse().transform(*p))
            .map(|x| x.to_bits())
            .collect();
        prop_assert_eq!(&ours, &theirs, "pose {:?} {:?}, point {:?}", t, a, p);
    }
    Ok(())
}

#[test]
fn poses_from_angles_are_octomaps() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_scans(dir.path()) else {
        return;
    };
    let mut runner = proptest::test_runner::TestRunner::new(ktree_verify::config(16));
    runner
        .run(&prop::collection::vec(pose_case(), 1..400), |cases| {
            check_poses(&exe, &cases)
        })
        .unwrap();
}

/// OctoMap's map of the graph `file` (`octomap_scans map`) as a valued tree at OctoMap's keys.
fn octomap_graph_map(exe: &Path, file: &Path, res: f64, max_range: Option<f64>) -> KTree<3, f32> {
    let mut args = vec![
        "map".to_string(),
        file.to_str().unwrap().to_string(),
        res.to_string(),
    ];
    if let Some(m) = max_range {
        args.push(m.to_string());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = run(exe, &args, String::new());
    let mut runs = Vec::new();
    for line in out.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f[0], "leaf");
        let k: Vec<u32> = f[1..5].iter().map(|s| s.parse().unwrap()).collect();
        let l = f32_hex(f[5]);
        for x in k[0]..k[0] + k[3] {
            for y in k[1]..k[1] + k[3] {
                runs.push((ktree::Ray::new([x, y, k[2]], k[2] + k[3]), l));
            }
        }
    }
    KTree::from_value_runs(&ktree::rays::ValueRuns::from_runs(16, runs).unwrap())
}

#[test]
fn the_spherical_scan_integrated_gives_octomaps_map() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_scans(dir.path()) else {
        return;
    };
    let file = spherical_scan();
    let scans = read_scans(&file).unwrap();
    // Its points lie 4.01002 m from the sensor (a sphere): the ranges cut no ray, some, or all.
    let mut unclipped = 0;
    for (res, range) in [
        (0.1, None),
        (0.05, None),
        (0.05, Some(4.010025)),
        (0.2, Some(3.0)),
    ] {
        let mut map = OccupancyMap::<3>::new(res).unwrap();
        for scan in &scans {
            map.insert(&scan.points, scan.origin, range).unwrap();
        }
        map.log_odds().assert_well_formed();
        let theirs = octomap_graph_map(&exe, &file, res, range);
        let occupied = map.occupied().voxel_count();
        match range {
            None => assert!(occupied > 1000, "at {res} m"),
            Some(r) if r > 4.0 => assert!(
                occupied > 0 && occupied < unclipped,
                "{occupied} of {unclipped} occupied voxels at range {r}"
            ),
            Some(_) => assert_eq!(occupied, 0),
        }
        unclipped = occupied;
        assert!(
            map.free().voxel_count() > 1000,
            "at {res} m, range {range:?}"
        );
        assert_eq!(map.log_odds(), &theirs, "at {res} m, range {range:?}");
    }
}

#[test]
fn random_graphs_integrated_give_octomaps_maps() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_scans(dir.path()) else {
        return;
    };
    let nodes = random_nodes(21, 4, 500);
    let file = dir.path().join("m.graph");
    run(
        &exe,
        &["write", file.to_str().unwrap()],
        write_input(&nodes),
    );
    let scans = read_scans(&file).unwrap();
    for (res, range) in [(0.5, None), (0.25, Some(6.0))] {
        let mut map = OccupancyMap::<3>::new(res).unwrap();
        for scan in &scans {
            map.insert(&scan.points, scan.origin, range).unwrap();
        }
        assert_eq!(
            map.log_odds(),
            &octomap_graph_map(&exe, &file, res, range),
            "at {res} m, range {range:?}"
        );
    }
}

/// A binary little-endian PLY of `points` as `float` (exact: the reader's `f64` rounds back to them).
fn write_ply(path: &Path, points: &[[f32; 3]]) {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
        points.len()
    )
    .into_bytes();
    for p in points {
        p.iter().for_each(|c| bytes.extend(c.to_le_bytes()));
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn scan_lists_place_point_files_as_graph_nodes_are_placed() {
    let dir = tempfile::tempdir().unwrap();
    let nodes = random_nodes(31, 3, 60);
    std::fs::create_dir(dir.path().join("clouds")).unwrap();
    let mut list = String::from("# posed scans, then one in world coordinates\n");
    for (i, (t, a, points)) in nodes.iter().enumerate() {
        write_ply(&dir.path().join(format!("clouds/s{i}.ply")), points);
        list += &format!(
            "clouds/s{i}.ply {} {} {} {} {} {}\n",
            t[0], t[1], t[2], a[0], a[1], a[2]
        );
    }
    list += "\nclouds/s0.ply 1.5 -2 0.25\n";
    let list_file = dir.path().join("scans.txt");
    std::fs::write(&list_file, &list).unwrap();
    let scans = read_scan_list(&list_file).unwrap();
    assert_eq!(scans.len(), 4);
    for (scan, (t, a, points)) in scans.iter().zip(&nodes) {
        let node = ScanNode {
            id: 0,
            pose: Pose::from_xyz_rpy(t[0], t[1], t[2], a[0], a[1], a[2]),
            points: points.clone(),
        };
        assert_eq!(scan, &node.to_scan());
    }
    assert_eq!(scans[3].points, nodes[0].2);
    assert_eq!(scans[3].origin, [1.5, -2.0, 0.25]);
    assert_eq!(read_scans(&list_file).unwrap(), scans);

    // And with OctoMap, the same poses and points in a graph it wrote: the same scans, bit for bit.
    if let Some(exe) = octomap_scans(dir.path()) {
        let file = dir.path().join("same.graph");
        run(
            &exe,
            &["write", file.to_str().unwrap()],
            write_input(&nodes),
        );
        assert_same_scans(&scans[..3], &octomap_world(&exe, &file), "the list");
    }

    // A folder: its point files in name order, in world coordinates.
    std::fs::write(dir.path().join("clouds/readme.md"), "not a cloud").unwrap();
    let folder = read_scan_directory(&dir.path().join("clouds"), [0.0, 0.0, 1.0]).unwrap();
    assert_eq!(folder.len(), 3);
    for (scan, (_, _, points)) in folder.iter().zip(&nodes) {
        assert_eq!((&scan.points, scan.origin), (points, [0.0, 0.0, 1.0]));
    }

    // A missing point file is the point file's error; a bad line the list's.
    std::fs::write(&list_file, "clouds/s0.ply 0 0 0\nclouds/none.ply 0 0 0\n").unwrap();
    let e = read_scan_list(&list_file).unwrap_err();
    assert!(e.file().ends_with("none.ply"), "{e}");
    std::fs::write(&list_file, "# c\nclouds/s0.ply 0 0\n").unwrap();
    let e = read_scan_list(&list_file).unwrap_err();
    assert_eq!(e.line(), Some(2), "{e}");
}

#[test]
fn bad_graphs_and_logs_are_named_at_their_byte_or_line() {
    let file = spherical_scan();
    let bytes = std::fs::read(&file).unwrap();
    // Truncated anywhere: an error at or before the cut.
    for cut in [
        0,
        3,
        4,
        7,
        8,
        100,
        285_600,
        bytes.len() - 72,
        bytes.len() - 5,
        bytes.len() - 1,
    ] {
        let e = read_scan_graph(&bytes[..cut], &file).unwrap_err();
        let at = e.offset().unwrap_or_else(|| panic!("{e}"));
        assert!(at as usize <= cut, "cut at {cut}: {e}");
        assert!(
            e.to_string()
                .starts_with(&format!("{}: byte ", file.display())),
            "{e}"
        );
    }
    // The point count of the node garbled to more than the file holds: refused where it stands.
    let mut garbled = bytes.clone();
    garbled[4..8].copy_from_slice(&0x4000_0000u32.to_le_bytes());
    let e = read_scan_graph(&garbled, &file).unwrap_err();
    assert_eq!(e.location.place, Place::Byte(4), "{e}");
    // The node count garbled.
    let mut garbled = bytes.clone();
    garbled[0..4].copy_from_slice(&2u32.to_le_bytes());
    assert!(read_scan_graph(&garbled, &file).is_err());
    // A point's stored length garbled.
    let mut garbled = bytes.clone();
    garbled[8] = 9;
    let e = read_scan_graph(&garbled, &file).unwrap_err();
    assert_eq!(e.location.place, Place::Byte(8), "{e}");
    // A byte after the end.
    let mut longer = bytes.clone();
    longer.extend([0; 3]);
    let e = read_scan_graph(&longer, &file).unwrap_err();
    assert_eq!(e.location.place, Place::Byte(bytes.len() as u64), "{e}");

    let log = Path::new("bad.log");
    for (text, line) in [
        (&b"0 0 1\n"[..], 1),
        (b"NODE 0 0 0 0 0 0\n1 2 3\n4 5\n", 3),
        (b"# c\nNODE 0 0 zero 0 0 0\n", 2),
        (b"NODE 0 0 0 0 0 0\n1 2 3 4\n", 2),
        (b"NODE 0 0 0 0 0 0\n1 2 nan\n", 2),
    ] {
        let e = read_scan_log(text, log).unwrap_err();
        assert_eq!(e.line(), Some(line), "{e}");
        assert!(
            e.to_string().starts_with(&format!("bad.log:{line}: ")),
            "{e}"
        );
    }
}
