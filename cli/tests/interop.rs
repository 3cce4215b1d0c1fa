//! Interoperability checked against the real tools, not against our own reading of their formats: OctoMap
//! (Debian `octomap-tools`, `liboctomap-dev`, and `octomap_check.cpp` here built against it with `g++`) for
//! `.bt` and binvox, OpenVDB's Python module (Debian `python3-openvdb`) for `.vdb`, and OpenVDB's C++
//! library (`libopenvdb-dev`, `vdb_values_check.cpp` here) for `Int32Grid`s, which the Python module cannot
//! read. A test whose tool is
//! missing prints a visible `SKIPPED:` line and passes, or fails under `KTREE_REQUIRE_TOOLS=1`, which
//! `.ci/run` sets after installing them (`common::tools`).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use common::{data_dir, ktree, run_openvdb, tools};
use ktree::input::read_tree;
use ktree::io::ktree::v3::{read_valued_ktree_file, write_valued_ktree_file};
use ktree::io::{write_tree, ReadOptions, WriteOptions};
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::value::{Rgb, Value};
use ktree::AnyTree;
use ktree::{KTree, NodeState};

/// Builds `octomap_check` against the installed OctoMap into `dir`; `None` after [`tools::missing`] without
/// `g++` or OctoMap's headers.
///
/// # Panics
/// If it does not build with both there.
fn octomap_check(dir: &Path) -> Option<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop/octomap_check.cpp");
    tools::build_octomap_program(dir, &src)
}

/// The occupied (`"leaf"`) or free leaves OctoMap reads from a file: (grid index of the corner, side).
fn octomap_leaves(check: &Path, file: &Path, kind: &str) -> (u64, Vec<([i64; 3], u64)>) {
    let out = Command::new(check).arg("read").arg(file).output().unwrap();
    assert!(
        out.status.success(),
        "OctoMap could not read {}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut nodes = 0;
    let mut leaves = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w[0] == "nodes" {
            nodes = w[1].parse().unwrap();
        } else if w[0] == kind {
            let n: Vec<i64> = w[1..].iter().map(|x| x.parse().unwrap()).collect();
            leaves.push(([n[0], n[1], n[2]], n[3] as u64));
        }
    }
    (nodes, leaves)
}

/// Asserts that disjoint cubes of grid indices, shifted by `offset`, are exactly the tree's voxels.
fn assert_same_voxels(tree: &KTree<3>, cubes: &[([i64; 3], u64)], offset: [i64; 3]) {
    let mut volume = 0u128;
    for &(corner, side) in cubes {
        volume += u128::from(side).pow(3);
        for dx in 0..side as i64 {
            for dy in 0..side as i64 {
                for dz in 0..side as i64 {
                    let v = [
                        corner[0] + dx + offset[0],
                        corner[1] + dy + offset[1],
                        corner[2] + dz + offset[2],
                    ];
                    let p = v.map(|c| u32::try_from(c).expect("inside the universe"));
                    assert!(tree.contains(p), "voxel {p:?} occupied in OctoMap only");
                }
            }
        }
    }
    assert_eq!(volume, tree.voxel_count(), "voxel counts differ");
}

