//! Sources: the peak memory of building a `.ktree` out of core from a mesh, a volume and a ray file, with
//! the whole ray set made (or read) first, as `ktree voxelize|build … --out X.ktree` did before, against
//! the rays made (or read) slab by slab as the cells are stacked ([`MeshSource`](ktree::solid::mesh::MeshSource),
//! [`VolumeSource`](ktree::solid::volume::VolumeSource), [`RaysFileSource`](ktree::io::RaysFileSource)).

use std::fmt::Write as _;
use std::hash::Hasher;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::Instant;

use ktree::fs::write_atomic_with;
use ktree::input::{voxel_source, voxelize};
use ktree::io::{
    open_rays_file, read_rays_file, write_rays_source, AnyRaysFileSource, RaysFile, ReadOptions,
};
use ktree::rays::RaySource;
use ktree::solid::volume::Select;
use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::{default_split_depth, Builder};
use ktree::AnyRaySet;

use crate::measure::{machine_line, results_path, run_child};

/// The largest bundled mesh, at these levels (fitted with `--fit`).
const MESH: &str = "meshes/armadillo.obj";
const MESH_LEVELS: [u32; 3] = [11, 12, 13];
/// The largest bundled volume (by samples), thresholded at 1, at its fitting level and in a larger
/// universe.
const VOLUME: &str = "volumes/itk_t1_brain.json";
const VOLUME_LEVELS: [u32; 2] = [7, 10];
/// The voxel-centre sphere's ray file (as `ktree rays --out X.rays` writes it) at these levels.
const RAYS_LEVELS: [u32; 2] = [10, 11];

fn data(rel: &str) -> PathBuf {
    let experiments = Path::new(env!("CARGO_MANIFEST_DIR"));
    experiments
        .parent()
        .unwrap_or(experiments)
        .join("data")
        .join(rel)
}

fn sphere(level: u32) -> Solid<3> {
    let u = 1i64 << level;
    let c = Rational::new(u, 2).expect("non-zero denominator");
    let r = Rational::new(u - 1, 2).expect("non-zero denominator");
    Solid::Quadric(Quadric::ball([c; 3], r, Frame::Voxel).expect("a valid ball"))
}

/// The ray file of the sphere at `level`, written slab by slab into `dir`.
fn sphere_rays(dir: &Path, level: u32) -> Result<PathBuf, String> {
    let path = dir.join(format!("sphere{level}.rays"));
    let solid = sphere(level);
    let source = SolidSource::new(&solid, level, Sample::Centre).map_err(|e| e.to_string())?;
    write_atomic_with(&path, |w| {
        write_rays_source(w, &source, default_split_depth(3, level), &|_, _| {}).map(|_| ())
    })
    .map_err(|e| e.to_string())?;
    Ok(path)
}

/// Builds `source` into a temporary `.ktree` on one thread; returns the seconds since `start` (when the
/// input began to be read), with the runs stacked (where known), the peak memory at the end of the build,
/// the file's size and a hash of its bytes as facts.
fn build<S>(
    source: &S,
    runs: Option<u64>,
    start: Instant,
) -> Result<(f64, Vec<(String, String)>), String>
where
    S: RaySource<3>,
    S::Error: std::fmt::Display,
{
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let out = dir.path().join("tree.ktree");
    let budget = u64::MAX;
    let report = pool
        .install(|| Builder::new(source).to_file(&out, budget))
        .map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let peak = ktree_repro::peak_rss_bytes().unwrap_or(0);
    let mut hasher = std::hash::DefaultHasher::new();
    let mut file = std::fs::File::open(&out).map_err(|e| e.to_string())?;
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf).map_err(|e| e.to_string())?;
        if n == 0 {
            break;
        }
        hasher.write(&buf[..n]);
    }
    let mut facts = vec![
        ("build_peak_bytes".into(), peak.to_string()),
        ("file_bytes".into(), report.file_bytes.to_string()),
        ("hash".into(), format!("{:016x}", hasher.finish())),
    ];
    facts.extend(runs.map(|r| ("runs".into(), r.to_string())));
    Ok((seconds, facts))
}

fn options(input: &str, level: u32) -> ReadOptions {
    if input == "mesh" {
        ReadOptions {
            level: Some(level),
            ..ReadOptions::default()
        }
    } else {
        ReadOptions {
            level: Some(level),
            select: Some(Select::AtLeast(1.0)),
            ..ReadOptions::default()
        }
    }
}

