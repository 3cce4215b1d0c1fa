//! Reproductions of the papers' results. Each writes tables (Markdown + CSV) and plots into
//! `results/<name>/` and returns a short report for the command line to print. Run them with
//! `ktree repro [NAME]`.
#![deny(missing_docs)]

pub mod akman_franklin;
pub mod common;
pub mod default_object;
pub mod meagher;
pub mod veenstra_ahuja;

use std::path::Path;

/// The names accepted by [`run`], in the order `ktree repro all` runs them.
pub const NAMES: &[&str] = &[
    "default-object",
    "akman-franklin",
    "meagher",
    "veenstra-ahuja",
];

/// Runs one reproduction, writing into `results` (the results directory); returns a report to print.
///
/// # Errors
/// A message naming what could not be computed or written.
pub fn run(name: &str, results: &Path) -> Result<String, String> {
    match name {
        "default-object" => default_object::run(results),
        "akman-franklin" => akman_franklin::run(results),
        "meagher" => meagher::run(results),
        "veenstra-ahuja" => veenstra_ahuja::run(results),
        _ => Err(format!("no reproduction named '{name}'")),
    }
}

/// The process's peak resident memory (VmHWM in `/proc/self/status`), in bytes; `None` where the system does
/// not report it. Used by reproductions and performance reports to record peak memory.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
