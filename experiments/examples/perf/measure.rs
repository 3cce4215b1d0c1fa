//! Running one case in a fresh child process and reading back its time and peak memory.

use std::process::{Command, ExitCode};

/// What a child reports for one case.
#[derive(Debug, Clone, Default)]
pub struct Measured {
    /// Best wall time over the repetitions, in seconds.
    pub seconds: f64,
    /// Peak resident memory of the child process (VmHWM), in bytes.
    pub peak_bytes: u64,
    /// Free-form `key=value` facts the case reported (node counts, sizes).
    pub facts: Vec<(String, String)>,
}

impl Measured {
    /// A reported fact by key.
    pub fn fact(&self, key: &str) -> &str {
        self.facts
            .iter()
            .find(|(k, _)| k == key)
            .map_or("?", |(_, v)| v.as_str())
    }
}

/// Child side: runs `case`, which returns (best seconds, facts), then prints them with the peak memory.
pub fn child(case: impl FnOnce() -> Result<(f64, Vec<(String, String)>), String>) -> ExitCode {
    match case() {
        Ok((seconds, facts)) => {
            println!("seconds={seconds}");
            println!("peak_bytes={}", ktree_repro::peak_rss_bytes().unwrap_or(0));
            for (k, v) in facts {
                println!("{k}={v}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// Parent side: runs `perf --child AREA CASE` and parses its report.
pub fn run_child(area: &str, case: &str) -> Result<Measured, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    run_child_of(&exe, area, case)
}

/// Runs `EXE --child AREA CASE` (this program, or a perf example built from another commit) and parses
/// its report.
pub fn run_child_of(exe: &std::path::Path, area: &str, case: &str) -> Result<Measured, String> {
    let out = Command::new(exe)
        .args(["--child", area, case])
        .output()
        .map_err(|e| format!("cannot run child for {area}/{case}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{area}/{case} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let mut m = Measured::default();
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        if let Some((k, v)) = line.split_once('=') {
            match k {
                "seconds" => m.seconds = v.parse().map_err(|_| format!("bad seconds '{v}'"))?,
                "peak_bytes" => m.peak_bytes = v.parse().map_err(|_| format!("bad peak '{v}'"))?,
                _ => m.facts.push((k.to_string(), v.to_string())),
            }
        }
    }
    Ok(m)
}

/// Timed runs in one process: `REPEATS` from the environment (the experiments' scripts set 1 and
/// interleave processes instead), 3 by default.
pub fn repeats() -> usize {
    std::env::var("REPEATS")
        .ok()
        .and_then(|r| r.parse().ok())
        .filter(|&r| r > 0)
        .unwrap_or(3)
}

/// Best wall time of `repeats` runs of `work` (each run's result is passed to `keep` to stay observable).
pub fn best_of<T>(repeats: usize, mut work: impl FnMut() -> T, mut keep: impl FnMut(T)) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..repeats {
        let start = std::time::Instant::now();
        let out = work();
        best = best.min(start.elapsed().as_secs_f64());
        keep(out);
    }
    best
}

/// Where the reports go: `results/performance/` of the project.
pub fn results_path(area: &str) -> std::path::PathBuf {
    let experiments = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let project = experiments.parent().unwrap_or(experiments);
    project
        .join("results/performance")
        .join(format!("{area}.md"))
}

/// Information about the machine for the report's header.
pub fn machine_line() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    // The machine is shared: the load when the report began says how quiet it was.
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .map_or(String::new(), |l| {
            format!("; load average {l} at the start")
        });
    format!("{cpu}, {cores} cores; one thread used; release build{load}")
}
