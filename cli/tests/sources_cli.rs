//! `ktree voxelize MESH|VOLUME --out X.ktree` and `ktree build --rays FILE --out X.ktree` build out of
//! core from rays made (or read) slab by slab: the files are byte for byte the in-memory build's, the
//! summary lines are those of the in-memory build, and bad input gives the errors it gave.

mod common;

use std::path::Path;

use common::ktree;
use ktree::input::voxelize;
use ktree::io::{read_rays_file, write_ktree, write_ktree_framed, Notes, ReadOptions};
use ktree::solid::mesh::MeshTransform;
use ktree::solid::volume::Select;
use ktree::stacking::paper::stack;
use ktree::AnyRaySet;

/// The bytes of the tree of a ray set built in memory, as `.ktree` version 2.
fn in_memory_bytes(rays: &AnyRaySet) -> Vec<u8> {
    let mut bytes = Vec::new();
    ktree::with_dim!(rays, AnyRaySet, r => write_ktree(&mut bytes, &stack(r)).unwrap());
    bytes
}

/// A summary line without the output's path.
fn after_path(line: &str) -> &str {
    line.split_once(": ").map_or(line, |(_, rest)| rest)
}

/// Runs `ktree` with `args` then `--out out` (and `extra`); returns stdout, failing on an error.
fn run(args: &[&str], out: &Path, extra: &[&str]) -> String {
    let mut all = args.to_vec();
    all.extend(["--out", out.to_str().unwrap()]);
    all.extend(extra);
    let (ok, stdout, err) = ktree(&all);
    assert!(ok, "{all:?}: {err}");
    stdout
}

#[test]
fn voxelize_builds_meshes_and_volumes_slab_by_slab() {
    let dir = tempfile::tempdir().unwrap();
    let data = common::data_dir();
    let fandisk = data.join("meshes/fandisk.obj");
    let bunny = data.join("meshes/bunny_npm.obj");
    let skull = data.join("volumes/skull_grey.json");
    let brain = data.join("volumes/itk_t1_brain.json");
    let (fandisk, bunny, skull, brain) = (
        fandisk.to_str().unwrap(),
        bunny.to_str().unwrap(),
        skull.to_str().unwrap(),
        brain.to_str().unwrap(),
    );
    // The bunny smaller, shifted along x and partly below the universe (crossings clamped to its face).
    let fit = MeshTransform::fit(&ktree::io::read_mesh(Path::new(bunny)).unwrap(), 6).unwrap();
    let bunny_transform = MeshTransform {
        scale: fit.scale * 0.75,
        translate: [
            fit.translate[0] + 21.0,
            fit.translate[1],
            fit.translate[2] - 20.0,
        ],
    }
    .to_arg();
    let cases: Vec<(Vec<&str>, ReadOptions)> = vec![
        (
            vec!["voxelize", fandisk, "--level", "7", "--fit"],
            ReadOptions {
                level: Some(7),
                ..ReadOptions::default()
            },
        ),
        (
            vec![
                "voxelize",
                bunny,
                "--level",
                "6",
                "--transform",
                &bunny_transform,
            ],
            ReadOptions {
                level: Some(6),
                mesh_placement: Some(MeshTransform::parse(&bunny_transform).unwrap()),
                ..ReadOptions::default()
            },
        ),
        (
            vec!["voxelize", skull, "--threshold", "29000"],
            ReadOptions {
                select: Some(Select::AtLeast(29_000.0)),
                ..ReadOptions::default()
            },
        ),
        (
            vec![
                "voxelize",
                brain,
                "--level",
                "8",
                "--threshold",
                "1",
                "--offset",
                "3,50,60",
            ],
            ReadOptions {
                level: Some(8),
                select: Some(Select::AtLeast(1.0)),
                offset: Some([3, 50, 60]),
                ..ReadOptions::default()
            },
        ),
    ];
    for (args, options) in cases {
        let input = Path::new(args[1]);
        let whole = voxelize(input, &options).unwrap();
        assert!(whole.rays.len() > 100, "{args:?}");
        let out = dir.path().join("slabs.ktree");
        let slabs = run(&args, &out, &["--threads", "2"]);
        // A mesh placed by --transform keeps its world frame.
        let frame = options.mesh_placement.and_then(|t| t.world_frame());
        let mut want = Vec::new();
        write_ktree_framed(
            &mut want,
            &stack(&whole.rays),
            frame.as_ref(),
            &Notes::new(),
        )
        .unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), want, "{args:?}");
        // The in-memory build (format version 1) and the ray file print the same figures.
        let v1 = run(
            &args,
            &dir.path().join("v1.ktree"),
            &["--format-version", "1"],
        );
        let rays = run(&args, &dir.path().join("r.rays"), &[]);
        let (slabs, v1, rays): (Vec<&str>, Vec<&str>, Vec<&str>) = (
            slabs.lines().collect(),
            v1.lines().collect(),
            rays.lines().collect(),
        );
        assert_eq!(slabs.len(), v1.len(), "{slabs:?} {v1:?}");
        let (last, v1_last) = (slabs[slabs.len() - 1], v1[v1.len() - 1]);
        assert_eq!(after_path(last), after_path(v1_last), "{args:?}");
        assert_eq!(&slabs[..slabs.len() - 1], &v1[..v1.len() - 1], "{args:?}");
        let counts = format!(
            "{} rays, {} voxels",
            whole.rays.len(),
            whole.rays.voxel_count()
        );
        assert!(last.contains(&counts), "{last} / {counts}");
        assert!(rays[rays.len() - 1].ends_with(&counts), "{rays:?}");
    }
    // A budget that does not hold the mesh's triangles names the input and the option.
    let (ok, _, err) = ktree(&[
        "voxelize",
        fandisk,
        "--level",
        "7",
        "--fit",
        "--out",
        dir.path().join("small.ktree").to_str().unwrap(),
        "--max-memory",
        "1K",
    ]);
    assert!(
        !ok && err.contains("fandisk.obj") && err.contains("--max-memory"),
        "{err}"
    );
}

