//! `ktree map`: scans in, the map written as .ot, .bt and .ktree equal to the library's map of the same
//! scans; `ktree project` of a map: its plane between two heights as a ROS map whose pixels are the
//! plane's occupied, free and unknown cells; bad input as one-line errors.

mod common;

use common::{ktree, run};
use ktree::io::{read_bt_map, read_ot_map};
use ktree::map::{OccupancyMap, SensorModel};
use ktree::KTree;

/// A room's walls (6 × 4 m, 2.5 m high) sampled on a grid, as seen from inside.
fn walls() -> Vec<[f32; 3]> {
    let mut points = Vec::new();
    for i in 0..60 {
        for k in 0..10 {
            let (u, z) = (i as f32 * 0.1, 0.05 + k as f32 * 0.25);
            points.push([u, 0.0, z]);
            points.push([u, 4.0, z]);
            if i < 40 {
                points.push([0.0, u, z]);
                points.push([6.0, u, z]);
            }
        }
    }
    points
}

fn write_xyz(path: &std::path::Path, points: &[[f32; 3]]) {
    let text: String = points
        .iter()
        .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(path, text).unwrap();
}

/// Runs `ktree map room.xyz --resolution 0.1 --sensor-origin 2.5,1.5,1.2 --out OUT` in `dir`.
fn map_room(dir: &std::path::Path, out: &str) {
    let s = |n: &str| dir.join(n).to_str().unwrap().to_string();
    run(&[
        "map",
        &s("room.xyz"),
        "--resolution",
        "0.1",
        "--sensor-origin",
        "2.5,1.5,1.2",
        "--out",
        &s(out),
    ]);
}

#[test]
fn map_files_hold_the_librarys_map() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let points = walls();
    let (a, b) = points.split_at(points.len() / 2);
    write_xyz(&dir.path().join("a.xyz"), a);
    write_xyz(&dir.path().join("b.xyz"), b);
    let origin = [2.5f32, 1.5, 1.2];
    let mut expected = OccupancyMap::<3>::new(0.1).unwrap();
    expected.insert(a, origin, Some(4.0)).unwrap();
    expected.insert(b, origin, Some(4.0)).unwrap();
    for out in ["room.ot", "room.bt", "room.ktree"] {
        let text = run(&[
            "map",
            &s("a.xyz"),
            &s("b.xyz"),
            "--resolution",
            "0.1",
            "--max-range",
            "4",
            "--sensor-origin",
            "2.5,1.5,1.2",
            "--out",
            &s(out),
        ]);
        assert!(text.contains("2 scans"), "{text}");
        let bytes = std::fs::read(dir.path().join(out)).unwrap();
        let model = SensorModel::default();
        match out {
            "room.ot" => assert_eq!(read_ot_map(&bytes, out, model).unwrap(), expected),
            "room.bt" => {
                let map = read_bt_map(&bytes, out, model).unwrap();
                assert_eq!(map.occupied(), expected.occupied());
                assert_eq!(map.free(), expected.free());
            }
            _ => {
                let (tree, frame) =
                    ktree::io::ktree::v3::read_valued_ktree_framed::<3, f32>(&bytes, out).unwrap();
                assert_eq!(&tree, expected.log_odds());
                // The map's resolution and OctoMap's origin as the file's world frame.
                let frame = frame.unwrap();
                assert_eq!(frame.voxel_size, 0.1);
                assert_eq!(frame.origin, [-32768.0 * 0.1; 3]);
            }
        }
    }
}

