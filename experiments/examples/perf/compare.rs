//! `perf compare BEFORE LABEL [ROUNDS]` (run by `experiments/compare.sh`): every case of the ops, display, build and solids reports, timed by
//! this program and by `BEFORE` (the perf example built from an earlier commit, named `LABEL` in the
//! report), alternating one run of each, `ROUNDS` times (default 5); the best of each side is kept. Both sides
//! see the same machine at the same moments, so the ratio holds even where the load moves the times.
//! Writes `results/performance/compare.md`.

use std::fmt::Write as _;
use std::path::Path;

use crate::measure::{machine_line, results_path, run_child_of};
use crate::{build, display, ops, solids};

/// Every `(area, case)` of the reports this compares.
fn cases() -> Vec<(&'static str, String)> {
    let mut all = Vec::new();
    for (what, level, _) in ops::CASES {
        all.push(("ops", format!("{what}-{level}")));
    }
    for (kind, _) in display::RASTER_CASES {
        all.push(("display", format!("raster-{kind}")));
    }
    for level in display::LINE_LEVELS {
        all.push(("display", format!("lines-pairwise-{level}")));
        all.push(("display", format!("lines-bucketed-{level}")));
    }
    for level in build::LEVELS {
        all.push(("build", format!("stack-{level}")));
        if level <= build::NAIVE_MAX {
            all.push(("build", format!("naive-{level}")));
        }
        if level <= build::DENSE_MAX {
            all.push(("build", format!("dense-{level}")));
        }
    }
    for (case, _) in solids::CASES {
        all.push(("solids", case.to_string()));
    }
    all
}

/// Runs the comparison and writes the report.
pub fn report(args: &[String]) -> Result<String, String> {
    let [before, label, rest @ ..] = args else {
        return Err("usage: perf compare BEFORE_PERF_BINARY LABEL [ROUNDS]".into());
    };
    let rounds: usize = match rest.first() {
        Some(r) => r.parse().map_err(|_| format!("bad ROUNDS '{r}'"))?,
        None => 5,
    };
    let before = Path::new(before);
    let after = std::env::current_exe().map_err(|e| e.to_string())?;
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Before and after: the same cases timed side by side\n"
    );
    let _ = writeln!(
        md,
        "Regenerate with `experiments/compare.sh {label} {rounds}`: it builds the perf example of commit \
         `{label}` and runs `perf compare` with it. Each case runs in a fresh process, \
         alternately from the earlier build and from this one, {rounds} times each; the table keeps the best \
         time of each side. A ratio below 1 means this build is faster.\n\nMachine: {}. Load average (1, 5, \
         15 min) when the comparison started: {}.\n",
        machine_line(),
        load.split_whitespace().take(3).collect::<Vec<_>>().join(", ")
    );
    let _ = writeln!(
        md,
        "| area | case | {label} s | now s | now / {label} |\n|---|---|---:|---:|---:|"
    );
    let mut slower = Vec::new();
    for (area, case) in cases() {
        let (mut best_before, mut best_after) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..rounds {
            best_before = best_before.min(run_child_of(before, area, &case)?.seconds);
            best_after = best_after.min(run_child_of(&after, area, &case)?.seconds);
        }
        let ratio = best_after / best_before;
        if ratio > 1.0 {
            slower.push(format!("{area} {case} ({ratio:.3})"));
        }
        let _ = writeln!(
            md,
            "| {area} | {case} | {best_before:.4} | {best_after:.4} | {ratio:.3} |"
        );
        eprintln!("{area} {case}: {best_before:.4} s -> {best_after:.4} s ({ratio:.3})");
    }
    let _ = writeln!(
        md,
        "\nCases slower now than at `{label}`: {}.",
        if slower.is_empty() {
            "none".to_string()
        } else {
            slower.join(", ")
        }
    );
    let path = results_path("compare");
    ktree::io::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
