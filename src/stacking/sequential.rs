//! Stacking with the dimension-level lists as sequential disk files, as Akman & Franklin describe for many
//! rays: "only three files will be open during the execution of the stacking algorithm: ι(D, L) for read
//! operations and ι(D+1, L) and ι(D, L+1) for write operations … the reads always take place sequentially
//! and the writes are always carried out as appends".
//!
//! # The algorithm
//! The same lists, combine and split as [`stack`](super::stack) (the steps are shared), in the paper's order:
//!
//! 0. For `l = 0 … L`: one pass over the rays appends their maximal rows of level `l` to the file ι(1, l)
//!    (one file open).
//! 1. For `D = 1 … K−1` and `l = 0 … L`: read ι(D, l) from start to end, sort it, and scan it once:
//!    combined groups are appended to ι(D + 1, l), the halves of every split item to ι(D, l + 1); then
//!    ι(D, l) is deleted. Three files are open, no more.
//! 2. The items of dimension `K` (the full leaves) are sorted by Morton key and assembled, as in memory.
//!
//! Each list file holds its items' keys, 8 bytes each (little-endian `u64`, the stage key of
//! `stack`). Memory holds one list at a time (plus the full leaves of the output) instead of every list of
//! a slab and the whole last stage at once; [`FileListStats`] records the largest list and the most files
//! open at once.

use std::fs::{File, OpenOptions};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use super::stack::{combine_or_split, half_offsets, pack_key, unpack_key, Cells};
use super::{radix_sort, StackingStats};
use crate::rays::{maximal_rows, RaySet};
use crate::tree::KTree;

/// What the file lists did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FileListStats {
    /// The most list files open at any time (at most 3).
    pub max_open_files: usize,
    /// List files created.
    pub files: usize,
    /// Bytes appended to list files.
    pub bytes_written: u64,
    /// Bytes read back from list files.
    pub bytes_read: u64,
    /// The largest list read into memory, in items.
    pub largest_list: u64,
}

/// Builds the minimal reduced k-tree of a ray set by stacking with the dimension-level lists as files in
/// the folder `dir` (which must exist; the list files are removed when done, also on error).
///
/// ```
/// use ktree::{rays::ball_rays, stacking};
/// let rays = ball_rays::<3>(5, [16, 16, 16], 12).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let (tree, stats, files) = stacking::stack_with_file_lists(&rays, dir.path()).unwrap();
/// assert_eq!(tree, stacking::stack(&rays));
/// assert_eq!(stats.cells, stacking::stack_with_stats(&rays).1.cells);
/// assert!(files.max_open_files <= 3);
/// ```
///
/// # Errors
/// Any I/O error on a list file, naming the file.
pub fn stack_with_file_lists<const K: usize>(
    rays: &RaySet<K>,
    dir: &Path,
) -> std::io::Result<(KTree<K>, StackingStats, FileListStats)> {
    let mut lists = ListFiles::new(dir);
    let outcome = run(rays, &mut lists);
    lists.remove_all();
    let (tree, stats) = outcome?;
    Ok((tree, stats, lists.stats))
}

