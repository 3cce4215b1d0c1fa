//! `cargo run --release --example perf -- AREA`: measures wall time (best of several runs) and peak memory
//! (the high-water mark of resident memory of a fresh child process per case) and writes
//! `results/performance/AREA.md`. Criterion benches (`cargo bench`) give the statistically careful
//! timings; this program records the figures the project tracks, regenerated rather than typed.
//!
//! Each area is a module with `run_case()` (one case, in a child) and `report()` (the Markdown table).
//! `perf compare BEFORE LABEL [ROUNDS]` times every case against a perf example built from an earlier
//! commit (see `compare.rs`).

mod build;
mod compare;
mod display;
mod export;
mod interop;
mod measure;
mod ops;
mod queries;
mod scale;
mod shape;
mod solids;
mod sources;
mod streaming;

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // A child process measures one case: `perf --child AREA CASE`.
    if args.first().map(String::as_str) == Some("--child") {
        let (area, case) = (&args[1], &args[2]);
        return match area.as_str() {
            "build" => measure::child(|| build::run_case(case)),
            "solids" => measure::child(|| solids::run_case(case)),
            "ops" => measure::child(|| ops::run_case(case)),
            "display" => measure::child(|| display::run_case(case)),
            "scale" => measure::child(|| scale::run_case(case)),
            "streaming" => measure::child(|| streaming::run_case(case)),
            "sources" => measure::child(|| sources::run_case(case)),
            "export" => measure::child(|| export::run_case(case)),
            "queries" => measure::child(|| queries::run_case(case)),
            "shape" => measure::child(|| shape::run_case(case)),
            _ => {
                eprintln!("perf: unknown area {area}");
                ExitCode::FAILURE
            }
        };
    }
    if args.first().map(String::as_str) == Some("compare") {
        return match compare::report(&args[1..]) {
            Ok(path) => {
                println!("wrote {path}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("perf: {e}");
                ExitCode::FAILURE
            }
        };
    }
    let areas: Vec<&str> = if args.is_empty() {
        vec!["build"]
    } else {
        args.iter().map(String::as_str).collect()
    };
    for area in areas {
        let result = match area {
            "build" => build::report(),
            "solids" => solids::report(),
            "ops" => ops::report(),
            "display" => display::report(),
            "scale" => scale::report(),
            "scale-large" => scale::report_large(),
            "interop" => interop::report(),
            "streaming" => streaming::report(),
            "sources" => sources::report(),
            "export" => export::report(),
            "queries" => queries::report(),
            "shape" => Err(
                "the shape area is measured against its peers by experiments/shape.sh, which writes \
                 results/performance/shape.md"
                    .into(),
            ),
            other => Err(format!(
                "unknown area '{other}' (known: build, solids, ops, display, scale, scale-large, interop, streaming, sources, export, queries)"
            )),
        };
        match result {
            Ok(path) => println!("wrote {path}"),
            Err(e) => {
                eprintln!("perf: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
