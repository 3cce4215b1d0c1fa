//! Scale: the voxel-centre sphere (centre U/2, radius (U−1)/2) built from its quadric, end to end, by the
//! partitioned build (cells of depth `L − 6` stacked apart, rays made slab by slab) on one and two threads,
//! L = 10 … 13; the whole-set build (all rays, then one stacking) beside it up to L = 12; and the
//! out-of-core build (subtrees spilled to temporary files, the `.ktree` written level by level in a memory
//! budget) at L = 13 and 14. Apart (`perf -- scale-large`, minutes and gigabytes of disk): the out-of-core
//! build at L = 15 and 16 in a budget of 1 GiB, and at L = 17 in 3 GiB.

use std::fmt::Write as _;

use ktree::io::KtreeView;
use ktree::rays::RaySource;
use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::{default_split_depth, paper::stack, Builder};
use ktree::LevelCounts;

use crate::measure::{best_of, machine_line, results_path, run_child, Measured};

const LEVELS: [u32; 4] = [10, 11, 12, 13];
/// The whole-set build is run up to this level (it holds every ray and every full cell at once).
const WHOLE_MAX: u32 = 12;
/// Levels built out of core, straight to a `.ktree` file.
const OUT_OF_CORE_LEVELS: [u32; 2] = [13, 14];
/// The memory budget of the out-of-core builds.
const OUT_OF_CORE_BUDGET: u64 = 1536 << 20;
/// Threads of the out-of-core builds.
const OUT_OF_CORE_THREADS: usize = 2;
/// Levels of the large out-of-core builds (`perf -- scale-large`), each with its memory budget: 1 GiB up to
/// L = 16; 3 GiB at L = 17, where the index of the stacked cells of depth 11 grows past 1 GiB (the
/// accounted peak there is in the report).
const LARGE_LEVELS: [(u32, u64); 3] = [(15, 1 << 30), (16, 1 << 30), (17, 3 << 30)];

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
                        Builder::new(&source)
                            .split_depth(depth)
                            .build()
                            .expect("the sphere's rays")
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
            facts.push(("voxels".into(), tree.voxel_count().to_string()));
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
        "ooc" => {
            // `ooc-L` in the default budget, `ooc-L-MIB` in MIB MiB.
            let budget = match parts.get(2) {
                Some(mib) => mib.parse::<u64>().map_err(|_| "ooc-L[-MIB]")? << 20,
                None => OUT_OF_CORE_BUDGET,
            };
            out_of_core_case(&solid, level, budget, &mut facts)?
        }
        _ => return Err(format!("unknown case {case}")),
    };
    Ok((seconds, facts))
}

/// The out-of-core build of the sphere to a `.ktree` in a temporary folder, timed; then (not timed, after
/// the peak memory of the build is recorded) the file is opened and checked section by section, its counts
/// compared with the build's, and its voxels with the sum of the runs' lengths made slab by slab again.
fn out_of_core_case(
    solid: &Solid<3>,
    level: u32,
    budget: u64,
    facts: &mut Vec<(String, String)>,
) -> Result<f64, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(OUT_OF_CORE_THREADS)
        .build()
        .map_err(|e| e.to_string())?;
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let out = dir.path().join("sphere.ktree");
    let source = SolidSource::new(solid, level, Sample::Centre).map_err(|e| e.to_string())?;
    let disk = DiskSampler::start(dir.path());
    let start = std::time::Instant::now();
    let report = pool
        .install(|| Builder::new(&source).to_file(&out, budget))
        .map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let disk_peak = disk.stop();
    let build_peak = ktree_repro::peak_rss_bytes().unwrap_or(0);
    let view = KtreeView::open(&out).map_err(|e| e.to_string())?;
    if view.counts_per_level() != report.counts_per_level {
        return Err(format!(
            "L = {level}: the file's counts differ from the build's"
        ));
    }
    let voxels: u128 = report
        .counts_per_level
        .iter()
        .map(|c| u128::from(c.full) << (3 * (level - c.level)))
        .sum();
    let side = 1u32 << level;
    let step = 1u32 << level.saturating_sub(6);
    let (mut rays, mut run_voxels) = (0u64, 0u128);
    for x in (0..side).step_by(step as usize) {
        let slab = source.slab(x..x + step).map_err(|e| e.to_string())?;
        rays += slab.runs.len() as u64;
        run_voxels += slab
            .runs
            .iter()
            .map(|&(z1, z2)| u128::from(z2 - z1))
            .sum::<u128>();
    }
    if voxels != run_voxels {
        return Err(format!(
            "L = {level}: the file holds {voxels} voxels, the runs {run_voxels}"
        ));
    }
    let total = LevelCounts::total(level, &report.counts_per_level);
    facts.push(("rays".into(), rays.to_string()));
    facts.push(("voxels".into(), voxels.to_string()));
    facts.push(("nodes".into(), total.nodes().to_string()));
    facts.push(("file_bytes".into(), report.file_bytes.to_string()));
    facts.push(("spilled_bytes".into(), report.spilled_bytes.to_string()));
    facts.push(("disk_peak_bytes".into(), disk_peak.to_string()));
    facts.push(("build_peak_bytes".into(), build_peak.to_string()));
    facts.push((
        "accounted_peak_bytes".into(),
        report.peak_accounted_bytes.to_string(),
    ));
    Ok(seconds)
}

