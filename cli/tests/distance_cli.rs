//! `ktree distance`: the narrow band written as an OpenVDB level set, checked against OpenVDB itself —
//! Debian's `pyopenvdb` reads it as a `FloatGrid` of class level set with the band's values, and OpenVDB's
//! `tools::sdfInteriorMask` (C++, `vdb_level_set_check.cpp` here built against `libopenvdb-dev`) gives back
//! the tree's voxels. A test whose tool is missing prints a visible `SKIPPED:` line and passes.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::ktree;
use ktree::io::{write_tree, WriteOptions};
use ktree::rays::ball_rays;
use ktree::{AnyTree, KTree, Ray, RaySet};

/// Octrees with a surface: a ball, a ball with a box cut out touching the universe's border, two voxels.
fn objects() -> Vec<(&'static str, KTree<3>)> {
    let ball = KTree::from_rays(&ball_rays::<3>(5, [32, 30, 34], 22).unwrap());
    let slab: Vec<Ray<3>> = (0..32u32)
        .flat_map(|x| (20..32u32).map(move |y| Ray::new([x, y, 0], 9)))
        .collect();
    let slab = KTree::from_rays(&RaySet::from_rays(5, slab).unwrap());
    let dots = KTree::from_rays(
        &RaySet::from_rays(4, [Ray::new([1, 2, 3], 4), Ray::new([9, 9, 9], 10)]).unwrap(),
    );
    vec![("ball", ball), ("slab", slab), ("dots", dots)]
}

fn write(dir: &Path, name: &str, tree: &KTree<3>) -> String {
    let path = dir.join(format!("{name}.ktree"));
    write_tree(&path, &AnyTree::K3(tree.clone()), &WriteOptions::default()).unwrap();
    path.display().to_string()
}

/// Runs `/usr/bin/python3` with OpenVDB's module on `script`; `None` (after a visible line) without it.
fn pyopenvdb(script: &str) -> Option<String> {
    let probe = Command::new("/usr/bin/python3")
        .args(["-c", "import pyopenvdb"])
        .output();
    if !matches!(probe, Ok(ref o) if o.status.success()) {
        println!("SKIPPED: python3-openvdb not installed (module pyopenvdb for /usr/bin/python3)");
        return None;
    }
    let out = Command::new("/usr/bin/python3")
        .args(["-c", script])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8(out.stdout).unwrap())
}

#[test]
fn pyopenvdb_reads_the_level_set_with_the_band_values() {
    let dir = tempfile::tempdir().unwrap();
    for (name, tree) in objects() {
        let (band, size) = (2.5, 0.25);
        let src = write(dir.path(), name, &tree);
        let out = dir.path().join(format!("{name}.vdb"));
        let (ok, _, err) = ktree(&[
            "distance",
            &src,
            "--band",
            &band.to_string(),
            "--out",
            &out.display().to_string(),
            "--voxel-size",
            &size.to_string(),
        ]);
        assert!(ok, "{err}");
        // Sampled voxels: every 3rd along each axis, plus every band voxel.
        let side = tree.universe().side() as u32;
        let mut points: Vec<[u32; 3]> = Vec::new();
        for x in (0..side).step_by(3) {
            for y in (0..side).step_by(3) {
                for z in (0..side).step_by(3) {
                    points.push([x, y, z]);
                }
            }
        }
        let nb = tree.narrow_band(band).unwrap();
        points.extend(nb.voxels.iter().copied());
        let list: Vec<String> = points
            .iter()
            .map(|p| format!("({},{},{})", p[0], p[1], p[2]))
            .collect();
        let script = format!(
            "import pyopenvdb as vdb\ng = vdb.read({:?}, 'ktree')\na = g.getConstAccessor()\n\
             print(type(g).__name__, g.gridClass, g.background, g.activeVoxelCount(), g.transform.voxelSize()[0])\n\
             for p in [{}]:\n    print(repr(a.getValue(p)), int(a.isValueOn(p)))",
            out.display().to_string(),
            list.join(",")
        );
        let Some(text) = pyopenvdb(&script) else {
            return;
        };
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
        assert_eq!(head[0], "FloatGrid");
        assert_eq!(head[1..3], ["level", "set"], "{name}");
        assert_eq!(head[3].parse::<f64>().unwrap(), band * size);
        assert_eq!(head[4].parse::<usize>().unwrap(), nb.len(), "{name}");
        assert_eq!(head[5].parse::<f64>().unwrap(), size);
        let sd = tree.signed_distance_at(&points).unwrap();
        for (p, (line, d)) in points.iter().zip(lines.zip(sd)) {
            let w: Vec<&str> = line.split_whitespace().collect();
            let value: f64 = w[0].parse().unwrap();
            let on = w[1] == "1";
            assert_eq!(on, d.abs() <= band, "{name} {p:?}");
            let want = if on {
                (d * size) as f32
            } else {
                (band * size).copysign(d) as f32
            };
            assert_eq!(value as f32, want, "{name} {p:?}");
        }
    }
}