#[test]
fn a_map_kept_within_a_distance_of_the_sensor_is_the_librarys() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let points = walls();
    write_xyz(&dir.path().join("room.xyz"), &points);
    // The sensor moves along the room (the walls' points in world coordinates, a line a scan with the
    // sensor's place); after each scan only what lies within 2 m of it is kept.
    let list: String = ["1.5 1.5 1.2", "4.5 2.5 1.2"]
        .iter()
        .map(|o| format!("room.xyz {o}\n"))
        .collect();
    std::fs::write(dir.path().join("walk.scans"), list).unwrap();
    let mut expected = OccupancyMap::<3>::new(0.1).unwrap();
    for origin in [[1.5f32, 1.5, 1.2], [4.5, 2.5, 1.2]] {
        expected.insert(&points, origin, None).unwrap();
        expected.forget_outside(origin.map(f64::from), 2.0).unwrap();
    }
    run(&[
        "map",
        &s("walk.scans"),
        "--resolution",
        "0.1",
        "--keep-within",
        "2",
        "--out",
        &s("near.ktree"),
    ]);
    let bytes = std::fs::read(dir.path().join("near.ktree")).unwrap();
    let tree = ktree::io::ktree::v3::read_valued_ktree::<3, f32>(&bytes, "near.ktree").unwrap();
    assert_eq!(&tree, expected.log_odds());
    // Nothing farther than 2 m from the last origin is known, and what is near it is.
    let far = expected.states(&[[0.5, 0.5, 1.2], [4.5, 4.0, 1.3]]);
    assert_eq!(far[0], ktree::map::VoxelState::Unknown);
    assert_ne!(far[1], ktree::map::VoxelState::Unknown);
    // A map kept near the sensor has no history (its steps would forget what they saw).
    let (ok, _, err) = ktree(&[
        "map",
        &s("walk.scans"),
        "--resolution",
        "0.1",
        "--keep-within",
        "2",
        "--history",
        &s("h.ktree"),
        "--out",
        &s("m.ktree"),
    ]);
    assert!(!ok && err.contains("--history"), "{err}");
}

#[test]
fn a_maps_plane_is_a_ros_map_of_its_three_states() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    write_xyz(&dir.path().join("room.xyz"), &walls());
    map_room(dir.path(), "room.ot");
    run(&[
        "project",
        &s("room.ot"),
        "--axis",
        "z",
        "--range",
        "0.2:1.8",
        "--out",
        &s("floor.png"),
    ]);
    let map = read_ot_map(
        &std::fs::read(dir.path().join("room.ot")).unwrap(),
        "room.ot",
        SensorModel::default(),
    )
    .unwrap();
    let plane = map.plane(2, 0.2, 1.8).unwrap();
    let image = image::open(dir.path().join("floor.png"))
        .unwrap()
        .to_luma8();
    let side = 1u32 << plane.known.level();
    assert_eq!(image.dimensions(), (side, side));
    let (mut occupied, mut free) = (0u128, 0u128);
    for (x, row, p) in image.enumerate_pixels() {
        let cell = [x, side - 1 - row];
        let want = if plane.occupied.contains(cell) {
            occupied += 1;
            0
        } else if plane.known.contains(cell) {
            free += 1;
            254
        } else {
            205
        };
        assert_eq!(p.0[0], want, "pixel ({x}, {row})");
    }
    assert_eq!(occupied, plane.occupied.voxel_count());
    assert!(occupied > 100 && free > 1000, "{occupied} {free}");
    // The walls' cells: the plane's occupied cells are the map's occupied voxels between the heights.
    let walls_2d: KTree<2> =
        ktree::ops::project::<3, 2, _>(&map.occupied(), 2, 32770..32786).unwrap();
    assert_eq!(walls_2d.voxel_count(), occupied);
    let yaml = std::fs::read_to_string(dir.path().join("floor.yaml")).unwrap();
    assert!(yaml.contains("resolution: 0.1"), "{yaml}");
    // The same map kept as a .ktree projects to the same ROS map.
    map_room(dir.path(), "room.ktree");
    run(&[
        "project",
        &s("room.ktree"),
        "--axis",
        "z",
        "--range",
        "0.2:1.8",
        "--out",
        &s("floor_k.png"),
    ]);
    let read = |n: &str| std::fs::read(dir.path().join(n)).unwrap();
    assert_eq!(read("floor_k.png"), read("floor.png"));
    let yaml_k = String::from_utf8(read("floor_k.yaml")).unwrap();
    assert_eq!(yaml_k.replace("floor_k", "floor"), yaml);
    assert!(
        yaml.contains(&format!(
            "origin: [{:?}, {:?}, 0.0]",
            plane.origin[0], plane.origin[1]
        )),
        "{yaml}"
    );
}

