//! Occupancy-map integration timed, for experiments/maps.sh: `maps insert RES FILE REPEATS` reads a scan
//! (`x y z` lines in world coordinates, sensor at the origin; OctoMap's `scan.dat`), integrates it into an
//! empty map REPEATS times and prints the best time, the map's voxel counts and a checksum of its
//! log-odds (to compare with OctoMap's), and the map's memory. `maps lidar OUT.log SCANS` makes a sequence
//! of synthetic 64-beam LiDAR scans (1 563 × 64 rays each) ray cast from poses along a loop through a
//! room holding the meshes of `data/meshes` (voxelized at 2 cm), written as OctoMap's `.log`;
//! `maps sequence RES FILE.log` integrates them one after the other and prints each scan's time and the
//! map's size after it. `maps history STEPS RES` times the history of the walking-person scene.
//! `maps queries RES FILE N M` integrates the scan, then times the states of N points and M ray casts
//! (OctoMap's `search` and `castRay`), both drawn by the same generator as `peers queries`.

use std::time::Instant;

use ktree::map::{HistoryRecorder, OccupancyMap};
use ktree::query::RayCast;
use ktree::solid::mesh::MeshTransform;
use ktree::{KTree, Ray, RaySet};

/// The scene's voxel: 2 cm; its universe: 2^10 voxels a side, x and y centred on the world's origin, z
/// from the floor's underside at 0.
const SCENE_VOXEL: f64 = 0.02;
const SCENE_LEVEL: u32 = 10;
const SCENE_CENTRE: f64 = 512.0;

/// The voxels of an axis-aligned box given in scene voxels `[lo, hi)`.
fn box_rays(lo: [u32; 3], hi: [u32; 3]) -> Vec<Ray<3>> {
    let mut rays = Vec::new();
    for x in lo[0]..hi[0] {
        for y in lo[1]..hi[1] {
            rays.push(Ray::new([x, y, lo[2]], hi[2]));
        }
    }
    rays
}

/// A room of 16 × 16 × 3 m (walls, floor and ceiling 10 cm thick) holding two copies of each mesh of
/// `data/meshes` scaled to between 0.9 and 1.8 m and standing on the floor.
fn scene() -> KTree<3> {
    let metres = |m: f64| (m / SCENE_VOXEL).round() as u32;
    let (lo, hi, top) = (metres(2.24), metres(18.24), metres(3.2));
    let boxes = [
        ([lo, lo, 0], [hi, hi, 5]), // floor: its top at z = 0.1 m
        ([lo, lo, top - 5], [hi, hi, top]),
        ([lo, lo, 0], [lo + 5, hi, top]),
        ([hi - 5, lo, 0], [hi, hi, top]),
        ([lo, lo, 0], [hi, lo + 5, top]),
        ([lo, hi - 5, 0], [hi, hi, top]),
    ];
    let union = |a: &KTree<3>, b: &KTree<3>| (a | b).expect("trees of one level");
    let mut tree = KTree::<3>::empty(SCENE_LEVEL).expect("a level");
    for (lo, hi) in boxes {
        let rays = RaySet::from_rays(SCENE_LEVEL, box_rays(lo, hi)).expect("a box's rays");
        tree = union(&tree, &KTree::from(&rays));
    }
    let meshes = [("bunny_npm", 1.2), ("armadillo", 1.8), ("fandisk", 0.9)];
    let places = [
        [-4.0, 3.0],
        [5.0, -2.5],
        [1.5, 5.5],
        [-3.5, -5.0],
        [6.0, 4.0],
        [-6.0, 0.5],
    ];
    for (i, (name, size)) in meshes.iter().enumerate() {
        let path = format!("{}/../data/meshes/{name}.obj", env!("CARGO_MANIFEST_DIR"));
        let mesh =
            ktree::io::read_mesh(std::path::Path::new(&path)).expect("a mesh of data/meshes");
        let (mlo, mhi) = mesh.bounds().expect("vertices");
        let extent = (0..3).map(|a| mhi[a] - mlo[a]).fold(0.0, f64::max);
        let scale = size / SCENE_VOXEL / extent;
        for place in &places[2 * i..2 * i + 2] {
            let translate = [
                SCENE_CENTRE + place[0] / SCENE_VOXEL - scale * (mlo[0] + mhi[0]) / 2.0,
                SCENE_CENTRE + place[1] / SCENE_VOXEL - scale * (mlo[1] + mhi[1]) / 2.0,
                5.0 - scale * mlo[2],
            ];
            let placed = MeshTransform { scale, translate };
            let rays = mesh
                .to_rays(SCENE_LEVEL, &placed)
                .expect("a placed mesh")
                .rays;
            tree = union(&tree, &KTree::from(&rays));
        }
    }
    tree
}

