//! Driving the load. The **closed** loop: each of N connections sends its next request when the
//! last one is answered. The **open** model: requests arrive on a schedule — a constant rate, or a
//! rate ramped linearly over the run — whatever the answers; the connections bound how many are in
//! flight, and a request that has to wait for a free one is sent late. Every request started is
//! recorded with its intended and actual send times, so latency can be taken from either: from
//! the intended time it is corrected for coordinated omission (as wrk2 does).

use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use tokio::sync::Semaphore;
use tokio::time::Instant;

use super::pattern::Paths;
use super::verify::{digest, References};

/// Status recorded for a request that failed below HTTP (connection refused, reset, …).
pub const TRANSPORT_ERROR: u16 = 0;
/// Status recorded for a request still in flight at the deadline.
pub const TIMED_OUT: u16 = u16::MAX;
/// Status recorded for an arrival that was due before the deadline but never sent (open model:
/// every connection was waiting on the server until the end).
pub const NEVER_SENT: u16 = u16::MAX - 1;

/// One request started: times since the phase began, the answer's status and size.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// When it was meant to be sent (the closed loop: when it was sent).
    pub intended: Duration,
    /// When it was sent.
    pub sent: Duration,
    /// When its answer was read whole (or the deadline, for a timed-out one).
    pub done: Duration,
    /// HTTP status, or [`TRANSPORT_ERROR`] / [`TIMED_OUT`].
    pub status: u16,
    /// Body bytes.
    pub bytes: usize,
    /// A 200 whose body differs from the reference (`--verify`).
    pub mismatch: bool,
}

impl Sample {
    /// Latency from the intended send time (coordinated omission corrected).
    pub fn corrected(&self) -> Duration {
        self.done.saturating_sub(self.intended)
    }
    /// Latency from the actual send time.
    pub fn uncorrected(&self) -> Duration {
        self.done.saturating_sub(self.sent)
    }
    /// Whether it counts as an error: a transport failure, a 4xx/5xx, or a body that differs
    /// from its reference. A request still unanswered at the end ([`Sample::unanswered`]) is
    /// counted apart, not as an error: a closed loop always ends with some in flight.
    pub fn is_error(&self) -> bool {
        !self.unanswered() && (self.status == TRANSPORT_ERROR || self.status >= 400 || self.mismatch)
    }

    /// Whether it was sent at all.
    pub fn was_sent(&self) -> bool {
        self.status != NEVER_SENT
    }

    /// Whether it got no answer by the end of the run: timed out in flight, or never sent. Its
    /// latency from its intended send time is then at least the run's end minus that time.
    pub fn unanswered(&self) -> bool {
        self.status == TIMED_OUT || self.status == NEVER_SENT
    }
}

/// How requests are issued.
#[derive(Debug, Clone)]
pub enum Model {
    /// Each connection sends when its last answer is in; `polite`: after a 503 it waits the
    /// advised Retry-After first.
    Closed {
        /// Honour Retry-After.
        polite: bool,
    },
    /// Arrivals at a rate going linearly from `from` to `to` requests per second over the phase.
    Open {
        /// Rate at the start.
        from: f64,
        /// Rate at the end.
        to: f64,
    },
    /// Arrivals at given times (seconds after the start, ascending): a log replayed at its pace.
    Timed(Arc<Vec<f64>>),
}

/// A phase's bounds: it ends at `seconds` or after `max_requests`, whichever comes first.
#[derive(Debug, Clone, Copy)]
pub struct Phase {
    /// Length in seconds.
    pub seconds: f64,
    /// Most requests started.
    pub max_requests: u64,
}

/// What a phase did.
pub struct Outcome {
    /// Every request started.
    pub samples: Vec<Sample>,
    /// Wall-clock length of the phase.
    pub seconds: f64,
    /// Open model: arrivals due before the deadline that were never sent (every connection was
    /// busy until then); each is also a [`NEVER_SENT`] sample ending at the deadline.
    pub unsent: u64,
}

/// The load: where it goes, what it asks for, and how.
pub struct Load {
    /// HTTP client (its pool holds the connections).
    pub client: reqwest::Client,
    /// The server: every request goes to it ([`super::pattern::target`]).
    pub root: reqwest::Url,
    /// Request paths, shared by the connections.
    pub paths: Arc<Mutex<Paths>>,
    /// Connections (open model: most requests in flight).
    pub concurrency: usize,
    /// Closed or open.
    pub model: Model,
    /// Print a progress line on the terminal (stderr) once a second.
    pub progress: bool,
    /// `--verify`: the reference digest of every path.
    pub references: Option<Arc<References>>,
    /// Paths whose answers differed from their reference: (expected, got, how often).
    pub mismatches: Mutex<std::collections::BTreeMap<String, (String, String, u64)>>,
    /// Verifying, the digests of the 200 answers of paths without a reference yet, by path and
    /// digest, with their counts: checked once the references are fetched after the run (so
    /// that fetching them does not warm the server's cache for the measured run).
    pub unchecked: Mutex<std::collections::BTreeMap<String, std::collections::BTreeMap<String, u64>>>,
}

