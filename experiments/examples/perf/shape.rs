//! Shape operations ([`ktree::shape`]) on one thread, for the side-by-side comparison with OpenVDB and
//! scipy of `experiments/shape.sh` (which writes `results/performance/shape.md`). The objects are the
//! queries area's (`ball-L`, `armadillo-L`, see [`crate::export::tree_of`]); `OBJECT:write-inputs:DIR`
//! writes them once as `tree.ktree`, `tree.vdb` (a BoolGrid, index = voxel) and for L ≤ 9 `dense.npy`, and
//! every other case reads `DIR/tree.ktree`, so that building the object is neither timed nor in the peak
//! memory:
//!
//! - `DIR:dilate:ELEMENT:R`, `DIR:erode:ELEMENT:R`: [`KTree::dilate`] / [`KTree::erode`] by `ball`, `box`
//!   or `cross` of radius `R`;
//! - `DIR:components`: [`KTree::components`] with connectivity 1 (scipy's `label` default);
//! - `DIR:band:W`: [`KTree::narrow_band`] of half-width `W`.
//!
//! A case prints `key=value` lines as the queries area does: `seconds` (best of `REPEATS`, default 3),
//! `peak_bytes`, `rss_loaded` (resident bytes once the input is read), `voxels_in`, `nodes_in`,
//! `tree_bytes_in` ([`KTree::heap_bytes`]) and the answer's `voxels` (`nodes`, `tree_bytes`), `count` and
//! `largest` (components) or `band` (voxels in the band).

use std::path::Path;

use ktree::shape::Element;
use ktree::KTree;

use crate::measure::{best_of, repeats};

/// Resident memory now (VmRSS), in bytes.
fn rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kib| kib * 1024)
}

/// Writes `tree.ktree`, `tree.vdb` and (L ≤ 9) `dense.npy` of `object` into `dir`.
fn write_inputs(object: &str, dir: &Path) -> Result<Vec<(String, String)>, String> {
    let tree = crate::export::tree_of(object)?;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot make {}: {e}", dir.display()))?;
    for name in ["tree.ktree", "tree.vdb"] {
        tree.save(dir.join(name))
            .map_err(|e| format!("cannot write {name}: {e}"))?;
    }
    if tree.level() <= 9 {
        let path = dir.join("dense.npy");
        ktree::fs::write_atomic(&path, &crate::queries::dense_npy(&tree)?)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(vec![
        ("voxels".into(), tree.voxel_count().to_string()),
        ("nodes".into(), tree.node_count().to_string()),
    ])
}

/// Runs one case in this (child) process, on a pool of one thread (see the module's docs).
pub fn run_case(case: &str) -> Result<(f64, Vec<(String, String)>), String> {
    let parts: Vec<&str> = case.split(':').collect();
    if parts.len() == 3 && parts[1] == "write-inputs" {
        return Ok((0.0, write_inputs(parts[0], Path::new(parts[2]))?));
    }
    let path = Path::new(parts[0]).join("tree.ktree");
    let tree = KTree::<3>::load(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut facts = vec![
        ("rss_loaded".to_string(), rss_bytes().to_string()),
        ("voxels_in".to_string(), tree.voxel_count().to_string()),
        ("nodes_in".to_string(), tree.node_count().to_string()),
        ("tree_bytes_in".to_string(), tree.heap_bytes().to_string()),
    ];
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    let radius = |s: &str| s.parse::<f64>().map_err(|_| format!("bad radius {s:?}"));
    let seconds = match parts[1..] {
        [op @ ("dilate" | "erode"), element, r] => {
            let element: Element = element.parse()?;
            let r = radius(r)?;
            let mut out = None;
            let s = pool.install(|| {
                best_of(
                    repeats(),
                    || {
                        if op == "dilate" {
                            tree.dilate(r, element)
                        } else {
                            tree.erode(r, element)
                        }
                    },
                    |t| out = Some(t),
                )
            });
            let out = out.ok_or("no run")?.map_err(|e| e.to_string())?;
            facts.push(("voxels".into(), out.voxel_count().to_string()));
            facts.push(("nodes".into(), out.node_count().to_string()));
            facts.push(("tree_bytes".into(), out.heap_bytes().to_string()));
            s
        }
        ["components"] => {
            let mut out = None;
            let s = pool.install(|| best_of(repeats(), || tree.components(1), |c| out = Some(c)));
            let parts = out.ok_or("no run")?.map_err(|e| e.to_string())?;
            facts.push(("count".into(), parts.len().to_string()));
            let largest = parts.first().map_or(0, |c| c.size);
            facts.push(("largest".into(), largest.to_string()));
            s
        }
        ["band", w] => {
            let w = radius(w)?;
            let mut out = None;
            let s = pool.install(|| best_of(repeats(), || tree.narrow_band(w), |b| out = Some(b)));
            let band = out.ok_or("no run")?.map_err(|e| e.to_string())?;
            facts.push(("band".into(), band.len().to_string()));
            let inside = band.values.iter().filter(|&&v| v < 0.0).count();
            facts.push(("band_inside".into(), inside.to_string()));
            s
        }
        _ => return Err(format!("unknown shape case {case:?}")),
    };
    Ok((seconds, facts))
}
