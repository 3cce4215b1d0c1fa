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

/// A small tmpfs mounted for a test (needs root and `mount`), in a temporary folder kept while it is
/// mounted; `None` where that is not allowed. `.0` is the mount point, `.1` the folder holding it (room for
/// files off the small disk); unmounted when dropped.
pub struct SmallDisk(pub PathBuf, pub tempfile::TempDir);

impl SmallDisk {
    /// Mounts a tmpfs of `size` (as `mount -o size=` takes it, e.g. `256k`).
    pub fn mount(size: &str) -> Option<Self> {
        let dir = tempfile::tempdir().ok()?;
        let mnt = dir.path().join("disk");
        std::fs::create_dir(&mnt).ok()?;
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(&mnt)
            .output()
            .is_ok_and(|o| o.status.success());
        ok.then_some(Self(mnt, dir))
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
