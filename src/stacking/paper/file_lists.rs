//! Stacking with the dimension-level lists as sequential disk files, as Akman & Franklin describe for many
//! rays: "only three files will be open during the execution of the stacking algorithm: ι(D, L) for read
//! operations and ι(D+1, L) and ι(D, L+1) for write operations … the reads always take place sequentially
//! and the writes are always carried out as appends".
//!
//! # The algorithm
//! The same lists, combine and split as [`stack`](super::stack) (the steps are shared), in the paper's order:
//!
//! 0. For `l = 0 … L`: one pass over the rays (made slab by slab by a [`RaySource`]) appends their maximal
//!    rows of level `l` to the file ι(1, l) (one file open).
//! 1. For `D = 1 … K−1` and `l = 0 … L`: ι(D, l) is sorted, then scanned once: combined groups are appended
//!    to ι(D + 1, l) (for `D = K − 1`, to the file of full leaves), the halves of every split item to
//!    ι(D, l + 1); then ι(D, l) is deleted.
//! 2. The full leaves are sorted by Morton key and assembled into the tree in one pass.
//!
//! A list of at most `max_items` keys is sorted in memory. A longer one is sorted on disk: sorted runs of
//! `max_items` keys are written one after another, then merged two at a time into one (two runs read, one
//! written), so no more than three files are ever open; the sorted list is then scanned in chunks, a group
//! that a chunk ends in carried into the next. Memory holds the rays of one slab, at most
//! `max(max_items, 2^(L+1))` keys of lists, and the tree being assembled (where `K·L + 5 > 64` the full
//! leaves do not fit a packed key and are kept in memory instead). Each list file holds its items' keys,
//! 8 bytes each (little-endian `u64`, the stage key of `stack`); [`FileListStats`] records the most keys
//! held and the most files open at once.

use std::collections::VecDeque;
use std::fs::{File, OpenOptions};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use super::lists::{combine_or_split, half_offsets, pack_key, unpack_key, Cells};
use super::StackingStats;
use crate::radix::radix_sort;
use crate::rays::RaySource;
use crate::rays::{maximal_rows, RaySet};
use crate::space::morton_encode;
use crate::tree::KTree;

/// What the file lists did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FileListStats {
    /// The most list files open at any time (at most 3).
    pub max_open_files: usize,
    /// List files created (sorted runs included).
    pub files: usize,
    /// Bytes appended to list files (sorted runs included).
    pub bytes_written: u64,
    /// Bytes read back from list files (sorted runs included).
    pub bytes_read: u64,
    /// The most keys of lists held in memory at once.
    pub largest_list: u64,
    /// Sorted runs written by lists sorted on disk.
    pub sorted_runs: usize,
}

/// Builds the minimal reduced k-tree of the rays of `source` by stacking with the dimension-level lists as
/// files in the folder `dir` (which must exist; the list files are removed when done, also on error),
/// sorting in memory at most `max_items` keys at a time (see the module's notes).
///
/// ```
/// use ktree::{rays::ball_rays, stacking};
/// let rays = ball_rays::<3>(5, [16, 16, 16], 12).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let (tree, stats, files) = stacking::paper::stack_with_file_lists(&rays, dir.path(), 100).unwrap();
/// assert_eq!(tree, stacking::paper::stack(&rays));
/// assert_eq!(stats.cells, stacking::paper::stack_with_stats(&rays).1.cells);
/// assert!(files.max_open_files <= 3 && files.sorted_runs > 0);
/// ```
///
/// # Errors
/// Any I/O error on a list file, naming the file; an error of the source.
pub fn stack_with_file_lists<const K: usize, S>(
    source: &S,
    dir: &Path,
    max_items: usize,
) -> std::io::Result<(KTree<K>, StackingStats, FileListStats)>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display,
{
    let mut lists = ListFiles::new(dir, max_items.max(1));
    let outcome = run(source, &mut lists);
    lists.remove_all();
    let (tree, stats) = outcome?;
    Ok((tree, stats, lists.stats))
}

