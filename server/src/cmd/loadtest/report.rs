//! `textile loadtest`'s figures: latency percentiles from HDR histograms (p50, p90, p99, p99.9,
//! max; of every answer, and of 200s only — without shed requests), status counts, a per-second
//! timeline, and the histogram in HdrHistogram's percentile-distribution text format (what
//! HdrHistogram's plotters read).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use hdrhistogram::Histogram;
use serde_json::{json, Value};

use super::drive::{Sample, NEVER_SENT, TIMED_OUT, TRANSPORT_ERROR};

/// Microseconds, 1 µs to an hour, three significant digits.
pub fn histogram<'a>(latencies: impl Iterator<Item = std::time::Duration> + 'a) -> Histogram<u64> {
    let mut h = Histogram::<u64>::new_with_bounds(1, 3_600_000_000, 3).unwrap_or_else(|_| Histogram::new(3).unwrap());
    for d in latencies {
        let _ = h.record((d.as_micros() as u64).clamp(1, 3_600_000_000));
    }
    h
}

/// Whether a sample's latency enters a histogram: an answer (`ok_only`: a 200); and, from the
/// intended send time (`corrected`), a request unanswered by the end too — timed out in flight
/// or never sent — whose latency is then at least the end of the run minus when it was due, so
/// a stalled server shows as the disaster it is instead of vanishing from the figures.
fn counted(s: &Sample, ok_only: bool, corrected: bool) -> bool {
    match s.status {
        200 => true,
        _ if ok_only => false,
        TRANSPORT_ERROR => false,
        _ if s.unanswered() => corrected,
        _ => true,
    }
}

/// The latencies of the samples that ended with an answer (`ok_only`: a 200), corrected or not;
/// corrected, the unanswered ones too (see [`counted`]).
pub fn latencies(samples: &[Sample], ok_only: bool, corrected: bool) -> Histogram<u64> {
    histogram(samples.iter().filter(|s| counted(s, ok_only, corrected)).map(|s| {
        if corrected {
            s.corrected()
        } else {
            s.uncorrected()
        }
    }))
}

/// Percentiles in milliseconds; null when there is nothing to measure.
pub fn percentiles(h: &Histogram<u64>) -> Value {
    if h.is_empty() {
        return json!({ "p50": null, "p90": null, "p99": null, "p99_9": null, "max": null });
    }
    let q = |p: f64| h.value_at_quantile(p) as f64 / 1e3;
    json!({ "p50": q(0.5), "p90": q(0.9), "p99": q(0.99), "p99_9": q(0.999), "max": h.max() as f64 / 1e3 })
}

/// A percentile object as one line of text.
pub fn line(p: &Value) -> String {
    let f = |k: &str| p[k].as_f64().map_or("n/a".to_string(), |v| format!("{v:.2}"));
    format!("p50 {}  p90 {}  p99 {}  p99.9 {}  max {}", f("p50"), f("p90"), f("p99"), f("p99_9"), f("max"))
}

/// Status counts: HTTP codes, `error` (no answer) and `timed_out` (in flight at the deadline).
pub fn statuses(samples: &[Sample]) -> BTreeMap<String, u64> {
    let mut m = BTreeMap::new();
    for s in samples {
        let key = match s.status {
            TRANSPORT_ERROR => "error".to_string(),
            TIMED_OUT => "timed_out".to_string(),
            NEVER_SENT => "never_sent".to_string(),
            c => c.to_string(),
        };
        *m.entry(key).or_insert(0) += 1;
    }
    m
}

/// Per second of the run, by when requests were meant to be sent (the closed loop: when they
/// were sent): requests, errors, and p50 / p99 of the latency the report leads with
/// (`corrected` for the open model) — what became of the load offered that second, as
/// open-model tools chart it. Answers still arriving after the last send (the drain) count
/// with their requests' seconds, and every second of the run has its row, sends or none (a run
/// of `D` seconds has at least `D` rows). Requests never sent count in the second they were due,
/// and with the corrected latency, they and those timed out count at their latency to the end.
pub fn timeline(samples: &[Sample], seconds: f64, corrected: bool) -> Vec<Value> {
    let last = samples.iter().map(|s| s.intended.as_secs() as usize + 1).max().unwrap_or(0);
    let n = last.max((seconds - 1e-6).ceil().max(1.0) as usize);
    let mut by: Vec<Vec<&Sample>> = vec![Vec::new(); n];
    for s in samples {
        by[s.intended.as_secs() as usize].push(s);
    }
    by.iter()
        .enumerate()
        .map(|(i, v)| {
            let counted: Vec<&&Sample> = v.iter().filter(|s| counted(s, false, corrected)).collect();
            let h = histogram(counted.iter().map(|s| if corrected { s.corrected() } else { s.uncorrected() }));
            let q = |p: f64| (!h.is_empty()).then(|| h.value_at_quantile(p) as f64 / 1e3);
            json!({
                "second": i, "requests": v.iter().filter(|s| s.was_sent()).count(),
                "unanswered": v.iter().filter(|s| s.unanswered()).count(),
                "errors": v.iter().filter(|s| s.is_error()).count(),
                "p50_ms": q(0.5), "p99_ms": q(0.99),
            })
        })
        .collect()
}

/// The histogram (µs) as HdrHistogram's percentile distribution in milliseconds: `Value
/// Percentile TotalCount 1/(1-Percentile)` rows, then the mean, deviation, max and count.
pub fn distribution_text(h: &Histogram<u64>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{:>12} {:>14} {:>10} {:>14}\n", "Value", "Percentile", "TotalCount", "1/(1-Percentile)");
    let mut total = 0u64;
    for v in h.iter_quantiles(5) {
        total += v.count_since_last_iteration();
        let p = v.quantile_iterated_to();
        let inv = if p < 1.0 { format!("{:14.2}", 1.0 / (1.0 - p)) } else { format!("{:>14}", "") };
        let _ = writeln!(s, "{:12.3} {:14.12} {:10} {inv}", v.value_iterated_to() as f64 / 1e3, p, total);
    }
    let _ = writeln!(s, "#[Mean    = {:12.3}, StdDeviation   = {:12.3}]", h.mean() / 1e3, h.stdev() / 1e3);
    let _ = writeln!(s, "#[Max     = {:12.3}, Total count    = {:12}]", h.max() as f64 / 1e3, h.len());
    s
}
