//! `--max-memory`, `--temp-dir` and `--progress` on `ktree build`, `rays`, `voxelize` (trees written out of
//! core) and `--max-memory` on `ktree op` (streamed from version 2 files beyond it): the files are byte for byte the in-memory build's; a budget too
//! small names one that works; an unusable temporary folder or a full disk is a clear error that leaves
//! the target untouched and no temporary file. The full disk is a small tmpfs, which only root may mount:
//! elsewhere its test prints a `SKIPPED:` line and passes, or fails under `KTREE_REQUIRE_TOOLS=1`.

mod common;

use std::path::{Path, PathBuf};

use common::{entries, ktree, SmallDisk};
use ktree::io::{read_rays_file, write_ktree};
use ktree::stacking::paper::stack;
use ktree::AnyRaySet;

/// The bytes of the tree of a ray file built in memory, as `.ktree` version 2.
fn in_memory_bytes(rays: &Path) -> Vec<u8> {
    let mut bytes = Vec::new();
    match read_rays_file(rays).unwrap() {
        AnyRaySet::K3(r) => write_ktree(&mut bytes, &stack(&r)).unwrap(),
        other => panic!("expected K = 3 rays, got K = {}", other.k()),
    }
    bytes
}

fn ball_rays(dir: &Path, level: u32) -> PathBuf {
    let rays = dir.join(format!("ball{level}.rays"));
    let radius = ((1u32 << level) * 7 / 16).to_string();
    let (ok, _, err) = ktree(&[
        "rays",
        "--level",
        &level.to_string(),
        "--radius",
        &radius,
        "--out",
        rays.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    rays
}

#[test]
fn build_writes_the_in_memory_bytes_for_any_budget_spelling() {
    let dir = tempfile::tempdir().unwrap();
    let rays = ball_rays(dir.path(), 7);
    let expected = in_memory_bytes(&rays);
    let out = dir.path().join("ball.ktree");
    for budget in [
        None,
        Some("512M"),
        Some("2G"),
        Some("100000000"),
        Some("1.5g"),
    ] {
        let mut args = vec![
            "build",
            "--rays",
            rays.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--progress",
        ];
        if let Some(b) = budget {
            args.extend(["--max-memory", b]);
        }
        let (ok, stdout, err) = ktree(&args);
        assert!(ok, "{budget:?}: {err}");
        assert!(stdout.contains("nodes"), "{stdout}");
        assert_eq!(std::fs::read(&out).unwrap(), expected, "{budget:?}");
    }
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        rays.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--max-memory",
        "lots",
    ]);
    assert!(!ok && err.contains("'lots' is not a size"), "{err}");
}

#[test]
fn a_budget_too_small_names_one_that_works() {
    let dir = tempfile::tempdir().unwrap();
    let rays = ball_rays(dir.path(), 7);
    let expected = in_memory_bytes(&rays);
    let out = dir.path().join("ball.ktree");
    std::fs::write(&out, b"old").unwrap();
    let rays_bytes = {
        let AnyRaySet::K3(r) = read_rays_file(&rays).unwrap() else {
            panic!("K = 3 rays")
        };
        16 * r.len() as u64
    };
    // The rays alone do not fit.
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        rays.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--max-memory",
        "1K",
    ]);
    assert!(
        !ok && err.contains("ball7.rays") && err.contains("--max-memory"),
        "{err}"
    );
    // The rays fit, a slab does not.
    let budget = (rays_bytes + 1000).to_string();
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        rays.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--max-memory",
        &budget,
    ]);
    assert!(!ok && err.contains("too small"), "{err}");
    // Each budget named is larger than the one refused; in a few steps the build runs.
    let mut err = err;
    let mut tries = 0;
    let (ok, budget, err) = loop {
        let needed = needed_budget(&err);
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
        assert_eq!(entries(dir.path()), vec!["ball.ktree", "ball7.rays"]);
        let budget = (needed + rays_bytes).to_string();
        let (ok, _, e) = ktree(&[
            "build",
            "--rays",
            rays.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--max-memory",
            &budget,
        ]);
        tries += 1;
        if ok || tries == 20 {
            break (ok, budget, e);
        }
        assert!(needed_budget(&e) > needed, "{e}");
        err = e;
    };
    assert!(ok, "with the budget named ({budget}): {err}");
    assert_eq!(std::fs::read(&out).unwrap(), expected);
}

