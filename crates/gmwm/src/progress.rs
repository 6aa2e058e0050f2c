//! Progress reporting of long inference runs (STYLE §4): the engine calls the hooks, a front
//! end (e.g. the CLI's indicatif bar) implements them; no terminal code here.

/// Receives progress of a replicate loop. Both methods default to no-ops; implementations must
/// be `Sync` because replicates finish on several threads.
///
/// Any `Fn(usize) + Sync` closure is a `Progress` whose call receives the number of replicates
/// done so far.
pub trait Progress: Sync {
    /// Called once before the loop with the number of replicates to run.
    fn start(&self, _total: usize) {}
    /// Called each time a replicate finishes, with the number finished so far (in completion
    /// order, so successive calls from different threads may arrive out of order).
    fn advance(&self, _done: usize) {}
}

/// No progress reporting.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct NoProgress;

impl Progress for NoProgress {}

impl<F: Fn(usize) + Sync> Progress for F {
    fn advance(&self, done: usize) {
        self(done)
    }
}