fn run<const K: usize, S>(
    source: &S,
    lists: &mut ListFiles,
) -> std::io::Result<(KTree<K>, StackingStats)>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display,
{
    let universe = source.universe();
    let top = universe.level();
    let levels = top as usize + 1;
    let mut stats = StackingStats {
        k: K,
        level: top,
        entered: vec![vec![0; levels]; K - 1],
        combined: vec![vec![0; levels]; K - 1],
        split: vec![vec![0; levels]; K - 1],
        ..Default::default()
    };
    let mut leaves = Leaves::<K>::new(top);
    if K == 1 {
        // No list: the maximal rows are the tree's full leaves.
        let mut out = leaves.open(lists)?;
        let mut result = Ok(());
        stats.rays = for_each_source_row(source, |origin, l| {
            if result.is_ok() {
                stats.maximal_rows += 1;
                result = leaves.push(out.as_mut(), origin, l);
            }
        })?;
        result?;
        leaves.close(lists, out)?;
    } else {
        // Step 0: the maximal rows of each level, one pass and one file at a time.
        for l in 0..levels {
            let mut out = lists.append(1, l)?;
            let mut result = Ok(());
            stats.rays = for_each_source_row(source, |origin, row_level| {
                if row_level as usize == l && result.is_ok() {
                    stats.maximal_rows += 1;
                    result = out.push(pack_key(top, K - 2, origin));
                }
            })?;
            result?;
            lists.close(out)?;
        }
    }
    // Step 1: each list, sorted, combined or split into the two lists it feeds.
    for d in 1..K {
        let axis = K - 1 - d;
        let offsets = half_offsets(K, d, top);
        for (l, halves) in offsets.iter().enumerate() {
            let sh = top - l as u32;
            let Some(mut list) = lists.sorted(d, l, if sh > 0 { K as u32 * top } else { 0 })?
            else {
                continue;
            };
            stats.entered[d - 1][l] += list.len;
            let mut up = if d + 1 < K {
                Some(lists.append(d + 1, l)?)
            } else {
                None
            };
            let mut cells = if d + 1 < K { None } else { leaves.open(lists)? };
            let mut down = if l < top as usize {
                Some(lists.append(d, l + 1)?)
            } else {
                None
            };
            let (mut up_result, mut down_result) = (Ok(()), Ok(()));
            let (mut combined, mut split) = (0, 0);
            // Chunks end at a group's end: the group a chunk ends in is carried into the next one.
            let mut chunk = Vec::new();
            loop {
                let more = list.fill(&mut chunk, lists)?;
                // (At the voxel level every item is a group of its own, in any order.)
                let cut = if more && sh > 0 {
                    let last = chunk.last().map_or(0, |&k| k >> sh);
                    chunk.partition_point(|&k| k >> sh < last)
                } else {
                    chunk.len()
                };
                split += combine_or_split(
                    &chunk[..cut],
                    sh,
                    |key| {
                        combined += 1;
                        let origin = unpack_key::<K>(top, axis, key);
                        match up.as_mut() {
                            Some(up) if up_result.is_ok() => {
                                up_result = up.push(pack_key(top, axis - 1, origin))
                            }
                            Some(_) => {}
                            None if up_result.is_ok() => {
                                up_result = leaves.push(cells.as_mut(), origin, l as u32)
                            }
                            None => {}
                        }
                    },
                    |key| {
                        let down = down
                            .as_mut()
                            .expect("items split only above the voxel level");
                        for &o in halves {
                            if down_result.is_ok() {
                                down_result = down.push(key + o);
                            }
                        }
                    },
                );
                chunk.drain(..cut);
                if !more {
                    break;
                }
            }
            up_result?;
            down_result?;
            stats.combined[d - 1][l] += combined;
            stats.split[d - 1][l] += split;
            list.finish(lists)?;
            for w in [up, down].into_iter().flatten() {
                lists.close(w)?;
            }
            leaves.close(lists, cells)?;
        }
    }
    stats.cells = leaves.count;
    stats.peak_items = lists.stats.largest_list;
    Ok((leaves.into_tree(lists, universe)?, stats))
}

