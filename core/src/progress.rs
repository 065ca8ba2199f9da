//! Progress of long computations (analyses, preparations, seamless images), so front ends can
//! show it: a progress bar on the terminal, a percentage in `/textures/{id}`.

/// Receives progress from long computations, so front ends can show it.
pub trait Progress: Sync {
    /// `done` of `total` steps are finished; `what` names the current step.
    fn step(&self, done: u32, total: u32, what: &str);
}

/// A [`Progress`] that ignores everything.
pub struct NoProgress;

impl Progress for NoProgress {
    fn step(&self, _: u32, _: u32, _: &str) {}
}
