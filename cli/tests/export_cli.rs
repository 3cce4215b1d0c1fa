//! `ktree convert X.ktree Y.ply|.obj|.stl|.glb|.svg`: the tree's boundary out as a mesh, in world units
//! (`--voxel-size`, `--origin`, or those of an input grid), read back and voxelized to the same tree.

mod common;

use std::path::Path;

use common::ktree;
use ktree::io::{read_tree_placed, write_tree, GridMeta, ReadOptions, WriteOptions};
use ktree::rays::ball_rays;
use ktree::solid::mesh::MeshTransform;
use ktree::{AnyTree, KTree};

fn ball() -> KTree<3> {
    KTree::from_rays(&ball_rays::<3>(4, [15, 17, 16], 90).unwrap())
}

fn save(path: &Path, tree: AnyTree) {
    write_tree(path, &tree, &WriteOptions::default()).unwrap();
}

/// The tree a mesh file voxelizes to at `level`, the world mapped back by `size` and `origin`.
fn voxelized(path: &Path, level: u32, size: f64, origin: [f64; 3]) -> KTree<3> {
    let mesh = ktree::io::read_mesh(path).unwrap();
    assert_eq!(mesh.open_edges(), 0, "{}", path.display());
    let placement = MeshTransform {
        scale: 1.0 / size,
        translate: origin.map(|o| -o / size),
    };
    KTree::from_rays(&mesh.to_rays(level, &placement).unwrap().rays)
}

#[test]
fn convert_writes_each_mesh_format_in_world_units() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ball.ktree");
    let tree = ball();
    save(&input, AnyTree::K3(tree.clone()));
    for name in ["ball.ply", "ball.obj", "ball.stl", "ball.glb"] {
        let out = dir.path().join(name);
        let (ok, stdout, stderr) = ktree(&[
            "convert",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--voxel-size",
            "0.5",
            "--origin",
            "1,-2,3",
        ]);
        assert!(ok, "{name}: {stderr}");
        assert!(stdout.contains(name), "{stdout}");
        if name.ends_with(".glb") {
            let bytes = std::fs::read(&out).unwrap();
            assert_eq!(&bytes[..4], b"glTF");
            continue;
        }
        let mesh = ktree::io::read_mesh(&out).unwrap();
        // In world units the sum of the tetrahedra rounds (voxel units are exact: verify/tests/mesh_out.rs).
        let volume = tree.voxel_count() as f64 * 0.125;
        assert!(
            (mesh.signed_volume() - volume).abs() <= 1e-12 * volume,
            "{name}: volume {} for {volume}",
            mesh.signed_volume()
        );
        assert_eq!(voxelized(&out, 4, 0.5, [1.0, -2.0, 3.0]), tree, "{name}");
        if name.ends_with(".stl") {
            let bytes = std::fs::read(&out).unwrap();
            assert_eq!(bytes.len(), 84 + 50 * mesh.triangles().len());
        }
    }
}

