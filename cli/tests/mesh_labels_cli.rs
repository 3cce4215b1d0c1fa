//! Meshes as labels from the outside: `ktree voxelize a.obj b.stl c.ply --labels` and `ktree voxelize
//! scene.obj --labels` (one label per group) print each label's name, and `ktree stats --json` of the tree
//! counts, for each label, the voxels the binary voxelizer gives that mesh alone in the same placement;
//! bad input is a one-line error naming the file.

mod common;

use std::path::Path;

use common::{ktree, run};
use ktree_verify::meshes::CUBE;

fn corners(lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| [0, 1, 2].map(|a| if i >> a & 1 == 1 { hi[a] } else { lo[a] }))
        .collect()
}

/// A box as OBJ lines, its vertices numbered after `base`; `faces` of its 12 triangles.
fn obj_box(lo: [f64; 3], hi: [f64; 3], base: u32, faces: usize) -> String {
    let mut s = String::new();
    for c in corners(lo, hi) {
        s += &format!("v {} {} {}\n", c[0], c[1], c[2]);
    }
    for t in &CUBE[..faces] {
        s += &format!(
            "f {} {} {}\n",
            base + t[0] + 1,
            base + t[1] + 1,
            base + t[2] + 1
        );
    }
    s
}

fn stl_box(lo: [f64; 3], hi: [f64; 3]) -> String {
    let c = corners(lo, hi);
    let mut s = String::from("solid box\n");
    for t in CUBE {
        s += "facet normal 0 0 0\nouter loop\n";
        for v in t {
            let p = c[v as usize];
            s += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        s += "endloop\nendfacet\n";
    }
    s + "endsolid box\n"
}

fn ply_box(lo: [f64; 3], hi: [f64; 3]) -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
         element face 12\nproperty list uchar int vertex_indices\nend_header\n",
    );
    for p in corners(lo, hi) {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for t in CUBE {
        s += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    s
}

fn stats(path: &Path) -> serde_json::Value {
    serde_json::from_str(&run(&["stats", path.to_str().unwrap(), "--json"])).unwrap()
}

/// The transform `--fit` printed.
fn fitted(stdout: &str) -> String {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix("--fit chose --transform "))
        .expect("the transform printed")
        .to_string()
}

/// The voxels of `mesh` voxelized alone by the binary voxelizer with `transform`.
fn alone(mesh: &Path, transform: &str, level: &str, dir: &Path) -> u64 {
    let out = dir.join("alone.ktree");
    run(&[
        "voxelize",
        mesh.to_str().unwrap(),
        "--level",
        level,
        "--transform",
        transform,
        "--out",
        out.to_str().unwrap(),
    ]);
    stats(&out)["voxels"].as_u64().unwrap()
}

