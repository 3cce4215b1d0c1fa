//! Operations performance: Booleans, complement and rotations by reordering on octrees of
//! L = 10 voxel-centre spheres (rate in input nodes per second on one core), translation and scaling by
//! overlays, arbitrary rotation of an L = 9 sphere-and-box object, interference and mass.

use std::fmt::Write as _;

use ktree::ops::{self, Affine, AxisMap, BoolOp};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::{KTree, Ray, RaySet};

use crate::measure::{best_of, machine_line, results_path, run_child, Measured};

/// The sphere of radius `r` (in units of U) centred at `(cx, cy, cz)` (units of U), exact voxel centres.
fn sphere(level: u32, c: [f64; 3], r: f64) -> KTree<3> {
    let u = (1u64 << level) as f64;
    let centre2 = c.map(|v| (2.0 * v * u).round() as i64);
    stack(&ball_rays::<3>(level, centre2, (2.0 * r * u).round() as i64).expect("level in range"))
}

/// A box `[lo, hi)` as rays.
pub fn cuboid(level: u32, lo: [u32; 3], hi: [u32; 3]) -> KTree<3> {
    let mut rays = Vec::new();
    for x in lo[0]..hi[0] {
        for y in lo[1]..hi[1] {
            rays.push(Ray::new([x, y, lo[2]], hi[2]));
        }
    }
    stack(&RaySet::from_rays(level, rays).expect("box inside the universe"))
}

/// Sphere and box: a ball of radius U/3 at the centre united with a slab through it.
fn sphere_and_box(level: u32) -> KTree<3> {
    let s = 1u32 << level;
    let ball = sphere(level, [0.5, 0.5, 0.5], 1.0 / 3.0);
    let slab = cuboid(
        level,
        [s / 8, s * 3 / 8, s / 4],
        [s * 7 / 8, s * 5 / 8, s * 3 / 4],
    );
    ops::union(&ball, &slab).expect("same level")
}

fn two_spheres(level: u32) -> (KTree<3>, KTree<3>) {
    (
        sphere(level, [0.5, 0.5, 0.5], 0.5),
        sphere(level, [0.6, 0.55, 0.45], 0.45),
    )
}