/// Runs the out-of-core case at each of `levels` (each in its budget, or the default budget) and appends
/// its table to `md`; `disk` adds the disk the build held at most.
fn out_of_core_table(
    md: &mut String,
    levels: &[(u32, Option<u64>)],
    disk: bool,
) -> Result<(), String> {
    let (budget_head, disk_head) = if disk {
        (" budget MiB |", " disk peak MiB | load at end |")
    } else {
        ("", "")
    };
    let columns = 10 + 3 * usize::from(disk);
    let _ = writeln!(
        md,
        "| L |{budget_head} rays | voxels | nodes | seconds | ns/node | peak MiB | accounted MiB | spilled MiB |{disk_head} file MiB |\n|{}",
        "---:|".repeat(columns)
    );
    for &(level, budget) in levels {
        let case = match budget {
            Some(bytes) => format!("ooc-{level}-{}", bytes >> 20),
            None => format!("ooc-{level}"),
        };
        let m: Measured = run_child("scale", &case)?;
        let nodes: f64 = m.fact("nodes").parse().unwrap_or(f64::NAN);
        let bytes = |key: &str| mib(m.fact(key).parse().unwrap_or(0));
        let budget_cell = match (disk, budget) {
            (true, Some(b)) => format!(" {} |", b >> 20),
            (true, None) => format!(" {} |", OUT_OF_CORE_BUDGET >> 20),
            (false, _) => String::new(),
        };
        // The machine is shared: how busy it was by the end of each build (1-minute load average).
        let disk_cell = if disk {
            let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
            let load = load.split_whitespace().next().unwrap_or("?").to_string();
            format!(" {} | {load} |", bytes("disk_peak_bytes"))
        } else {
            String::new()
        };
        let _ = writeln!(
            md,
            "| {level} |{budget_cell} {} | {} | {} | {:.1} | {:.1} | {} | {} | {} |{disk_cell} {} |",
            m.fact("rays"),
            m.fact("voxels"),
            m.fact("nodes"),
            m.seconds,
            m.seconds * 1e9 / nodes,
            bytes("build_peak_bytes"),
            bytes("accounted_peak_bytes"),
            bytes("spilled_bytes"),
            bytes("file_bytes"),
        );
    }
    Ok(())
}

