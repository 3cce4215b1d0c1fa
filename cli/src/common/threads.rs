//! Worker threads: every command that stacks or combines trees runs on a pool of `--threads` threads.

use crate::common::error::{CliError, CliResult};

/// Runs `work` on a pool of `threads` worker threads (all cores when `None`).
pub fn with_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> T + Send,
) -> CliResult<T> {
    Ok(thread_pool(threads)?.install(work))
}

/// A pool of `threads` worker threads (all cores when `None`).
pub fn thread_pool(threads: Option<usize>) -> CliResult<rayon::ThreadPool> {
    if threads == Some(0) {
        return Err("--threads 0: at least one thread is needed".into());
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| CliError::about("cannot start worker threads", e))
}