#[test]
fn an_unusable_temporary_folder_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let rays = ball_rays(dir.path(), 6);
    let out = dir.path().join("ball.ktree");
    std::fs::write(&out, b"old").unwrap();
    // A plain file where the folder should be: nobody, not even root, can create files in it.
    let not_a_folder = dir.path().join("not-a-folder");
    std::fs::write(&not_a_folder, b"").unwrap();
    for args in [
        vec!["build", "--rays", rays.to_str().unwrap()],
        vec!["rays", "--level", "6", "--radius", "20"],
    ] {
        let mut args = args.clone();
        args.extend([
            "--out",
            out.to_str().unwrap(),
            "--temp-dir",
            not_a_folder.to_str().unwrap(),
        ]);
        let (ok, _, err) = ktree(&args);
        assert!(
            !ok && err.contains("not-a-folder") && err.contains("temporary folder"),
            "{args:?}: {err}"
        );
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
        assert_eq!(
            entries(dir.path()),
            vec!["ball.ktree", "ball6.rays", "not-a-folder"]
        );
    }
}

#[test]
fn rays_and_voxelize_build_out_of_core_with_progress() {
    let dir = tempfile::tempdir().unwrap();
    let rays = ball_rays(dir.path(), 6);
    let expected = in_memory_bytes(&rays);
    let out = dir.path().join("direct.ktree");
    let (ok, stdout, err) = ktree(&[
        "rays",
        "--level",
        "6",
        "--radius",
        "28",
        "--out",
        out.to_str().unwrap(),
        "--max-memory",
        "64M",
        "--progress",
        "--threads",
        "2",
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("voxels -> "), "{stdout}");
    assert_eq!(std::fs::read(&out).unwrap(), expected);
    // A mesh: the same tree as the in-memory build of its rays.
    let mesh = common::data_dir().join("meshes/fandisk.obj");
    let mesh_rays = dir.path().join("bunny.rays");
    let mesh_tree = dir.path().join("bunny.ktree");
    for out in [&mesh_rays, &mesh_tree] {
        let (ok, _, err) = ktree(&[
            "voxelize",
            mesh.to_str().unwrap(),
            "--level",
            "6",
            "--fit",
            "--out",
            out.to_str().unwrap(),
            "--max-memory",
            "256M",
            "--progress",
        ]);
        assert!(ok, "{err}");
    }
    assert_eq!(
        std::fs::read(&mesh_tree).unwrap(),
        in_memory_bytes(&mesh_rays)
    );
}

/// `ktree rays` writes a ray file slab by slab: the file is the whole set's, so building it gives the tree
/// `ktree rays` writes directly; at L = 12 a quadric's ray count passes no cap.
#[test]
fn ray_files_are_written_slab_by_slab() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let solid = [
        "--solid",
        "ellipsoid",
        "--radii",
        "30,21.5,17",
        "--level",
        "6",
    ];
    for out in [p("e.rays"), p("e.ktree")] {
        let mut args = vec!["rays"];
        args.extend(solid);
        args.extend(["--out", &out, "--progress"]);
        let (ok, _, err) = ktree(&args);
        assert!(ok, "{err}");
    }
    let whole = {
        use ktree::solid::{Frame, Quadric, Rational, Sample, Solid};
        let r = |n, d| Rational::new(n, d).unwrap();
        let q =
            Quadric::<3>::ellipsoid([r(32, 1); 3], [r(30, 1), r(43, 2), r(17, 1)], Frame::Voxel)
                .unwrap();
        let mut text = Vec::new();
        ktree::io::write_rays(
            &mut text,
            &Solid::Quadric(q).to_rays(6, Sample::Centre, false).unwrap(),
        )
        .unwrap();
        text
    };
    assert_eq!(std::fs::read(p("e.rays")).unwrap(), whole);
    let (ok, _, err) = ktree(&["build", "--rays", &p("e.rays"), "--out", &p("f.ktree")]);
    assert!(ok, "{err}");
    assert_eq!(
        std::fs::read(p("f.ktree")).unwrap(),
        std::fs::read(p("e.ktree")).unwrap()
    );
}

