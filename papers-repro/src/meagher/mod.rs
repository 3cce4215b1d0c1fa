//! Reproduction of Meagher 1982, "Geometric modeling using octree encoding" (claims M1–M14 of
//! `../shared/papers/README.md`), writing `results/meagher/`: the milling scene (M12), five objects of
//! about 1 200 nodes (M11), nodes against surface area (M1), time against nodes, a CT object (M13), the
//! complexity metric (M9), progressive mass (M10), space-time interference (M14) and checks of M2–M8.
//! Run with `ktree repro meagher`.

mod ct;
pub(crate) mod plot;
mod scene;
mod solids;
mod studies;
mod views;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use ktree::fs::write_atomic;

/// Largest sphere level of the timing study.
pub const TIMING_MAX_LEVEL: u32 = 9;

/// The output directory.
pub(crate) struct Out {
    dir: PathBuf,
}

impl Out {
    pub(crate) fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    pub(crate) fn write(&self, name: &str, text: &str) -> Result<(), String> {
        write_atomic(&self.path(name), text.as_bytes()).map_err(|e| e.to_string())
    }
}

/// Runs every part, writes `results/meagher/README.md` and the CSVs and plots; returns a short report.
///
/// # Errors
/// A message naming the part that failed (a failed internal check is a failure, not a footnote).
pub fn run(results: &Path) -> Result<String, String> {
    let start = Instant::now();
    let out = Out {
        dir: results.join("meagher"),
    };
    std::fs::create_dir_all(&out.dir).map_err(|e| format!("{}: {e}", out.dir.display()))?;
    let skull = ct::skull()?;
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Meagher 1982 — Geometric modeling using octree encoding\n\nRegenerate with `cargo run --release -- \
         repro meagher` (writes this directory). Every number below is computed by that command; the paper's \
         figures are quoted beside ours. Operations: `ktree::ops` (Booleans, translation, scaling, rotations by \
         reordering, affine maps by overlays, interference, mass, complexity). Performance figures on large \
         trees: `results/performance/ops.md`.\n\n| claim | where | status |\n|---|---|---|\n\
         | M1 nodes ∝ surface area | (c) | reproduced: linear fits, r² ≈ 1 |\n\
         | M2 linear, regularized Booleans | (d), checks | reproduced |\n\
         | M3 translation by overlays | checks, (d) | reproduced |\n\
         | M4 scaling through the root; other factors by overlays | checks; `ops::scale` | reproduced |\n\
         | M5 rotations/reflections by reordering; arbitrary angles by overlays | checks, (d) | reproduced (all 48 in 3-D; K!·2^K in any K) |\n\
         | M6 concatenated matrices in one pass; perspective by deformation | checks | reproduced |\n\
         | M7 hidden-surface display | (f) | reproduced: top, front, side, isometric and perspective views of the milling scene, and a line drawing |\n\
         | M8 no floating point | checks | reproduced: arbitrary rotations too, in fixed point (`ops::transform_fixed`); `f64` versions kept beside |\n\
         | M9 complexity metric | complexity | reproduced |\n\
         | M10 progressive mass | progressive mass | reproduced |\n\
         | M11 five objects of ≈ 1 200 nodes | (b) | reproduced with tuned sizes |\n\
         | M12 milling scene | (a) | reproduced with our own dimensions |\n\
         | M13 CT skull | (e) | reproduced on a 64³ real volume (smaller than the paper's) |\n\
         | M14 N-D interference | space-time | reproduced in 4-D |\n"
    );
    let milled: std::cell::RefCell<Option<ktree::tree::KTree<3>>> = std::cell::RefCell::new(None);
    type Part<'a> = Box<dyn Fn() -> Result<String, String> + 'a>;
    let parts: Vec<(&str, Part)> = vec![
        (
            "milling scene",
            Box::new(|| {
                let (md, tree) = scene::milling(&out)?;
                *milled.borrow_mut() = Some(tree);
                Ok(md)
            }),
        ),
        ("five objects", Box::new(|| scene::five_objects(&out))),
        ("surface area", Box::new(|| studies::surface_area(&out))),
        (
            "timing",
            Box::new(|| studies::timing(&out, TIMING_MAX_LEVEL)),
        ),
        ("CT", Box::new(|| ct::section(&skull))),
        (
            "views",
            Box::new(|| {
                let scene = milled.borrow();
                let scene = scene.as_ref().ok_or("the milling scene was not built")?;
                views::views(
                    &out,
                    scene,
                    &format!(
                        "The machined scene of (a) — the workpiece with its channel, the clamp, and the tool \
                         (bit, shaft, holder) at the path's end x = {} — as one tree (their union by `ops::union`)",
                        scene::PATH.1
                    ),
                )
            }),
        ),
        ("complexity", Box::new(|| studies::complexity(&out))),
        (
            "progressive mass",
            Box::new(|| {
                let s = solids::ball(8, [257, 255, 256], 240)?;
                let mut md = studies::progressive(&s, "a solid sphere of radius 120 (L = 8)", 0.05);
                md.push_str(&studies::progressive(
                    &skull,
                    "the CT skull (thin bone)",
                    0.05,
                ));
                md.push_str(
                    "A thin object like the skull's bone has most of its volume in partial nodes down to \
                     the last levels, so the bounds stay wide until the end: the early stop pays off for \
                     solid objects, not for shells.\n",
                );
                Ok(md)
            }),
        ),
        ("space-time", Box::new(studies::spacetime)),
        ("checks", Box::new(studies::checks)),
    ];
    let mut timings = Vec::new();
    for (name, part) in &parts {
        let t = Instant::now();
        let section = part().map_err(|e| format!("{name}: {e}"))?;
        timings.push((*name, t.elapsed().as_secs_f64()));
        let _ = writeln!(md, "\n{section}");
    }
    let _ = writeln!(
        md,
        "\n---\nRun time by part (s): {}.",
        timings
            .iter()
            .map(|(n, s)| format!("{n} {s:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    out.write("README.md", &md)?;
    Ok(format!(
        "meagher: wrote {} in {:.1} s",
        out.dir.display(),
        start.elapsed().as_secs_f64(),
    ))
}