fn objects() -> Vec<(&'static str, KTree<3>)> {
    let bunny = read_tree(
        &data_dir().join("meshes/bunny_npm.obj"),
        &ReadOptions {
            level: Some(5),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    let AnyTree::K3(bunny) = bunny else {
        unreachable!()
    };
    vec![
        ("ball", stack(&ball_rays::<3>(6, [30, 33, 29], 21).unwrap())),
        ("bunny", bunny),
        ("full", KTree::full(3).unwrap()),
        ("empty", KTree::empty(4).unwrap()),
    ]
}

#[test]
fn a_bt_written_by_ktree_opens_in_octomap_with_the_same_occupied_voxels() {
    let dir = tempfile::tempdir().unwrap();
    let Some(check) = octomap_check(dir.path()) else {
        return;
    };
    for (name, tree) in objects() {
        // The last offset is not a multiple of the universe's side: the universe is written as the
        // smallest one on OctoMap's keys around it.
        for offset in [[0, 0, 0], [64, -128, 0], [3, -5, 1]] {
            let path = dir.path().join(format!("{name}.bt"));
            let options = WriteOptions {
                offset,
                ..WriteOptions::default()
            };
            write_tree(&path, &AnyTree::K3(tree.clone()), &options).unwrap();
            let (nodes, occupied) = octomap_leaves(&check, &path, "leaf");
            // OctoMap's grid index + offset = ktree voxel.
            assert_same_voxels(&tree, &occupied, offset);
            // The nodes OctoMap counts: the tree's, plus one per level above the universe.
            if offset.iter().all(|o| o % (1 << tree.level()) == 0) {
                let above = 16 - u64::from(tree.level());
                assert_eq!(nodes, tree.node_count() + above, "{name}");
            }
        }
    }
}

#[test]
fn a_bt_written_by_octomap_reads_into_ktree_with_the_same_voxels() {
    let dir = tempfile::tempdir().unwrap();
    let Some(check) = octomap_check(dir.path()) else {
        return;
    };
    for (name, tree) in objects() {
        // Occupied voxels at grid index = voxel − 5 (negative indices included), free ones where the
        // universe is empty, written by OctoMap itself.
        let mut input = String::new();
        let side = 1u32 << tree.level();
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    let free = if tree.contains([x, y, z]) {
                        ""
                    } else {
                        "free "
                    };
                    input += &format!("{free}{} {} {}\n", x as i64 - 5, y as i64 - 5, z as i64 - 5);
                }
            }
        }
        let path = dir.path().join(format!("{name}_octomap.bt"));
        let mut child = Command::new(&check)
            .arg("write")
            .arg(&path)
            .arg("0.25")
            .stdin(Stdio::piped())
            .spawn()
            .unwrap();
        use std::io::Write;
        child
            .stdin
            .take()
            .unwrap()
            .write_all(input.as_bytes())
            .unwrap();
        assert!(child.wait().unwrap().success());
        // At the offset written with, the same tree.
        let options = ReadOptions {
            level: Some(tree.level()),
            offset: Some([5, 5, 5]),
            ..ReadOptions::default()
        };
        let read = read_tree(&path, &options).unwrap();
        assert_eq!(read, AnyTree::K3(tree.clone()), "{name}");
        // The default placement moves the negative indices to at least 0, by a multiple of the side of
        // OctoMap's largest pruned node (so it stays one node): the same voxels, shifted.
        let bytes = std::fs::read(&path).unwrap();
        let placed = ktree::io::read_bt(&bytes, "octomap.bt", None, None, false).unwrap();
        let [o, oy, oz] = placed.placement.offset;
        assert!(
            o >= 5 && [oy, oz] == [o, o],
            "{name}: {:?}",
            placed.placement
        );
        let shift = (o - 5) as u32;
        assert_eq!(placed.tree.voxel_count(), tree.voxel_count(), "{name}");
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    if tree.contains([x, y, z]) {
                        assert!(
                            placed.tree.contains([x + shift, y + shift, z + shift]),
                            "{name}"
                        );
                    }
                }
            }
        }
        // Unknown space read as full: the universe of the next level has the rest filled.
        let options = ReadOptions {
            level: Some(tree.level() + 1),
            offset: Some([5, 5, 5]),
            unknown_full: true,
            ..ReadOptions::default()
        };
        let AnyTree::K3(wide) = read_tree(&path, &options).unwrap() else {
            unreachable!()
        };
        let outside = (1u128 << (3 * (tree.level() + 1))) - (1u128 << (3 * tree.level()));
        assert_eq!(wide.voxel_count(), tree.voxel_count() + outside, "{name}");
    }
}

