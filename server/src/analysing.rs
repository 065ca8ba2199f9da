//! Where and how analyses run in the service: a rayon pool of their own whose threads run at the
//! lowest CPU priority (Linux `SCHED_IDLE`, elsewhere the highest nice value), so an analysis
//! only gets the CPU time that tile work leaves idle and can never starve serving; and the watch
//! over one analysis — its progress in percent on the texture, and what stops it: the texture's
//! removal, the service stopping, or its time budget running out.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use crate::textures::Texture;

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

    /// Its threads.
    pub fn threads(&self) -> usize {
        self.0.current_num_threads()
    }
}

/// Put the calling thread at the lowest CPU priority there is: it runs only when no other
/// thread wants the core. Failure is harmless (the pool is still bounded), so it is ignored.
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
    #[cfg(all(unix, not(target_os = "linux")))]
    // SAFETY: a plain system call; on these systems it lowers the whole process's priority.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, 19);
    }
}

/// The watch over one texture's analysis: its progress kept on the texture (percent), and the
/// answer to whether it should stop — removed, stopping, or past its deadline.
pub struct Watch<'a> {
    tex: &'a Texture,
    stop: &'a (dyn Fn() -> bool + Sync),
    budget: Duration,
    deadline: Instant,
}

impl<'a> Watch<'a> {
    /// Watch `tex`'s analysis, started now, for at most `budget`; `stop` says when the service
    /// is stopping.
    pub fn new(tex: &'a Texture, stop: &'a (dyn Fn() -> bool + Sync), budget: Duration) -> Self {
        Watch { tex, stop, budget, deadline: Instant::now() + budget }
    }

    /// Whether the time budget has run out.
    pub fn timed_out(&self) -> bool {
        Instant::now() >= self.deadline
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
        let before = self.tex.progress.swap(pct, Ordering::Relaxed);
        if pct / 25 != before / 25 || done == 0 {
            tracing::info!("texture '{}': analysis {pct} % ({what})", self.tex.config.id);
        }
    }

    fn cancelled(&self) -> bool {
        self.tex.removed.is_set() || (self.stop)() || self.timed_out()
    }
}
