//! Reproductions of the papers' results. Each writes tables (Markdown + CSV) and plots into
//! `results/<name>/` and returns a short report for the command line to print. Run them with
//! `ktree repro [NAME]`.

pub mod akman_franklin;
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