#[test]
fn a_binvox_written_by_ktree_reads_in_binvox2bt_and_comes_back() {
    let dir = tempfile::tempdir().unwrap();
    let Some(binvox2bt) = tools::require(&["binvox2bt"], "install Debian's octomap-tools") else {
        return;
    };
    for (name, tree) in objects() {
        if tree.root_state() == NodeState::Empty {
            continue; // binvox2bt writes no file for an empty grid
        }
        let vox = dir.path().join(format!("{name}.binvox"));
        let bt = dir.path().join(format!("{name}_binvox2bt.bt"));
        write_tree(&vox, &AnyTree::K3(tree.clone()), &WriteOptions::default()).unwrap();
        let out = Command::new(&binvox2bt)
            .arg("-o")
            .arg(&bt)
            .arg(&vox)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        // binvox2bt marks only the occupied voxels (the rest stays unknown): give the universe.
        let options = ReadOptions {
            level: Some(tree.level()),
            offset: Some([0; 3]),
            ..ReadOptions::default()
        };
        assert_eq!(
            read_tree(&bt, &options).unwrap(),
            AnyTree::K3(tree.clone()),
            "{name}"
        );
    }
}

#[test]
fn convert_goes_through_every_format_and_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let (ok, _, err) = ktree(&[
        "convert",
        data_dir().join("meshes/fandisk.obj").to_str().unwrap(),
        &d("fandisk.ktree"),
        "--level",
        "5",
    ]);
    assert!(ok, "{err}");
    let mut previous = d("fandisk.ktree");
    for ext in ["rays", "binvox", "bt", "vdb", "ktree"] {
        let next = d(&format!("step.{ext}"));
        let (ok, _, err) = ktree(&["convert", &previous, &next]);
        assert!(ok, "{ext}: {err}");
        previous = next;
    }
    assert_eq!(
        std::fs::read(d("fandisk.ktree")).unwrap(),
        std::fs::read(d("step.ktree")).unwrap()
    );
    // Errors name the file.
    let (ok, _, err) = ktree(&["convert", &d("fandisk.ktree"), &d("out.txt")]);
    assert!(
        !ok && err.contains("out.txt") && err.contains("unknown extension"),
        "{err}"
    );
    std::fs::write(d("bad.binvox"), "#binvox 1\ndim 4 4 4\ndata\n\u{1}").unwrap();
    let (ok, _, err) = ktree(&["convert", &d("bad.binvox"), &d("out.ktree")]);
    assert!(!ok && err.contains("bad.binvox: byte"), "{err}");
}

#[test]
fn a_vdb_written_by_ktree_opens_in_openvdb_with_the_same_voxels_and_box() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for (name, tree) in objects() {
        for offset in [[0, 0, 0], [20, -7, 3]] {
            let path = dir.path().join(format!("{name}.vdb"));
            let options = WriteOptions {
                offset,
                ..WriteOptions::default()
            };
            write_tree(&path, &AnyTree::K3(tree.clone()), &options).unwrap();
            let script = format!(
                "g = vdb.read({:?}, 'ktree')\nprint(type(g).__name__, g.activeVoxelCount(), \
                 *g.evalActiveVoxelBoundingBox()[0], *g.evalActiveVoxelBoundingBox()[1])",
                path.display().to_string()
            );
            let out = run_openvdb(&python, &script);
            let w: Vec<&str> = out.split_whitespace().collect();
            assert_eq!(w[0], "BoolGrid");
            assert_eq!(w[1], tree.voxel_count().to_string(), "{name}");
            if tree.voxel_count() > 0 {
                // The box of the full voxels, in OpenVDB's indices (voxel − offset).
                let mut lo = [u32::MAX; 3];
                let mut hi = [0u32; 3];
                tree.for_each_leaf(|c, s| {
                    if s == NodeState::Full {
                        for a in 0..3 {
                            lo[a] = lo[a].min(c.origin()[a]);
                            hi[a] = hi[a].max(c.origin()[a] + c.side() as u32 - 1);
                        }
                    }
                });
                let expect: Vec<String> = lo
                    .iter()
                    .chain(hi.iter())
                    .enumerate()
                    .map(|(i, &v)| (i64::from(v) - offset[i % 3]).to_string())
                    .collect();
                assert_eq!(w[2..8], expect[..], "{name}");
            }
        }
    }
}

