//! The ktree side of `experiments/values.sh` (results/performance/values.md): trees with values built from a
//! dense volume, and values read at random points, timed on one thread beside OpenVDB
//! (experiments/values/peers.cpp) reading the same files.
//!
//! ```text
//! values phantom L DIR                 write DIR/labels-L.raw (u32) and DIR/density-L.raw (f32), x fastest
//! values build labels|density L DIR R  build from the raw file (best of R), then 10^7 values (best of R)
//! values bits L DIR                    bits a node of the phantom's tree for every value type
//! values surfaces FILE R               each label's closed surface of a uint32 `.ktree` (best of R)
//! values cells L SIDE DIR              write DIR/cells-L.raw (u32): many small labels, as supervoxels
//! ```
//!
//! `cells` are the Voronoi cells of one seed in each cube of `SIDE` voxels (placed at random in it), each
//! voxel labelled by its nearest seed (1, 2, …) — an over-segmentation such as electron-microscopy
//! pipelines make, with `(2^L / SIDE)^3` labels.
//!
//! The volume is the 3-D Shepp–Logan head phantom (ten ellipsoids, Kak & Slaney's table as extended to 3-D
//! by Schabel's `phantom3d`, the "modified" intensities; the rotations about z only): its density is the sum
//! of the intensities of the ellipsoids holding a voxel's centre, its label the last such ellipsoid (1–10),
//! 0 outside. `build` prints `key=value` lines: `seconds`, `nodes`, `voxels`, `heap_bytes`,
//! `query_seconds`, `checksum` (the sum of the values at the points, 0 where empty); `surfaces` prints
//! `seconds`, `labels`, `triangles`, `vertices`,
//! `faces_once` (each face between two labels counted once) and `unit_faces` (the labels' surface
//! areas, from `value_stats`).

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use ktree::export::surface::value_boundary_mesh;
use ktree::rays::ValueRuns;
use ktree::value::{Rgb, Value};
use ktree::KTree;

/// Points asked for.
const POINTS: usize = 10_000_000;

/// `[intensity, a, b, c, x0, y0, z0, phi°]` of the ten ellipsoids, in a cube of side 2 centred on 0.
const ELLIPSOIDS: [[f64; 8]; 10] = [
    [1.0, 0.69, 0.92, 0.81, 0.0, 0.0, 0.0, 0.0],
    [-0.8, 0.6624, 0.874, 0.78, 0.0, -0.0184, 0.0, 0.0],
    [-0.2, 0.11, 0.31, 0.22, 0.22, 0.0, 0.0, -18.0],
    [-0.2, 0.16, 0.41, 0.28, -0.22, 0.0, 0.0, 18.0],
    [0.1, 0.21, 0.25, 0.41, 0.0, 0.35, -0.15, 0.0],
    [0.1, 0.046, 0.046, 0.05, 0.0, 0.1, 0.25, 0.0],
    [0.1, 0.046, 0.046, 0.05, 0.0, -0.1, 0.25, 0.0],
    [0.1, 0.046, 0.023, 0.05, -0.08, -0.605, 0.0, 0.0],
    [0.1, 0.023, 0.023, 0.02, 0.0, -0.606, 0.0, 0.0],
    [0.1, 0.023, 0.046, 0.02, 0.06, -0.605, 0.0, 0.0],
];

/// The phantom's label (0 outside) and density at voxel `(x, y, z)` of a universe of side `u`.
fn phantom(u: usize, x: usize, y: usize, z: usize) -> (u32, f32) {
    let c = |i: usize| (2.0 * i as f64 + 1.0) / u as f64 - 1.0;
    let (px, py, pz) = (c(x), c(y), c(z));
    let (mut label, mut density) = (0, 0.0f64);
    for (n, e) in ELLIPSOIDS.iter().enumerate() {
        let (s, co) = e[7].to_radians().sin_cos();
        let (dx, dy, dz) = (px - e[4], py - e[5], pz - e[6]);
        let (rx, ry) = (co * dx + s * dy, -s * dx + co * dy);
        if (rx / e[1]).powi(2) + (ry / e[2]).powi(2) + (dz / e[3]).powi(2) <= 1.0 {
            label = n as u32 + 1;
            density += e[0];
        }
    }
    // Rounded to a thousandth: the sums of the table's intensities without floating-point noise.
    // (+ 0.0 turns a -0.0 into 0.0: the background.)
    (label, ((density * 1000.0).round() / 1000.0 + 0.0) as f32)
}

fn write_phantom(level: u32, dir: &Path) {
    let u = 1usize << level;
    let mut labels = std::io::BufWriter::new(
        std::fs::File::create(dir.join(format!("labels-{level}.raw"))).unwrap(),
    );
    let mut density = std::io::BufWriter::new(
        std::fs::File::create(dir.join(format!("density-{level}.raw"))).unwrap(),
    );
    for z in 0..u {
        for y in 0..u {
            for x in 0..u {
                let (l, d) = phantom(u, x, y, z);
                labels.write_all(&l.to_le_bytes()).unwrap();
                density.write_all(&d.to_le_bytes()).unwrap();
            }
        }
    }
    labels.flush().unwrap();
    density.flush().unwrap();
}

