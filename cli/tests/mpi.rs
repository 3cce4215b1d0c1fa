//! Builds over MPI ranks write the very file a single process writes (`mpirun -n 2`, and 3 ranks
//! oversubscribed on this machine), in K = 2, 3 and 4, for `rays`, `build` and `voxelize` (volumes with
//! values too: `--labels`, `--window`, meshes as labels, a cloud's colours), also in the
//! smallest `--max-memory` per rank the build names; a failed run (before the build, or while rank 0
//! writes) leaves no output and no spill folder. Compiled with the cargo feature `mpi` only; needs
//! `mpirun` (OpenMPI) on the PATH (every test fails without it). The failure while rank 0 writes fills a
//! small tmpfs, which only root may mount: elsewhere that test prints a `SKIPPED:` line and passes, or
//! fails under `KTREE_REQUIRE_TOOLS=1`.
#![cfg(feature = "mpi")]

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{data_dir, entries, ktree, SmallDisk};

/// Runs `mpirun -n ranks ktree args…` (allowed as root, oversubscribed, traffic on this machine only).
fn mpirun(ranks: usize, args: &[&str]) -> Output {
    Command::new("mpirun")
        .args(["--oversubscribe", "--mca", "btl", "self,vader,tcp"])
        .args([
            "--mca",
            "btl_tcp_if_include",
            "lo",
            "--mca",
            "oob_tcp_if_include",
            "lo",
        ])
        .args(["-n", &ranks.to_string(), env!("CARGO_BIN_EXE_ktree")])
        .args(args)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .expect("run mpirun (install openmpi-bin)")
}

/// The largest budget named by "needs a budget of at least N bytes" in the ranks' messages.
fn needed_budget(stderr: &str) -> Option<u64> {
    stderr
        .split("needs a budget of at least ")
        .skip(1)
        .filter_map(|rest| rest.split(' ').next()?.parse().ok())
        .max()
}

/// Runs one command alone and over 2 and 3 ranks, writing `out` each time; the files must be identical,
/// and the output's folder must hold nothing else (no spill folder left).
fn same_bytes(dir: &Path, name: &str, command: &[&str]) {
    let single = dir.join(format!("{name}-1.ktree"));
    let mut args: Vec<&str> = command.to_vec();
    let single_s = single.to_str().unwrap().to_string();
    args.extend(["--out", &single_s]);
    let (ok, single_stdout, err) = ktree(&args);
    assert!(ok, "{name}: single process failed: {err}");
    let want = std::fs::read(&single).unwrap();
    for ranks in [2, 3] {
        let path = dir.join(format!("{name}-{ranks}.ktree"));
        let path_s = path.to_str().unwrap().to_string();
        let mut args: Vec<&str> = command.to_vec();
        args.extend(["--out", &path_s]);
        let out = mpirun(ranks, &args);
        assert!(
            out.status.success(),
            "{name}: {ranks} ranks failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let got = std::fs::read(&path).unwrap();
        assert!(got == want, "{name}: {ranks} ranks wrote other bytes");
        let summary = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            summary.lines().count(),
            single_stdout.lines().count(),
            "rank 0 alone prints: {summary}"
        );
        std::fs::remove_file(&path).unwrap();
    }
    assert_eq!(entries(dir), vec![format!("{name}-1.ktree")], "{name}");
    std::fs::remove_file(&single).unwrap();
}