#[test]
fn a_grid_keeps_its_voxel_size_and_origin() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("ball.binvox");
    let tree = ball();
    let meta = GridMeta {
        voxel_size: 0.25,
        origin: [5.0, 0.0, -1.0],
    };
    write_tree(
        &grid,
        &AnyTree::K3(tree.clone()),
        &WriteOptions {
            offset: [0; 3],
            meta: Some(meta),
            ..WriteOptions::default()
        },
    )
    .unwrap();
    let read = read_tree_placed(&grid, &ReadOptions::default()).unwrap();
    let m = read.meta.unwrap();
    let offset = read.placement.unwrap().offset;
    let out = dir.path().join("ball.ply");
    let (ok, _, stderr) = ktree(&["convert", grid.to_str().unwrap(), out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    // World of ktree voxel v: the grid's origin + (v − offset) · size.
    let origin = std::array::from_fn(|a| m.origin[a] - offset[a] as f64 * m.voxel_size);
    let AnyTree::K3(read_tree) = read.tree else {
        panic!("not an octree")
    };
    assert_eq!(
        voxelized(&out, read_tree.level(), m.voxel_size, origin),
        read_tree
    );
    let mesh = ktree::io::read_mesh(&out).unwrap();
    let (lo, _) = mesh.bounds().unwrap();
    assert!(lo[0] >= 5.0, "{lo:?}");
}

#[test]
fn smooth_writes_a_closed_surface_near_the_voxels_volume() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ball.ktree");
    let tree = ball();
    save(&input, AnyTree::K3(tree.clone()));
    let out = dir.path().join("smooth.ply");
    let (ok, stdout, stderr) = ktree(&[
        "convert",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--smooth",
        "--voxel-size",
        "0.5",
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("smooth"), "{stdout}");
    let mesh = ktree::io::read_mesh(&out).unwrap();
    assert_eq!(mesh.open_edges(), 0);
    let volume = tree.voxel_count() as f64 * 0.125;
    assert!(
        (mesh.signed_volume() - volume).abs() < 0.02 * volume,
        "{}",
        mesh.signed_volume()
    );
    // Not the exact boundary: the exact one holds the voxels' volume to rounding.
    assert!((mesh.signed_volume() - volume).abs() > 1e-9 * volume);
    let square = dir.path().join("q.ktree");
    save(
        &square,
        AnyTree::K2(KTree::<2>::from_dense(1, &[true; 4]).unwrap()),
    );
    let (ok, _, stderr) = ktree(&[
        "convert",
        square.to_str().unwrap(),
        dir.path().join("q.ply").to_str().unwrap(),
        "--smooth",
    ]);
    assert!(!ok && stderr.contains("q.ktree"), "{stderr}");
}

#[test]
fn a_quadtree_is_an_svg_outline_and_bad_requests_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let square = dir.path().join("q.ktree");
    save(
        &square,
        AnyTree::K2(KTree::<2>::from_dense(2, &[true; 16]).unwrap()),
    );
    let svg = dir.path().join("q.svg");
    let (ok, _, stderr) = ktree(&["convert", square.to_str().unwrap(), svg.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&svg).unwrap();
    // Counter-clockwise (y up), the four corners.
    assert!(text.contains("M0 4 L0 0 L4 0 L4 4 Z"), "{text}");
    let cube = dir.path().join("c.ktree");
    save(&cube, AnyTree::K3(ball()));
    for (out, extra, says) in [
        ("c.svg", None, "K = 3"),
        ("c.ply", Some("1,2"), "--origin"),
        ("c.ply", Some("a,b,c"), "--origin"),
    ] {
        let out = dir.path().join(out);
        let mut args = vec!["convert", cube.to_str().unwrap(), out.to_str().unwrap()];
        if let Some(o) = extra {
            args.extend(["--origin", o]);
        }
        let (ok, _, stderr) = ktree(&args);
        assert!(!ok, "{args:?}");
        assert!(stderr.contains(says), "{stderr}");
        assert!(!out.exists());
    }
    let line = dir.path().join("l.ktree");
    save(&line, AnyTree::K1(KTree::<1>::full(2).unwrap()));
    let (ok, _, stderr) = ktree(&[
        "convert",
        line.to_str().unwrap(),
        dir.path().join("l.ply").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("K = 1"), "{stderr}");
    let (ok, _, stderr) = ktree(&[
        "convert",
        dir.path().join("x.glb").to_str().unwrap(),
        dir.path().join("x.ktree").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("x.glb"), "{stderr}");
}

/// The value of `NumberOfCells` in a `.vtu`.
fn vtu_cells(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    let key = "NumberOfCells=\"";
    let at = text.find(key).unwrap() + key.len();
    text[at..at + text[at..].find('"').unwrap()]
        .parse()
        .unwrap()
}

#[test]
fn convert_writes_vtk_files_and_a_4d_time_series() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ball.ktree");
    let tree = ball();
    save(&input, AnyTree::K3(tree.clone()));
    let vtu = dir.path().join("ball.vtu");
    let htg = dir.path().join("ball.htg");
    for out in [&vtu, &htg] {
        let (ok, _, stderr) = ktree(&["convert", input.to_str().unwrap(), out.to_str().unwrap()]);
        assert!(ok, "{stderr}");
    }
    assert_eq!(vtu_cells(&vtu), tree.full_cells().count());
    let text = std::fs::read_to_string(&htg).unwrap();
    assert!(text.contains("type=\"HyperTreeGrid\""));
    assert!(text.contains(&format!(
        "NumberOfVerticesPerDepth\" NumberOfTuples=\"{}\"",
        tree.depth_count()
    )));

    let ball4 = KTree::from_rays(&ball_rays::<4>(3, [8, 8, 8, 8], 40).unwrap());
    let input4 = dir.path().join("ball4.ktree");
    save(&input4, AnyTree::K4(ball4.clone()));
    let pvd = dir.path().join("run.pvd");
    let (ok, stdout, stderr) = ktree(&[
        "convert",
        input4.to_str().unwrap(),
        pvd.to_str().unwrap(),
        "--time-axis",
        "3",
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("8 slices"), "{stdout}");
    let collection = std::fs::read_to_string(&pvd).unwrap();
    assert_eq!(collection.matches("<DataSet ").count(), 8);
    for t in 0..8u32 {
        let slice = dir.path().join(format!("run_{t:04}.vtu"));
        assert!(collection.contains(&format!("file=\"run_{t:04}.vtu\"")));
        let want = ktree::display::slices::slice_4d(&ball4, 3, t).unwrap();
        assert_eq!(vtu_cells(&slice), want.full_cells().count(), "slice {t}");
    }
    let (ok, _, stderr) = ktree(&[
        "convert",
        input4.to_str().unwrap(),
        dir.path().join("run.htg").to_str().unwrap(),
        "--time-axis",
        "0",
    ]);
    assert!(ok, "{stderr}");
    assert!(dir.path().join("run_0007.htg").exists());
    // A 4-D tree needs --time-axis for VTK; a 3-D tree cannot be sliced.
    let (ok, _, stderr) = ktree(&[
        "convert",
        input4.to_str().unwrap(),
        dir.path().join("x.vtu").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("K = 4"), "{stderr}");
    let (ok, _, stderr) = ktree(&[
        "convert",
        input.to_str().unwrap(),
        dir.path().join("y.pvd").to_str().unwrap(),
        "--time-axis",
        "3",
    ]);
    assert!(!ok && stderr.contains("K = 3"), "{stderr}");
}