/// Runs one case in this (child) process: `INPUT-HOW-L[-FILE]`, INPUT `mesh`, `volume` or `rays`, HOW
/// `whole` (the whole ray set first) or `slabs`.
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let parts: Vec<&str> = case.splitn(4, '-').collect();
    let (input, how) = (parts[0], parts.get(1).copied().unwrap_or(""));
    let level: u32 = parts
        .get(2)
        .and_then(|l| l.parse().ok())
        .ok_or("case must be INPUT-HOW-LEVEL[-FILE]")?;
    let start = Instant::now();
    match (input, how) {
        ("mesh" | "volume", "whole") => {
            let path = data(if input == "mesh" { MESH } else { VOLUME });
            let rays = voxelize(&path, &options(input, level))
                .map_err(|e| e.to_string())?
                .rays;
            build(&rays, Some(rays.len() as u64), start)
        }
        ("mesh" | "volume", "slabs") => {
            let path = data(if input == "mesh" { MESH } else { VOLUME });
            let v = voxel_source(&path, &options(input, level)).map_err(|e| e.to_string())?;
            build(&v.source, None, start)
        }
        ("rays", "whole") => {
            let file = Path::new(parts.get(3).ok_or("rays-whole-L-FILE")?);
            let AnyRaySet::K3(rays) = read_rays_file(file).map_err(|e| e.to_string())? else {
                return Err("expected K = 3 rays".into());
            };
            build(&rays, Some(rays.len() as u64), start)
        }
        ("rays", "slabs") => {
            let file = Path::new(parts.get(3).ok_or("rays-slabs-L-FILE")?);
            let RaysFile::Sorted(AnyRaysFileSource::K3(source)) =
                open_rays_file(file).map_err(|e| e.to_string())?
            else {
                return Err("expected a sorted file of K = 3 rays".into());
            };
            build(&source, Some(source.runs()), start)
        }
        _ => Err(format!("unknown case '{case}'")),
    }
}

fn mib(bytes: &str) -> String {
    bytes
        .parse::<f64>()
        .map_or("?".into(), |b| format!("{:.1}", b / (1024.0 * 1024.0)))
}

/// Measures every case in a child process and writes `results/performance/sources.md`.
pub fn report() -> Result<String, String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let mut cases: Vec<(String, u32, String)> = Vec::new();
    for level in MESH_LEVELS {
        cases.push((
            format!("`{MESH}`, `--fit`"),
            level,
            format!("mesh-{{}}-{level}"),
        ));
    }
    for level in VOLUME_LEVELS {
        cases.push((
            format!("`{VOLUME}`, `--threshold 1`"),
            level,
            format!("volume-{{}}-{level}"),
        ));
    }
    for level in RAYS_LEVELS {
        let file = sphere_rays(dir.path(), level)?;
        cases.push((
            "sphere ray file".into(),
            level,
            format!("rays-{{}}-{level}-{}", file.display()),
        ));
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Sources: trees built out of core from meshes, volumes and ray files\n"
    );
    let _ = writeln!(
        md,
        "Regenerate with `cargo run --release --example perf -- sources`. Each case builds a `.ktree` out of \
         core (`ktree::stacking::Builder::to_file`, cells of depth L − 6, no budget limit, one thread) in a fresh \
         process, as `ktree voxelize IN --out X.ktree` and `ktree build --rays IN --out X.ktree` do: *whole* \
         makes (or reads) the whole ray set first, as these commands did before; *slabs* makes (or reads) the \
         rays slab by slab as the cells are stacked (`MeshSource`, `VolumeSource`, `RaysFileSource`). Peak: \
         the process's high-water resident set at the end of the build (the input read included). Both write \
         the same file (checked by a hash of its bytes). Seconds: one run, end to end, from reading the input to \
         the file written. Mesh: the largest bundled one, fitted into the \
         universe; volume: the largest bundled one (128 × 128 × 62 samples), placed at the origin; ray file: \
         the voxel-centre sphere (centre U/2, radius (U − 1)/2) as `ktree rays --out X.rays` writes it.\n\nMachine: {}.\n",
        machine_line()
    );
    let _ = writeln!(
        md,
        "| input | L | runs | whole: peak MiB | whole: s | slabs: peak MiB | slabs: s | file bytes |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for (input, level, case) in &cases {
        let whole = run_child("sources", &case.replacen("{}", "whole", 1))?;
        let slabs = run_child("sources", &case.replacen("{}", "slabs", 1))?;
        if whole.fact("hash") != slabs.fact("hash") || whole.fact("hash") == "?" {
            return Err(format!("{case}: the two builds wrote different files"));
        }
        let _ = writeln!(
            md,
            "| {input} | {level} | {} | {} | {:.2} | {} | {:.2} | {} |",
            whole.fact("runs"),
            mib(whole.fact("build_peak_bytes")),
            whole.seconds,
            mib(slabs.fact("build_peak_bytes")),
            slabs.seconds,
            whole.fact("file_bytes"),
        );
    }
    let path = results_path("sources");
    ktree::fs::write_atomic(&path, md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(path.display().to_string())
}
