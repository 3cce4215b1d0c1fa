//! Solids to rays: quadric balls, meshes (bunny, armadillo), a CT volume and Boolean operations at L = 10,
//! and end to end (solid → rays → tree).

use std::fmt::Write as _;
use std::path::PathBuf;

use ktree::rays::ball_rays;
use ktree::solid::mesh::{MeshTransform, TriangleMesh};
use ktree::solid::volume::{Select, Volume};
use ktree::solid::{Frame, Quadric, Rational, Sample};
use ktree::stacking::paper::stack;
use ktree::RaySet;

use crate::measure::{best_of, machine_line, results_path, run_child};

const LEVEL: u32 = 10;

fn data(rel: &str) -> Result<PathBuf, String> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(rel);
    if p.exists() {
        Ok(p)
    } else {
        Err(format!("test data {} not found", p.display()))
    }
}

fn ball(level: u32) -> Quadric<3> {
    let h = Rational::int(1 << (level - 1));
    Quadric::ball([h, h, h], h, Frame::Voxel).expect("valid ball")
}

fn mesh_rays(name: &str) -> Result<(TriangleMesh, MeshTransform), String> {
    let mesh =
        ktree::io::read_mesh(&data(&format!("meshes/{name}"))?).map_err(|e| e.to_string())?;
    let p = MeshTransform::fit(&mesh, LEVEL).map_err(|e| e.to_string())?;
    Ok((mesh, p))
}

type Facts = Vec<(String, String)>;

fn facts_of(rays: &RaySet<3>) -> Facts {
    vec![
        ("rays".into(), rays.len().to_string()),
        ("voxels".into(), rays.voxel_count().to_string()),
    ]
}

/// Runs one case in this (child) process.
pub fn run_case(case: &str) -> Result<(f64, Facts), String> {
    let mut facts = Vec::new();
    let mut keep = |r: RaySet<3>| facts = facts_of(&r);
    let seconds = match case {
        "quadric-ball" => best_of(
            5,
            || {
                ball(LEVEL)
                    .to_rays(LEVEL, Sample::Centre, false)
                    .expect("ok")
            },
            &mut keep,
        ),
        "quadric-ball-normals" => best_of(
            5,
            || {
                ball(LEVEL)
                    .to_rays(LEVEL, Sample::Centre, true)
                    .expect("ok")
            },
            &mut keep,
        ),
        "direct-ball" => {
            let u = 1i64 << LEVEL;
            best_of(
                5,
                || ball_rays::<3>(LEVEL, [u, u, u], u).expect("ok"),
                &mut keep,
            )
        }
        "bunny" | "armadillo" => {
            let file = if case == "bunny" {
                "bunny_npm.obj"
            } else {
                "armadillo.obj"
            };
            let (mesh, p) = mesh_rays(file)?;
            let s = best_of(3, || mesh.to_rays(LEVEL, &p).expect("ok").rays, &mut keep);
            facts.push(("triangles".into(), mesh.triangles().len().to_string()));
            s
        }
        "skull" => {
            let v = Volume::read(&data("volumes/skull_grey.json")?).map_err(|e| e.to_string())?;
            best_of(
                5,
                || v.to_rays(6, [0; 3], Select::AtLeast(29_000.0)).expect("ok"),
                &mut keep,
            )
        }
        "csg" => {
            // A box minus a cylinder along x, both at L = 10.
            let u = 1i64 << LEVEL;
            let q = |x: i64| Rational::int(x);
            let b =
                ktree::solid::BoxSolid::<3>::new([q(u / 8); 3], [q(7 * u / 8); 3], Frame::Voxel)
                    .expect("box")
                    .to_rays(LEVEL, Sample::Centre, false)
                    .expect("ok");
            let c = Quadric::<3>::cylinder(0, [q(0), q(u / 2), q(u / 2)], q(u / 4), Frame::Voxel)
                .expect("cylinder")
                .to_rays(LEVEL, Sample::Centre, false)
                .expect("ok");
            best_of(5, || b.difference(&c).expect("same level"), &mut keep)
        }
        "e2e-ball" | "e2e-bunny" => {
            let mut nodes = 0;
            let s = if case == "e2e-ball" {
                best_of(
                    3,
                    || {
                        stack(
                            &ball(LEVEL)
                                .to_rays(LEVEL, Sample::Centre, false)
                                .expect("ok"),
                        )
                    },
                    |t| nodes = t.node_count(),
                )
            } else {
                let (mesh, p) = mesh_rays("bunny_npm.obj")?;
                best_of(
                    3,
                    || stack(&mesh.to_rays(LEVEL, &p).expect("ok").rays),
                    |t| nodes = t.node_count(),
                )
            };
            facts.push(("nodes".into(), nodes.to_string()));
            s
        }
        _ => return Err(format!("unknown case {case}")),
    };
    Ok((seconds, facts))
}

/// The cases: name and what it measures.
pub const CASES: [(&str, &str); 9] = [
    (
        "quadric-ball",
        "ball of radius U/2 centred, quadric → rays (exact, centre test)",
    ),
    (
        "quadric-ball-normals",
        "same, with unit normals at run ends",
    ),
    (
        "direct-ball",
        "same ball by the core's direct generator `rays::ball_rays`",
    ),
    ("bunny", "Stanford bunny (npm) mesh → rays"),
    ("armadillo", "armadillo mesh (52 000 triangles) → rays"),
    ("skull", "CT skull 64³ volume ≥ 29 000 → rays (L = 6)"),
    ("csg", "box minus cylinder, difference of two ray sets"),
    ("e2e-ball", "ball: quadric → rays → tree (stacking)"),
    ("e2e-bunny", "bunny: mesh → rays → tree (stacking)"),
];

/// Measures every case in a child process and writes `results/performance/solids.md`.
pub fn report() -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(md, "# Solids to rays and trees (L = {LEVEL})\n");
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- solids`. Best of 3–5 runs in a fresh process \
         per case; peak memory is that process's high-water resident set (including the input). Meshes are \
         placed with `--fit` (uniform scale into the universe with a one-voxel margin); reading the file is \
         not timed.\n\nMachine: {}.\n",
        machine_line()
    );
    let _ = writeln!(md, "| case | what | seconds | rays | voxels | triangles | nodes | peak MiB |\n|---|---|---:|---:|---:|---:|---:|---:|");

    for (case, what) in CASES {
        let m = run_child("solids", case)?;
        let _ = writeln!(
            md,
            "| {case} | {what} | {:.4} | {} | {} | {} | {} | {:.1} |",
            m.seconds,
            m.fact("rays"),
            m.fact("voxels"),
            m.fact("triangles"),
            m.fact("nodes"),
            m.peak_bytes as f64 / 1048576.0
        );
    }
    let _ = writeln!(
        md,
        "\nThe target: the ball's quadric → rays well under 0.1 s; the bunny and a 50 000-triangle mesh \
         → rays under a second each; end to end faster than OpenVDB builds the same sphere (measured side \
         by side in `results/performance/openvdb.md`). `?` marks facts a case does not report."
    );
    let path = results_path("solids");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