/// Calls `visit(origin, level)` with every maximal row of the source's rays, in column order, one slab
/// of rays made at a time; returns the number of rays.
fn for_each_source_row<const K: usize, S>(
    source: &S,
    mut visit: impl FnMut([u32; K], u32),
) -> std::io::Result<u64>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display,
{
    let universe = source.universe();
    let top = universe.level();
    let slabs = if K == 1 {
        vec![0]
    } else {
        source.occupied_slabs(top)
    };
    let mut rays = 0;
    for x in slabs {
        let slab = source
            .slab(x..x + 1)
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        rays += slab.runs.len() as u64;
        for (&key, &(z1, z2)) in slab.keys.iter().zip(slab.runs.iter()) {
            let mut origin = RaySet::<K>::column_of_key_at(top, key);
            for row in maximal_rows(z1, z2) {
                origin[K - 1] = row.z;
                visit(origin, top - row.log_len);
            }
        }
    }
    Ok(rays)
}

/// Calls `visit(origin, level)` with every maximal row of the rays, in column order.
pub(super) fn for_each_row<const K: usize>(rays: &RaySet<K>, mut visit: impl FnMut([u32; K], u32)) {
    let top = rays.universe().level();
    for (i, &(z1, z2)) in rays.runs().iter().enumerate() {
        let mut origin = rays.column_of_key(rays.column_keys()[i]);
        for row in maximal_rows(z1, z2) {
            origin[K - 1] = row.z;
            visit(origin, top - row.log_len);
        }
    }
}

/// The full leaves: appended to a file as packed keys (Morton key and level), sorted on disk and
/// assembled at the end; kept in memory where a packed key does not fit 64 bits.
struct Leaves<const K: usize> {
    top: u32,
    packed: bool,
    in_memory: Cells<K>,
    count: u64,
}

impl<const K: usize> Leaves<K> {
    fn new(top: u32) -> Self {
        Self {
            top,
            packed: K as u32 * top + 5 <= 64,
            in_memory: Cells::new(top),
            count: 0,
        }
    }

    /// The leaves' file open for appending (none when they are kept in memory).
    fn open(&self, lists: &mut ListFiles) -> std::io::Result<Option<Appender>> {
        if self.packed {
            lists.append(K, 0).map(Some)
        } else {
            Ok(None)
        }
    }

    fn push(
        &mut self,
        out: Option<&mut Appender>,
        origin: [u32; K],
        level: u32,
    ) -> std::io::Result<()> {
        self.count += 1;
        match out {
            Some(out) => out.push(morton_encode(origin) << 5 | u64::from(level)),
            None => {
                self.in_memory.push(origin, level);
                Ok(())
            }
        }
    }

    fn close(&self, lists: &mut ListFiles, out: Option<Appender>) -> std::io::Result<()> {
        match out {
            Some(out) => lists.close(out),
            None => Ok(()),
        }
    }

    fn into_tree(
        self,
        lists: &mut ListFiles,
        universe: crate::space::Universe<K>,
    ) -> std::io::Result<KTree<K>> {
        if !self.packed {
            return Ok(self.in_memory.into_tree(universe, Vec::new()));
        }
        let bits = K as u32 * self.top + 5;
        let Some(mut list) = lists.sorted(K, 0, bits)? else {
            return Ok(KTree::from_sorted_packed(universe, &[]));
        };
        let mut error = None;
        let mut chunk = Vec::new();
        let mut at = 0;
        let keys = std::iter::from_fn(|| {
            if at == chunk.len() {
                chunk.clear();
                at = 0;
                match list.fill(&mut chunk, lists) {
                    Ok(_) if chunk.is_empty() => return None,
                    Ok(_) => {}
                    Err(e) => {
                        error = Some(e);
                        return None;
                    }
                }
            }
            at += 1;
            Some(chunk[at - 1])
        });
        let tree = KTree::from_sorted_packed_keys(universe, keys);
        if let Some(e) = error {
            return Err(e);
        }
        list.finish(lists)?;
        Ok(tree)
    }
}

/// The list files ι(d, l) of one run (the full leaves are ι(K, 0)), and what was done with them.
struct ListFiles {
    dir: PathBuf,
    max_items: usize,
    created: Vec<PathBuf>,
    open: usize,
    runs_made: usize,
    scratch: Vec<u64>,
    stats: FileListStats,
}

/// A list file open for appending.
struct Appender {
    out: BufWriter<File>,
    path: PathBuf,
    bytes: u64,
}

impl Appender {
    #[inline]
    fn push(&mut self, key: u64) -> std::io::Result<()> {
        self.bytes += 8;
        self.out
            .write_all(&key.to_le_bytes())
            .map_err(|e| with_path(&self.path, e))
    }
}