#[test]
fn bad_map_arguments_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    write_xyz(&dir.path().join("p.xyz"), &walls()[..10]);
    for (args, needle) in [
        (vec!["--resolution", "0", "--out", "m.ot"], "resolution"),
        (
            vec!["--resolution", "0.1", "--out", "m.png"],
            ".ot, .bt or .ktree",
        ),
        (
            vec!["--resolution", "0.1", "--max-range", "-1", "--out", "m.ot"],
            "--max-range",
        ),
        (
            vec!["--resolution", "0.1", "--prob-hit", "0.3", "--out", "m.ot"],
            "hit",
        ),
        (
            vec![
                "--resolution",
                "0.1",
                "--keep-within",
                "-1",
                "--out",
                "m.ot",
            ],
            "--keep-within",
        ),
    ] {
        let mut all = vec!["map".to_string(), s("p.xyz")];
        all.extend(args.iter().map(|a| {
            if a.starts_with("m.") {
                s(a)
            } else {
                a.to_string()
            }
        }));
        let all: Vec<&str> = all.iter().map(String::as_str).collect();
        let (ok, _, err) = ktree(&all);
        assert!(!ok, "{all:?}");
        assert!(
            err.contains(needle) && err.trim().lines().count() == 1,
            "{all:?}: {err}"
        );
        assert!(!dir.path().join("m.ot").exists());
    }
    let (ok, _, err) = ktree(&[
        "map",
        &s("missing.xyz"),
        "--resolution",
        "0.1",
        "--out",
        &s("m.ot"),
    ]);
    assert!(!ok && err.contains("missing.xyz"), "{err}");
}

#[test]
fn scan_graphs_and_posed_point_files_are_placed_as_octomap_places_them() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let graph = common::data_dir().join("scans/spherical_scan.graph");
    let graph = graph.to_str().unwrap();
    run(&["map", graph, "--resolution", "0.2", "--out", &s("g.ot")]);
    let mut expected = OccupancyMap::<3>::new(0.2).unwrap();
    for scan in ktree::io::scan::read_scans(graph.as_ref()).unwrap() {
        expected.insert(&scan.points, scan.origin, None).unwrap();
    }
    let got = read_ot_map(
        &std::fs::read(s("g.ot")).unwrap(),
        "g.ot",
        SensorModel::default(),
    )
    .unwrap();
    assert_eq!(got, expected);
    assert!(got.occupied().voxel_count() > 100);

    // A point file in the sensor's frame at a pose.
    let points = walls();
    write_xyz(&dir.path().join("w.xyz"), &points);
    run(&[
        "map",
        &s("w.xyz"),
        "--pose",
        "1,-2,0.5,0.1,-0.2,1.5",
        "--resolution",
        "0.1",
        "--out",
        &s("p.ot"),
    ]);
    let pose = ktree::io::scan::Pose::from_xyz_rpy(1.0, -2.0, 0.5, 0.1, -0.2, 1.5);
    let scan = ktree::io::scan::ScanNode {
        id: 0,
        pose,
        points,
    }
    .to_scan();
    let mut expected = OccupancyMap::<3>::new(0.1).unwrap();
    expected.insert(&scan.points, scan.origin, None).unwrap();
    let got = read_ot_map(
        &std::fs::read(s("p.ot")).unwrap(),
        "p.ot",
        SensorModel::default(),
    )
    .unwrap();
    assert_eq!(got, expected);
    let (ok, _, err) = ktree(&[
        "map",
        &s("w.xyz"),
        "--pose",
        "1,2,3",
        "--resolution",
        "0.1",
        "--out",
        &s("q.ot"),
    ]);
    assert!(!ok && err.contains("6"), "{err}");
}

