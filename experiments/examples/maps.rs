//! Occupancy-map integration timed, for experiments/maps.sh: `maps insert RES FILE REPEATS` reads a scan
//! (`x y z` lines in world coordinates, sensor at the origin; OctoMap's `scan.dat`), integrates it into an
//! empty map REPEATS times and prints the best time, the map's voxel counts and a checksum of its
//! log-odds (to compare with OctoMap's), and the map's memory.

use std::time::Instant;

use ktree::map::OccupancyMap;

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
                let tree = ktree::map::apply(map.log_odds(), &update.voxels, map.model());
                let merge = t.elapsed().as_secs_f64();
                println!(
                    "voxels={} gather={gather:.3} merge={merge:.3} nodes={}",
                    update.voxels.len(),
                    tree.node_count()
                );
            }
        }
        _ => eprintln!("usage: maps insert|phases RES FILE REPEATS"),
    }
}