#[test]
fn op_streams_version_2_files_beyond_its_budget() {
    let dir = tempfile::tempdir().unwrap();
    let spill = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.ktree");
    let b = dir.path().join("b.ktree");
    for (out, centre) in [(&a, "30,32,32"), (&b, "40,28,36")] {
        let (ok, _, err) = ktree(&[
            "rays",
            "--level",
            "6",
            "--center",
            centre,
            "--radius",
            "20",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
    }
    // The same trees as version 1 files, which are read into memory.
    let (a1, b1) = (dir.path().join("a1.ktree"), dir.path().join("b1.ktree"));
    for (v2, v1) in [(&a, &a1), (&b, &b1)] {
        let (ok, _, err) = ktree(&[
            "--format-version",
            "1",
            "convert",
            v2.to_str().unwrap(),
            v1.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
    }
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let (a1, b1) = (a1.to_str().unwrap(), b1.to_str().unwrap());
    for (op, streamed, in_memory) in [
        ("union", vec![a, b], vec![a1, b1]),
        ("intersect", vec![a, b], vec![a1, b1]),
        ("diff", vec![a, b], vec![a1, b1]),
        ("xor", vec![b, a], vec![b1, a1]),
        ("not", vec![a], vec![a1]),
    ] {
        let run = |inputs: &[&str], budget: &str, name: &str| {
            let out = dir.path().join(name);
            let mut args = vec!["op", op];
            args.extend(inputs);
            args.extend(["--out", out.to_str().unwrap(), "--max-memory", budget]);
            args.extend(["--temp-dir", spill.path().to_str().unwrap()]);
            let (ok, stdout, err) = ktree(&args);
            assert!(ok, "{op} with {budget}: {err}");
            (std::fs::read(&out).unwrap(), stdout.replace(name, "OUT"))
        };
        // 100 bytes hold no tree: the version 2 files are streamed.
        assert_eq!(
            run(&in_memory, "1G", "memory.ktree"),
            run(&streamed, "100", "streamed.ktree"),
            "{op}"
        );
        assert!(entries(spill.path()).is_empty(), "{op}: spill files left");
    }
    // A version 1 input cannot be streamed: the budget is an error naming the input.
    let c = dir.path().join("c.ktree");
    let (ok, _, err) = ktree(&[
        "op",
        "not",
        a1,
        "--out",
        c.to_str().unwrap(),
        "--max-memory",
        "100",
    ]);
    assert!(
        !ok && err.contains("a1.ktree") && err.contains("--max-memory"),
        "{err}"
    );
    assert!(!c.exists());
}

#[test]
fn a_full_temporary_disk_is_a_clear_error() {
    let Some(disk) = SmallDisk::mount("64k") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let rays = ball_rays(dir.path(), 9);
    let out = dir.path().join("ball.ktree");
    std::fs::write(&out, b"old").unwrap();
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        rays.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--temp-dir",
        disk.0.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("spill file") && err.contains("No space left"),
        "{err}"
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"old");
    assert!(entries(&disk.0).is_empty(), "{:?}", entries(&disk.0));
    assert_eq!(entries(dir.path()), vec!["ball.ktree", "ball9.rays"]);
}

/// The budget a failed build names ("… at least N bytes …").
fn needed_budget(err: &str) -> u64 {
    err.split("at least ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no budget named: {err}"))
}

/// A budget far too small for a large universe fails at the first slab that does not fit, naming the
/// budget needed, without going through the other slabs (at level 16 that would take minutes); nothing
/// is left behind.
#[test]
fn a_tiny_budget_at_a_large_level_fails_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball16.ktree");
    let (ok, _, err) = ktree(&[
        "rays",
        "--solid",
        "ball",
        "--radius",
        "65535/2",
        "--level",
        "16",
        "--out",
        out.to_str().unwrap(),
        "--max-memory",
        "1M",
    ]);
    assert!(
        !ok && err.contains("too small") && err.contains("--max-memory"),
        "{err}"
    );
    assert!(needed_budget(&err) > 1 << 20, "{err}");
    assert!(err.contains("ball16.ktree"), "{err}");
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
}