/// Runs one command over `ranks` ranks with a budget per rank too small, then with the budget the
/// ranks name, until it runs (the budget of rank 0 also covers the index of every part, which it learns
/// only once the others have stacked); the file must be the single-process one.
fn same_bytes_in_the_budget_named(dir: &Path, name: &str, command: &[&str], ranks: usize) {
    let single = dir.join(format!("{name}-1.ktree"));
    let mut args: Vec<&str> = command.to_vec();
    let single_s = single.to_str().unwrap().to_string();
    args.extend(["--out", &single_s]);
    let (ok, _, err) = ktree(&args);
    assert!(ok, "{name}: single process failed: {err}");
    let path = dir.join(format!("{name}-{ranks}.ktree"));
    let path_s = path.to_str().unwrap().to_string();
    let mut budget = 1u64 << 10;
    let mut tries = 0;
    loop {
        let budget_s = budget.to_string();
        let mut args: Vec<&str> = command.to_vec();
        args.extend(["--out", &path_s, "--max-memory", &budget_s]);
        let out = mpirun(ranks, &args);
        if out.status.success() {
            break;
        }
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!path.exists(), "{name}: a failed run left its output");
        let needed = needed_budget(&err)
            .unwrap_or_else(|| panic!("{name}: no budget named in the failure: {err}"));
        assert!(
            needed > budget,
            "{name}: {needed} named after {budget}: {err}"
        );
        budget = needed;
        tries += 1;
        assert!(tries < 4, "{name}: still too small at {budget}: {err}");
    }
    assert!(tries > 0, "{name}: the first budget was not too small");
    assert!(
        std::fs::read(&path).unwrap() == std::fs::read(&single).unwrap(),
        "{name}: {ranks} ranks in {budget} bytes each wrote other bytes"
    );
    std::fs::remove_file(&path).unwrap();
    std::fs::remove_file(&single).unwrap();
    assert!(entries(dir).is_empty(), "{name}: left {:?}", entries(dir));
}

#[test]
fn solids_over_ranks_write_the_single_process_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    same_bytes(
        d,
        "disk",
        &[
            "rays", "-k", "2", "--solid", "ball", "--level", "7", "--radius", "50",
        ],
    );
    same_bytes(
        d,
        "ball",
        &["rays", "--solid", "ball", "--level", "6", "--radius", "25"],
    );
    same_bytes(
        d,
        "cone",
        &[
            "rays", "--solid", "cone", "--level", "6", "--radius", "20", "--height", "40",
            "--axis", "2",
        ],
    );
    same_bytes(
        d,
        "ball4",
        &[
            "rays", "-k", "4", "--solid", "ball", "--level", "4", "--radius", "6",
        ],
    );
    same_bytes(
        d,
        "segment",
        &[
            "rays", "-k", "1", "--solid", "ball", "--level", "9", "--radius", "100",
        ],
    );
}

#[test]
fn a_small_budget_per_rank_names_one_that_works_and_writes_the_same_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    same_bytes_in_the_budget_named(
        d,
        "disk",
        &[
            "rays", "-k", "2", "--solid", "ball", "--level", "9", "--radius", "200",
        ],
        2,
    );
    same_bytes_in_the_budget_named(
        d,
        "ball",
        &["rays", "--solid", "ball", "--level", "8", "--radius", "100"],
        3,
    );
    same_bytes_in_the_budget_named(
        d,
        "ball4",
        &[
            "rays", "-k", "4", "--solid", "ball", "--level", "5", "--radius", "12",
        ],
        3,
    );
}