#[test]
fn queries_of_a_map_answer_unknown_free_or_occupied() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    write_xyz(&dir.path().join("room.xyz"), &walls());
    map_room(dir.path(), "room.bt");
    let probes = [
        [3.0f32, 0.0, 1.05],
        [2.5, 1.5, 1.2],
        [-20.0, 5.0, 1.0],
        [3.0, 2.0, 1.1],
    ];
    write_xyz(&dir.path().join("p.txt"), &probes);
    let text = run(&["query", &s("room.bt"), "--points", &s("p.txt")]);
    let map = read_bt_map(
        &std::fs::read(s("room.bt")).unwrap(),
        "room.bt",
        SensorModel::default(),
    )
    .unwrap();
    let names: Vec<&str> = map
        .states(&probes)
        .iter()
        .map(|s| match s {
            ktree::map::VoxelState::Unknown => "unknown",
            ktree::map::VoxelState::Free => "free",
            ktree::map::VoxelState::Occupied => "occupied",
        })
        .collect();
    assert_eq!(&names[..3], ["occupied", "free", "unknown"]);
    let got: Vec<&str> = text
        .lines()
        .map(|l| l.rsplit(' ').next().unwrap())
        .collect();
    assert_eq!(got, names);
    let json = run(&["query", &s("room.bt"), "--points", &s("p.txt"), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v[0]["state"], "occupied");
    assert_eq!(v[2]["point"], serde_json::json!([-20.0, 5.0, 1.0]));
    let (ok, _, err) = ktree(&["query", &s("room.bt"), "--points", &s("p.txt"), "--nearest"]);
    assert!(!ok && err.contains("unknown, free or occupied"), "{err}");
    // The same map as a .ktree, read in place, answers the same.
    map_room(dir.path(), "room.ktree");
    assert_eq!(
        run(&["query", &s("room.ktree"), "--points", &s("p.txt")]),
        text
    );
}

#[test]
fn ray_casts_on_a_map_report_where_they_end() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    write_xyz(&dir.path().join("room.xyz"), &walls());
    map_room(dir.path(), "room.ot");
    map_room(dir.path(), "room.ktree");
    let map = read_ot_map(
        &std::fs::read(s("room.ot")).unwrap(),
        "room.ot",
        SensorModel::default(),
    )
    .unwrap();
    let rays: [[f32; 6]; 3] = [
        [2.5, 1.5, 1.2, 1.0, 0.0, 0.0],
        [2.5, 1.5, 1.2, 0.0, 0.0, 1.0],
        [-9.0, 0.0, 0.0, 1.0, 0.0, 0.0],
    ];
    let text: String = rays
        .iter()
        .map(|r| r.map(|v| v.to_string()).join(" ") + "\n")
        .collect();
    std::fs::write(dir.path().join("r.txt"), text).unwrap();
    for (extra, ignore, range) in [
        (vec![], false, -1.0),
        (vec!["--ignore-unknown", "--max-range", "2"], true, 2.0),
    ] {
        let mut args = vec![
            "raycast".to_string(),
            s("room.ot"),
            "--rays".into(),
            s("r.txt"),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run(&args);
        // The same map as a .ktree, read in place: the same ends.
        let in_place: Vec<String> = args
            .iter()
            .map(|a| a.replace("room.ot", "room.ktree"))
            .collect();
        let in_place: Vec<&str> = in_place.iter().map(String::as_str).collect();
        assert_eq!(run(&in_place), out);
        for (r, line) in rays.iter().zip(out.lines()) {
            let end = map.cast_ray([r[0], r[1], r[2]], [r[3], r[4], r[5]], ignore, range);
            let word = line.split(' ').next().unwrap();
            let want = match end {
                ktree::map::CastEnd::Occupied(_) => "occupied",
                ktree::map::CastEnd::Unknown(_) => "unknown",
                ktree::map::CastEnd::Range(_) => "range",
                ktree::map::CastEnd::Outside(_) => "outside",
            };
            assert_eq!(word, want, "{line}");
        }
        // Towards the wall at x = 6, 3.5 m away: a hit, or beyond a range of 2 m.
        let first = if ignore { "range" } else { "occupied" };
        assert!(out.lines().next().unwrap().starts_with(first), "{out}");
    }
    let (ok, _, err) = ktree(&[
        "raycast",
        &s("room.ot"),
        "--rays",
        &s("r.txt"),
        "--max-range",
        "0",
    ]);
    assert!(!ok && err.contains("--max-range"), "{err}");
}