#[test]
fn a_vdb_written_by_openvdb_reads_into_ktree_with_the_same_voxels() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for (name, tree) in objects() {
        // The full voxels at OpenVDB index = voxel − 9 (negative indices included), written by pyopenvdb
        // with its default compression.
        let mut voxels = String::new();
        let side = 1u32 << tree.level();
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    if tree.contains([x, y, z]) {
                        voxels += &format!("({},{},{}),", x as i64 - 9, y as i64 - 9, z as i64 - 9);
                    }
                }
            }
        }
        let path = dir.path().join(format!("{name}_openvdb.vdb"));
        let script = format!(
            "g = vdb.BoolGrid()\ng.name = 'g'\na = g.getAccessor()\nfor p in [{voxels}]:\n    \
             a.setValueOn(p, True)\ng.prune()\nvdb.write({:?}, grids=[g])\nprint(g.activeVoxelCount())",
            path.display().to_string()
        );
        let out = run_openvdb(&python, &script);
        assert_eq!(out.trim(), tree.voxel_count().to_string());
        let options = ReadOptions {
            level: Some(tree.level()),
            offset: Some([9; 3]),
            ..ReadOptions::default()
        };
        assert_eq!(
            read_tree(&path, &options).unwrap(),
            AnyTree::K3(tree.clone()),
            "{name}"
        );
    }
}

#[test]
fn a_vdb_with_tiles_at_negative_indices_reads_by_default_with_its_tiles_aligned() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    // A 128³ tile of an internal node at x = −128 and one voxel at x = −131, as OpenVDB writes them.
    let path = dir.path().join("tiles.vdb");
    let script = format!(
        "g = vdb.BoolGrid()\ng.name = 'g'\ng.fill((-128, 0, 0), (-1, 127, 127), True, True)\n\
         g.getAccessor().setValueOn((-131, 0, 0), True)\nvdb.write({:?}, grids=[g])\n\
         print(g.activeVoxelCount(), g.leafCount())",
        path.display().to_string()
    );
    let out = run_openvdb(&python, &script);
    assert_eq!(
        out.trim(),
        format!("{} 1", (1u64 << 21) + 1),
        "one tile, one leaf"
    );
    // The default offset is the smallest multiple of the tile's side that makes every index ≥ 0 (256, not
    // 131): the tile is one node, not a cube cut into nodes along its faces.
    let placed =
        ktree::io::read_vdb(&std::fs::read(&path).unwrap(), "tiles.vdb", None, None).unwrap();
    assert_eq!(placed.placement.offset, [256, 0, 0]);
    let tree = placed.tree;
    assert_eq!(tree.voxel_count(), (1 << 21) + 1);
    for (voxel, inside) in [
        ([128, 0, 0], true),
        ([255, 127, 127], true),
        ([125, 0, 0], true),
        ([127, 0, 0], false),
        ([256, 0, 0], false),
        ([128, 128, 0], false),
    ] {
        assert_eq!(tree.contains(voxel), inside, "{voxel:?}");
    }
    let shifted = ktree::io::read_vdb(
        &std::fs::read(&path).unwrap(),
        "tiles.vdb",
        Some([131, 0, 0]),
        None,
    )
    .unwrap()
    .tree;
    assert_eq!(shifted.voxel_count(), tree.voxel_count());
    assert!(
        tree.node_count() * 100 < shifted.node_count(),
        "{} nodes aligned, {} at offset 131",
        tree.node_count(),
        shifted.node_count()
    );
}