#[test]
fn build_reads_sorted_ray_files_slab_by_slab() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let sorted = p("ball.rays");
    run(&["rays", "--level", "7", "--radius", "50"], &sorted, &[]);
    // The same runs in reverse order: read whole.
    let text = std::fs::read_to_string(&sorted).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let body = lines.split_off(2);
    let mut shuffled = lines.join("\n") + "\n";
    for line in body.iter().rev() {
        shuffled.push_str(line);
        shuffled.push('\n');
    }
    std::fs::write(p("shuffled.rays"), shuffled).unwrap();
    let whole = read_rays_file(&sorted).unwrap();
    assert!(read_rays_file(&p("shuffled.rays")).unwrap() == whole);
    let expected = in_memory_bytes(&whole);
    let mut summaries = Vec::new();
    for (input, extra) in [
        ("ball.rays", vec!["--threads", "2"]),
        ("shuffled.rays", vec![]),
        ("ball.rays", vec!["--format-version", "1"]),
    ] {
        let out = p(&format!("{input}.{}.ktree", extra.len()));
        let mut args = vec!["build", "--rays"];
        let input = p(input);
        args.push(input.to_str().unwrap());
        let stdout = run(&args, &out, &extra);
        if extra.first() != Some(&"--format-version") {
            assert_eq!(std::fs::read(&out).unwrap(), expected, "{input:?}");
        }
        summaries.push(after_path(stdout.trim_end()).to_string());
    }
    assert!(
        summaries.iter().all(|s| s == &summaries[0]),
        "{summaries:?}"
    );
    assert!(
        summaries[0].contains(&format!("{} rays", whole.len())),
        "{summaries:?}"
    );
    // The sorted file is indexed (its index is what a tiny budget must hold), the other read whole.
    for (input, held) in [
        ("ball.rays", "the index of"),
        ("shuffled.rays", "the rays of"),
    ] {
        let (ok, _, err) = ktree(&[
            "build",
            "--rays",
            p(input).to_str().unwrap(),
            "--out",
            p("tiny.ktree").to_str().unwrap(),
            "--max-memory",
            "1K",
        ]);
        assert!(!ok && err.contains(held), "{input}: {err}");
    }
    // A bad line: the error names the file and line, as the whole read does.
    let mut text = std::fs::read_to_string(&sorted).unwrap();
    text.push_str("1 2 x 4\n");
    std::fs::write(p("bad.rays"), &text).unwrap();
    let line = text.lines().count();
    let (ok, _, err) = ktree(&[
        "build",
        "--rays",
        p("bad.rays").to_str().unwrap(),
        "--out",
        p("bad.ktree").to_str().unwrap(),
    ]);
    let want = format!(
        "{}:{line}: field 3 (\"x\") is not a whole number",
        p("bad.rays").display()
    );
    assert!(!ok && err.contains(&want), "{err} / {want}");
    assert!(!p("bad.ktree").exists());
}
