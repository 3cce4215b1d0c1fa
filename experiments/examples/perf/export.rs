//! Mesh export performance: the boundary of balls (L = 6, 8, 10) and of the armadillo mesh voxelized at
//! L = 8 and 10, as merged-rectangle triangle meshes, against one quad (two triangles) per voxel face.

use std::fmt::Write as _;
use std::path::Path;

use ktree::export::files::write_ply;
use ktree::export::surface::boundary_mesh;
use ktree::rays::ball_rays;
use ktree::solid::mesh::{MeshTransform, TriangleMesh};
use ktree::{KTree, Octree};

use crate::measure::{best_of, machine_line, results_path, run_child};

/// The cases: `ball-L` and `armadillo-L`.
pub const CASES: [&str; 5] = ["ball-6", "ball-8", "ball-10", "armadillo-8", "armadillo-10"];

pub fn tree_of(case: &str) -> Result<Octree, String> {
    let (what, level) = case.split_once('-').ok_or("case must be WHAT-L")?;
    let level: u32 = level.parse().map_err(|_| "bad level")?;
    match what {
        "ball" => {
            let u = 1i64 << level;
            Ok(KTree::from_rays(
                &ball_rays::<3>(level, [u, u, u], u).map_err(|e| e.to_string())?,
            ))
        }
        "armadillo" => {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/meshes/armadillo.obj");
            let mesh = TriangleMesh::read(&path).map_err(|e| e.to_string())?;
            let placement = MeshTransform::fit(&mesh, level).map_err(|e| e.to_string())?;
            let rays = mesh.to_rays(level, &placement).map_err(|e| e.to_string())?;
            Ok(KTree::from_rays(&rays.rays))
        }
        _ => Err(format!("unknown case {case}")),
    }
}

/// Runs one case in this (child) process.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let tree = tree_of(case)?;
    let mut out = None;
    let repeats = if case.ends_with("-10") { 1 } else { 3 };
    let seconds = best_of(
        repeats,
        || {
            let mesh = boundary_mesh(&tree);
            let mut bytes = Vec::new();
            write_ply(&mut bytes, &mesh).expect("in memory");
            (mesh, bytes.len())
        },
        |r| out = Some(r),
    );
    let (mesh, bytes) = out.expect("ran");
    // Each unit voxel face has area 1: the surface area in voxels is the number of unit faces.
    let area: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0
        })
        .sum();
    let chi = mesh.vertices.len() as i64 - mesh.triangles.len() as i64 / 2;
    let facts = [
        ("nodes", tree.node_count().to_string()),
        ("voxels", tree.voxel_count().to_string()),
        ("faces", (area.round() as u64).to_string()),
        ("triangles", mesh.triangles.len().to_string()),
        ("vertices", mesh.vertices.len().to_string()),
        ("bytes", bytes.to_string()),
        ("chi", chi.to_string()),
    ];
    Ok((
        seconds,
        facts.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
    ))
}

/// Measures every case in a child process and writes `results/performance/export.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Export: the boundary of an octree as a triangle mesh\n"
    );
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- export`. Objects: the voxels whose centres \
         lie in the ball of radius U/2 centred in the universe, and the armadillo (`data/meshes/`) fitted into \
         the universe and voxelized. Time: the best of 3 runs (1 at L = 10) in a fresh process per case of extracting the \
         closed mesh (`export::surface::boundary_mesh`) and writing it as binary PLY into memory, excluding \
         building the tree. One quad per face: two triangles per unit voxel face, vertices shared \
         (V = F + χ for a closed quad mesh of F faces and Euler characteristic χ), the same PLY layout \
         (12 bytes a vertex, 13 a triangle).\n\n\
         Machine: {}.\n",
        machine_line()
    );
    let _ = writeln!(
        md,
        "| case | nodes | voxels | unit faces | triangles | vertices | PLY MiB | seconds | one quad per face: triangles | PLY MiB | triangles saved |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for case in CASES {
        let m = run_child("export", case)?;
        let num = |k: &str| m.fact(k).parse::<f64>().unwrap_or(f64::NAN);
        let (faces, triangles, chi) = (num("faces"), num("triangles"), num("chi"));
        let header = 200.0;
        let quad_bytes = header + 12.0 * (faces + chi) + 13.0 * 2.0 * faces;
        let mib = |b: f64| b / (1024.0 * 1024.0);
        let _ = writeln!(
            md,
            "| {case} | {} | {} | {} | {} | {} | {:.2} | {:.3} | {} | {:.2} | {:.1}× |",
            m.fact("nodes"),
            m.fact("voxels"),
            m.fact("faces"),
            m.fact("triangles"),
            m.fact("vertices"),
            mib(num("bytes")),
            m.seconds,
            2.0 * faces,
            mib(quad_bytes),
            2.0 * faces / triangles
        );
    }
    let path = results_path("export");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
