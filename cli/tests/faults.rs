//! Fault injection: a write killed part-way, a full disk, an unreadable or vanished input. The previous
//! output survives every failed write, no temporary file is left once the next write has run, and every
//! failure is a clear error naming the file. A reader that closes the output early (`ktree stats A | head`)
//! ends the command quietly, not in a panic. The full disk is a small tmpfs, which only root may mount:
//! elsewhere its test prints a `SKIPPED:` line and passes, or fails under `KTREE_REQUIRE_TOOLS=1`.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

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

/// Runs `command` with a file-size limit of `blocks` blocks (of 512 or 1024 bytes, as the shell counts them):
/// the kernel kills the process with `SIGXFSZ` at its first write past the limit, in the middle of its
/// output, and no clean-up runs — a kill at a known point, whatever the machine's speed.
#[cfg(unix)]
fn killed_at_size(command: &Command, blocks: u32) -> std::process::ExitStatus {
    let mut shell = Command::new("sh");
    shell
        .arg("-c")
        .arg(format!(
            "ulimit -c 0; ulimit -f {blocks}; exec \"$0\" \"$@\""
        ))
        .arg(command.get_program())
        .args(command.get_args());
    if let Some(dir) = command.get_current_dir() {
        shell.current_dir(dir);
    }
    shell.status().unwrap()
}

#[cfg(unix)]
#[test]
fn a_write_killed_part_way_keeps_the_old_file_and_the_next_write_removes_its_temporary() {
    use std::os::unix::process::ExitStatusExt;

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball.rays");
    assert!(rays_to(3, &out).status().unwrap().success());
    let old = std::fs::read(&out).unwrap();
    // The complete level-7 file (about 10 000 runs, over 100 kB), written elsewhere, for comparison.
    let whole_path = dir.path().join("whole").join("ball.rays");
    assert!(rays_to(7, &whole_path).status().unwrap().success());
    let whole = std::fs::read(&whole_path).unwrap();
    // The same write over the old file, killed once 16 blocks (at most 16 kB) are written.
    let status = killed_at_size(&rays_to(7, &out), 16);
    const SIGXFSZ: i32 = 25;
    assert_eq!(
        status.signal(),
        Some(SIGXFSZ),
        "the writer was not killed by the size limit: {status}"
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
    // The temporary holds the start of the output, and not all of it: the kill came part-way.
    let partial = std::fs::read(&left[0]).unwrap();
    assert!(
        !partial.is_empty() && partial.len() < whole.len() && whole.starts_with(&partial),
        "the temporary is not a strict beginning of the output: {} of {} bytes",
        partial.len(),
        whole.len()
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
