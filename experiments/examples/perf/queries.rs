//! Queries asked of a map ([`ktree::query`]) on the octree of the voxel-centre ball of radius U/2 at
//! L = 10: 10^7 random and 10^7 coherent (random-walk) point queries — one at a time, through the cached
//! cursor, and in a batch ordered by Morton key —, 10^6 random rays and 10^6 nearest full voxels; batches
//! on one thread and on all threads. The cases also run on other objects (`OBJECT:CASE`, e.g.
//! `armadillo-10:rays-1`) and write their inputs for the peers of `experiments/queries.sh`
//! (`OBJECT:write-inputs:DIR`).

use std::fmt::Write as _;
use std::path::Path;

use ktree::query::{self, RayCast};
use ktree::KTree;

use crate::measure::{best_of, machine_line, repeats, results_path, run_child, Measured};

const LEVEL: u32 = 10;
const POINTS: usize = 10_000_000;
const RAYS: usize = 1_000_000;
const NEAREST: usize = 1_000_000;

/// The cases: name, what is measured, queries.
const CASES: [(&str, &str, usize); 12] = [
    (
        "contains-random",
        "`KTree::contains`, random points, 1 thread",
        POINTS,
    ),
    (
        "contains-coherent",
        "`KTree::contains`, random walk, 1 thread",
        POINTS,
    ),
    (
        "cursor-random",
        "`PointCursor::contains`, random points, 1 thread",
        POINTS,
    ),
    (
        "cursor-coherent",
        "`PointCursor::contains`, random walk, 1 thread",
        POINTS,
    ),
    (
        "batch-random-1",
        "`contains_many`, random points, 1 thread",
        POINTS,
    ),
    (
        "batch-random-all",
        "`contains_many`, random points, all threads",
        POINTS,
    ),
    (
        "batch-coherent-1",
        "`contains_many`, random walk, 1 thread",
        POINTS,
    ),
    (
        "batch-coherent-all",
        "`contains_many`, random walk, all threads",
        POINTS,
    ),
    ("rays-1", "`cast_rays`, random rays, 1 thread", RAYS),
    ("rays-all", "`cast_rays`, random rays, all threads", RAYS),
    (
        "nearest-1",
        "`nearest_many`, random points, 1 thread",
        NEAREST,
    ),
    (
        "nearest-all",
        "`nearest_many`, random points, all threads",
        NEAREST,
    ),
];

/// xorshift64*: deterministic inputs.
struct Rng(u64);

/// The seed every case starts from: each case's inputs are the first draws, so the inputs written for the
/// peers (`write-inputs`) are the ones ktree's cases answer.
const SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// Rays whose casts are checked against OctoMap's `castRay` (the first of the batch): facts `*_head`.
const RAY_HEAD: usize = 100_000;

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The object of a case: `ball-L` or `armadillo-L` (as in the export area); the default, `ball-10`.
fn object(name: &str) -> Result<KTree<3>, String> {
    crate::export::tree_of(name)
}

fn random_points(level: u32, n: usize, rng: &mut Rng) -> Vec<[u32; 3]> {
    let side = 1u64 << level;
    (0..n)
        .map(|_| std::array::from_fn(|_| rng.below(side) as u32))
        .collect()
}

fn walk_points(level: u32, n: usize, rng: &mut Rng) -> Vec<[u32; 3]> {
    let side = 1u32 << level;
    let mut p = [side / 2; 3];
    (0..n)
        .map(|_| {
            let a = rng.below(3) as usize;
            p[a] = if rng.below(2) == 0 {
                p[a].saturating_sub(1)
            } else {
                (p[a] + 1).min(side - 1)
            };
            p
        })
        .collect()
}

fn random_rays(level: u32, n: usize, rng: &mut Rng) -> Vec<RayCast<3>> {
    let side = (1u64 << level) as f64;
    (0..n)
        .map(|_| {
            let origin = std::array::from_fn(|_| rng.unit() * side);
            let direction = std::array::from_fn(|_| rng.unit() * 2.0 - 1.0);
            RayCast::new(origin, direction, f64::INFINITY).expect("finite")
        })
        .collect()
}

/// Runs `work` on a pool of one thread, or on the global pool.
fn on_threads<T: Send>(one: bool, work: impl FnOnce() -> T + Send) -> T {
    if one {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a pool")
            .install(work)
    } else {
        work()
    }
}

