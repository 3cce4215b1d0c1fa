//! `--threads N` on `ktree rays`, `build`, `voxelize` and `op`: the files written are byte-identical for any
//! number of threads, and equal to the tree of the whole ray set.

mod common;

use common::{data_dir, ktree};

fn run(args: &[&str]) {
    let (ok, _, err) = ktree(args);
    assert!(ok, "ktree {args:?}: {err}");
}

#[test]
fn outputs_are_the_same_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let mut trees = Vec::new();
    for threads in ["1", "2", "3"] {
        let ball = p(&format!("ball{threads}.ktree"));
        let cyl = p(&format!("cyl{threads}.ktree"));
        run(&[
            "rays",
            "--center",
            "40,33.5,70",
            "--radius",
            "29.25",
            "--level",
            "7",
            "--out",
            &ball,
            "--threads",
            threads,
        ]);
        run(&[
            "rays",
            "--solid",
            "cylinder",
            "--center",
            "64,64,64",
            "--radius",
            "20",
            "--level",
            "7",
            "--out",
            &cyl,
            "--threads",
            threads,
        ]);
        let union = p(&format!("union{threads}.ktree"));
        run(&[
            "op",
            "union",
            &ball,
            &cyl,
            "--out",
            &union,
            "--threads",
            threads,
        ]);
        trees.push([ball, cyl, union]);
    }
    // The ball as a ray file, stacked by `build` on one and on two threads.
    let rays = p("ball.rays");
    run(&[
        "rays",
        "--center",
        "40,33.5,70",
        "--radius",
        "29.25",
        "--level",
        "7",
        "--out",
        &rays,
    ]);
    for threads in ["1", "2"] {
        let built = p(&format!("built{threads}.ktree"));
        run(&[
            "build",
            "--rays",
            &rays,
            "--out",
            &built,
            "--threads",
            threads,
        ]);
        assert_eq!(
            std::fs::read(&built).unwrap(),
            std::fs::read(&trees[0][0]).unwrap(),
            "build --threads {threads} differs from rays straight to a tree"
        );
    }
    for t in &trees[1..] {
        for (a, b) in t.iter().zip(&trees[0]) {
            assert_eq!(
                std::fs::read(a).unwrap(),
                std::fs::read(b).unwrap(),
                "{a} vs {b}"
            );
        }
    }
    let obj = data_dir().join("meshes/fandisk.obj").display().to_string();
    let (a, b) = (p("mesh1.ktree"), p("mesh2.ktree"));
    run(&[
        "voxelize",
        &obj,
        "--level",
        "6",
        "--fit",
        "--out",
        &a,
        "--threads",
        "1",
    ]);
    run(&[
        "voxelize",
        &obj,
        "--level",
        "6",
        "--fit",
        "--out",
        &b,
        "--threads",
        "2",
    ]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn zero_threads_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.ktree").display().to_string();
    let (ok, _, err) = ktree(&[
        "rays",
        "--radius",
        "3",
        "--level",
        "3",
        "--out",
        &out,
        "--threads",
        "0",
    ]);
    assert!(!ok);
    assert!(err.contains("--threads 0"), "{err}");
}