#[test]
fn a_maps_history_and_static_map_are_written_beside_it() {
    use ktree::map::{state_labels, HistoryRecorder};
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    std::fs::create_dir(dir.path().join("scans")).unwrap();
    let scene = ktree_verify::scenes::WalkingPerson::new(10);
    let mut expected = OccupancyMap::<3>::new(0.1).unwrap();
    let mut recorder = HistoryRecorder::new(*expected.grid());
    for t in 0..scene.steps {
        let scan = scene.scan(t, 180, 32);
        write_xyz(&dir.path().join(format!("scans/{t:02}.xyz")), &scan.points);
        expected.insert(&scan.points, scan.origin, None).unwrap();
        if t % 2 == 1 {
            recorder.record(&expected).unwrap();
        }
    }
    let origin = scene.sensor.map(|c| (c as f32).to_string()).join(",");
    let text = run(&[
        "map",
        &s("scans"),
        "--resolution",
        "0.1",
        "--sensor-origin",
        &origin,
        "--out",
        &s("room.ot"),
        "--history",
        &s("history.ktree"),
        "--scans-per-step",
        "2",
        "--static-map",
        &s("static.bt"),
    ]);
    assert!(text.contains("the history of 5 steps"), "{text}");
    let history = recorder.finish();
    // The file keeps the map's grid and the 5 steps.
    let bytes = std::fs::read(dir.path().join("history.ktree")).unwrap();
    let read = ktree::io::ktree::read_history_ktree(&bytes, "history.ktree").unwrap();
    assert_eq!(read, history);
    assert_eq!((read.steps(), read.grid()), (5, expected.grid()));
    assert_eq!(read.at(4).unwrap(), state_labels(&expected));
    let bytes = std::fs::read(s("static.bt")).unwrap();
    let still = read_bt_map(&bytes, "static.bt", SensorModel::default()).unwrap();
    let want = expected.cleared(&history.moved()).unwrap();
    assert_eq!(still.occupied(), want.occupied());
    assert!(history.moved().voxel_count() > 0);
    // A history is a .ktree file.
    let (ok, _, err) = ktree(&[
        "map",
        &s("scans/00.xyz"),
        "--resolution",
        "0.1",
        "--out",
        &s("m.ot"),
        "--history",
        &s("h.ot"),
    ]);
    assert!(!ok);
    assert!(err.contains("a history is written as .ktree"), "{err}");
}

#[test]
fn queries_of_a_colour_map_report_each_voxels_colour_in_json() {
    let dir = tempfile::tempdir().unwrap();
    let s = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    map.insert(&walls(), [2.5, 1.5, 1.2], None).unwrap();
    // The occupied voxels of the wall y = 0 red, the others of the map uncoloured.
    let probes = [
        [3.0f32, 0.0, 1.05],
        [3.0, 4.0, 1.05],
        [2.5, 1.5, 1.2],
        [-20.0, 5.0, 1.0],
    ];
    let wall = ktree::rays::ValueRuns::from_runs(
        16,
        (32708u32..32838).map(|x| (ktree::Ray::new([x, 32768, 32700], 32850), [200u8, 10, 10])),
    )
    .unwrap();
    let colours = KTree::from_value_runs(&wall).mask(&map.occupied());
    assert_eq!(
        colours.value_at(map.grid().keys(probes[0]).unwrap()),
        Some([200, 10, 10])
    );
    let mut bytes = Vec::new();
    ktree::io::write_color_ot_map(&mut bytes, &map, &colours).unwrap();
    std::fs::write(s("room.ot"), bytes).unwrap();
    write_xyz(&dir.path().join("p.txt"), &probes);
    let json = run(&["query", &s("room.ot"), "--points", &s("p.txt"), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let got: Vec<(&str, serde_json::Value)> = (0..4)
        .map(|i| (v[i]["state"].as_str().unwrap(), v[i]["colour"].clone()))
        .collect();
    let null = serde_json::Value::Null;
    assert_eq!(
        got,
        [
            ("occupied", serde_json::json!([200, 10, 10])),
            ("occupied", null.clone()),
            ("free", null.clone()),
            ("unknown", null)
        ]
    );
    // Text output, and a plain OcTree's JSON, are as they were: no colour.
    let text = run(&["query", &s("room.ot"), "--points", &s("p.txt")]);
    assert_eq!(text.lines().next().unwrap().split(' ').count(), 4);
    let mut plain = Vec::new();
    ktree::io::write_ot_map(&mut plain, &map).unwrap();
    std::fs::write(s("plain.ot"), plain).unwrap();
    let json = run(&["query", &s("plain.ot"), "--points", &s("p.txt"), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v[0]["state"], "occupied");
    assert!(v[0].get("colour").is_none(), "{json}");
}