/// Measures the large out-of-core builds in a child process each and writes
/// `results/performance/scale-large.md`.
pub fn report_large() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Scale, out of core: the sphere at L = 15 and 16 in 1 GiB, and at L = 17\n\n\
         Regenerate with `cargo run --release --example perf -- scale-large` (about 50 minutes here, and \
         35 GB free in the temporary folder for L = 17). Object: the sphere of `scale.md`. Build: \
         `ktree::stacking::Builder::to_file`, what `ktree rays --solid ball --radius (U−1)/2 --level L \
         --max-memory BUDGET --out FILE.ktree` runs, on {OUT_OF_CORE_THREADS} threads in the budget shown. \
         Seconds, peak and checks as in the out-of-core table of `scale.md`: the peak is the process's \
         high-water resident set when the file is written, the checks (not timed) open the file, verify \
         every section and compare its counts and voxels with the build's and the runs'. Disk peak: the \
         most disk the build's folder held (spill files and the output being written, sampled every \
         {DISK_SAMPLE_MS} ms; the folder holds nothing else): the spill files give their disk back as they are read into the output, so it \
         stays near the file's size instead of the spill's and the file's sum. Load at end: the 1-minute load \
         average when the build ended, the build's own threads included. The goal: L = 16 in at most \
         1 GiB and 10 minutes, and L = 17 given the disk.\n\nMachine: {}.\n",
        machine_line().replace("; one thread used", "")
    );
    let levels: Vec<(u32, Option<u64>)> = LARGE_LEVELS
        .iter()
        .map(|&(level, budget)| (level, Some(budget)))
        .collect();
    out_of_core_table(&mut md, &levels, true)?;
    let path = results_path("scale-large");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}

/// How often [`DiskSampler`] looks.
const DISK_SAMPLE_MS: u64 = 200;

/// Samples, on its own thread, the disk held by the files under a folder (their allocated blocks, so
/// holes punched count as freed) and keeps the most seen.
struct DiskSampler {
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: std::thread::JoinHandle<u64>,
}

impl DiskSampler {
    fn start(folder: &std::path::Path) -> Self {
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let (flag, folder) = (stop.clone(), folder.to_path_buf());
        let thread = std::thread::spawn(move || {
            let mut most = 0;
            loop {
                most = most.max(held_bytes(&folder));
                if flag.load(std::sync::atomic::Ordering::Relaxed) {
                    return most;
                }
                std::thread::sleep(std::time::Duration::from_millis(DISK_SAMPLE_MS));
            }
        });
        Self { stop, thread }
    }

    /// Stops sampling; the most bytes held.
    fn stop(self) -> u64 {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        self.thread.join().unwrap_or(0)
    }
}

/// Bytes allocated to the files under `folder` (512-byte blocks, as `du` counts).
fn held_bytes(folder: &std::path::Path) -> u64 {
    use std::os::unix::fs::MetadataExt;
    let Ok(entries) = std::fs::read_dir(folder) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| match e.metadata() {
            Ok(meta) if meta.is_dir() => held_bytes(&e.path()),
            Ok(meta) => 512 * meta.blocks(),
            Err(_) => 0,
        })
        .sum()
}

fn mib(bytes: u64) -> String {
    format!("{:.1}", bytes as f64 / (1024.0 * 1024.0))
}

/// Measures every case in a child process and writes `results/performance/scale.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Scale: the partitioned build, L = 10 … 13; out of core, L = 13 and 14\n"
    );
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
    let _ = writeln!(
        md,
        "\n## Out of core\n\nThe same sphere built by `ktree::stacking::Builder::to_file` (what `ktree rays|build|voxelize \
         … --out FILE.ktree` run): the subtrees of the cells of depth L − 6 spilled to per-level temporary \
         files as slabs finish, then the `.ktree` version 2 written level by level into a temporary folder, \
         on {OUT_OF_CORE_THREADS} threads in a budget of {} MiB. One run per level. Peak: the process's \
         high-water resident set when the file is written (before the checks); accounted: the most the \
         build's own accounting held. Checks, not timed: the file opens (every section's checksum, shape and \
         reduction checked), its counts equal the build's, and its voxels equal the sum of the runs' \
         lengths.\n",
        OUT_OF_CORE_BUDGET >> 20
    );
    let levels: Vec<(u32, Option<u64>)> = OUT_OF_CORE_LEVELS.iter().map(|&l| (l, None)).collect();
    out_of_core_table(&mut md, &levels, false)?;
    let path = results_path("scale");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