fn run<const K: usize>(
    rays: &RaySet<K>,
    lists: &mut ListFiles,
) -> std::io::Result<(KTree<K>, StackingStats)> {
    let universe = rays.universe();
    let top = universe.level();
    let levels = top as usize + 1;
    let mut stats = StackingStats {
        k: K,
        level: top,
        rays: rays.len() as u64,
        entered: vec![vec![0; levels]; K - 1],
        combined: vec![vec![0; levels]; K - 1],
        split: vec![vec![0; levels]; K - 1],
        ..Default::default()
    };
    let mut cells = Cells::<K>::new(top);
    if K == 1 {
        // No list: the maximal rows are the tree's full leaves.
        for_each_row(rays, |origin, l| {
            stats.maximal_rows += 1;
            cells.push(origin, l);
        });
    } else {
        // Step 0: the maximal rows of each level, one pass and one file at a time.
        for l in 0..levels {
            let mut out = lists.append(1, l)?;
            let mut result = Ok(());
            for_each_row(rays, |origin, row_level| {
                if row_level as usize == l && result.is_ok() {
                    stats.maximal_rows += 1;
                    result = out.push(pack_key(top, K - 2, origin));
                }
            });
            result?;
            lists.close(out)?;
        }
    }
    // Step 1: each list, read in order, combined or split into the two lists it feeds.
    let mut scratch = Vec::new();
    for d in 1..K {
        let axis = K - 1 - d;
        let offsets = half_offsets(K, d, top);
        for (l, halves) in offsets.iter().enumerate() {
            let mut list = lists.read(d, l)?;
            if list.is_empty() {
                continue;
            }
            stats.entered[d - 1][l] += list.len() as u64;
            let sh = top - l as u32;
            if sh > 0 {
                radix_sort(&mut list, K as u32 * top, &mut scratch);
            }
            let mut up = if d + 1 < K {
                Some(lists.append(d + 1, l)?)
            } else {
                None
            };
            let mut down = if l < top as usize {
                Some(lists.append(d, l + 1)?)
            } else {
                None
            };
            let (mut up_result, mut down_result) = (Ok(()), Ok(()));
            let mut combined = 0;
            let split = combine_or_split(
                &list,
                sh,
                |key| {
                    combined += 1;
                    let origin = unpack_key::<K>(top, axis, key);
                    match up.as_mut() {
                        Some(up) if up_result.is_ok() => {
                            up_result = up.push(pack_key(top, axis - 1, origin))
                        }
                        Some(_) => {}
                        None => cells.push(origin, l as u32),
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
            up_result?;
            down_result?;
            stats.combined[d - 1][l] += combined;
            stats.split[d - 1][l] += split;
            drop(list);
            for w in [up, down].into_iter().flatten() {
                lists.close(w)?;
            }
        }
    }
    stats.cells = cells.len();
    stats.peak_items = lists.stats.largest_list;
    Ok((cells.into_tree(universe, scratch), stats))
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

/// The list files ι(D, l) of one run, and what was done with them.
struct ListFiles {
    dir: PathBuf,
    created: Vec<PathBuf>,
    open: usize,
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

fn with_path(path: &Path, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

impl ListFiles {
    fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
            created: Vec::new(),
            open: 0,
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

    /// Opens ι(d, l) for appending, creating it if needed.
    fn append(&mut self, d: usize, l: usize) -> std::io::Result<Appender> {
        let path = self.path(d, l);
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

    fn close(&mut self, mut w: Appender) -> std::io::Result<()> {
        w.out.flush().map_err(|e| with_path(&w.path, e))?;
        self.stats.bytes_written += w.bytes;
        self.open -= 1;
        Ok(())
    }

    /// Reads ι(d, l) from start to end (empty if it was never written), then deletes it.
    fn read(&mut self, d: usize, l: usize) -> std::io::Result<Vec<u64>> {
        let path = self.path(d, l);
        if !self.created.contains(&path) {
            return Ok(Vec::new());
        }
        let file = File::open(&path).map_err(|e| with_path(&path, e))?;
        self.opened();
        let len = file.metadata().map_err(|e| with_path(&path, e))?.len();
        if len % 8 != 0 {
            return Err(with_path(
                &path,
                std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("a list file of {len} bytes is not whole keys"),
                ),
            ));
        }
        let mut keys = Vec::with_capacity((len / 8) as usize);
        let mut reader = BufReader::with_capacity(1 << 16, file);
        let mut buf = [0u8; 8];
        for _ in 0..len / 8 {
            reader
                .read_exact(&mut buf)
                .map_err(|e| with_path(&path, e))?;
            keys.push(u64::from_le_bytes(buf));
        }
        drop(reader);
        self.open -= 1;
        std::fs::remove_file(&path).map_err(|e| with_path(&path, e))?;
        self.created.retain(|p| p != &path);
        self.stats.bytes_read += len;
        self.stats.largest_list = self.stats.largest_list.max(keys.len() as u64);
        Ok(keys)
    }

    /// Removes every list file still present.
    fn remove_all(&mut self) {
        for path in self.created.drain(..) {
            let _ = std::fs::remove_file(path);
        }
    }
}
