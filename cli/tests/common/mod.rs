//! Helpers of the command-line tests: run the `ktree` binary built for this test run, find the project's data.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

/// Runs the `ktree` binary built for this test run: (success, stdout, stderr).
pub fn ktree(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ktree"))
        .args(args)
        .output()
        .expect("run ktree");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The project's folder `data/` (the real meshes and volumes).
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data")
}