/// Builds `vdb_level_set_check` against the installed OpenVDB into `dir`, or says why it cannot.
fn level_set_check(dir: &Path) -> Option<PathBuf> {
    if !Path::new("/usr/include/openvdb/openvdb.h").exists() {
        println!("SKIPPED: libopenvdb-dev not installed (OpenVDB's headers)");
        return None;
    }
    let exe = dir.join("vdb_level_set_check");
    let src =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/interop/vdb_level_set_check.cpp");
    let built = Command::new("g++")
        .args(["-std=c++17", "-O1", "-o"])
        .arg(&exe)
        .arg(&src)
        .args(["-lopenvdb", "-ltbb"])
        .output();
    match built {
        Ok(o) if o.status.success() => Some(exe),
        Ok(o) => panic!(
            "vdb_level_set_check does not build: {}",
            String::from_utf8_lossy(&o.stderr)
        ),
        Err(e) => {
            println!("SKIPPED: g++ not found ({e})");
            None
        }
    }
}

#[test]
fn openvdb_takes_the_inside_of_the_level_set_as_the_trees_voxels() {
    let dir = tempfile::tempdir().unwrap();
    // The build goes to the target dir, kept between runs as the tests' other tools are.
    let build_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let Some(check) = level_set_check(&build_dir) else {
        return;
    };
    for (name, tree) in objects() {
        let src = write(dir.path(), name, &tree);
        let out = dir.path().join(format!("{name}.vdb"));
        let (ok, _, err) = ktree(&[
            "distance",
            &src,
            "--band",
            "3",
            "--out",
            &out.display().to_string(),
        ]);
        assert!(ok, "{err}");
        let run = Command::new(&check).arg(&out).output().unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let text = String::from_utf8(run.stdout).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("class level set"));
        assert_eq!(lines.next(), Some("background 3"));
        let active: usize = lines.next().unwrap()["active ".len()..].parse().unwrap();
        assert_eq!(active, tree.narrow_band(3.0).unwrap().len(), "{name}");
        let interior: u128 = lines.next().unwrap()["interior ".len()..].parse().unwrap();
        assert_eq!(interior, tree.voxel_count(), "{name}");
        let mut voxels: Vec<[u32; 3]> = lines
            .map(|l| {
                let c: Vec<u32> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                [c[0], c[1], c[2]]
            })
            .collect();
        voxels.sort();
        let mut want: Vec<[u32; 3]> = Vec::new();
        tree.for_each_leaf(|c, s| {
            if s == ktree::NodeState::Full {
                let o = c.origin();
                let n = c.side() as u32;
                for x in 0..n {
                    for y in 0..n {
                        for z in 0..n {
                            want.push([o[0] + x, o[1] + y, o[2] + z]);
                        }
                    }
                }
            }
        });
        want.sort();
        assert_eq!(voxels, want, "{name}");
    }
}

#[test]
fn bad_arguments_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let src = write(dir.path(), "ball", &objects()[0].1);
    let out = dir.path().join("x.vdb").display().to_string();
    for args in [
        vec!["distance", &src, "--band", "0.5", "--out", &out],
        vec!["distance", &src, "--voxel-size", "0", "--out", &out],
        vec!["distance", &src, "--out", "x.ktree"],
        vec!["distance", "missing.ktree", "--out", &out],
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok && err.trim().lines().count() == 1, "{args:?}: {err}");
    }
    assert!(!Path::new(&out).exists());
}
