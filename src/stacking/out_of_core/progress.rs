//! Progress reports of a build.

/// What an out-of-core build is doing, for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Stacking slabs of cells (`done` of `total` slabs).
    Stacking,
    /// Writing the output file (`done` of `total` levels).
    Writing,
}

/// A progress report: `done` of `total` steps of a stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// The stage.
    pub stage: Stage,
    /// Steps done.
    pub done: u64,
    /// Steps in the stage.
    pub total: u64,
}
