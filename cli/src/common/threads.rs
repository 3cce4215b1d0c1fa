//! Worker threads: every command that stacks or combines trees runs on a pool of `--threads` threads.

/// Runs `work` on a pool of `threads` worker threads (all cores when `None`).
pub fn with_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> T + Send,
) -> Result<T, String> {
    Ok(thread_pool(threads)?.install(work))
}

/// A pool of `threads` worker threads (all cores when `None`).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, String> {
    if threads == Some(0) {
        return Err("--threads 0: at least one thread is needed".into());
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| format!("cannot start worker threads: {e}"))
}