/// Writes the inputs of every case of `object` into folder `dir` for the peers of
/// `experiments/queries.sh`: the voxels as `tree.vdb` (a BoolGrid, index = voxel) and `tree.bt` (OctoMap,
/// key = voxel + 32768, unit resolution, so world coordinates are ktree's), the queries as little-endian
/// arrays (`random.bin`, `walk.bin`, `nearest.bin`: 3 × u32 a point; `rays.bin`: origin and direction,
/// 6 × f64 a ray), and for L ≤ 9 the voxels as a dense `dense.npy` (u8, shape (U, U, U), index [z, y, x]).
fn write_inputs(tree: &KTree<3>, dir: &Path) -> Result<(), String> {
    let level = tree.level();
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot make {}: {e}", dir.display()))?;
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        ktree::fs::write_atomic(&path, bytes)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    for name in ["tree.vdb", "tree.bt"] {
        tree.save(dir.join(name))
            .map_err(|e| format!("cannot write {name}: {e}"))?;
    }
    let points = |p: Vec<[u32; 3]>| -> Vec<u8> {
        p.iter()
            .flat_map(|v| v.iter().flat_map(|c| c.to_le_bytes()))
            .collect()
    };
    write(
        "random.bin",
        &points(random_points(level, POINTS, &mut Rng(SEED))),
    )?;
    write(
        "walk.bin",
        &points(walk_points(level, POINTS, &mut Rng(SEED))),
    )?;
    write(
        "nearest.bin",
        &points(random_points(level, NEAREST, &mut Rng(SEED))),
    )?;
    let rays: Vec<u8> = random_rays(level, RAYS, &mut Rng(SEED))
        .iter()
        .flat_map(|r| {
            r.origin()
                .into_iter()
                .chain(r.direction())
                .flat_map(f64::to_le_bytes)
        })
        .collect();
    write("rays.bin", &rays)?;
    if level <= 9 {
        write("dense.npy", &dense_npy(tree)?)?;
    }
    Ok(())
}

/// The voxels of `tree` as a dense `.npy` array (u8, shape (U, U, U), index [z, y, x], npy format 1.0).
pub fn dense_npy(tree: &KTree<3>) -> Result<Vec<u8>, String> {
    let dense = tree.to_dense().map_err(|e| e.to_string())?;
    let side = 1usize << tree.level();
    let mut header =
        format!("{{'descr': '|u1', 'fortran_order': False, 'shape': ({side}, {side}, {side}), }}");
    // The header, padded with spaces and a newline to a multiple of 64 bytes.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend_from_slice(&(header.len() as u16).to_le_bytes());
    npy.extend_from_slice(header.as_bytes());
    npy.extend(dense.iter().map(|&b| u8::from(b)));
    Ok(npy)
}