#[test]
fn several_mesh_files_are_one_label_each() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let files = [
        (d.join("a.obj"), obj_box([0.0; 3], [1.0, 2.0, 1.5], 0, 12)),
        (d.join("b.stl"), stl_box([1.5, 0.0, 0.0], [3.0, 1.0, 1.0])),
        (d.join("c.ply"), ply_box([0.0, 2.5, 0.5], [2.5, 3.25, 2.0])),
    ];
    for (path, text) in &files {
        std::fs::write(path, text).unwrap();
    }
    let out = d.join("labels.ktree");
    let mut args = vec!["voxelize"];
    args.extend(files.iter().map(|(p, _)| p.to_str().unwrap()));
    args.extend([
        "--labels",
        "--level",
        "5",
        "--fit",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = run(&args);
    for (i, (path, _)) in files.iter().enumerate() {
        let line = format!("label {}: {} (", i + 1, path.display());
        assert!(
            stdout.lines().any(|l| l.starts_with(&line)),
            "{line} in {stdout}"
        );
    }
    let transform = fitted(&stdout);
    let s = stats(&out);
    assert_eq!(s["dtype"], "uint8");
    assert_eq!(s["level"], 5);
    let values = s["values"].as_object().unwrap();
    assert_eq!(values.len(), 3);
    let mut total = 0;
    for (i, (path, _)) in files.iter().enumerate() {
        let want = alone(path, &transform, "5", d);
        assert!(want > 0, "{}", path.display());
        assert_eq!(
            values[&(i + 1).to_string()]["voxels"],
            want,
            "{}",
            path.display()
        );
        let printed = format!("label {}: {} ({want} voxels)", i + 1, path.display());
        assert!(
            stdout.lines().any(|l| l == printed),
            "{printed} in {stdout}"
        );
        total += want;
    }
    assert_eq!(s["voxels"], total);
    // The file keeps the placement as its world frame: voxel c's corner is the mesh point (c − t) / s.
    let bytes = std::fs::read(&out).unwrap();
    let (_, frame) =
        ktree::io::ktree::v3::read_valued_ktree_framed::<3, u8>(&bytes, "labels").unwrap();
    let t = ktree::solid::mesh::MeshTransform::parse(&transform).unwrap();
    assert_eq!(frame, t.world_frame());
    assert!(frame.is_some());
    // The same with --transform: the labels do not depend on how the placement was given.
    let again = d.join("again.ktree");
    let mut args = vec!["voxelize"];
    args.extend(files.iter().map(|(p, _)| p.to_str().unwrap()));
    args.extend([
        "--labels",
        "--level",
        "5",
        "--transform",
        &transform,
        "--out",
        again.to_str().unwrap(),
    ]);
    run(&args);
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn one_obj_file_s_groups_are_one_label_each() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let boxes = [
        ("base", [0.0, 0.0, 0.0], [4.0, 4.0, 1.0]),
        ("post", [1.0, 1.0, 1.0], [1.5, 1.5, 3.0]),
        ("ball", [2.5, 2.5, 1.5], [3.5, 3.5, 2.5]),
    ];
    let mut scene = String::from("# three boxes\n");
    for (i, (name, lo, hi)) in boxes.iter().enumerate() {
        scene += &format!("g {name}\n{}", obj_box(*lo, *hi, 8 * i as u32, 12));
        std::fs::write(d.join(format!("{name}.obj")), obj_box(*lo, *hi, 0, 12)).unwrap();
    }
    let path = d.join("scene.obj");
    std::fs::write(&path, scene).unwrap();
    let out = d.join("scene.ktree");
    let stdout = run(&[
        "voxelize",
        path.to_str().unwrap(),
        "--labels",
        "--level",
        "5",
        "--fit",
        "--out",
        out.to_str().unwrap(),
    ]);
    for (i, (name, _, _)) in boxes.iter().enumerate() {
        let line = format!("label {}: {name} (", i + 1);
        assert!(
            stdout.lines().any(|l| l.starts_with(&line)),
            "{line} in {stdout}"
        );
    }
    let transform = fitted(&stdout);
    let s = stats(&out);
    let values = s["values"].as_object().unwrap();
    assert_eq!(values.len(), 3);
    for (i, (name, _, _)) in boxes.iter().enumerate() {
        let want = alone(&d.join(format!("{name}.obj")), &transform, "5", d);
        assert!(want > 0, "{name}");
        assert_eq!(values[&(i + 1).to_string()]["voxels"], want, "{name}");
        // The file keeps each label's name.
        assert_eq!(values[&(i + 1).to_string()]["name"], *name, "{name}");
        let printed = format!("label {}: {name} ({want} voxels)", i + 1);
        assert!(
            stdout.lines().any(|l| l == printed),
            "{printed} in {stdout}"
        );
    }
    // Moved, or copied to another .ktree, the labels keep their names.
    let moved = d.join("moved.ktree");
    let copied = d.join("copied.ktree");
    let (o, m, c) = (
        out.to_str().unwrap(),
        moved.to_str().unwrap(),
        copied.to_str().unwrap(),
    );
    run(&["transform", o, "--rotate", "z:90", "--out", m]);
    run(&["convert", o, c]);
    for file in [&moved, &copied] {
        let again = stats(file);
        for (i, (name, _, _)) in boxes.iter().enumerate() {
            assert_eq!(
                again["values"][&(i + 1).to_string()]["name"],
                *name,
                "{}",
                file.display()
            );
        }
    }
    // Written as meshes, each label's part is named by its name.
    let (obj, glb, ply) = (
        d.join("parts.obj"),
        d.join("parts.glb"),
        d.join("parts.ply"),
    );
    for mesh in [&obj, &glb, &ply] {
        run(&["convert", o, mesh.to_str().unwrap()]);
    }
    let obj_text = std::fs::read_to_string(&obj).unwrap();
    let mtl_text = std::fs::read_to_string(d.join("parts.mtl")).unwrap();
    let glb_text = String::from_utf8_lossy(&std::fs::read(&glb).unwrap()).into_owned();
    let ply_bytes = std::fs::read(&ply).unwrap();
    let ply_text = String::from_utf8_lossy(&ply_bytes[..ply_bytes.len().min(2000)]).into_owned();
    for (i, (name, _, _)) in boxes.iter().enumerate() {
        assert!(
            obj_text.contains(&format!("\ng {name}\nusemtl {name}\n")),
            "{name} in {obj_text:.300}"
        );
        assert!(mtl_text.contains(&format!("newmtl {name}\n")), "{mtl_text}");
        assert!(
            glb_text.matches(&format!(r#""name":"{name}""#)).count() >= 2,
            "{name}: a mesh and a material"
        );
        assert!(
            ply_text.contains(&format!("\ncomment {} {name}\n", i + 1)),
            "{ply_text:.500}"
        );
    }
    assert!(!obj_text.contains("label_"), "{obj_text:.300}");
    // A label selected is named in what is printed (the binary file has no place for it).
    let post = d.join("post.ktree");
    let said = run(&["select", o, "--value", "2", "--out", post.to_str().unwrap()]);
    assert!(said.contains("selected (label 2: post)"), "{said}");
    let text = run(&["stats", out.to_str().unwrap()]);
    for (i, (name, _, _)) in boxes.iter().enumerate() {
        let line = format!("  {} ({name}): ", i + 1);
        assert!(
            text.lines().any(|l| l.starts_with(&line)),
            "{line} in {text}"
        );
    }
    // Without groups, one label named by the file.
    let single = d.join("base.obj");
    let out = d.join("single.ktree");
    let stdout = run(&[
        "voxelize",
        single.to_str().unwrap(),
        "--labels",
        "--level",
        "4",
        "--fit",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        stdout.contains(&format!("label 1: {}", single.display())),
        "{stdout}"
    );
    assert_eq!(stats(&out)["values"].as_object().unwrap().len(), 1);
}

#[test]
fn bad_mesh_labels_are_one_line_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |name: &str| d.join(name).display().to_string();
    std::fs::write(
        d.join("open.obj"),
        format!(
            "g shut\n{}g holed\n{}",
            obj_box([0.0; 3], [1.0; 3], 0, 12),
            obj_box([2.0; 3], [3.0; 3], 8, 11)
        ),
    )
    .unwrap();
    std::fs::write(d.join("box.obj"), obj_box([0.0; 3], [1.0; 3], 0, 12)).unwrap();
    std::fs::write(d.join("vol.json"), "{}").unwrap();
    let out = p("out.ktree");
    for (args, names) in [
        (
            vec![
                "voxelize",
                &p("open.obj"),
                "--labels",
                "--level",
                "4",
                "--fit",
                "--out",
                &out,
            ],
            vec!["open.obj", "'holed'", "not closed"],
        ),
        (
            vec![
                "voxelize",
                &p("box.obj"),
                &p("missing.stl"),
                "--labels",
                "--level",
                "4",
                "--fit",
                "--out",
                &out,
            ],
            vec!["missing.stl"],
        ),
        (
            vec![
                "voxelize",
                &p("box.obj"),
                &p("box.obj"),
                "--level",
                "4",
                "--fit",
                "--out",
                &out,
            ],
            vec!["--labels"],
        ),
        (
            vec![
                "voxelize",
                &p("box.obj"),
                &p("vol.json"),
                "--labels",
                "--level",
                "4",
                "--fit",
                "--out",
                &out,
            ],
            vec!["vol.json", "not a mesh"],
        ),
        (
            vec![
                "voxelize",
                &p("box.obj"),
                &p("box.obj"),
                "--labels",
                "--level",
                "4",
                "--fit",
                "--out",
                &p("out.rays"),
            ],
            vec!["out.rays"],
        ),
        (
            vec![
                "voxelize",
                &p("box.obj"),
                &p("box.obj"),
                "--labels",
                "--fit",
                "--out",
                &out,
            ],
            vec!["--level"],
        ),
        (
            vec![
                "voxelize",
                &p("box.obj"),
                "--labels",
                "--level",
                "4",
                "--out",
                &out,
            ],
            vec!["--fit"],
        ),
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?} should fail");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("ktree: "), "{err}");
        for name in names {
            assert!(err.contains(name), "{args:?}: {err} should name {name}");
        }
        assert!(!Path::new(&out).exists(), "{args:?} wrote {out}");
    }
}
