//! Build performance: stacking vs naive voxel insertion vs the dense pyramid on voxel-centre balls of
//! radius U/2 centred in the universe, L = 6 … 10 (octrees); and the builder with each cell stacked
//! through a bitmap pyramid vs by the paper's lists, side by side.

use std::fmt::Write as _;

use ktree::rays::ball_rays;
use ktree::RaySet;
use ktree::{
    reference::{DensePyramid, NaiveTree},
    stacking::{paper::stack, Builder, CellStacking},
};

use crate::measure::{best_of, machine_line, results_path, run_child, Measured};

pub const LEVELS: [u32; 5] = [6, 7, 8, 9, 10];
/// Naive insertion is run up to this level (it is O(voxels · L)).
pub const NAIVE_MAX: u32 = 8;
/// The dense pyramid needs U^3 bytes and more; run up to this level.
pub const DENSE_MAX: u32 = 9;

fn sphere(level: u32) -> RaySet<3> {
    let u = 1i64 << level;
    ball_rays::<3>(level, [u, u, u], u).expect("level in range")
}

/// Runs one case in this (child) process: `stack-L`, `naive-L`, `dense-L`, or the builder on one thread
/// with each cell through a bitmap (`bitmap-L`) or the paper's lists (`lists-L`).
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let (what, level) = case.split_once('-').ok_or("case must be WHAT-LEVEL")?;
    let level: u32 = level.parse().map_err(|_| "bad level")?;
    let rays = sphere(level);
    let repeats = if level >= 9 { 3 } else { 5 };
    let mut facts = vec![("rays".to_string(), rays.len().to_string())];
    let seconds = match what {
        "stack" => {
            let mut nodes = 0;
            let mut heap = 0;
            let s = best_of(
                repeats,
                || stack(&rays),
                |t| {
                    nodes = t.node_count();
                    heap = t.heap_bytes();
                },
            );
            facts.push(("nodes".into(), nodes.to_string()));
            facts.push(("tree_heap_bytes".into(), heap.to_string()));
            s
        }
        "bitmap" | "lists" => {
            let cells = if what == "bitmap" {
                CellStacking::Bitmap
            } else {
                CellStacking::Lists
            };
            let builder = Builder::new(&rays).threads(1).cells(cells);
            let want = stack(&rays);
            best_of(
                repeats,
                || builder.build().expect("the ball's rays"),
                |t| assert_eq!(t, want, "the builder and stacking differ"),
            )
        }
        "naive" => best_of(
            1,
            || NaiveTree::from_rays(&rays).expect("level ok").to_tree(),
            |t| {
                assert_eq!(t, stack(&rays), "naive and stacking differ");
            },
        ),
        "dense" => best_of(
            1,
            || DensePyramid::from_rays(&rays).expect("fits").to_tree(),
            |t| {
                assert_eq!(t, stack(&rays), "dense and stacking differ");
            },
        ),
        _ => return Err(format!("unknown case {case}")),
    };
    Ok((seconds, facts))
}

fn mib(bytes: u64) -> String {
    format!("{:.1}", bytes as f64 / (1024.0 * 1024.0))
}

/// Measures every case in a child process and writes `results/performance/build.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Building octrees: stacking vs naive insertion vs dense pyramid\n"
    );
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- build`. Object: the voxels whose centres lie \
         in the ball of radius U/2 centred in the universe (exact integer test), as rays along z. Times are \
         the best of 3–5 runs (stacking) or one run (references) in a fresh process per case; peak memory is \
         that process's high-water resident set, including the input rays. Each reference's tree is checked \
         equal to stacking's node for node.\n\nMachine: {}.\n",
        machine_line()
    );
    let _ = writeln!(
        md,
        "| L | rays | nodes | stacking s | naive s | dense s | naive / stacking | dense / stacking | tree bits/node in memory | stacking peak MiB | naive peak MiB | dense peak MiB |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for level in LEVELS {
        let s: Measured = run_child("build", &format!("stack-{level}"))?;
        let naive = (level <= NAIVE_MAX)
            .then(|| run_child("build", &format!("naive-{level}")))
            .transpose()?;
        let dense = (level <= DENSE_MAX)
            .then(|| run_child("build", &format!("dense-{level}")))
            .transpose()?;
        let nodes: f64 = s.fact("nodes").parse().unwrap_or(f64::NAN);
        let heap: f64 = s.fact("tree_heap_bytes").parse().unwrap_or(f64::NAN);
        let time = |m: &Option<Measured>| {
            m.as_ref()
                .map_or("—".into(), |m| format!("{:.4}", m.seconds))
        };
        let ratio = |m: &Option<Measured>| {
            m.as_ref()
                .map_or("—".into(), |m| format!("{:.0}×", m.seconds / s.seconds))
        };
        let peak = |m: &Option<Measured>| m.as_ref().map_or("—".into(), |m| mib(m.peak_bytes));
        let _ = writeln!(
            md,
            "| {level} | {} | {} | {:.4} | {} | {} | {} | {} | {:.3} | {} | {} | {} |",
            s.fact("rays"),
            s.fact("nodes"),
            s.seconds,
            time(&naive),
            time(&dense),
            ratio(&naive),
            ratio(&dense),
            8.0 * heap / nodes,
            mib(s.peak_bytes),
            peak(&naive),
            peak(&dense),
        );
    }
    let _ = writeln!(
        md,
        "\nThe tree in memory is the navigable tree (2-bit states and their rank index, `KTree::heap_bytes`). \
         The target: at L = 10 stacking well under a second on one core, aiming for 0.2 s; peak memory \
         far under 1 GiB. OpenVDB building the same sphere is measured side by side in \
         `results/performance/openvdb.md` (`experiments/openvdb.sh`). \
         Naive insertion is not run above L = {NAIVE_MAX} and the dense pyramid above L = {DENSE_MAX} \
         (U^3 voxels in memory)."
    );
    let _ = writeln!(
        md,
        "\n## The builder: each cell through a bitmap pyramid or by the paper's lists\n\n\
         `ktree::stacking::Builder` (what `KTree::from_rays`, the CLI and Python run) on one thread, cells \
         of depth L − 6 (2^18 voxels), each cell the sphere's boundary passes through stacked through a \
         bitmap pyramid of its voxels (`CellStacking::Bitmap`) or by Akman & Franklin's list stacking of its \
         rays (`CellStacking::Lists`); beside them the paper's stacking of the whole set (the table above). \
         Interleaved per level, best of 3–5 runs each, a fresh process per case. The faster per-cell way \
         is the builder's default.\n\n\
         | L | paper's stacking s | builder, bitmap cells s | builder, list cells s | lists / bitmap | bitmap peak MiB | lists peak MiB |\n\
         |---:|---:|---:|---:|---:|---:|---:|"
    );
    for level in LEVELS {
        let s: Measured = run_child("build", &format!("stack-{level}"))?;
        let b: Measured = run_child("build", &format!("bitmap-{level}"))?;
        let l: Measured = run_child("build", &format!("lists-{level}"))?;
        let _ = writeln!(
            md,
            "| {level} | {:.4} | {:.4} | {:.4} | {:.2} | {} | {} |",
            s.seconds,
            b.seconds,
            l.seconds,
            l.seconds / b.seconds,
            mib(b.peak_bytes),
            mib(l.peak_bytes),
        );
    }
    let path = results_path("build");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
