//! Builds over MPI ranks write the very file a single process writes (`mpirun -n 2`, and 3 ranks
//! oversubscribed on this machine), in K = 2, 3 and 4, for `rays`, `build` and `voxelize`; a failed run
//! leaves no output. Compiled with the cargo feature `mpi` only; needs `mpirun` (OpenMPI) on the PATH.
#![cfg(feature = "mpi")]

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{data_dir, ktree};

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

/// Runs one command alone and over 2 and 3 ranks, writing `out` each time; the files must be identical.
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
    }
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
}

#[test]
fn ray_files_and_meshes_over_ranks_write_the_single_process_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rays = d.join("box.rays");
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
    assert!(
        std::fs::read_dir(dir.path()).unwrap().next().is_none(),
        "no file left behind"
    );
}
