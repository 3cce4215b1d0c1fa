//! `--max-memory SIZE`, `--temp-dir DIR` and `--progress`: trees written out of core, in a memory budget.
//! (`ktree op` streams version 2 files in bounded memory, and checks that trees it must load fit.)
//!
//! A command that writes a `.ktree` from rays builds it with [`ktree::stacking::Builder::to_file`] (in
//! [`crate::common::output::TreeOutput::write`]): the subtrees of the cells are spilled to temporary files
//! as they are stacked and streamed into the output, so only the top of the tree and the slabs being
//! stacked are held. The file is byte for byte the one the in-memory build writes. The budget covers what the command
//! holds besides: a solid, a sorted ray file, a mesh or a volume makes its rays slab by slab, and only its
//! own data (the ray file's index, the placed triangles, the samples) counts against it; rays read whole (an
//! unsorted ray file) count whole. A file of format version 1 is built the same way, as a version 2 file that
//! is then streamed into version 1 ([`crate::common::tree_file::as_version_1`]): the format version never
//! chooses how a tree is built.
//! Across MPI ranks the budget applies to each rank (see [`crate::distributed`]).

use std::path::PathBuf;

use ktree::{LevelCounts, RaySet};

/// The share of the machine's memory used when no `--max-memory` is given: a half.
const DEFAULT_SHARE: u64 = 2;
/// The budget when the machine's memory is unknown (no `/proc/meminfo`): 4 GiB.
const FALLBACK_BYTES: u64 = 4 << 30;

/// `--max-memory`: the memory budget of a command.
#[derive(Debug, Clone, clap::Args)]
pub struct BudgetArgs {
    /// Memory budget: bytes, or a number with K, M, G or T (powers of 1024), e.g. 512M, 2G. Default: half
    /// the machine's memory (MemTotal in /proc/meminfo; 4G where it is unknown).
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    max_memory: Option<u64>,
}

impl BudgetArgs {
    /// The budget in bytes.
    pub fn budget(&self) -> u64 {
        self.max_memory.unwrap_or_else(default_budget)
    }

    /// Checks that `what` (taking `bytes` in memory) fits in the budget; returns what is left.
    pub fn left_after(&self, what: &str, bytes: u64) -> crate::common::error::CliResult<u64> {
        let budget = self.budget();
        budget.checked_sub(bytes).ok_or_else(|| {
            crate::common::error::CliError::Failed(format!(
                "{what} take {} in memory, more than the budget of {} (--max-memory)",
                size_text(bytes),
                size_text(budget)
            ))
        })
    }
}

/// The options of the commands that build trees: worker threads, budget, spill folder, progress bar.
#[derive(Debug, Clone, clap::Args)]
pub struct BuildArgs {
    #[command(flatten)]
    pub threads: crate::common::args::ThreadsArg,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// Folder for the temporary spill files of a tree built out of core (default: the output's folder).
    #[arg(long, value_name = "DIR")]
    pub temp_dir: Option<PathBuf>,
    /// Show a progress bar (slabs of cells stacked, then levels written).
    #[arg(long)]
    pub progress: bool,
}

/// Parses `512M`, `2G`, `1.5G`, `4096` (bytes); suffixes K, M, G, T are powers of 1024, with an optional
/// `B`/`iB`.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let bad = || {
        format!("'{text}' is not a size: give bytes or a number with K, M, G or T, e.g. 512M or 2G")
    };
    let upper = t.to_ascii_uppercase();
    let upper = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, shift) = match upper.chars().last() {
        Some('K') => (&upper[..upper.len() - 1], 10),
        Some('M') => (&upper[..upper.len() - 1], 20),
        Some('G') => (&upper[..upper.len() - 1], 30),
        Some('T') => (&upper[..upper.len() - 1], 40),
        _ => (upper, 0),
    };
    let number = number.trim();
    if let Ok(n) = number.parse::<u64>() {
        return n.checked_mul(1u64 << shift).ok_or_else(bad);
    }
    let x: f64 = number.parse().map_err(|_| bad())?;
    let bytes = x * (1u64 << shift) as f64;
    if !(x.is_finite() && x >= 0.0 && bytes < u64::MAX as f64) {
        return Err(bad());
    }
    Ok(bytes as u64)
}

/// Half the machine's memory (MemTotal in `/proc/meminfo`), or 4 GiB where it is unknown.
pub fn default_budget() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|info| {
            let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
            let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kib * 1024 / DEFAULT_SHARE)
        })
        .unwrap_or(FALLBACK_BYTES)
}

/// Bytes with their size in MiB or GiB.
pub fn size_text(bytes: u64) -> String {
    const MIB: f64 = 1024.0 * 1024.0;
    let b = bytes as f64;
    if b >= 1024.0 * MIB {
        format!("{bytes} bytes ({:.2} GiB)", b / (1024.0 * MIB))
    } else {
        format!("{bytes} bytes ({:.1} MiB)", b / MIB)
    }
}

/// The voxels of a tree from its counts per level in a level-`level` universe of `k` dimensions.
pub fn voxels(k: usize, level: u32, counts: &[LevelCounts]) -> u128 {
    counts
        .iter()
        .map(|c| u128::from(c.full) << (k as u32 * (level - c.level)))
        .sum()
}

/// The memory a ray set holds: a column key and a run each, and their normals if any.
pub fn ray_bytes<const K: usize>(rays: &RaySet<K>) -> u64 {
    let per_run = 16 + if rays.has_normals() { 16 * K as u64 } else { 0 };
    rays.len() as u64 * per_run
}

/// The process's peak resident memory (VmHWM in `/proc/self/status`), in bytes; `None` where the system does
/// not report it.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib = status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?;
    Some(kib.split_whitespace().next()?.parse::<u64>().ok()? * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_suffixes() {
        assert_eq!(parse_size("4096").unwrap(), 4096);
        assert_eq!(parse_size("512M").unwrap(), 512 << 20);
        assert_eq!(parse_size("2G").unwrap(), 2 << 30);
        assert_eq!(parse_size("2GiB").unwrap(), 2 << 30);
        assert_eq!(parse_size("1.5k").unwrap(), 1536);
        assert_eq!(parse_size(" 3 T ").unwrap(), 3 << 40);
        for bad in ["", "G", "-1M", "two", "1e30G", "5X"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert!(default_budget() > 0);
    }
}