/// Writes `DIR/cells-L.raw`: the label of each voxel's nearest seed, one seed at a random place in each
/// cube of `side` voxels (see the module's documentation), x fastest.
fn write_cells(level: u32, side: usize, dir: &Path) {
    let u = 1usize << level;
    let cubes = u.div_ceil(side);
    let mut draw = splitmix(7);
    let seeds: Vec<[f64; 3]> = (0..cubes * cubes * cubes)
        .map(|i| {
            let at = [i % cubes, i / cubes % cubes, i / (cubes * cubes)];
            at.map(|c| (c as f64 + (draw() >> 11) as f64 / (1u64 << 53) as f64) * side as f64)
        })
        .collect();
    let mut out = std::io::BufWriter::new(
        std::fs::File::create(dir.join(format!("cells-{level}.raw"))).unwrap(),
    );
    for z in 0..u {
        for y in 0..u {
            for x in 0..u {
                let p = [x, y, z].map(|c| c as f64 + 0.5);
                let cube = p.map(|c| (c / side as f64) as i64);
                // A seed two cubes away or more is farther than the voxel's own cube's seed.
                let mut best = (f64::INFINITY, 0usize);
                for dz in -2..=2i64 {
                    for dy in -2..=2i64 {
                        for dx in -2..=2i64 {
                            let c = [cube[0] + dx, cube[1] + dy, cube[2] + dz];
                            if c.iter().any(|&c| c < 0 || c >= cubes as i64) {
                                continue;
                            }
                            let i = c[0] as usize + cubes * (c[1] as usize + cubes * c[2] as usize);
                            let d: f64 = (0..3).map(|a| (seeds[i][a] - p[a]).powi(2)).sum();
                            if d < best.0 {
                                best = (d, i);
                            }
                        }
                    }
                }
                out.write_all(&(best.1 as u32 + 1).to_le_bytes()).unwrap();
            }
        }
    }
    out.flush().unwrap();
}

/// A splitmix64 generator started at `seed`.
fn splitmix(seed: u64) -> impl FnMut() -> u64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// The raw file's values (4 bytes each), read a block at a time: the process holds the values once.
fn read_raw<V: Value>(path: &Path) -> Vec<V> {
    use std::io::Read;
    let mut file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let len = file.metadata().unwrap().len() as usize;
    let mut values = Vec::with_capacity(len / 4);
    let mut block = vec![0u8; 1 << 20];
    let mut left = len - len % 4;
    while left > 0 {
        let n = left.min(block.len());
        file.read_exact(&mut block[..n]).unwrap();
        values.extend(block[..n].chunks_exact(4).map(V::read_le));
        left -= n;
    }
    values
}

/// The value whose bytes are all 0: the background.
fn zero<V: Value>() -> V {
    V::read_le(&vec![0; V::DTYPE.map_or(0, |d| d.bytes())])
}

/// splitmix64: the same points as the OpenVDB program's.
fn points(level: u32) -> Vec<[u32; 3]> {
    let mut next = splitmix(0x9E37_79B9_7F4A_7C15);
    let mask = (1u64 << level) - 1;
    (0..POINTS)
        .map(|_| {
            let r = next();
            [r & mask, (r >> 21) & mask, (r >> 42) & mask].map(|c| c as u32)
        })
        .collect()
}

fn build<V: Value>(level: u32, raw: &Path, repeats: usize, as_f64: impl Fn(V) -> f64) {
    let dense: Vec<V> = read_raw(raw);
    let background = zero::<V>();
    // The least any builder does: read every voxel once (each compared with the background).
    let mut read_once = f64::INFINITY;
    for _ in 0..repeats {
        let start = Instant::now();
        let empty = dense.iter().filter(|v| v.same(background)).count();
        read_once = read_once.min(start.elapsed().as_secs_f64());
        std::hint::black_box(empty);
    }
    println!("read_once_seconds={read_once}");
    let mut best = f64::INFINITY;
    let mut tree = None;
    for _ in 0..repeats {
        drop(tree.take());
        let start = Instant::now();
        // VALUES_VIA_RUNS=1: through the array's runs (the stacking path), else straight from the array.
        let built = if std::env::var_os("VALUES_VIA_RUNS").is_some() {
            let runs = ValueRuns::<3, V>::from_dense_background(level, &dense, background).unwrap();
            let scanned = start.elapsed().as_secs_f64();
            eprintln!("scan {scanned:.4} s, {} runs", runs.len());
            KTree::from_value_runs(&runs)
        } else {
            KTree::<3, V>::from_dense_background(level, &dense, background).unwrap()
        };
        best = best.min(start.elapsed().as_secs_f64());
        tree = Some(built);
    }
    let tree = tree.unwrap();
    drop(dense);
    println!("seconds={best}");
    println!("nodes={}", tree.node_count());
    println!("voxels={}", tree.voxel_count());
    println!("heap_bytes={}", tree.heap_bytes());
    let points = points(level);
    let mut best = f64::INFINITY;
    let mut checksum = 0.0;
    // One buffer for every repeat, as OpenVDB's side keeps none: the time is the answers'.
    let mut values = vec![None; points.len()];
    for _ in 0..repeats {
        let start = Instant::now();
        tree.values_at_into(&points, &mut values);
        best = best.min(start.elapsed().as_secs_f64());
        checksum = values.iter().map(|v| v.map_or(0.0, &as_f64)).sum();
    }
    println!("query_seconds={best}");
    println!("checksum={checksum}");
}

