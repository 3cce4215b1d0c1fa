//! AF8 (the dimension-level lists as sequential disk files) and AF9 (one processor per data-flow box): the
//! same balls stacked in memory, with file lists, and as a pipeline of threads; same tree, memory and time.

use std::fmt::Write as _;
use std::time::Instant;

use ktree::rays::RaySet;
use ktree::solid::Rational;
use ktree::stacking::{stack, stack_pipelined, stack_with_file_lists, stack_with_stats};

use super::{best_time, centred_ball};

/// Resets this process's peak resident memory (`VmHWM`) to its current resident memory, so that the next
/// reading is the peak of what runs in between (Linux: `/proc/self/clear_refs`, value 5).
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn mib(bytes: Option<u64>) -> f64 {
    bytes.map_or(f64::NAN, |b| b as f64 / (1024.0 * 1024.0))
}

/// Peak resident memory (MiB) while `f` runs, measured from a reset high-water mark, and `f`'s value.
fn peak_during<T>(f: impl FnOnce() -> T) -> (f64, T) {
    reset_peak_rss();
    let value = f();
    (mib(crate::peak_rss_bytes()), value)
}

fn rays_of(level: u32) -> Result<RaySet<3>, String> {
    centred_ball::<3>(level, Rational::int(1 << (level - 1)))
}