/// A list file open for reading from start to end.
struct Reader {
    input: BufReader<File>,
    path: PathBuf,
    left: u64,
}

impl Reader {
    /// Appends up to `n` keys to `keys`.
    fn read_into(&mut self, keys: &mut Vec<u64>, n: usize) -> std::io::Result<usize> {
        let take = (n as u64).min(self.left) as usize;
        let mut buf = [0u8; 8];
        for _ in 0..take {
            self.input
                .read_exact(&mut buf)
                .map_err(|e| with_path(&self.path, e))?;
            keys.push(u64::from_le_bytes(buf));
        }
        self.left -= take as u64;
        Ok(take)
    }

    fn next(&mut self) -> std::io::Result<Option<u64>> {
        if self.left == 0 {
            return Ok(None);
        }
        let mut buf = [0u8; 8];
        self.input
            .read_exact(&mut buf)
            .map_err(|e| with_path(&self.path, e))?;
        self.left -= 1;
        Ok(Some(u64::from_le_bytes(buf)))
    }
}

/// A sorted list: in memory, or a sorted file read in chunks.
struct SortedList {
    len: u64,
    memory: Option<Vec<u64>>,
    file: Option<Reader>,
}

impl SortedList {
    /// Appends the next keys (up to the chunk size) to `chunk`; returns whether keys are left after them.
    fn fill(&mut self, chunk: &mut Vec<u64>, lists: &mut ListFiles) -> std::io::Result<bool> {
        if let Some(keys) = self.memory.take() {
            chunk.extend(keys);
            return Ok(false);
        }
        let Some(file) = self.file.as_mut() else {
            return Ok(false);
        };
        // Room for a whole group carried over besides a chunk.
        let room = lists.max_items.saturating_sub(chunk.len()).max(1);
        file.read_into(chunk, room)?;
        lists.hold(chunk.len() as u64);
        Ok(file.left > 0)
    }

    /// Closes and deletes the sorted file.
    fn finish(mut self, lists: &mut ListFiles) -> std::io::Result<()> {
        if let Some(file) = self.file.take() {
            let path = file.path.clone();
            drop(file);
            lists.open -= 1;
            lists.delete(&path)?;
        }
        Ok(())
    }
}

