//! Mesh export performance: the boundary of balls (L = 6, 8, 10) and of the armadillo mesh voxelized at
//! L = 8 and 10, as merged-rectangle triangle meshes. The children this program runs are timed against
//! OpenVDB's `volumeToMesh` by `experiments/export.sh`, which writes `results/performance/export.md`.

use std::path::Path;

use ktree::export::files::write_ply;
use ktree::export::surface::boundary_mesh;
use ktree::rays::ball_rays;
use ktree::solid::mesh::MeshTransform;
use ktree::{KTree, Octree};

use crate::measure::best_of;

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
            let mesh = ktree::io::read_mesh(&path).map_err(|e| e.to_string())?;
            let placement = MeshTransform::fit(&mesh, level).map_err(|e| e.to_string())?;
            let rays = mesh.to_rays(level, &placement).map_err(|e| e.to_string())?;
            Ok(KTree::from_rays(&rays.rays))
        }
        _ => Err(format!("unknown case {case}")),
    }
}

/// Runs one case in this (child) process: `OBJECT` (`ball-L`, `armadillo-L`) times the export;
/// `OBJECT:write-vdb:PATH` writes the object's voxels as an OpenVDB `BoolGrid` (as `ktree convert X.ktree
/// X.vdb` does) for the peer of `experiments/export.sh`.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    if let Some((object, path)) = case.split_once(":write-vdb:") {
        let tree = tree_of(object)?;
        tree.save(Path::new(path))
            .map_err(|e| format!("cannot write {path}: {e}"))?;
        return Ok((0.0, vec![("voxels".into(), tree.voxel_count().to_string())]));
    }
    let tree = tree_of(case)?;
    let mut out = None;
    let repeats = if case.ends_with("-10") { 1 } else { 3 };
    let seconds = best_of(repeats, || boundary_mesh(&tree), |m| out = Some(m));
    let mesh = out.expect("ran");
    let start = std::time::Instant::now();
    let mut bytes = Vec::new();
    write_ply(&mut bytes, &mesh).expect("in memory");
    let ply_seconds = start.elapsed().as_secs_f64();
    let bytes = bytes.len();
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
        ("ply_seconds", ply_seconds.to_string()),
        ("chi", chi.to_string()),
    ];
    Ok((
        seconds,
        facts.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
    ))
}

/// `results/performance/export.md` compares ktree with OpenVDB and is written by `experiments/export.sh`
/// (which runs this program's children, `--child export CASE`).
pub fn report() -> Result<String, String> {
    Err(
        "results/performance/export.md is written by experiments/export.sh (it needs OpenVDB)"
            .into(),
    )
}