/// Runs one case in this (child) process: `CASE` on the L = 10 ball, `OBJECT:CASE` on another object
/// (`ball-L`, `armadillo-L`), or `OBJECT:write-inputs:DIR` (see [`write_inputs`]).
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let (name, case) = case.split_once(':').unwrap_or(("ball-10", case));
    let tree = object(name)?;
    if let Some(dir) = case.strip_prefix("write-inputs:") {
        write_inputs(&tree, Path::new(dir))?;
        return Ok((0.0, vec![("voxels".into(), tree.voxel_count().to_string())]));
    }
    let level = tree.level();
    let mut rng = Rng(SEED);
    let mut facts = vec![
        ("nodes".to_string(), tree.node_count().to_string()),
        ("voxels".to_string(), tree.voxel_count().to_string()),
    ];
    let one = case.ends_with("-1");
    let coherent = case.contains("coherent");
    let mut answers = 0usize;
    let seconds = if case.starts_with("contains-") || case.starts_with("cursor-") {
        let points = if coherent {
            walk_points(level, POINTS, &mut rng)
        } else {
            random_points(level, POINTS, &mut rng)
        };
        if case.starts_with("contains-") {
            best_of(
                repeats(),
                || points.iter().filter(|&&p| tree.contains(p)).count(),
                |n| answers = n,
            )
        } else {
            best_of(
                repeats(),
                || {
                    let mut cursor = tree.cursor();
                    points
                        .iter()
                        .filter(|&&p| cursor.contains(p) == Ok(true))
                        .count()
                },
                |n| answers = n,
            )
        }
    } else if case.starts_with("batch-") {
        let points = if coherent {
            walk_points(level, POINTS, &mut rng)
        } else {
            random_points(level, POINTS, &mut rng)
        };
        let expect = points.iter().filter(|&&p| tree.contains(p)).count();
        let s = on_threads(one, || {
            best_of(
                repeats(),
                || tree.contains_many(&points),
                |v| answers = v.iter().filter(|&&b| b).count(),
            )
        });
        if answers != expect {
            return Err(format!("{case}: {answers} inside, one at a time {expect}"));
        }
        s
    } else if case.starts_with("rays-") {
        let rays = random_rays(level, RAYS, &mut rng);
        let mut hits = Vec::new();
        let s = on_threads(one, || {
            best_of(repeats(), || tree.cast_rays(&rays), |h| hits = h)
        });
        answers = hits.iter().flatten().count();
        // A checksum of the voxels hit, to compare with the peers' (all rays, and the first RAY_HEAD).
        let voxel_sum = |hits: &[Option<query::RayHit<3>>]| -> u64 {
            hits.iter()
                .flatten()
                .map(|h| h.voxel.iter().map(|&c| u64::from(c)).sum::<u64>())
                .sum()
        };
        facts.push(("voxel_sum".into(), voxel_sum(&hits).to_string()));
        let head = &hits[..RAY_HEAD.min(hits.len())];
        facts.push((
            "hits_head".into(),
            head.iter().flatten().count().to_string(),
        ));
        facts.push(("voxel_sum_head".into(), voxel_sum(head).to_string()));
        let single = rays
            .iter()
            .take(1000)
            .map(|r| query::cast_ray(&tree, r).unwrap_or_else(|e| match e {}))
            .collect::<Vec<_>>();
        if single != hits[..1000] {
            return Err(format!("{case}: batch and single casts differ"));
        }
        s
    } else if case.starts_with("nearest-") {
        let points = random_points(level, NEAREST, &mut rng);
        let mut found = Vec::new();
        let s = on_threads(one, || {
            best_of(repeats(), || tree.nearest_many(&points), |f| found = f)
        });
        answers = found
            .iter()
            .filter(|n| n.is_some_and(|n| n.squared == 0))
            .count();
        // The sum of the squared distances, to compare with scipy's transform at the same voxels.
        let sum: u128 = found.iter().flatten().map(|n| n.squared).sum();
        facts.push(("sum_squared".into(), sum.to_string()));
        s
    } else {
        return Err(format!("unknown case {case}"));
    };
    facts.push(("answers".into(), answers.to_string()));
    Ok((seconds, facts))
}

/// Measures every case in a child process and writes `results/performance/queries-ktree.md` (ktree
/// alone; `experiments/queries.sh` writes `queries.md`, ktree and its peers).
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(md, "# Queries: points, rays, nearest voxels\n");
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- queries`. ktree alone. Object: the octree of the voxels \
         whose centres lie in the ball of radius U/2 centred in the universe, L = {LEVEL}, stacked. Times \
         are the best of 3 runs in a fresh process per case, excluding building the tree and making the \
         inputs (random points uniform in the universe; a random walk of unit steps; rays from uniform \
         origins in uniform directions of the cube [-1, 1]^3). \"answers\" counts the points inside (for \
         nearest: at distance 0) or the rays that hit.\n\nMachine: {}.\n",
        machine_line().replace("; one thread used", "")
    );
    let _ = writeln!(
        md,
        "| case | queries | best time (s) | ns / query | answers |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|");
    for (case, what, n) in CASES {
        let m: Measured = run_child("queries", case)?;
        let _ = writeln!(
            md,
            "| {what} | {n} | {:.3} | {:.1} | {} |",
            m.seconds,
            m.seconds * 1e9 / n as f64,
            m.fact("answers")
        );
    }
    let _ = writeln!(
        md,
        "\nThe same questions side by side with OpenVDB, OctoMap and scipy: `queries.md`, written by \
         `experiments/queries.sh`."
    );
    let path = results_path("queries-ktree");
    ktree::fs::write_atomic(&path, md.as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path.display().to_string())
}
