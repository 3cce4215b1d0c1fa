//! `perf compare BEFORE LABEL [ROUNDS]` (run by `experiments/compare.sh`): every case of the ops, display, build and solids reports, timed by
//! this program and by `BEFORE` (the perf example built from an earlier commit, named `LABEL` in the
//! report), alternating one run of each, `ROUNDS` times (default 5); the best of each side is kept. Both sides
//! see the same machine at the same moments, so the ratio holds even where the load moves the times. How far
//! each side's median lies above its best is the case's spread: a ratio above 1 by less than that is told
//! apart from a real slowdown. Writes `results/performance/compare.md`.

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
        Some(r) => r
            .parse()
            .ok()
            .filter(|&n| n > 0)
            .ok_or(format!("bad ROUNDS '{r}': a count of at least 1"))?,
        None => 5,
    };
    let before = Path::new(before);
    let after = std::env::current_exe().map_err(|e| e.to_string())?;
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
         time of each side. A ratio below 1 means this build is faster. The spread is how far the median of \
         a side's {rounds} times lies above its best (the larger of the two sides): the run-to-run noise of \
         the case on this machine.\n\nMachine: {}.\n",
        machine_line(),
    );
    let _ = writeln!(
        md,
        "| area | case | {label} s | now s | now / {label} | spread |\n|---|---|---:|---:|---:|---:|"
    );
    let (mut slower, mut within_spread) = (Vec::new(), Vec::new());
    for (area, case) in cases() {
        let (mut times_before, mut times_after) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            times_before.push(run_child_of(before, area, &case)?.seconds);
            times_after.push(run_child_of(&after, area, &case)?.seconds);
        }
        let (best_before, spread_before) = best_and_spread(&mut times_before);
        let (best_after, spread_after) = best_and_spread(&mut times_after);
        let spread = spread_before.max(spread_after);
        let ratio = best_after / best_before;
        if ratio > 1.0 + spread {
            slower.push(format!("{area} {case} ({ratio:.3}, spread {spread:.3})"));
        } else if ratio > 1.0 {
            within_spread.push(format!("{area} {case} ({ratio:.3}, spread {spread:.3})"));
        }
        let _ = writeln!(
            md,
            "| {area} | {case} | {best_before:.4} | {best_after:.4} | {ratio:.3} | {spread:.3} |"
        );
        eprintln!(
            "{area} {case}: {best_before:.4} s -> {best_after:.4} s ({ratio:.3}, spread {spread:.3})"
        );
    }
    let list = |cases: &[String]| {
        if cases.is_empty() {
            "none".to_string()
        } else {
            cases.join(", ")
        }
    };
    let _ = writeln!(
        md,
        "\nCases slower now than at `{label}` by more than their spread: {}.\n\nCases slower by less than \
         their spread (within this machine's noise): {}.",
        list(&slower),
        list(&within_spread)
    );
    let path = results_path("compare");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}

/// The best of `times` and how far their median lies above it, as a fraction of the best.
fn best_and_spread(times: &mut [f64]) -> (f64, f64) {
    times.sort_by(f64::total_cmp);
    let best = times[0];
    let median = times[times.len() / 2];
    (best, median / best - 1.0)
}