/// Writes `scans` LiDAR scans of the scene as OctoMap's `.log`: the sensor 1.6 m above the floor on a loop
/// of radius 3.5 m, 64 beams from 25° below to 15° above the horizon, 1 563 rays a beam.
fn lidar(out: &str, scans: usize) {
    let tree = scene();
    let (beams, azimuths) = (64usize, 1563usize);
    let mut text = String::new();
    for s in 0..scans {
        let angle = std::f64::consts::TAU * s as f64 / scans as f64;
        let origin_m = [3.5 * angle.cos(), 3.5 * angle.sin(), 1.7];
        let origin = [
            SCENE_CENTRE + origin_m[0] / SCENE_VOXEL,
            SCENE_CENTRE + origin_m[1] / SCENE_VOXEL,
            origin_m[2] / SCENE_VOXEL,
        ];
        let mut casts = Vec::with_capacity(beams * azimuths);
        for b in 0..beams {
            let elevation = (-25.0 + 40.0 * b as f64 / (beams - 1) as f64).to_radians();
            for a in 0..azimuths {
                let azimuth = std::f64::consts::TAU * (a as f64 + 0.5) / azimuths as f64 + angle;
                let d = [
                    elevation.cos() * azimuth.cos(),
                    elevation.cos() * azimuth.sin(),
                    elevation.sin(),
                ];
                casts.push(RayCast::new(origin, d, 4096.0).expect("a finite ray"));
            }
        }
        let hits = tree.cast_rays(&casts);
        text += &format!(
            "NODE {} {} {} 0 0 0\n",
            origin_m[0], origin_m[1], origin_m[2]
        );
        for (cast, hit) in casts.iter().zip(&hits) {
            let Some(hit) = hit else { continue };
            let d = cast.direction();
            // The hit in metres, relative to the sensor (the scan's frame: the world's axes).
            let local: [f64; 3] = std::array::from_fn(|i| hit.t * d[i] * SCENE_VOXEL);
            text += &format!(
                "{} {} {}\n",
                local[0] as f32, local[1] as f32, local[2] as f32
            );
        }
    }
    std::fs::write(out, text).unwrap_or_else(|e| panic!("{out}: {e}"));
}

fn read_scan(path: &str) -> Vec<[f32; 3]> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .lines()
        .filter_map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            (v.len() == 3).then(|| [v[0], v[1], v[2]])
        })
        .collect()
}

/// The generator both programs draw query points and rays from: 64-bit LCG steps, 53 bits a number in
/// [0, 1).
struct Draw(u64);

