//! Queries asked of a map ([`ktree::query`]) on the octree of the voxel-centre ball of radius U/2 at
//! L = 10: 10^7 random and 10^7 coherent (random-walk) point queries — one at a time, through the cached
//! cursor, and in a batch ordered by Morton key —, 10^6 random rays and 10^6 nearest full voxels; batches
//! on one thread and on all threads.

use std::fmt::Write as _;

use ktree::query::{self, RayCast};
use ktree::rays::ball_rays;
use ktree::KTree;

use crate::measure::{best_of, machine_line, results_path, run_child, Measured};

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

fn ball() -> KTree<3> {
    let u = 1i64 << LEVEL;
    KTree::from_rays(&ball_rays::<3>(LEVEL, [u, u, u], u).expect("level in range"))
}

fn random_points(n: usize, rng: &mut Rng) -> Vec<[u32; 3]> {
    let side = 1u64 << LEVEL;
    (0..n)
        .map(|_| std::array::from_fn(|_| rng.below(side) as u32))
        .collect()
}

fn walk_points(n: usize, rng: &mut Rng) -> Vec<[u32; 3]> {
    let side = 1u32 << LEVEL;
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

fn random_rays(n: usize, rng: &mut Rng) -> Vec<RayCast<3>> {
    let side = (1u64 << LEVEL) as f64;
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

/// Runs one case in this (child) process.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let tree = ball();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut facts = vec![("nodes".to_string(), tree.node_count().to_string())];
    let one = case.ends_with("-1");
    let coherent = case.contains("coherent");
    let mut answers = 0usize;
    let seconds = if case.starts_with("contains-") || case.starts_with("cursor-") {
        let points = if coherent {
            walk_points(POINTS, &mut rng)
        } else {
            random_points(POINTS, &mut rng)
        };
        if case.starts_with("contains-") {
            best_of(
                3,
                || points.iter().filter(|&&p| tree.contains(p)).count(),
                |n| answers = n,
            )
        } else {
            best_of(
                3,
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
            walk_points(POINTS, &mut rng)
        } else {
            random_points(POINTS, &mut rng)
        };
        let expect = points.iter().filter(|&&p| tree.contains(p)).count();
        let s = on_threads(one, || {
            best_of(
                3,
                || tree.contains_many(&points),
                |v| answers = v.iter().filter(|&&b| b).count(),
            )
        });
        if answers != expect {
            return Err(format!("{case}: {answers} inside, one at a time {expect}"));
        }
        s
    } else if case.starts_with("rays-") {
        let rays = random_rays(RAYS, &mut rng);
        let s = on_threads(one, || {
            best_of(
                3,
                || tree.cast_rays(&rays),
                |hits| answers = hits.iter().flatten().count(),
            )
        });
        let single = rays
            .iter()
            .take(1000)
            .map(|r| query::cast_ray(&tree, r).unwrap_or_else(|e| match e {}))
            .collect::<Vec<_>>();
        if single != tree.cast_rays(&rays[..1000]) {
            return Err(format!("{case}: batch and single casts differ"));
        }
        s
    } else if case.starts_with("nearest-") {
        let points = random_points(NEAREST, &mut rng);
        // One run: a second of these would double the report's time for little.
        on_threads(one, || {
            best_of(
                1,
                || tree.nearest_many(&points),
                |found| {
                    answers = found
                        .iter()
                        .filter(|n| n.is_some_and(|n| n.squared == 0))
                        .count()
                },
            )
        })
    } else {
        return Err(format!("unknown case {case}"));
    };
    facts.push(("answers".into(), answers.to_string()));
    Ok((seconds, facts))
}

/// Measures every case in a child process and writes `results/performance/queries.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(md, "# Queries: points, rays, nearest voxels\n");
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- queries`. Object: the octree of the voxels \
         whose centres lie in the ball of radius U/2 centred in the universe, L = {LEVEL}, stacked. Times \
         are the best of 3 runs (1 for nearest voxels) in a fresh process per case, excluding building the tree and making the \
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
        "\nThe peers of the same questions (OpenVDB's `ValueAccessor` and ray intersector, OctoMap's \
         `search` and `castRay`, scipy's `distance_transform_edt`) are not in this table yet."
    );
    let path = results_path("queries");
    ktree::fs::write_atomic(&path, md.as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path.display().to_string())
}
