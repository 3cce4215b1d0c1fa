//! Streaming: Booleans of two `.ktree` version 2 files, loaded into memory (`ops::boolean`, as for version 1
//! files) against streamed from the files' memory maps to the output (`io::boolean_files`), L = 11 … 13.
//! Each case is end to end, as `ktree op` runs it: read, operate, write the `.ktree`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use ktree::io::{self, read_ktree_file, write_ktree_file};
use ktree::ops::{self, BoolOp};
use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::Builder;
use ktree::AnyTree;
use ktree::LevelCounts;

use crate::measure::{machine_line, results_path, run_child, Measured};

const LEVELS: [u32; 3] = [11, 12, 13];
/// The operations measured (`not` is the complement of the first input).
const OPS: [&str; 5] = ["union", "intersect", "diff", "xor", "not"];
/// The folder of the input files, set by the parent for its children.
const DIR_VAR: &str = "KTREE_PERF_STREAMING_DIR";

/// Sphere `a` (centre U/2, radius 7U/16) or `b` (shifted by (U/8, 0, −U/16), radius 3U/8).
fn sphere(level: u32, which: &str) -> Solid<3> {
    let u = 1i64 << level;
    let (centre, radius) = if which == "a" {
        ([u / 2; 3], u * 7 / 16)
    } else {
        ([u / 2 + u / 8, u / 2, u / 2 - u / 16], u * 3 / 8)
    };
    Solid::Quadric(
        Quadric::ball(
            centre.map(Rational::int),
            Rational::int(radius),
            Frame::Voxel,
        )
        .expect("a valid ball"),
    )
}

fn input(dir: &Path, level: u32, which: &str) -> PathBuf {
    dir.join(format!("{which}{level}.ktree"))
}

/// The most anonymous resident memory (`RssAnon`, what the process allocated, as opposed to the mapped
/// files' pages) seen by a thread reading `/proc/self/status` every millisecond until dropped.
struct AnonSampler {
    stop: Arc<AtomicBool>,
    peak: Arc<AtomicU64>,
    thread: Option<std::thread::JoinHandle<()>>,
}

fn rss_anon_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("RssAnon:"))?;
            line.split_whitespace().nth(1)?.parse::<u64>().ok()
        })
        .map_or(0, |kib| kib * 1024)
}

impl AnonSampler {
    fn start() -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let peak = Arc::new(AtomicU64::new(rss_anon_bytes()));
        let (s, p) = (stop.clone(), peak.clone());
        let thread = std::thread::spawn(move || {
            while !s.load(Ordering::Relaxed) {
                p.fetch_max(rss_anon_bytes(), Ordering::Relaxed);
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        });
        Self {
            stop,
            peak,
            thread: Some(thread),
        }
    }

    fn finish(mut self) -> u64 {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        self.peak.load(Ordering::Relaxed).max(rss_anon_bytes())
    }
}

/// Runs one case in this (child) process: `memory-L-OP` or `stream-L-OP`, on the inputs in `$DIR_VAR`.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let parts: Vec<&str> = case.split('-').collect();
    let [how, level, op] = parts.as_slice() else {
        return Err("case must be memory|stream-LEVEL-OP".into());
    };
    let level: u32 = level.parse().map_err(|_| "bad level")?;
    let dir = PathBuf::from(std::env::var(DIR_VAR).map_err(|_| format!("{DIR_VAR} is not set"))?);
    let (a, b) = (input(&dir, level, "a"), input(&dir, level, "b"));
    let out = dir.join(format!("out-{how}-{level}-{op}.ktree"));
    let bool_op = BoolOp::ALL.into_iter().find(|o| o.name() == *op);
    let sampler = AnonSampler::start();
    let start = std::time::Instant::now();
    let counts: Vec<LevelCounts> = match *how {
        "memory" => {
            let load = |p: &Path| match read_ktree_file(p) {
                Ok(AnyTree::K3(t)) => Ok(t),
                Ok(_) => Err("not K = 3".to_string()),
                Err(e) => Err(e.to_string()),
            };
            let ta = load(&a)?;
            let result = match bool_op {
                Some(o) => ops::boolean(&ta, &load(&b)?, o).map_err(|e| e.to_string())?,
                None => ops::complement(&ta),
            };
            write_ktree_file(&out, &result).map_err(|e| e.to_string())?;
            result.counts_per_level()
        }
        "stream" => {
            let report = match bool_op {
                Some(o) => io::boolean_files(&a, &b, o, &out, None),
                None => io::complement_file(&a, &out, None),
            };
            report.map_err(|e| e.to_string())?.counts_per_level
        }
        _ => return Err(format!("unknown case {case}")),
    };
    let seconds = start.elapsed().as_secs_f64();
    let anon = sampler.finish();
    let file_bytes = std::fs::metadata(&out).map_err(|e| e.to_string())?.len();
    let _ = std::fs::remove_file(&out);
    let c = LevelCounts::total(level, &counts);
    Ok((
        seconds,
        vec![
            ("nodes".into(), c.nodes().to_string()),
            ("file_bytes".into(), file_bytes.to_string()),
            ("anon_peak_bytes".into(), anon.to_string()),
        ],
    ))
}