/// Valued octrees of the value types OpenVDB's Python module holds as grids (`FloatGrid`, `Vec3SGrid`),
/// in a level-4 universe: an 8³ block of one value (a tile of a 16³ node) and single voxels of other values,
/// none 0 (OpenVDB's `copyFromArray` leaves the background's voxels inactive).
fn valued_objects() -> (KTree<3, f32>, KTree<3, Rgb>) {
    let mut floats = vec![None; 4096];
    let mut colours = vec![None; 4096];
    for x in 0..16 {
        for y in 0..16 {
            for z in 0..16 {
                let i = x + 16 * (y + 16 * z);
                if x >= 8 && y >= 8 && z >= 8 {
                    floats[i] = Some(2.5);
                    colours[i] = Some([200, 10, 3]);
                } else if (x * 7 + y * 3 + z) % 5 == 0 {
                    floats[i] = Some(x as f32 * 0.25 - y as f32 - 0.375);
                    colours[i] = Some([x as u8 * 16, y as u8 * 16 + 1, 255]);
                }
            }
        }
    }
    (
        KTree::from_dense_values(4, &floats).unwrap(),
        KTree::from_dense_values(4, &colours).unwrap(),
    )
}

/// A valued tree's voxels and their values as text (`x y z value`, colours `r,g,b`), sorted.
fn voxel_values<V: Value>(tree: &KTree<3, V>) -> Vec<String> {
    let mut out = Vec::new();
    let dense = tree.to_dense_values().unwrap();
    for (i, v) in dense.iter().enumerate() {
        if let Some(v) = v {
            out.push(format!(
                "{} {} {} {}",
                i % 16,
                i / 16 % 16,
                i / 256,
                v.text()
            ));
        }
    }
    out.sort();
    out
}

/// Writes `tree` with `ktree convert` as a `.vdb` and has OpenVDB list every active value (tiles spread
/// into their voxels): they must be the tree's voxels and values, and a tile must be among them.
fn check_typed_grid_in_openvdb<V: Value>(
    python: &tools::PythonOpenVdb,
    dir: &Path,
    tree: &KTree<3, V>,
    grid: &str,
) {
    let name = V::DTYPE.unwrap().name();
    let input = dir.join(format!("{name}.ktree"));
    let output = dir.join(format!("{name}.vdb"));
    write_valued_ktree_file(&input, tree).unwrap();
    let (ok, _, err) = ktree(&["convert", input.to_str().unwrap(), output.to_str().unwrap()]);
    assert!(ok, "{err}");
    let script = format!(
        "g = vdb.read({:?}, 'ktree')\nprint(type(g).__name__, g.gridClass, g.activeVoxelCount())\n\
         for t in g.iterOnValues():\n    v = t['value']\n    v = ','.join(str(round(c)) for c in v) \
         if isinstance(v, tuple) else '%g' % v\n    (x0, y0, z0), (x1, y1, z1) = t['min'], t['max']\n    \
         for x in range(x0, x1 + 1):\n        for y in range(y0, y1 + 1):\n            \
         for z in range(z0, z1 + 1):\n                print(x, y, z, v, int(t['count'] > 1))",
        output.display().to_string()
    );
    let out = run_openvdb(python, &script);
    let mut lines = out.lines();
    let head: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
    assert_eq!(head[0], grid, "{out}");
    assert_ne!(head[1], "GRID_LEVEL_SET");
    assert_eq!(head[2], tree.voxel_count().to_string());
    let mut seen = Vec::new();
    let mut tiles = 0;
    for line in lines {
        let (voxel, tile) = line.rsplit_once(' ').unwrap();
        tiles += usize::from(tile == "1");
        seen.push(voxel.to_string());
    }
    seen.sort();
    assert_eq!(seen, voxel_values(tree), "{name}");
    assert_eq!(tiles, 512, "{name}: the 8³ block is one tile");
}

