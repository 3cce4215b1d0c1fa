//! Helpers of the command-line tests: run the `ktree` binary built for this test run, find the project's data,
//! mount a small disk. A test that needs a tool this machine may lack (Chromium, OctoMap, OpenVDB, root for
//! the small disk) asks [`tools`] for it: when it is missing, the test fails if `KTREE_REQUIRE_TOOLS=1` (as
//! `.ci/run` sets it), and otherwise writes a visible `SKIPPED:` line and returns.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

pub use ktree_verify::tools;

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

/// Runs the `ktree` binary, which must succeed: its standard output.
///
/// # Panics
/// If the command fails, with its arguments and standard error.
pub fn run(args: &[&str]) -> String {
    let (ok, out, err) = ktree(args);
    assert!(ok, "ktree {args:?} failed: {err}");
    out
}

/// Runs `script` with OpenVDB's Python module imported as `vdb`: its standard output.
///
/// # Panics
/// If the script fails, with its standard error.
pub fn run_openvdb(python: &tools::PythonOpenVdb, script: &str) -> String {
    python.run(script, &[]).unwrap_or_else(|e| panic!("{e}"))
}

/// The project's folder `data/` (the real meshes and volumes).
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data")
}

/// A small tmpfs mounted for a test (needs root and `mount`), in a temporary folder kept while it is
/// mounted. `.0` is the mount point, `.1` the folder holding it (room for files off the small disk);
/// unmounted when dropped.
pub struct SmallDisk(pub PathBuf, pub tempfile::TempDir);

impl SmallDisk {
    /// Mounts a tmpfs of `size` (as `mount -o size=` takes it, e.g. `256k`); `None` where that is not
    /// allowed, after [`tools::missing`] (the test fails under `KTREE_REQUIRE_TOOLS=1`, else skips).
    #[track_caller]
    pub fn mount(size: &str) -> Option<Self> {
        let dir = tempfile::tempdir().unwrap();
        let mnt = dir.path().join("disk");
        std::fs::create_dir(&mnt).unwrap();
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(&mnt)
            .output();
        match mounted {
            Ok(o) if o.status.success() => Some(Self(mnt, dir)),
            failed => {
                let why = match failed {
                    Ok(o) => String::from_utf8_lossy(&o.stderr)
                        .lines()
                        .next()
                        .unwrap_or_default()
                        .to_string(),
                    Err(e) => format!("mount: {e}"),
                };
                tools::missing(
                    &format!("a {size} tmpfs mounted for the test ({why})"),
                    "run the tests as root (mount needs it)",
                );
                None
            }
        }
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// The names in a folder, hidden entries (spill folders, temporary files) included, sorted.
pub fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