fn mib(bytes: u64) -> String {
    format!("{:.1}", bytes as f64 / (1024.0 * 1024.0))
}

/// Builds the inputs, measures every case in a child process, and writes
/// `results/performance/streaming.md`.
pub fn report() -> Result<String, String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    std::env::set_var(DIR_VAR, dir.path());
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Streaming: Booleans of `.ktree` files larger than what is allocated\n\n\
         Regenerate with `cargo run --release --example perf -- streaming`. Inputs: sphere a (centre U/2, \
         radius 7U/16) and sphere b (centre shifted by (U/8, 0, −U/16), radius 3U/8), voxel centres, built out \
         of core to `.ktree` version 2 files. Each case runs end to end in a fresh process, once, as `ktree \
         op` runs it: *in memory* reads both files into trees, runs `ops::boolean` (or `ops::complement` for \
         `not`) and writes the result; *streamed* runs `io::boolean_files` (or `io::complement_file`) from \
         the files' memory maps to the output, its levels spilled to temporary files (what `ktree op` does \
         for version 2 files). Both write the same bytes (tested in `verify/tests/ops_boolean_files.rs`; \
         here the node counts are compared). Peak: the process's high-water resident set (VmHWM), which \
         counts the pages of the mapped input files that were read; allocated: the most anonymous resident \
         memory (RssAnon, sampled every millisecond), what the process itself holds.\n\nMachine: {}.\n",
        machine_line()
    );
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let _ = writeln!(
        md,
        "Load average (1 minute) when the measurements started: {}.\n",
        load.split_whitespace().next().unwrap_or("?")
    );
    let _ = writeln!(
        md,
        "| L | op | input MiB (a + b) | result nodes | in memory s | streamed s | speed-up | in memory peak MiB | streamed peak MiB | in memory allocated MiB | streamed allocated MiB |\n|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for level in LEVELS {
        let mut inputs = 0;
        for which in ["a", "b"] {
            let path = input(dir.path(), level, which);
            let solid = sphere(level, which);
            let source =
                SolidSource::new(&solid, level, Sample::Centre).map_err(|e| e.to_string())?;
            let budget = 4 << 30;
            Builder::new(&source)
                .to_file(&path, budget)
                .map_err(|e| e.to_string())?;
            inputs += std::fs::metadata(&path).map_err(|e| e.to_string())?.len();
        }
        for op in OPS {
            let memory: Measured = run_child("streaming", &format!("memory-{level}-{op}"))?;
            let stream: Measured = run_child("streaming", &format!("stream-{level}-{op}"))?;
            if memory.fact("nodes") != stream.fact("nodes")
                || memory.fact("file_bytes") != stream.fact("file_bytes")
            {
                return Err(format!("L = {level} {op}: the two results differ"));
            }
            let anon = |m: &Measured| mib(m.fact("anon_peak_bytes").parse().unwrap_or(0));
            let _ = writeln!(
                md,
                "| {level} | {op} | {} | {} | {:.3} | {:.3} | {:.2}× | {} | {} | {} | {} |",
                mib(inputs),
                stream.fact("nodes"),
                memory.seconds,
                stream.seconds,
                memory.seconds / stream.seconds,
                mib(memory.peak_bytes),
                mib(stream.peak_bytes),
                anon(&memory),
                anon(&stream),
            );
        }
        for which in ["a", "b"] {
            let _ = std::fs::remove_file(input(dir.path(), level, which));
        }
    }
    let path = results_path("streaming");
    std::fs::write(&path, md).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