#[test]
fn valued_trees_written_as_typed_vdb_grids_open_in_openvdb_with_every_value() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (floats, colours) = valued_objects();
    check_typed_grid_in_openvdb(&python, dir.path(), &floats, "FloatGrid");
    check_typed_grid_in_openvdb(&python, dir.path(), &colours, "Vec3SGrid");
}

#[test]
fn typed_grids_written_by_openvdb_convert_to_valued_ktree_files_value_for_value() {
    let Some(python) = tools::require_python_openvdb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (floats, colours) = valued_objects();
    // The dense arrays (x slowest, as numpy's C order and OpenVDB's x, y, z) copied into grids at index
    // −8, pruned into tiles, written with OpenVDB's default compression.
    let arrays = |values: Vec<String>| {
        values
            .into_iter()
            .map(|l| {
                let w: Vec<&str> = l.split(' ').collect();
                format!("a[{}, {}, {}] = ({})", w[0], w[1], w[2], w[3])
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    for (name, grid, shape, set, want) in [
        (
            "float32",
            "FloatGrid",
            "(16, 16, 16)",
            arrays(voxel_values(&floats)),
            voxel_values(&floats),
        ),
        (
            "rgb8",
            "Vec3SGrid",
            "(16, 16, 16, 3)",
            arrays(voxel_values(&colours)),
            voxel_values(&colours),
        ),
    ] {
        let path = dir.path().join(format!("{name}_openvdb.vdb"));
        let script = format!(
            "import numpy as np\na = np.zeros({shape}, dtype=np.float32)\n{set}\ng = vdb.{grid}()\n\
             g.name = 'g'\ng.copyFromArray(a, ijk=(-8, -8, -8))\ng.prune(g.zeroValue)\nvdb.write({:?}, grids=[g])\n\
             print(g.activeVoxelCount(), sum(t['count'] > 1 for t in g.iterOnValues()))",
            path.display().to_string()
        );
        let out = run_openvdb(&python, &script);
        let counts: Vec<&str> = out.split_whitespace().collect();
        assert_eq!(counts[0], want.len().to_string(), "{name}");
        assert_eq!(counts[1], "1", "{name}: the 8³ block is one tile");
        let output = dir.path().join(format!("{name}.ktree"));
        let (ok, _, err) = ktree(&[
            "convert",
            path.to_str().unwrap(),
            output.to_str().unwrap(),
            "--offset",
            "8,8,8",
            "--level",
            "4",
        ]);
        assert!(ok, "{err}");
        let got = match name {
            "float32" => voxel_values(&read_valued_ktree_file::<3, f32>(&output).unwrap()),
            _ => voxel_values(&read_valued_ktree_file::<3, Rgb>(&output).unwrap()),
        };
        assert_eq!(got, want, "{name}");
        // The command-line statistics read the grid's shape.
        let (ok, out, err) = ktree(&["stats", path.to_str().unwrap()]);
        assert!(ok && out.contains(&want.len().to_string()), "{out}{err}");
    }
}

/// Labels over 16³: an 8³ block of one label (a whole OpenVDB leaf node) and scattered labels from `label`.
fn label_object<V: Value>(label: impl Fn(usize, usize, usize) -> V) -> KTree<3, V> {
    let mut dense = vec![None; 4096];
    for (i, v) in dense.iter_mut().enumerate() {
        let (x, y, z) = (i % 16, i / 16 % 16, i / 256);
        if x >= 8 && y >= 8 && z >= 8 {
            *v = Some(label(1, 1, 1));
        } else if (x * 5 + y * 3 + z) % 7 == 0 {
            *v = Some(label(x, y, z));
        }
    }
    KTree::from_dense_values(4, &dense).unwrap()
}

/// `Int32Grid`s both ways, checked by OpenVDB's C++ library (`tests/interop/vdb_values_check.cpp`): labels
/// written by `ktree convert` list in OpenVDB as the tree's voxels and values, the block as a tile; labels
/// written and pruned by OpenVDB convert to the same tree.
fn check_int32_grids_both_ways<V: Value>(check: &Path, dir: &Path, labels: &KTree<3, V>) {
    let name = V::DTYPE.unwrap().name();
    let want = voxel_values(labels);
    let input = dir.join(format!("{name}.ktree"));
    let output = dir.join(format!("{name}.vdb"));
    write_valued_ktree_file(&input, labels).unwrap();
    let (ok, _, err) = ktree(&["convert", input.to_str().unwrap(), output.to_str().unwrap()]);
    assert!(ok, "{err}");
    let listed = Command::new(check).arg(&output).output().unwrap();
    let text = String::from_utf8(listed.stdout).unwrap();
    assert!(
        listed.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&listed.stderr)
    );
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
    assert_eq!(head[1], "Tree_int32_5_4_3", "{text}");
    assert_eq!(head[5], labels.voxel_count().to_string());
    let (mut got, mut tiles) = (Vec::new(), 0);
    for line in lines {
        let (voxel, tile) = line.rsplit_once(' ').unwrap();
        tiles += usize::from(tile == "1");
        got.push(voxel.to_string());
    }
    got.sort();
    assert_eq!(got, want, "{name}: OpenVDB's voxels and values");
    assert_eq!(tiles, 512, "{name}: the 8³ block is one tile");

    // OpenVDB writes the labels at grid index − 8; ktree reads them back at + 8.
    let voxels = dir.join(format!("{name}_voxels.txt"));
    let shifted: Vec<String> = want
        .iter()
        .map(|l| {
            let w: Vec<i64> = l.split(' ').map(|n| n.parse().unwrap()).collect();
            format!("{} {} {} {}", w[0] - 8, w[1] - 8, w[2] - 8, w[3])
        })
        .collect();
    std::fs::write(&voxels, shifted.join("\n")).unwrap();
    let by_openvdb = dir.join(format!("{name}_openvdb.vdb"));
    let written = Command::new(check)
        .arg("--write")
        .args([&voxels, &by_openvdb])
        .output()
        .unwrap();
    assert!(
        written.status.success(),
        "{}",
        String::from_utf8_lossy(&written.stderr)
    );
    let report = String::from_utf8(written.stdout).unwrap();
    assert_eq!(report.trim(), format!("active {} tiles 1", want.len()));
    let back = dir.join(format!("{name}_back.ktree"));
    let (ok, _, err) = ktree(&[
        "convert",
        by_openvdb.to_str().unwrap(),
        back.to_str().unwrap(),
        "--offset",
        "8,8,8",
        "--level",
        "4",
    ]);
    assert!(ok, "{err}");
    let read = read_valued_ktree_file::<3, V>(&back).unwrap();
    assert_eq!(&read, labels, "{name}: OpenVDB's grid read back");
}

#[test]
fn int32_grids_go_both_ways_between_ktree_and_openvdb_label_for_label() {
    let dir = tempfile::tempdir().unwrap();
    let source =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/interop/vdb_values_check.cpp");
    let Some(check) = tools::build_openvdb_program(dir.path(), &source) else {
        return;
    };
    let wide = |x: usize, y: usize, z: usize| (70_000 + x * 1000 + y * 10 + z) as u32;
    check_int32_grids_both_ways(
        &check,
        dir.path(),
        &label_object(|x, y, z| (x + y + z) as u8),
    );
    check_int32_grids_both_ways(
        &check,
        dir.path(),
        &label_object(|x, y, _| (300 + x * 16 + y) as u16),
    );
    check_int32_grids_both_ways(&check, dir.path(), &label_object(wide));
    check_int32_grids_both_ways(
        &check,
        dir.path(),
        &label_object(|x, y, z| x as i8 - y as i8 - z as i8),
    );
}
