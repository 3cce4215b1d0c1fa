//! AF8 (the dimension-level lists as sequential disk files) and AF9 (one processor per data-flow box): the
//! same balls stacked in memory, with file lists, and as a pipeline of threads; same tree, memory and time.

use std::fmt::Write as _;
use std::time::Instant;

use ktree::rays::RaySet;
use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::paper::{stack, stack_pipelined, stack_with_file_lists, stack_with_stats};

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

/// The keys of lists sorted in memory at once by the file-list runs (8 MiB); longer lists are sorted on
/// disk in runs of this many keys.
const AF8_MAX_ITEMS: usize = 1 << 20;

/// The ball of [`rays_of`] as a solid, whose rays are made slab by slab.
fn ball_of(level: u32) -> Result<Solid<3>, String> {
    let h = Rational::int(1 << (level - 1));
    Quadric::<3>::ball([h; 3], h, Frame::Voxel)
        .map(Solid::Quadric)
        .map_err(|e| e.to_string())
}

fn rays_of(level: u32) -> Result<RaySet<3>, String> {
    centred_ball::<3>(level, Rational::int(1 << (level - 1)))
}

/// AF8: writes `af8_file_lists.md`/`.csv`, returns the claims row.
pub(super) fn af8(write: &dyn Fn(&str, &str) -> Result<(), String>) -> Result<[String; 5], String> {
    let resets = reset_peak_rss();
    let mut csv = String::from(
        "level,rays,nodes,memory_peak_items,memory_peak_rss_mib,memory_seconds,files_items_held,files_sorted_runs,files_max_open,files_mib_written,files_peak_rss_mib,files_seconds,same_tree\n",
    );
    let mut md = format!(
        "# AF8: the dimension-level lists as sequential disk files\n\n\
         Ball of radius U/2 centred in an octree universe (voxel centres). *In memory* is `stacking::paper::stack`: it \
         holds the input rays, per slab of rays the lists of that slab, and the last stage's lists whole. \
         *File lists* is `stacking::paper::stack_with_file_lists` on the ball's quadric (its rays made slab by slab, \
         never held whole): every list ι(D, l) is a file, written only by appending, read from start to end, \
         at most three open at a time (ι(D, l) read, ι(D+1, l) and ι(D, l+1) appended), in the paper's order \
         (all levels of D = 1, then D = 2). A list of more than {AF8_MAX_ITEMS} keys is sorted on disk: sorted \
         runs of that many keys, merged two at a time (two read, one written). The full leaves go to a file \
         too, sorted the same way and assembled into the tree in one pass. *Items held* is the most list \
         items in memory at once (`StackingStats::peak_items`; for file lists `FileListStats::largest_list`, at \
         most {AF8_MAX_ITEMS} plus one group carried between chunks). Peak RSS is the process's high-water \
         mark, reset before each run (`/proc/self/clear_refs`); the file-list run comes first at each level, \
         before the in-memory run makes its rays, and its peak includes the tree it returns (about 2 bits a \
         node).\n\n\
         | L | rays | nodes | in memory: items held | peak RSS MiB | s | file lists: items held | sorted runs | files open at most | MiB written | peak RSS MiB | s | same tree |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    let tmp = tempfile::tempdir().map_err(|e| format!("temporary folder: {e}"))?;
    let mut rows = Vec::new();
    for level in 8..=11u32 {
        let ball = ball_of(level)?;
        let source = SolidSource::new(&ball, level, Sample::Centre).map_err(|e| e.to_string())?;
        let t = Instant::now();
        let (files_rss, outcome) =
            peak_during(|| stack_with_file_lists(&source, tmp.path(), AF8_MAX_ITEMS));
        let files_s = t.elapsed().as_secs_f64();
        let (on_disk, disk_stats, files) = outcome.map_err(|e| e.to_string())?;
        let rays = rays_of(level)?;
        let t = Instant::now();
        let (memory_rss, (tree, stats)) = peak_during(|| stack_with_stats(&rays));
        let memory_s = t.elapsed().as_secs_f64();
        let nodes = tree.node_count();
        let same = on_disk == tree && disk_stats.rays == rays.len() as u64;
        drop(tree);
        let written = files.bytes_written as f64 / (1024.0 * 1024.0);
        let _ = writeln!(
            csv,
            "{level},{},{nodes},{},{memory_rss:.1},{memory_s:.3},{},{},{},{written:.1},{files_rss:.1},{files_s:.3},{same}",
            rays.len(),
            stats.peak_items,
            files.largest_list,
            files.sorted_runs,
            files.max_open_files
        );
        let _ = writeln!(
            md,
            "| {level} | {} | {nodes} | {} | {memory_rss:.1} | {memory_s:.2} | {} | {} | {} | {written:.1} | {files_rss:.1} | {files_s:.2} | {} |",
            rays.len(),
            stats.peak_items,
            files.largest_list,
            files.sorted_runs,
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
    let bounded = rows
        .iter()
        .all(|r| r.2 <= AF8_MAX_ITEMS as u64 + (1u64 << r.0));
    let ours = format!(
        "`stacking::paper::stack_with_file_lists` on the ball's quadric (rays made slab by slab): every list a file, at most {max_open} open, read in order, appended to; lists longer than {AF8_MAX_ITEMS} keys sorted on disk in runs merged two at a time; same tree as in memory for L = {}…{} ({}); items held in memory at most {} (L = {}) against {} in memory, peak RSS {:.0} against {:.0} MiB (the file-list figure includes the tree it returns)",
        first.0,
        last.0,
        if all_same { "node for node" } else { "NOT equal" },
        rows.iter().map(|r| r.2).max().unwrap_or(0),
        last.0,
        last.1,
        last.4,
        last.3,
    );
    let verdict = if all_same && max_open <= 3 && bounded {
        "reproduced (three files, sequential, same tree, lists held in bounded memory)"
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
         Ball of radius U/2 centred in an octree universe. *One thread* is `stacking::paper::stack`; *pipeline* is \
         `stacking::paper::stack_pipelined`: a producer thread cuts maximal rows, one thread per stage D = 1, 2 combines \
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
            "`stacking::paper::stack_pipelined`: a thread per stage, bounded channels between; same tree ({}); throughput against one thread ({threads} hardware threads): {speedups}",
            if all_same { "node for node, L = 8…11" } else { "NOT equal" }
        ),
        if all_same { "reproduced (speed-up as measured)" } else { "differs" }.into(),
        "af9_pipeline.md; verify/stacking_modes.rs (= in-memory stacking, K = 1…4)".into(),
    ])
}