/// Runs one case in this (child) process.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let (what, level) = case.rsplit_once('-').ok_or("case must be WHAT-LEVEL")?;
    let level: u32 = level.parse().map_err(|_| "bad level")?;
    let repeats = 3;
    let mut facts = Vec::new();
    let mut out_nodes = 0u64;
    let keep = |t: KTree<3>, out: &mut u64| {
        t.assert_well_formed();
        *out = t.node_count();
    };
    let seconds = match what {
        "union" | "intersect" | "diff" | "xor" => {
            let op = BoolOp::ALL
                .into_iter()
                .find(|o| o.name() == what)
                .expect("known op");
            let (a, b) = two_spheres(level);
            facts.push((
                "input_nodes".into(),
                (a.node_count() + b.node_count()).to_string(),
            ));
            best_of(
                repeats,
                || ops::boolean(&a, &b, op).unwrap(),
                |t| keep(t, &mut out_nodes),
            )
        }
        "complement" => {
            let (a, _) = two_spheres(level);
            facts.push(("input_nodes".into(), a.node_count().to_string()));
            best_of(repeats, || ops::complement(&a), |t| keep(t, &mut out_nodes))
        }
        "interferes" => {
            let (a, b) = two_spheres(level);
            // Disjoint pair: no early exit, the worst case.
            let far = ops::translate(&b, [1 << (level - 1), 0, 0]).unwrap();
            let small = ops::intersection(&a, &ops::complement(&far)).unwrap();
            facts.push((
                "input_nodes".into(),
                (small.node_count() + far.node_count()).to_string(),
            ));
            best_of(repeats, || ops::interferes(&small, &far).unwrap(), |_| {})
        }
        "separation" => {
            let (a, b) = two_spheres(level);
            let far = ops::translate(&b, [1 << (level - 1), 0, 0]).unwrap();
            let small = ops::intersection(&a, &ops::complement(&far)).unwrap();
            facts.push((
                "input_nodes".into(),
                (small.node_count() + far.node_count()).to_string(),
            ));
            let mut d = 0.0;
            let s = best_of(
                repeats,
                || ops::min_separation(&small, &far).unwrap(),
                |r| d = r.unwrap_or(f64::NAN),
            );
            facts.push(("separation".into(), d.to_string()));
            s
        }
        "rotate90" => {
            let (a, _) = two_spheres(level);
            let q = AxisMap::<3>::quarter_turn(0, 1)
                .unwrap()
                .compose(&AxisMap::reflection(2).unwrap());
            facts.push(("input_nodes".into(), a.node_count().to_string()));
            best_of(
                repeats,
                || ops::rotate_axes(&a, &q).unwrap(),
                |t| keep(t, &mut out_nodes),
            )
        }
        "translate" => {
            let (_, b) = two_spheres(level);
            facts.push(("input_nodes".into(), b.node_count().to_string()));
            best_of(
                1,
                || ops::translate(&b, [3, -5, 7]).unwrap(),
                |t| keep(t, &mut out_nodes),
            )
        }
        "scale" => {
            let (_, b) = two_spheres(level);
            facts.push(("input_nodes".into(), b.node_count().to_string()));
            best_of(
                1,
                || ops::scale(&b, 2, 3).unwrap(),
                |t| keep(t, &mut out_nodes),
            )
        }
        "affine" => {
            let a = sphere_and_box(level);
            facts.push(("input_nodes".into(), a.node_count().to_string()));
            let m = rotation_30_20(level);
            best_of(
                1,
                || ops::transform(&a, &m).unwrap(),
                |t| keep(t, &mut out_nodes),
            )
        }
        "affine-fixed" => {
            let a = sphere_and_box(level);
            facts.push(("input_nodes".into(), a.node_count().to_string()));
            let m = rotation_30_20(level);
            best_of(
                1,
                || ops::transform_fixed(&a, &m, 32).unwrap(),
                |t| keep(t, &mut out_nodes),
            )
        }
        "mass" => {
            let (a, _) = two_spheres(level);
            facts.push(("input_nodes".into(), a.node_count().to_string()));
            best_of(repeats, || ops::mass_properties(&a).unwrap(), |_| {})
        }
        "progressive" => {
            let (a, _) = two_spheres(level);
            facts.push(("input_nodes".into(), a.node_count().to_string()));
            let mut touched = 0;
            let s = best_of(
                repeats,
                || ops::mass_progressive(&a, 0.01).unwrap(),
                |p| touched = p.levels.last().map_or(0, |l| l.nodes_touched),
            );
            facts.push(("touched".into(), touched.to_string()));
            s
        }
        _ => return Err(format!("unknown case {case}")),
    };
    facts.push(("output_nodes".into(), out_nodes.to_string()));
    Ok((seconds, facts))
}

pub const CASES: &[(&str, u32, &str)] = &[
    ("union", 10, "two spheres (r = U/2 and 0.45 U, offset)"),
    ("intersect", 10, "same pair"),
    ("diff", 10, "same pair"),
    ("xor", 10, "same pair"),
    ("complement", 10, "sphere r = U/2"),
    (
        "interferes",
        10,
        "sphere vs a disjoint sphere part (no early exit)",
    ),
    (
        "separation",
        10,
        "minimum separation of two touching objects (branch and bound)",
    ),
    (
        "rotate90",
        10,
        "sphere r = U/2, quarter turn + reflection by reordering",
    ),
    ("translate", 10, "sphere r = 0.45 U by (3, −5, 7), overlays"),
    ("scale", 10, "sphere r = 0.45 U by 2/3, overlays"),
    (
        "affine",
        9,
        "sphere-and-box, rotation 30° about z after 20° about x, overlays",
    ),
    (
        "affine-fixed",
        9,
        "same, integer additions and shifts (32-bit fixed point)",
    ),
    ("mass", 10, "sphere r = U/2: volume, centroid, inertia"),
    ("progressive", 10, "sphere r = U/2: progressive mass to 1 %"),
];

