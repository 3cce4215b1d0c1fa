//! Criterion benchmarks of solids to rays.
fn main() {}
