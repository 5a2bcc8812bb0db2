//! Progress of long library runs (renders, fits), reported through a small trait so that the
//! library draws nothing itself: the `xylem` command line shows it as an indicatif bar
//! (`cli::progress`), embedders (the Python bindings, renderer plugins) pass their own or
//! [`NoProgress`].

/// Receives the progress of a run of `total` steps (tiles of a render, texels of a fit).
///
/// Called from the run's worker threads, so `done` may arrive slightly out of order; a step
/// takes milliseconds, so an implementation may lock or allocate in [`Progress::update`].
pub trait Progress: Sync {
    /// A run of `total` steps starts; `unit` names the steps as a reader sees them
    /// (`tiles`, `tiles × 48 frames`, `texels`).
    fn start(&self, _total: u64, _unit: &str) {}
    /// `done` of `total` steps are finished; `message` is a figure of the run so far, such as
    /// the render's `12.34 Mrays/s` (empty when the run has none).
    fn update(&self, done: u64, total: u64, message: &str);
    /// The run ended: called once, after the last [`Progress::update`].
    fn finish(&self) {}
    /// True when the caller wants the run to stop (Ctrl-C in Python): a render checks it
    /// before each tile and ends with `RenderError::Stopped`.
    fn stop(&self) -> bool {
        false
    }
}

/// Reports nothing: the default of [`crate::render::RunOptions`] and [`crate::fit::FitOptions`].
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn update(&self, _done: u64, _total: u64, _message: &str) {}
}

/// Lets option structs holding a `&dyn Progress` derive `Debug`.
impl std::fmt::Debug for dyn Progress + '_ {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("dyn Progress")
    }
}