/// Measures every case in a child process and writes `results/performance/ops.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(md, "# Operations on k-trees\n");
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- ops`. Objects: voxel-centre spheres built \
         by stacking (an L = 10 sphere of radius U/2 has about 7.5 million nodes); each output tree is \
         checked well-formed (reduced). Times: best of 3 (one run for the overlay operations) in a fresh \
         process per case; peak memory is that process's high-water resident set, including building the \
         inputs. Rate = input nodes / time.\n\nMachine: {}. Load average (1, 5, 15 min) when the report \
         started: {} — the machine is shared with other jobs, and under load the times grow.\n",
        machine_line(),
        std::fs::read_to_string("/proc/loadavg")
            .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(", "))
            .unwrap_or_else(|_| "unknown".into())
    );
    let _ = writeln!(
        md,
        "| operation | L | objects | input nodes | output nodes | seconds | million input nodes/s | million output nodes/s | peak MiB |\n|---|---:|---|---:|---:|---:|---:|---:|---:|"
    );
    for &(what, level, objects) in CASES {
        let m: Measured = run_child("ops", &format!("{what}-{level}"))?;
        let input: f64 = m.fact("input_nodes").parse().unwrap_or(f64::NAN);
        let output: f64 = m.fact("output_nodes").parse().unwrap_or(0.0);
        let (out_nodes, out_rate) = if output > 0.0 {
            (
                m.fact("output_nodes").to_string(),
                format!("{:.1}", output / m.seconds / 1e6),
            )
        } else {
            ("— (not a tree)".to_string(), "—".to_string())
        };
        let _ = writeln!(
            md,
            "| {what} | {level} | {objects} | {} | {out_nodes} | {:.4} | {:.1} | {out_rate} | {:.1} |",
            m.fact("input_nodes"),
            m.seconds,
            input / m.seconds / 1e6,
            m.peak_bytes as f64 / (1024.0 * 1024.0)
        );
        if what == "progressive" {
            let _ = writeln!(
                md,
                "\nProgressive mass to 1 %: touched {} of {} nodes.\n",
                m.fact("touched"),
                m.fact("input_nodes")
            );
        }
    }
    let _ = writeln!(
        md,
        "\nThe target: Booleans and rotations by reordering at least 20 million input nodes per second \
         on one core on L = 10 spheres; arbitrary rotation of an L = 9 sphere-and-box in seconds. A Boolean \
         does not visit the part of one input lying under a leaf of the other that decides the result (under \
         an empty node, for an intersection), so input nodes per second overstate the work per node visited; \
         output nodes per second (every output node is written once) is the conservative rate. The \
         complement flips 32 packed nodes per machine word and touches no structure. \
         `interferes` on a disjoint pair visits every overlapping pair of partial nodes (no early exit); \
         on overlapping objects it stops at the first shared voxel. `separation` is the worst case for the \
         branch and bound: the two objects touch along a large curved surface (distance 1), so every pair of \
         nodes near it is expanded. Translation uses Meagher's fixed overlay of 2^3 obels per target node \
         (children's overlays from one 3^3 grid of resolved obels); scaling and affine maps use the general overlay \
         engine (a target's overlay refined per child, cell boxes per node), so they are slower per node \
         than the Booleans."
    );
    let path = results_path("ops");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}

/// The arbitrary rotation the affine cases use: 30° in the x-y plane after 20° in the y-z plane, about the
/// universe's centre.
fn rotation_30_20(level: u32) -> Affine<3> {
    let c = Affine::<3>::universe_centre(level);
    Affine::rotation_about(0, 1, 30.0, c)
        .expect("valid plane")
        .after(&Affine::rotation_about(1, 2, 20.0, c).expect("valid plane"))
}