impl Draw {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// N points in the box of the scan's points, and M ray directions, as float32 (OctoMap's precision).
fn queries(points: &[[f32; 3]], n: usize, m: usize) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(f64::from(p[a]));
            hi[a] = hi[a].max(f64::from(p[a]));
        }
    }
    let mut draw = Draw(42);
    let at: Vec<[f32; 3]> = (0..n)
        .map(|_| std::array::from_fn(|a| (lo[a] + (hi[a] - lo[a]) * draw.next()) as f32))
        .collect();
    let directions = (0..m)
        .map(|_| std::array::from_fn(|_| (2.0 * draw.next() - 1.0) as f32))
        .collect();
    (at, directions)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("insert") => {
            let res: f64 = args[2].parse().expect("resolution");
            let points = read_scan(&args[3]);
            let repeats: usize = args[4].parse().expect("repeats");
            let mut best = f64::MAX;
            let mut map = None;
            for _ in 0..repeats {
                let mut m = OccupancyMap::<3>::new(res).unwrap();
                let t = Instant::now();
                m.insert(&points, [0.0; 3], None).unwrap();
                best = best.min(t.elapsed().as_secs_f64());
                map = Some(m);
            }
            let map = map.expect("at least one repeat");
            let (occupied, free) = (map.occupied().voxel_count(), map.free().voxel_count());
            // The sum of the log-odds over all voxels, leaf by leaf (a leaf counts its voxels).
            let sum: f64 = map
                .log_odds()
                .value_leaves()
                .filter_map(|(cell, v)| v.map(|v| f64::from(v) * (cell.side() as f64).powi(3)))
                .sum();
            println!("points={}", points.len());
            println!("seconds={best}");
            println!("occupied={occupied}");
            println!("free={free}");
            println!("checksum={sum:.3}");
            println!("map_bytes={}", map.log_odds().heap_bytes());
        }
        Some("phases") => {
            let res: f64 = args[2].parse().expect("resolution");
            let points = read_scan(&args[3]);
            let map = OccupancyMap::<3>::new(res).unwrap();
            for _ in 0..3 {
                let t = Instant::now();
                let update = ktree::map::ScanUpdate::compute(map.grid(), &points, [0.0; 3], None);
                let gather = t.elapsed().as_secs_f64();
                let t = Instant::now();
                let tree = ktree::map::apply(map.log_odds(), &update, map.model());
                let merge = t.elapsed().as_secs_f64();
                println!(
                    "voxels={} gather={gather:.3} merge={merge:.3} nodes={}",
                    update.len(),
                    tree.node_count()
                );
            }
        }
        Some("queries") => {
            let res: f64 = args[2].parse().expect("resolution");
            let points = read_scan(&args[3]);
            let (n, m): (usize, usize) = (args[4].parse().expect("N"), args[5].parse().expect("M"));
            let mut map = OccupancyMap::<3>::new(res).unwrap();
            map.insert(&points, [0.0; 3], None).unwrap();
            let (at, directions) = queries(&points, n, m);
            let mut best = (f64::MAX, f64::MAX);
            let (mut counts, mut hits) = ([0usize; 3], 0usize);
            for _ in 0..3 {
                let t = Instant::now();
                let states = map.states(&at);
                best.0 = best.0.min(t.elapsed().as_secs_f64());
                counts = [0; 3];
                for s in states {
                    counts[s as usize] += 1;
                }
                let t = Instant::now();
                hits = directions
                    .iter()
                    .filter(|&&d| {
                        matches!(
                            map.cast_ray([0.0; 3], d, false, -1.0),
                            ktree::map::CastEnd::Occupied(_)
                        )
                    })
                    .count();
                best.1 = best.1.min(t.elapsed().as_secs_f64());
            }
            println!("search_seconds={:.6}", best.0);
            println!("cast_seconds={:.6}", best.1);
            println!("unknown={} free={} occupied={}", counts[0], counts[1], counts[2]);
            println!("hits={hits}");
        }
        Some("lidar") => lidar(&args[2], args[3].parse().expect("scans")),
        Some("sequence") => {
            let res: f64 = args[2].parse().expect("resolution");
            let path = std::path::Path::new(&args[3]);
            let scans = ktree::io::scan::read_scans(path).expect("a .log of scans");
            let mut map = OccupancyMap::<3>::new(res).unwrap();
            let mut total = 0.0;
            for (i, scan) in scans.iter().enumerate() {
                let t = Instant::now();
                map.insert(&scan.points, scan.origin, None).unwrap();
                let s = t.elapsed().as_secs_f64();
                total += s;
                println!(
                    "scan={i} points={} seconds={s:.6} nodes={}",
                    scan.points.len(),
                    map.log_odds().node_count()
                );
            }
            let sum: f64 = map
                .log_odds()
                .value_leaves()
                .filter_map(|(cell, v)| v.map(|v| f64::from(v) * (cell.side() as f64).powi(3)))
                .sum();
            println!("seconds={total:.6}");
            println!("occupied={}", map.occupied().voxel_count());
            println!("free={}", map.free().voxel_count());
            println!("checksum={sum:.3}");
            println!("map_bytes={}", map.log_odds().heap_bytes());
        }
        Some("history") => {
            let steps: usize = args[2].parse().expect("steps");
            let res: f64 = args[3].parse().expect("resolution");
            let scene = ktree_verify::scenes::WalkingPerson::new(steps);
            let mut map = OccupancyMap::<3>::new(res).unwrap();
            let mut recorder = HistoryRecorder::new(*map.grid());
            let mut record = 0.0;
            // The recorder's largest hold, and what keeping every step's states would hold.
            let (mut held, mut every_step) = (0usize, 0usize);
            for t in 0..scene.steps {
                let scan = scene.scan(t, 360, 64);
                map.insert(&scan.points, scan.origin, None).unwrap();
                let start = Instant::now();
                recorder.record(&map).unwrap();
                record += start.elapsed().as_secs_f64();
                held = held.max(recorder.heap_bytes());
                every_step += ktree::map::state_labels(&map).heap_bytes();
            }
            let start = Instant::now();
            let history = recorder.finish();
            let build = start.elapsed().as_secs_f64();
            let start = Instant::now();
            let (still, moved) = (history.static_map(), history.moved());
            let split = start.elapsed().as_secs_f64();
            println!("steps={steps} res={res}");
            println!("history_nodes={}", history.tree().node_count());
            println!("history_bytes={}", history.tree().heap_bytes());
            println!("map_nodes={}", map.log_odds().node_count());
            println!("recorder_bytes={held} every_step_bytes={every_step}");
            println!("static_voxels={}", still.voxel_count());
            println!("moved_voxels={}", moved.voxel_count());
            println!("record_seconds={record:.3} build_seconds={build:.3} split_seconds={split:.3}");
        }
        _ => eprintln!("usage: maps insert|phases RES FILE REPEATS | lidar OUT.log SCANS | sequence RES FILE.log | history STEPS RES"),
    }
}