#[test]
fn ray_files_and_meshes_over_ranks_write_the_single_process_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inputs = tempfile::tempdir().unwrap();
    let rays = inputs.path().join("box.rays");
    let (ok, _, err) = ktree(&[
        "rays",
        "-k",
        "4",
        "--solid",
        "box",
        "--level",
        "4",
        "--lo",
        "1,2,3,4",
        "--hi",
        "9,15,7,12",
        "--out",
        rays.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    same_bytes(d, "box4", &["build", "--rays", rays.to_str().unwrap()]);
    let bunny = data_dir().join("meshes/bunny_npm.obj");
    same_bytes(
        d,
        "bunny",
        &["voxelize", bunny.to_str().unwrap(), "--level", "6", "--fit"],
    );
}

#[test]
fn trees_with_values_over_ranks_write_the_single_process_file() {
    // Each rank reads only its share of the planes (thin slabs: a quarter of --max-memory a slab), in a
    // volume placed off the universe's corner.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let classes = data_dir().join("volumes/skull_classes.json");
    let classes = classes.to_str().unwrap();
    same_bytes(
        d,
        "classes",
        &["voxelize", classes, "--labels", "--max-memory", "64K"],
    );
    same_bytes(
        d,
        "classes-placed",
        &[
            "voxelize",
            classes,
            "--labels",
            "--offset",
            "3,0,37",
            "--max-memory",
            "32K",
        ],
    );
    let brain = data_dir().join("volumes/itk_t1_brain.json");
    same_bytes(
        d,
        "window",
        &[
            "voxelize",
            brain.to_str().unwrap(),
            "--window",
            "60:140",
            "--max-memory",
            "1M",
        ],
    );
    // Meshes as labels and a point cloud's colours: runs cut at each rank's slabs.
    let mesh = |name: &str| data_dir().join("meshes").join(name);
    same_bytes(
        d,
        "meshes",
        &[
            "voxelize",
            mesh("bunny_npm.obj").to_str().unwrap(),
            mesh("fandisk.obj").to_str().unwrap(),
            "--labels",
            "--level",
            "8",
            "--fit",
        ],
    );
    let cloud = data_dir().join("clouds/pcl_colored_cloud.pcd");
    same_bytes(
        d,
        "colours",
        &[
            "voxelize",
            cloud.to_str().unwrap(),
            "--voxel-size",
            "0.005",
            "--value",
            "rgb",
        ],
    );
    // A label too large for the type in the last plane: only the last rank reads it, and every rank
    // stops with nothing written and no spill folder left.
    let inputs = tempfile::tempdir().unwrap();
    let mut labels: Vec<u16> = (0..16 * 16 * 16u16).map(|i| i % 3).collect();
    labels[16 * 16 * 16 - 1] = 300;
    let raw: Vec<u8> = labels.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(inputs.path().join("u.raw"), raw).unwrap();
    let json = inputs.path().join("u.json");
    std::fs::write(
        &json,
        r#"{"file": "u.raw", "dtype": "uint16", "endianness": "little", "shape_xyz": [16, 16, 16]}"#,
    )
    .unwrap();
    let bad = d.join("bad.ktree");
    let out = mpirun(
        3,
        &[
            "voxelize",
            json.to_str().unwrap(),
            "--labels",
            "--dtype",
            "uint8",
            "--max-memory",
            "4K",
            "--out",
            bad.to_str().unwrap(),
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("rank 2 of 3") && stderr.contains("is 300"),
        "{stderr}"
    );
    assert!(entries(d).is_empty(), "{:?}", entries(d));
}

#[test]
fn a_failed_run_stops_every_rank_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.ktree");
    let out = mpirun(
        2,
        &[
            "build",
            "--rays",
            "/nonexistent/in.rays",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("in.rays"), "the error names the input: {err}");
    assert!(entries(dir.path()).is_empty(), "no file left behind");
}

#[test]
fn a_failure_while_rank_0_writes_leaves_no_output_and_no_spill_folder() {
    let Some(disk) = SmallDisk::mount("64k") else {
        return;
    };
    let spill = tempfile::tempdir().unwrap();
    let out = disk.0.join("ball.ktree");
    // The file (about 300 KB) does not fit on the disk; the spill files go elsewhere.
    let run = mpirun(
        3,
        &[
            "rays",
            "--solid",
            "ball",
            "--level",
            "9",
            "--radius",
            "200",
            "--temp-dir",
            spill.path().to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("rank 0 of 3") && err.contains("ball.ktree"),
        "rank 0 names the output: {err}"
    );
    assert!(
        !err.contains("rank 1 of 3") && !err.contains("rank 2 of 3"),
        "the ranks that did not fail say nothing: {err}"
    );
    assert!(entries(&disk.0).is_empty(), "left {:?}", entries(&disk.0));
    assert!(
        entries(spill.path()).is_empty(),
        "left {:?}",
        entries(spill.path())
    );
}

#[test]
fn format_version_1_over_ranks_is_the_one_process_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("v1.ktree");
    let one = dir.path().join("one.ktree");
    let solid = ["rays", "--solid", "ball", "--level", "5", "--radius", "10"];
    let version = ["--format-version", "1", "--out"];
    let run = mpirun(
        2,
        &[&solid[..], &version[..], &[out.to_str().unwrap()]].concat(),
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (ok, _, err) = ktree(&[&solid[..], &version[..], &[one.to_str().unwrap()]].concat());
    assert!(ok, "{err}");
    assert_eq!(ktree::io::ktree_file_version(&out).unwrap(), 1);
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&one).unwrap());
    // The version 2 file it was streamed from is gone.
    assert_eq!(entries(dir.path()), vec!["one.ktree", "v1.ktree"]);
}