/// Bits a node of the phantom's labels as each value type (the labels' colours from a palette for RGB),
/// and of its density as `f32`; and of the shape without values.
fn bits(level: u32, dir: &Path) {
    let labels: Vec<u32> = read_raw(&dir.join(format!("labels-{level}.raw")));
    fn report<V: Value>(name: &str, dense: &[V], level: u32) {
        let runs = ValueRuns::<3, V>::from_dense_background(level, dense, zero::<V>()).unwrap();
        let tree = KTree::from_value_runs(&runs);
        let c = tree.counts();
        println!(
            "bits {name} {} {} {}",
            tree.node_count(),
            c.full,
            tree.heap_bytes()
        );
    }
    let u8s: Vec<u8> = labels.iter().map(|&l| l as u8).collect();
    let u16s: Vec<u16> = labels.iter().map(|&l| l as u16).collect();
    let i8s: Vec<i8> = labels.iter().map(|&l| l as i8).collect();
    let rgbs: Vec<Rgb> = labels
        .iter()
        .map(|&l| {
            if l == 0 {
                [0; 3]
            } else {
                [l as u8 * 20, 255 - l as u8 * 20, 128]
            }
        })
        .collect();
    report("uint8", &u8s, level);
    report("int8", &i8s, level);
    report("uint16", &u16s, level);
    report("uint32", &labels, level);
    report("rgb", &rgbs, level);
    let density: Vec<f32> = read_raw(&dir.join(format!("density-{level}.raw")));
    report("float32", &density, level);
    let shape: Vec<bool> = labels.iter().map(|&l| l != 0).collect();
    let tree = KTree::<3>::from_dense(level, &shape).unwrap();
    println!(
        "bits none {} {} {}",
        tree.node_count(),
        tree.counts().full,
        tree.heap_bytes()
    );
}

/// Each label's closed surface (`value_boundary_mesh`) of the uint32 labels in `file`, timed from the
/// tree read.
fn surfaces(file: &Path, repeats: usize) {
    let tree = ktree::io::ktree::v3::read_valued_ktree_file::<3, u32>(file).unwrap();
    let mut best = f64::INFINITY;
    let mut mesh = None;
    for _ in 0..repeats {
        drop(mesh.take()); // one mesh held at a time: the peak is one run's
        let start = Instant::now();
        let made = value_boundary_mesh(&tree);
        best = best.min(start.elapsed().as_secs_f64());
        mesh = Some(made);
    }
    let mesh = mesh.expect("at least one run");
    let stats = tree.value_stats();
    println!("seconds={best}");
    println!("labels={}", mesh.surfaces.len());
    println!(
        "triangles={}",
        mesh.surfaces
            .iter()
            .map(|s| s.mesh.triangles.len())
            .sum::<usize>()
    );
    println!("vertices={}", mesh.vertex_count());
    println!("faces_once={}", mesh.faces_once().count());
    println!(
        "unit_faces={}",
        stats.values().map(|s| s.surface_area).sum::<u128>()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| args.get(i).map(String::as_str).unwrap_or_default();
    let level = |i: usize| -> u32 { arg(i).parse().expect("a level") };
    match arg(0) {
        "phantom" => write_phantom(level(1), Path::new(arg(2))),
        "bits" => bits(level(1), Path::new(arg(2))),
        "surfaces" => surfaces(Path::new(arg(1)), arg(2).parse().unwrap_or(3)),
        "cells" => write_cells(level(1), arg(2).parse().expect("a side"), Path::new(arg(3))),
        "build" => {
            let (l, dir) = (level(2), Path::new(arg(3)));
            let repeats = arg(4).parse().unwrap_or(3);
            match arg(1) {
                "labels" => {
                    build::<u32>(l, &dir.join(format!("labels-{l}.raw")), repeats, f64::from)
                }
                _ => build::<f32>(l, &dir.join(format!("density-{l}.raw")), repeats, f64::from),
            }
        }
        _ => {
            eprintln!(
                "usage: values phantom L DIR | build labels|density L DIR R | bits L DIR | surfaces FILE R | cells L SIDE DIR"
            );
            std::process::exit(2);
        }
    }
}