/// Seconds after the start at which arrival `i` is due, at a rate going linearly from `from` to
/// `to` over `seconds`: the inverse of the arrivals counted up to t, `from·t + (to − from)·t²/2T`.
pub fn arrival(i: u64, from: f64, to: f64, seconds: f64) -> f64 {
    let i = i as f64;
    if (to - from).abs() < 1e-12 {
        return i / from;
    }
    let a = (to - from) / (2.0 * seconds);
    let disc = from * from + 4.0 * a * i;
    if disc < 0.0 {
        return f64::INFINITY;
    }
    (-from + disc.sqrt()) / (2.0 * a)
}

/// Counters behind the progress line.
#[derive(Default)]
struct Progress {
    done: AtomicU64,
    errors: AtomicU64,
}

impl Progress {
    fn record(&self, s: &Sample) {
        self.done.fetch_add(1, Ordering::Relaxed);
        if s.is_error() {
            self.errors.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// One answer: status, body size, advised Retry-After, and whether a 200 differed from the
/// reference.
struct Answer {
    status: u16,
    bytes: usize,
    retry: Option<u64>,
    mismatch: bool,
}

impl Answer {
    /// The sample of this answer, ended now.
    fn sample(&self, intended: Duration, sent: Duration, start: Instant) -> Sample {
        let (status, bytes, mismatch) = (self.status, self.bytes, self.mismatch);
        Sample { intended, sent, done: start.elapsed(), status, bytes, mismatch }
    }
}

impl Load {
    /// One request of `path`, checked against its reference when verifying; [`TIMED_OUT`] at
    /// `deadline`.
    async fn request(&self, path: &str, deadline: Instant) -> Answer {
        let r = tokio::time::timeout_at(deadline, async {
            let resp = self.client.get(super::pattern::target(&self.root, path)).send().await?;
            let status = resp.status().as_u16();
            let retry = resp.headers().get("retry-after").and_then(|v| v.to_str().ok()?.parse::<u64>().ok());
            let body = resp.bytes().await?;
            Ok::<_, reqwest::Error>((status, body, retry))
        })
        .await;
        let (status, body, retry) = match r {
            Ok(Ok(x)) => x,
            Ok(Err(_)) => return Answer { status: TRANSPORT_ERROR, bytes: 0, retry: None, mismatch: false },
            Err(_) => return Answer { status: TIMED_OUT, bytes: 0, retry: None, mismatch: false },
        };
        let references = self.references.as_ref().filter(|_| status == 200);
        if references.is_some_and(|r| !r.contains_key(path)) {
            let mut u = self.unchecked.lock().unwrap_or_else(|e| e.into_inner());
            *u.entry(path.to_string()).or_default().entry(digest(&body)).or_insert(0) += 1;
        }
        let expected = references.and_then(|r| r.get(path));
        let mismatch = match expected {
            Some(want) => {
                let got = digest(&body);
                let differs = &got != want;
                if differs {
                    let mut m = self.mismatches.lock().unwrap_or_else(|e| e.into_inner());
                    m.entry(path.to_string()).or_insert_with(|| (want.clone(), got, 0)).2 += 1;
                }
                differs
            }
            None => false,
        };
        Answer { status, bytes: body.len(), retry, mismatch }
    }

    fn next_path(&self) -> Option<String> {
        self.paths.lock().unwrap_or_else(|e| e.into_inner()).next()
    }

    /// Run one phase.
    pub async fn run(self: &Arc<Self>, phase: Phase) -> Outcome {
        let start = Instant::now();
        let deadline = start + Duration::from_secs_f64(phase.seconds);
        let progress = Arc::new(Progress::default());
        let ticker = self.progress.then(|| {
            let p = progress.clone();
            tokio::spawn(async move {
                let mut tick = tokio::time::interval(Duration::from_secs(1));
                tick.tick().await;
                loop {
                    tick.tick().await;
                    let (t, n) = (start.elapsed().as_secs_f64(), p.done.load(Ordering::Relaxed));
                    let e = p.errors.load(Ordering::Relaxed);
                    let mut err = std::io::stderr().lock();
                    let _ = write!(err, "\r{t:6.1} s  {n} requests  {:.1} req/s  {e} errors   ", n as f64 / t);
                    let _ = err.flush();
                }
            })
        });
        let (samples, unsent) = match self.model {
            Model::Closed { polite } => (self.closed(phase, start, deadline, polite, &progress).await, 0),
            Model::Open { from, to } => {
                let due = move |i| arrival(i, from, to, phase.seconds);
                self.open(phase, start, deadline, &due, &progress).await
            }
            Model::Timed(ref at) => {
                let due = |i: u64| at.get(i as usize).copied().unwrap_or(f64::INFINITY);
                self.open(phase, start, deadline, &due, &progress).await
            }
        };
        if let Some(t) = ticker {
            t.abort();
            if std::io::stderr().is_terminal() {
                eprint!("\r{:60}\r", "");
            }
        }
        Outcome { samples, seconds: start.elapsed().as_secs_f64(), unsent }
    }

    async fn closed(
        self: &Arc<Self>,
        phase: Phase,
        start: Instant,
        deadline: Instant,
        polite: bool,
        progress: &Arc<Progress>,
    ) -> Vec<Sample> {
        let issued = Arc::new(AtomicU64::new(0));
        let mut tasks = Vec::new();
        for _ in 0..self.concurrency {
            let (load, issued, progress) = (self.clone(), issued.clone(), progress.clone());
            tasks.push(tokio::spawn(async move {
                let mut out = Vec::new();
                while Instant::now() < deadline && issued.fetch_add(1, Ordering::Relaxed) < phase.max_requests {
                    let Some(path) = load.next_path() else { break };
                    let sent = start.elapsed();
                    let a = load.request(&path, deadline).await;
                    let s = a.sample(sent, sent, start);
                    progress.record(&s);
                    out.push(s);
                    if a.status == TIMED_OUT {
                        break;
                    }
                    if let Some(secs) = a.retry.filter(|_| polite && a.status == 503) {
                        let wait = Instant::now() + Duration::from_secs(secs.min(60));
                        tokio::time::sleep_until(wait.min(deadline)).await;
                    }
                }
                out
            }));
        }
        let mut all = Vec::new();
        for t in tasks {
            all.extend(t.await.unwrap_or_default());
        }
        all
    }

    async fn open(
        self: &Arc<Self>,
        phase: Phase,
        start: Instant,
        deadline: Instant,
        due: &(dyn Fn(u64) -> f64 + Sync),
        progress: &Arc<Progress>,
    ) -> (Vec<Sample>, u64) {
        let connections = Arc::new(Semaphore::new(self.concurrency));
        let mut tasks = Vec::new();
        let mut unsent = 0;
        let mut never_sent = Vec::new();
        let mut i = 0u64;
        while i < phase.max_requests {
            let t = due(i);
            if t.is_nan() || t >= phase.seconds {
                break;
            }
            let intended = Duration::from_secs_f64(t);
            tokio::time::sleep_until(start + intended).await;
            // A free connection, waited for up to the deadline: the wait is part of the
            // request's corrected latency.
            let Ok(Ok(permit)) = tokio::time::timeout_at(deadline, connections.clone().acquire_owned()).await else {
                // Every connection stayed busy to the end: the arrivals still due were never
                // sent. Each ends unanswered at the deadline, its latency counted from when it
                // was due (as wrk2 and k6 count it), not left out.
                let end = deadline.saturating_duration_since(start);
                while i < phase.max_requests && due(i) < phase.seconds {
                    let intended = Duration::from_secs_f64(due(i));
                    never_sent.push(Sample {
                        intended,
                        sent: end,
                        done: end,
                        status: NEVER_SENT,
                        bytes: 0,
                        mismatch: false,
                    });
                    unsent += 1;
                    i += 1;
                }
                break;
            };
            let Some(path) = self.next_path() else { break };
            let (load, progress) = (self.clone(), progress.clone());
            tasks.push(tokio::spawn(async move {
                let sent = start.elapsed();
                let a = load.request(&path, deadline).await;
                drop(permit);
                let s = a.sample(intended, sent, start);
                progress.record(&s);
                s
            }));
            i += 1;
        }
        let mut all = Vec::with_capacity(tasks.len() + never_sent.len());
        for t in tasks {
            if let Ok(s) = t.await {
                all.push(s);
            }
        }
        all.extend(never_sent);
        (all, unsent)
    }
}

#[cfg(test)]
mod tests {
    use super::arrival;

    #[test]
    fn arrivals_follow_the_rate() {
        assert_eq!(arrival(200, 100.0, 100.0, 10.0), 2.0);
        // 0 → 200 req/s over 10 s: 1000 arrivals in all, the first half of them after 7.07 s.
        assert!((arrival(1000, 0.0, 200.0, 10.0) - 10.0).abs() < 1e-9);
        assert!((arrival(500, 0.0, 200.0, 10.0) - 50f64.sqrt()).abs() < 1e-9);
        // Ramping down: 200 → 100 over 10 s is 1500 arrivals.
        assert!((arrival(1500, 200.0, 100.0, 10.0) - 10.0).abs() < 1e-9);
    }
}
