//! Scale: the voxel-centre sphere (centre U/2, radius (U−1)/2) built from its quadric, end to end, by the
//! partitioned build (cells of depth `L − 6` stacked apart, rays made slab by slab) on one and two threads,
//! L = 10 … 13; the whole-set build (all rays, then one stacking) beside it up to L = 12.

use std::fmt::Write as _;

use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::{default_split_depth, stack, stack_source, RaySource};

use crate::measure::{best_of, machine_line, results_path, run_child, Measured};

const LEVELS: [u32; 4] = [10, 11, 12, 13];
/// The whole-set build is run up to this level (it holds every ray and every full cell at once).
const WHOLE_MAX: u32 = 12;

fn sphere(level: u32) -> Solid<3> {
    let u = 1i64 << level;
    let c = Rational::new(u, 2).expect("non-zero denominator");
    let r = Rational::new(u - 1, 2).expect("non-zero denominator");
    Solid::Quadric(Quadric::ball([c; 3], r, Frame::Voxel).expect("a valid ball"))
}

fn repeats(level: u32) -> usize {
    if level <= 10 {
        3
    } else {
        1
    }
}

/// Runs one case in this (child) process: `cells-L-THREADS` or `whole-L`.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let parts: Vec<&str> = case.split('-').collect();
    let level: u32 = parts
        .get(1)
        .and_then(|l| l.parse().ok())
        .ok_or("case must be WHAT-LEVEL[-THREADS]")?;
    let solid = sphere(level);
    let mut facts = Vec::new();
    let seconds = match parts[0] {
        "cells" => {
            let threads: usize = parts
                .get(2)
                .and_then(|t| t.parse().ok())
                .ok_or("cells-L-THREADS")?;
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| e.to_string())?;
            let depth = default_split_depth(3, level);
            let mut tree = None;
            let s = best_of(
                repeats(level),
                || {
                    pool.install(|| {
                        let source = SolidSource::new(&solid, level, Sample::Centre)
                            .expect("level in range");
                        stack_source(&source, depth).expect("the sphere's rays")
                    })
                },
                |t| tree = Some(t),
            );
            let tree = tree.ok_or("no run")?;
            // Count the rays slab by slab (not timed).
            let source =
                SolidSource::new(&solid, level, Sample::Centre).map_err(|e| e.to_string())?;
            let side = 1u32 << level;
            let step = 1u32 << level.saturating_sub(4);
            let rays: usize = (0..side)
                .step_by(step as usize)
                .map(|x| source.slab(x..x + step).map(|s| s.runs.len()))
                .sum::<Result<usize, _>>()
                .map_err(|e| e.to_string())?;
            let path =
                std::env::temp_dir().join(format!("ktree-perf-scale-{}.ktree", std::process::id()));
            ktree::io::write_ktree_file(&path, &tree).map_err(|e| e.to_string())?;
            let bytes = std::fs::metadata(&path).map_err(|e| e.to_string())?.len();
            let _ = std::fs::remove_file(&path);
            facts.push(("rays".into(), rays.to_string()));
            facts.push(("nodes".into(), tree.node_count().to_string()));
            facts.push(("file_bytes".into(), bytes.to_string()));
            s
        }
        "whole" => {
            let mut nodes = 0;
            let s = best_of(
                1,
                || {
                    stack(
                        &solid
                            .to_rays(level, Sample::Centre, false)
                            .expect("under the cap"),
                    )
                },
                |t| nodes = t.node_count(),
            );
            facts.push(("nodes".into(), nodes.to_string()));
            s
        }
        _ => return Err(format!("unknown case {case}")),
    };
    Ok((seconds, facts))
}

fn mib(bytes: u64) -> String {
    format!("{:.1}", bytes as f64 / (1024.0 * 1024.0))
}

/// Measures every case in a child process and writes `results/performance/scale.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(md, "# Scale: the partitioned build, L = 10 … 13\n");
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- scale`. Object: the voxels whose centres lie \
         in the sphere of centre U/2 and radius (U−1)/2, from its quadric, end to end (rays made slab by slab \
         from the quadric, cells of depth L − 6 stacked apart, levels joined). Times are the best of 3 runs at \
         L = 10 and one run above, in a fresh process per case; peak memory is that process's high-water \
         resident set. The whole-set build (every ray generated, then one stacking) is run up to L = \
         {WHOLE_MAX} and checked to give as many nodes. File: the `.ktree` written.\n\nMachine: {}.\n",
        machine_line().replace("; one thread used", "")
    );
    // Other work on the machine takes cores from the two-thread runs: record how busy it was.
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let load = load.split_whitespace().next().unwrap_or("?");
    let _ = writeln!(
        md,
        "Load average (1 minute) when the measurements started: {load} (on {} cores).\n",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let _ = writeln!(
        md,
        "| L | rays | nodes | 1 thread s | 2 threads s | speed-up | ns/node (1 thread) | peak MiB (1 thread) | peak MiB (2 threads) | whole-set s | whole-set peak MiB | file MiB |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for level in LEVELS {
        let one: Measured = run_child("scale", &format!("cells-{level}-1"))?;
        let two: Measured = run_child("scale", &format!("cells-{level}-2"))?;
        let whole = (level <= WHOLE_MAX)
            .then(|| run_child("scale", &format!("whole-{level}")))
            .transpose()?;
        if let Some(w) = &whole {
            if w.fact("nodes") != one.fact("nodes") {
                return Err(format!(
                    "L = {level}: the whole-set and partitioned builds differ"
                ));
            }
        }
        let nodes: f64 = one.fact("nodes").parse().unwrap_or(f64::NAN);
        let file: u64 = one.fact("file_bytes").parse().unwrap_or(0);
        let _ = writeln!(
            md,
            "| {level} | {} | {} | {:.3} | {:.3} | {:.2}× | {:.1} | {} | {} | {} | {} | {} |",
            one.fact("rays"),
            one.fact("nodes"),
            one.seconds,
            two.seconds,
            one.seconds / two.seconds,
            one.seconds * 1e9 / nodes,
            mib(one.peak_bytes),
            mib(two.peak_bytes),
            whole
                .as_ref()
                .map_or("—".into(), |w| format!("{:.3}", w.seconds)),
            whole.as_ref().map_or("—".into(), |w| mib(w.peak_bytes)),
            mib(file),
        );
    }
    let path = results_path("scale");
    ktree::io::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
