//! Where and how analyses run in the service: a rayon pool of their own whose threads run at the
//! lowest CPU priority (Linux `SCHED_IDLE`, else the thread's highest nice value), so an analysis
//! only gets the CPU time that tile work leaves idle and can never starve serving; and the watch
//! over one analysis — its progress in percent on the texture, and what stops it: the texture's
//! removal, the service stopping, or its time budget running out.

use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use textile_core::Cancel;

/// The analysis pool.
pub struct AnalysisPool(rayon::ThreadPool);

impl AnalysisPool {
    /// A pool of `threads` threads (0: one fewer than the cores, at least one).
    pub fn new(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = if threads == 0 { cores.saturating_sub(1).max(1) } else { threads };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("textile-analysis-{i}"))
            .start_handler(|_| lowest_priority())
            .build()
            .map(AnalysisPool)
    }

    /// Run `f` with its parallel work (rayon) on this pool's threads; the caller waits.
    pub fn run<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.0.install(f)
    }
}

/// Put the calling thread at the lowest CPU priority there is: it runs only when no other
/// thread wants the core. Linux sets both per thread; elsewhere the same calls would lower the
/// whole process, serving included, so the pool is only bounded there. Failure is harmless (the
/// pool is still bounded), so it is ignored.
fn lowest_priority() {
    #[cfg(target_os = "linux")]
    {
        let param = libc::sched_param { sched_priority: 0 };
        // SAFETY: plain system calls on the calling thread (pid 0), with a valid parameter.
        unsafe {
            if libc::sched_setscheduler(0, libc::SCHED_IDLE, &param) != 0 {
                libc::setpriority(libc::PRIO_PROCESS, 0, 19);
            }
        }
    }
}

/// The watch over one texture's analysis: its progress kept on the texture (percent), and the
/// token that stops it — set when the texture is removed, when the service stops, or at its
/// deadline.
pub struct Watch<'a> {
    /// The texture's id, for the log.
    id: &'a str,
    /// Where its progress is kept, in percent.
    progress: &'a AtomicU32,
    budget: Duration,
    cancel: Cancel,
}

impl<'a> Watch<'a> {
    /// Watch the analysis of texture `id`, started now, for at most `budget`: its progress kept
    /// in `progress`, stopped once `removed` (the texture's) or `stopping` (the service's) is set.
    pub fn new(id: &'a str, progress: &'a AtomicU32, removed: &Cancel, stopping: &Cancel, budget: Duration) -> Self {
        let cancel = Cancel::within(&[removed, stopping], Some(Instant::now() + budget));
        Watch { id, progress, budget, cancel }
    }

    /// The token the analysis is run with.
    pub fn cancel(&self) -> &Cancel {
        &self.cancel
    }

    /// Whether the time budget has run out.
    pub fn timed_out(&self) -> bool {
        self.cancel.past_deadline()
    }

    /// The failure of an analysis stopped by its time budget.
    pub fn timeout_message(&self) -> String {
        format!(
            "the analysis took longer than its budget of {} s (analysis_timeout_secs) and was stopped",
            self.budget.as_secs()
        )
    }
}

impl textile_core::Progress for Watch<'_> {
    fn step(&self, done: u32, total: u32, what: &str) {
        // Steps are bands of the candidate search, a level's bands cost alike, so the share of
        // steps done is a fair share of the work.
        let pct = if done >= total { 100 } else { (done as u64 * 100 / total.max(1) as u64).min(99) as u32 };
        let before = self.progress.swap(pct, Ordering::Relaxed);
        if pct / 25 != before / 25 || done == 0 {
            tracing::info!("texture '{}': analysis {pct} % ({what})", self.id);
        }
    }
}
