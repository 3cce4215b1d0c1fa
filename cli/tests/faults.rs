//! Fault injection: a write killed part-way, a full disk, an unreadable or vanished input. The previous
//! output survives every failed write, no temporary file is left once the next write has run, and every
//! failure is a clear error naming the file. A reader that closes the output early (`ktree stats A | head`)
//! ends the command quietly, not in a panic.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::{ktree, SmallDisk};

/// The temporary files of atomic writes in `dir` (`.NAME.XXXXXX.PID.ktree-tmp`).
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.to_string_lossy().ends_with(".ktree-tmp"))
        .collect()
}

fn rays_to(level: u32, out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ktree"));
    // A ball filling most of the universe.
    let radius = ((1u32 << level) * 7 / 16).max(1);
    c.args([
        "rays",
        "--level",
        &level.to_string(),
        "--radius",
        &radius.to_string(),
        "--out",
    ])
    .arg(out);
    c
}

#[test]
fn a_write_killed_part_way_keeps_the_old_file_and_the_next_write_removes_its_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball.rays");
    assert!(rays_to(3, &out).status().unwrap().success());
    let old = std::fs::read(&out).unwrap();
    // A level-11 ball is about 3 million runs (tens of MB of text): kill the writer as soon as its
    // temporary file appears, while it is being filled.
    let mut child = rays_to(11, &out).spawn().unwrap();
    let start = Instant::now();
    let killed_mid_write = loop {
        if !temporaries(dir.path()).is_empty() {
            child.kill().unwrap(); // SIGKILL on Unix: no clean-up runs
            break true;
        }
        if child.try_wait().unwrap().is_some() || start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            break false;
        }
        std::thread::sleep(Duration::from_micros(200));
    };
    child.wait().unwrap();
    assert!(
        killed_mid_write,
        "the writer finished before its temporary file was seen"
    );
    assert_eq!(
        std::fs::read(&out).unwrap(),
        old,
        "the old file was changed by a killed write"
    );
    let left = temporaries(dir.path());
    assert_eq!(
        left.len(),
        1,
        "a killed writer leaves exactly its one temporary file: {left:?}"
    );
    let name = left[0].file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        name.starts_with(".ball.rays."),
        "unrecognisable temporary {name}"
    );
    // The next write to the same target removes it.
    assert!(rays_to(2, &out).status().unwrap().success());
    assert!(
        temporaries(dir.path()).is_empty(),
        "{:?}",
        temporaries(dir.path())
    );
    assert_ne!(std::fs::read(&out).unwrap(), old);
}

#[test]
fn a_full_disk_is_a_clear_error_and_keeps_the_old_file() {
    let Some(disk) = SmallDisk::mount("256k") else {
        eprintln!("SKIPPED a_full_disk_is_a_clear_error_and_keeps_the_old_file: cannot mount a tmpfs here (needs root)");
        return;
    };
    let out = disk.0.join("ball.rays");
    assert!(rays_to(3, &out).status().unwrap().success());
    let old = std::fs::read(&out).unwrap();
    // About 200 000 runs: a few MB, far more than the disk holds.
    let res = rays_to(9, &out).output().unwrap();
    let stderr = String::from_utf8_lossy(&res.stderr);
    assert!(!res.status.success());
    assert!(
        stderr.contains("ball.rays") && stderr.contains("No space left on device"),
        "unclear error: {stderr}"
    );
    assert_eq!(
        std::fs::read(&out).unwrap(),
        old,
        "the old file was changed"
    );
    assert!(
        temporaries(&disk.0).is_empty(),
        "{:?}",
        temporaries(&disk.0)
    );
    // The same for a tree.
    let tree = disk.0.join("ball.ktree");
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        out.to_str().unwrap(),
        "--out",
        tree.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let old_tree = std::fs::read(&tree).unwrap();
    let big = disk.1.path().join("big.rays");
    // A level-10 ball's tree is about a megabyte.
    assert!(rays_to(10, &big).status().unwrap().success());
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        big.to_str().unwrap(),
        "--out",
        tree.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("ball.ktree") && err.contains("No space left"),
        "{err}"
    );
    assert_eq!(std::fs::read(&tree).unwrap(), old_tree);
    assert!(temporaries(&disk.0).is_empty());
}

#[test]
fn unreadable_and_vanished_inputs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let gone = dir.path().join("gone.ktree");
    std::fs::write(&gone, b"x").unwrap();
    std::fs::remove_file(&gone).unwrap();
    let gone = gone.to_str().unwrap();
    let (ok, _, err) = ktree(&["stats", gone]);
    assert!(
        !ok && err.contains("gone.ktree") && err.contains("No such file"),
        "{err}"
    );
    let (ok, _, err) = ktree(&["stats", "--rays", gone]);
    assert!(
        !ok && err.contains("gone.ktree") && err.contains("No such file"),
        "{err}"
    );
    // A directory where a file is expected cannot be read (unlike permission bits, this holds for root too).
    let d = dir.path().to_str().unwrap();
    let (ok, _, err) = ktree(&["stats", d]);
    assert!(!ok && err.contains(d), "{err}");
    for input in [
        "missing.ply",
        "missing.stl",
        "missing.obj",
        "missing.nii",
        "missing.json",
    ] {
        let p = dir.path().join(input);
        let p = p.to_str().unwrap();
        let (ok, _, err) = ktree(&[
            "voxelize",
            p,
            "--level",
            "4",
            "--fit",
            "--threshold",
            "1",
            "--out",
            "o.rays",
        ]);
        assert!(
            !ok && err.contains(input) && err.contains("No such file"),
            "{input}: {err}"
        );
    }
    // An input that vanishes between the sidecar and its samples.
    let json = dir.path().join("v.json");
    std::fs::write(&json, br#"{"shape_xyz": [1, 1, 1], "dtype": "uint8"}"#).unwrap();
    let (ok, _, err) = ktree(&[
        "voxelize",
        json.to_str().unwrap(),
        "--threshold",
        "1",
        "--out",
        "o.rays",
    ]);
    assert!(
        !ok && err.contains("v.raw") && err.contains("No such file"),
        "{err}"
    );
}

#[test]
fn a_closed_output_pipe_ends_the_command_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("ball.ktree");
    let (ok, _, err) = ktree(&[
        "rays",
        "--level",
        "5",
        "--radius",
        "11",
        "--out",
        tree.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    for args in [
        vec!["stats", tree.to_str().unwrap()],
        vec!["stats", tree.to_str().unwrap(), "--json"],
        vec!["mass", tree.to_str().unwrap()],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_ktree"))
            .args(&args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Close the reading end before the command has read its file and printed anything.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(out.status.success(), "{args:?}: {stderr}");
    }
}