/// AF8: writes `af8_file_lists.md`/`.csv`, returns the claims row.
pub(super) fn af8(write: &dyn Fn(&str, &str) -> Result<(), String>) -> Result<[String; 5], String> {
    let resets = reset_peak_rss();
    let mut csv = String::from(
        "level,rays,nodes,memory_peak_items,memory_peak_rss_mib,memory_seconds,files_largest_list,files_max_open,files_mib_written,files_peak_rss_mib,files_seconds,same_tree\n",
    );
    let mut md = String::from(
        "# AF8: the dimension-level lists as sequential disk files\n\n\
         Ball of radius U/2 centred in an octree universe (voxel centres). *In memory* is `stacking::stack`: per \
         slab of rays it holds the lists of that slab, and the last stage's lists whole. *File lists* is \
         `stacking::stack_with_file_lists`: every list ι(D, l) is a file, written only by appending, read from \
         start to end once, at most three open at a time (ι(D, l) read, ι(D+1, l) and ι(D, l+1) appended), in \
         the paper's order (all levels of D = 1, then D = 2). Both keep the input rays and the output's full \
         leaves in memory. *Items held* is the most list items in memory at once (`StackingStats::peak_items`; \
         for file lists, the largest list read). Peak RSS is the process's high-water mark, reset before each \
         run (`/proc/self/clear_refs`), so it includes the rays already in memory.\n\n\
         | L | rays | nodes | in memory: items held | peak RSS MiB | s | file lists: items held | files open at most | MiB written | peak RSS MiB | s | same tree |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    let tmp = tempfile::tempdir().map_err(|e| format!("temporary folder: {e}"))?;
    let mut rows = Vec::new();
    for level in 8..=11u32 {
        let rays = rays_of(level)?;
        let t = Instant::now();
        let (memory_rss, (tree, stats)) = peak_during(|| stack_with_stats(&rays));
        let memory_s = t.elapsed().as_secs_f64();
        let nodes = tree.node_count();
        drop(tree);
        let t = Instant::now();
        let (files_rss, outcome) = peak_during(|| stack_with_file_lists(&rays, tmp.path()));
        let files_s = t.elapsed().as_secs_f64();
        let (on_disk, _, files) = outcome.map_err(|e| e.to_string())?;
        let same = on_disk == stack(&rays);
        let written = files.bytes_written as f64 / (1024.0 * 1024.0);
        let _ = writeln!(
            csv,
            "{level},{},{nodes},{},{memory_rss:.1},{memory_s:.3},{},{},{written:.1},{files_rss:.1},{files_s:.3},{same}",
            rays.len(),
            stats.peak_items,
            files.largest_list,
            files.max_open_files
        );
        let _ = writeln!(
            md,
            "| {level} | {} | {nodes} | {} | {memory_rss:.1} | {memory_s:.2} | {} | {} | {written:.1} | {files_rss:.1} | {files_s:.2} | {} |",
            rays.len(),
            stats.peak_items,
            files.largest_list,
            files.max_open_files,
            if same { "yes" } else { "NO" }
        );
        rows.push((
            level,
            stats.peak_items,
            files.largest_list,
            memory_rss,
            files_rss,
            files.max_open_files,
            same,
        ));
    }
    if !resets {
        md.push_str("\nThis system could not reset the peak RSS: the RSS columns are cumulative high-water marks.\n");
    }
    write("af8_file_lists.csv", &csv)?;
    write("af8_file_lists.md", &md)?;
    let all_same = rows.iter().all(|r| r.6);
    let max_open = rows.iter().map(|r| r.5).max().unwrap_or(0);
    let last = rows.last().ok_or("no AF8 rows")?;
    let first = rows.first().ok_or("no AF8 rows")?;
    let items_ratio = last.2 as f64 / last.1 as f64;
    let ours = format!(
        "`stacking::stack_with_file_lists`: every list a file, at most {max_open} open, read in order, appended to; same tree as in memory for L = {}…{} ({}); items held in memory at L = {}: {} (largest list) against {} in memory ({:.2}×), peak RSS {:.0} against {:.0} MiB; from L = {} to {} the items held grow {:.0}× with the rays",
        first.0,
        last.0,
        if all_same { "node for node" } else { "NOT equal" },
        last.0,
        last.2,
        last.1,
        items_ratio,
        last.4,
        last.3,
        first.0,
        last.0,
        last.2 as f64 / first.2.max(1) as f64,
    );
    let verdict = if all_same && max_open <= 3 {
        "reproduced (three files, sequential, same tree; memory is one list, not bounded: a list is sorted in memory)"
    } else {
        "differs"
    };
    Ok([
        "AF8".into(),
        "lists as sequential disk files, three open at a time (out of core)".into(),
        ours,
        verdict.into(),
        "af8_file_lists.md; verify/stacking_modes.rs (= in-memory stacking, same list traffic, K = 1…4)".into(),
    ])
}

/// AF9: writes `af9_pipeline.md`/`.csv`, returns the claims row.
pub(super) fn af9(write: &dyn Fn(&str, &str) -> Result<(), String>) -> Result<[String; 5], String> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut csv = String::from("level,rays,nodes,one_thread_s,pipeline_s,speedup,same_tree\n");
    let mut md = format!(
        "# AF9: the data-flow boxes as a pipeline of threads\n\n\
         Ball of radius U/2 centred in an octree universe. *One thread* is `stacking::stack`; *pipeline* is \
         `stacking::stack_pipelined`: a producer thread cuts maximal rows, one thread per stage D = 1, 2 combines \
         and splits its lists and sends what it combines on through a bounded channel, and the calling thread \
         collects the full leaves and assembles the tree (4 threads for K = 3). Times are the best of 3 runs, \
         interleaved, on a machine with {threads} hardware threads shared with other work; throughput is rays \
         per second.\n\n\
         | L | rays | nodes | one thread s | pipeline s | one thread Mrays/s | pipeline Mrays/s | pipeline speed-up | same tree |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    let mut rows = Vec::new();
    for level in 8..=11u32 {
        let rays = rays_of(level)?;
        let tree = stack(&rays);
        let same = stack_pipelined(&rays) == tree;
        let (mut one, mut piped) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..3 {
            one = one.min(best_time(1, || stack(&rays)));
            piped = piped.min(best_time(1, || stack_pipelined(&rays)));
        }
        let n = rays.len() as f64;
        let _ = writeln!(
            csv,
            "{level},{},{},{one:.4},{piped:.4},{:.3},{same}",
            rays.len(),
            tree.node_count(),
            one / piped
        );
        let _ = writeln!(
            md,
            "| {level} | {} | {} | {one:.3} | {piped:.3} | {:.2} | {:.2} | {:.2}× | {} |",
            rays.len(),
            tree.node_count(),
            n / one / 1e6,
            n / piped / 1e6,
            one / piped,
            if same { "yes" } else { "NO" }
        );
        rows.push((level, one / piped, same));
    }
    write("af9_pipeline.csv", &csv)?;
    write("af9_pipeline.md", &md)?;
    let all_same = rows.iter().all(|r| r.2);
    let speedups = rows
        .iter()
        .map(|(l, s, _)| format!("L={l}: {s:.2}×"))
        .collect::<Vec<_>>()
        .join(", ");
    Ok([
        "AF9".into(),
        "one processor per box of the data flow (pipeline)".into(),
        format!(
            "`stacking::stack_pipelined`: a thread per stage, bounded channels between; same tree ({}); throughput against one thread ({threads} hardware threads): {speedups}",
            if all_same { "node for node, L = 8…11" } else { "NOT equal" }
        ),
        if all_same { "reproduced (speed-up as measured)" } else { "differs" }.into(),
        "af9_pipeline.md; verify/stacking_modes.rs (= in-memory stacking, K = 1…4)".into(),
    ])
}