fn with_path(path: &Path, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

impl ListFiles {
    fn new(dir: &Path, max_items: usize) -> Self {
        Self {
            dir: dir.to_path_buf(),
            max_items,
            created: Vec::new(),
            open: 0,
            runs_made: 0,
            scratch: Vec::new(),
            stats: FileListStats::default(),
        }
    }

    fn path(&self, d: usize, l: usize) -> PathBuf {
        self.dir.join(format!("list-d{d}-l{l}.keys"))
    }

    fn opened(&mut self) {
        self.open += 1;
        self.stats.max_open_files = self.stats.max_open_files.max(self.open);
    }

    /// Records that `n` keys are held in memory.
    fn hold(&mut self, n: u64) {
        self.stats.largest_list = self.stats.largest_list.max(n);
    }

    fn create(&mut self, path: PathBuf) -> std::io::Result<Appender> {
        if !self.created.contains(&path) {
            self.created.push(path.clone());
            self.stats.files += 1;
        }
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| with_path(&path, e))?;
        self.opened();
        Ok(Appender {
            out: BufWriter::with_capacity(1 << 16, file),
            path,
            bytes: 0,
        })
    }

    /// Opens ι(d, l) for appending, creating it if needed.
    fn append(&mut self, d: usize, l: usize) -> std::io::Result<Appender> {
        self.create(self.path(d, l))
    }

    fn close(&mut self, mut w: Appender) -> std::io::Result<()> {
        w.out.flush().map_err(|e| with_path(&w.path, e))?;
        self.stats.bytes_written += w.bytes;
        self.open -= 1;
        Ok(())
    }

    /// Opens a list file for reading (`None` if it was never written).
    fn open_reader(&mut self, path: &Path) -> std::io::Result<Option<Reader>> {
        if !self.created.iter().any(|p| p == path) {
            return Ok(None);
        }
        let file = File::open(path).map_err(|e| with_path(path, e))?;
        let len = file.metadata().map_err(|e| with_path(path, e))?.len();
        if len % 8 != 0 {
            return Err(with_path(
                path,
                std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("a list file of {len} bytes is not whole keys"),
                ),
            ));
        }
        self.opened();
        self.stats.bytes_read += len;
        Ok(Some(Reader {
            input: BufReader::with_capacity(1 << 16, file),
            path: path.to_path_buf(),
            left: len / 8,
        }))
    }

    fn delete(&mut self, path: &Path) -> std::io::Result<()> {
        std::fs::remove_file(path).map_err(|e| with_path(path, e))?;
        self.created.retain(|p| p != path);
        Ok(())
    }

    /// ι(d, l) sorted on its keys' low `bits` bits (unsorted for 0), the file deleted: in memory if it
    /// holds at most `max_items` keys, else as a sorted file. `None` if it is empty or was never written.
    fn sorted(&mut self, d: usize, l: usize, bits: u32) -> std::io::Result<Option<SortedList>> {
        let path = self.path(d, l);
        let Some(mut input) = self.open_reader(&path)? else {
            return Ok(None);
        };
        let len = input.left;
        if len == 0 {
            drop(input);
            self.open -= 1;
            self.delete(&path)?;
            return Ok(None);
        }
        if bits == 0 && len > self.max_items as u64 {
            // Unsorted: the file is read as it is, in chunks, and deleted after.
            return Ok(Some(SortedList {
                len,
                memory: None,
                file: Some(input),
            }));
        }
        let mut runs = VecDeque::new();
        loop {
            let mut keys = Vec::with_capacity((input.left as usize).min(self.max_items));
            input.read_into(&mut keys, self.max_items)?;
            self.hold(keys.len() as u64);
            if bits > 0 {
                radix_sort(&mut keys, bits, &mut self.scratch);
            }
            if runs.is_empty() && input.left == 0 {
                // The whole list fits: sorted in memory.
                drop(input);
                self.open -= 1;
                self.delete(&path)?;
                return Ok(Some(SortedList {
                    len,
                    memory: Some(keys),
                    file: None,
                }));
            }
            runs.push_back(self.write_run(&keys)?);
            if input.left == 0 {
                break;
            }
        }
        drop(input);
        self.open -= 1;
        self.delete(&path)?;
        self.scratch = Vec::new();
        // Merge two runs into one (three files open) until one is left.
        while runs.len() > 1 {
            let (a, b) = (
                runs.pop_front().expect("two runs"),
                runs.pop_front().expect("two runs"),
            );
            runs.push_back(self.merge_runs(&a, &b)?);
        }
        let sorted = runs.pop_front().expect("one run");
        let file = self.open_reader(&sorted)?;
        Ok(Some(SortedList {
            len,
            memory: None,
            file,
        }))
    }

    fn run_path(&mut self) -> PathBuf {
        self.runs_made += 1;
        self.stats.sorted_runs += 1;
        self.dir.join(format!("run-{}.keys", self.runs_made))
    }

    fn write_run(&mut self, keys: &[u64]) -> std::io::Result<PathBuf> {
        let path = self.run_path();
        let mut out = self.create(path.clone())?;
        for &k in keys {
            out.push(k)?;
        }
        self.close(out)?;
        Ok(path)
    }

    /// Merges the sorted runs `a` and `b` into a new run, deleting them.
    fn merge_runs(&mut self, a: &Path, b: &Path) -> std::io::Result<PathBuf> {
        let path = self.run_path();
        let mut ra = self.open_reader(a)?.expect("a run");
        let mut rb = self.open_reader(b)?.expect("a run");
        let mut out = self.create(path.clone())?;
        let (mut x, mut y) = (ra.next()?, rb.next()?);
        loop {
            match (x, y) {
                (Some(p), Some(q)) if p <= q => {
                    out.push(p)?;
                    x = ra.next()?;
                }
                (_, Some(q)) => {
                    out.push(q)?;
                    y = rb.next()?;
                }
                (Some(p), None) => {
                    out.push(p)?;
                    x = ra.next()?;
                }
                (None, None) => break,
            }
        }
        self.close(out)?;
        drop((ra, rb));
        self.open -= 2;
        self.delete(a)?;
        self.delete(b)?;
        Ok(path)
    }

    /// Removes every list file still present.
    fn remove_all(&mut self) {
        for path in self.created.drain(..) {
            let _ = std::fs::remove_file(path);
        }
    }
}
