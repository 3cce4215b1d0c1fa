//! Interop: a sphere, two real meshes and the CT skull written as `.ktree`, OctoMap `.bt`, OpenVDB `.vdb` and
//! binvox; file sizes side by side, each file read back by ktree, and each checked by the real tool where it
//! is installed: OctoMap's `convert_octree` reads ktree's `.bt` and writes it again, and ktree reads that back;
//! `binvox2bt` turns ktree's binvox into a `.bt` that ktree reads back; OpenVDB's Python module (in the
//! interpreter `ktree_verify::tools::PythonOpenVdb::find` finds: `KTREE_PYTHON_OPENVDB`, else `python3` or
//! `/usr/bin/python3`) counts the active voxels of ktree's `.vdb`. Writes `results/interop.md`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use ktree::input::{read_tree, voxelize};
use ktree::io::{write_ktree_file, write_tree, ReadOptions, WriteOptions};
use ktree::rays::ball_rays;
use ktree::solid::volume::Select;
use ktree::stacking::paper::stack;
use ktree::AnyTree;
use ktree_verify::tools::{find_program, PythonOpenVdb};

const LEVEL: u32 = 8;

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(rel)
}

fn objects() -> Result<Vec<(String, AnyTree)>, String> {
    let mut out = Vec::new();
    let u = 1i64 << LEVEL;
    let ball = ball_rays::<3>(LEVEL, [u, u, u], u - 1).map_err(|e| e.to_string())?;
    out.push((format!("sphere, L = {LEVEL}"), AnyTree::K3(stack(&ball))));
    for mesh in ["bunny_npm.obj", "armadillo.obj"] {
        let options = ReadOptions {
            level: Some(LEVEL),
            ..ReadOptions::default()
        };
        let v = voxelize(&data(&format!("meshes/{mesh}")), &options).map_err(|e| e.to_string())?;
        out.push((
            format!("{mesh}, fitted, L = {LEVEL}"),
            AnyTree::K3(stack(&v.rays)),
        ));
    }
    let options = ReadOptions {
        select: Some(Select::AtLeast(29_000.0)),
        ..ReadOptions::default()
    };
    let skull = read_tree(&data("volumes/skull_grey.json"), &options).map_err(|e| e.to_string())?;
    out.push(("CT skull ≥ 29 000, 64³".to_string(), skull));
    Ok(out)
}

fn have(command: &str) -> bool {
    find_program(&[command]).is_some()
}

/// Runs a command; whether it succeeded.
fn run(command: &str, args: &[&Path]) -> bool {
    Command::new(command)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

fn same(path: &Path, tree: &AnyTree) -> bool {
    read_tree(path, &ReadOptions::default()).is_ok_and(|t| &t == tree)
}

fn vdb_active_voxels(python: &PythonOpenVdb, path: &Path) -> Option<u128> {
    let script = "import sys\nprint(vdb.read(sys.argv[1], vdb.readAllGridMetadata(sys.argv[1])[0].name).activeVoxelCount())";
    let out = python.run(script, &[path.as_os_str()]).ok()?;
    out.trim().parse().ok()
}

/// Writes the report; returns its path.
pub fn report() -> Result<String, String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    let (octomap, binvox2bt, openvdb) = (
        have("convert_octree"),
        have("binvox2bt"),
        PythonOpenVdb::find().ok(),
    );
    let mut md = String::from(
        "# Interop: the same objects in four formats\n\nRegenerate with `cargo run --release --example perf -- interop`. \
         Each object is written by `ktree::io` in every format and read back by ktree (\"read back\" = the same tree, \
         node for node); the real tools check the files where they are installed (Debian's `octomap-tools` and \
         `python3-openvdb`). `.ktree` is version 2 (2 bits a node plus per-level rank samples and checksums); \
         `.bt` is OctoMap's 2 bits a child of each inner node; `.vdb` is an uncompressed OpenVDB `BoolGrid` \
         (tiles for full 8³ and 128³ blocks); binvox is run-length coded voxels.\n\n\
         | object | voxels | nodes | .ktree bytes | .bt bytes | .vdb bytes | .binvox bytes | read back | real tools |\n\
         |---|---:|---:|---:|---:|---:|---:|---|---|\n",
    );
    for (name, tree) in objects()? {
        let AnyTree::K3(t) = &tree else {
            return Err("interop objects are octrees".into());
        };
        let paths: Vec<PathBuf> = ["o.ktree", "o.bt", "o.vdb", "o.binvox"]
            .iter()
            .map(|f| dir.path().join(f))
            .collect();
        write_ktree_file(&paths[0], t).map_err(|e| e.to_string())?;
        for p in &paths[1..] {
            write_tree(p, &tree, &WriteOptions::default()).map_err(|e| e.to_string())?;
        }
        let back = paths.iter().all(|p| same(p, &tree));
        let mut tools = Vec::new();
        if octomap {
            let again = dir.path().join("again.bt");
            let ok = run("convert_octree", &[&paths[1], &again]) && same(&again, &tree);
            tools.push(format!(
                "OctoMap convert_octree: {}",
                if ok { "same" } else { "DIFFERS" }
            ));
        }
        if binvox2bt {
            // binvox2bt writes NAME.binvox.bt beside its input.
            let bt = dir.path().join("o.binvox.bt");
            let ok = run("binvox2bt", &[&paths[3]]) && same(&bt, &tree);
            tools.push(format!(
                "binvox2bt: {}",
                if ok { "same" } else { "DIFFERS" }
            ));
        }
        if let Some(python) = &openvdb {
            let ok = vdb_active_voxels(python, &paths[2]) == Some(t.voxel_count());
            tools.push(format!(
                "pyopenvdb active voxels: {}",
                if ok { "same" } else { "DIFFER" }
            ));
        }
        if tools.is_empty() {
            tools.push("none installed".into());
        }
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} |",
            t.voxel_count(),
            t.node_count(),
            size(&paths[0]),
            size(&paths[1]),
            size(&paths[2]),
            size(&paths[3]),
            if back { "yes" } else { "NO" },
            tools.join("; ")
        );
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../results/interop.md");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok("results/interop.md".into())
}
