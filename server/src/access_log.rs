//! The access log's writer: one line per answered request ([`Entry`]), as a JSON object or in
//! Combined Log Format, handed over a bounded channel to a thread of its own that appends them
//! to a file (or stdout). A request never waits for it: when the channel is full the line is
//! dropped and counted (`textile_access_log_dropped_total`), and so is every line a failed
//! write or flush held (a full disk); `textile_access_log_lines_total` counts lines written. [`AccessLog::reopen`] (SIGHUP)
//! makes the writer close and reopen its file, so logrotate can move it away. How the HTTP layer
//! fills an [`Entry`] is `http::access`'s.

use std::fs::OpenOptions;
use std::io::{self, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use prometheus::IntCounter;

/// How lines are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// One JSON object a line: `ts` (Unix milliseconds of the request's arrival), `time` (the
    /// same, RFC 3339 UTC), `method`, `path` (with the query), `status`, `bytes` (of the body
    /// sent), `ms` (from arrival to the body's last byte), `cache` (`hit`, `miss` or `-`),
    /// `client`, and `aborted` when the client went away before the body ended.
    Json,
    /// Apache/nginx Combined Log Format (second timestamps, as that format has).
    Combined,
}

impl Format {
    /// The format named by the `access_log_format` setting.
    pub fn parse(name: &str) -> Option<Format> {
        match name {
            "json" => Some(Format::Json),
            "combined" => Some(Format::Combined),
            _ => None,
        }
    }
}

/// A line of the JSON access log (`access_log_format = "json"`), as the server writes it and as
/// `textile loadtest --replay` reads it back: one type for both. Its fields are written in this
/// (alphabetical) order; a reader needs only `ts` and `path` (`method` defaults to GET, `status`
/// to 200).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JsonRecord {
    /// The client went away before the body ended (written only then).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub aborted: bool,
    /// Body bytes sent.
    #[serde(default)]
    pub bytes: u64,
    /// `hit`, `miss` or `-`.
    #[serde(default)]
    pub cache: String,
    /// Client address.
    #[serde(default)]
    pub client: String,
    /// Request method.
    #[serde(default = "JsonRecord::get")]
    pub method: String,
    /// From arrival to the body's end, milliseconds (thousandths).
    #[serde(default)]
    pub ms: f64,
    /// Path and query, as requested.
    #[serde(default)]
    pub path: Option<String>,
    /// Status sent.
    #[serde(default = "JsonRecord::ok")]
    pub status: u16,
    /// Arrival, UTC, to the millisecond.
    #[serde(default)]
    pub time: String,
    /// Arrival, Unix milliseconds.
    #[serde(default)]
    pub ts: Option<i64>,
}

impl JsonRecord {
    fn get() -> String {
        "GET".into()
    }

    fn ok() -> u16 {
        200
    }
}

/// One answered request.
#[derive(Debug, Clone)]
pub struct Entry {
    /// Arrival, Unix milliseconds.
    pub ts_ms: u64,
    /// Client address (without port).
    pub client: String,
    /// Request method.
    pub method: String,
    /// Path and query, as requested.
    pub path: String,
    /// HTTP version, e.g. `HTTP/1.1`.
    pub version: &'static str,
    /// Status sent.
    pub status: u16,
    /// Body bytes sent.
    pub bytes: u64,
    /// From arrival to the body's end (or the client's going away), milliseconds.
    pub ms: f64,
    /// The `x-cache` answer: `hit`, `miss`, or `-` for answers the tile cache did not see.
    pub cache: &'static str,
    /// Whether the client went away before the body ended.
    pub aborted: bool,
    /// `Referer`, if sent.
    pub referer: Option<String>,
    /// `User-Agent`, if sent.
    pub user_agent: Option<String>,
}

/// Civil date `(year, month, day)` of days since 1970-01-01 (proleptic Gregorian).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

const MONTHS: [&str; 12] = ["Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"];

/// `(year, month, day, hour, minute, second, millisecond)` of Unix milliseconds, UTC.
fn utc(ts_ms: u64) -> (i64, u32, u32, u64, u64, u64, u64) {
    let secs = ts_ms / 1000;
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    let s = secs % 86_400;
    (y, m, d, s / 3600, s / 60 % 60, s % 60, ts_ms % 1000)
}

impl Entry {
    /// The line, with its newline.
    pub fn line(&self, format: Format) -> String {
        let (y, mo, d, h, mi, s, ms) = utc(self.ts_ms);
        match format {
            Format::Json => {
                let record = JsonRecord {
                    aborted: self.aborted,
                    bytes: self.bytes,
                    cache: self.cache.to_string(),
                    client: self.client.clone(),
                    method: self.method.clone(),
                    ms: (self.ms * 1000.0).round() / 1000.0,
                    path: Some(self.path.clone()),
                    status: self.status,
                    time: format!("{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{s:02}.{ms:03}Z"),
                    ts: Some(self.ts_ms as i64),
                };
                format!("{}\n", serde_json::to_string(&record).unwrap_or_default())
            }
            Format::Combined => {
                let quoted = |v: &Option<String>| match v {
                    Some(v) => format!("\"{}\"", v.replace('\\', "\\\\").replace('"', "\\\"")),
                    None => "\"-\"".into(),
                };
                let month = MONTHS[(mo - 1) as usize];
                format!(
                    "{} - - [{d:02}/{month}/{y:04}:{h:02}:{mi:02}:{s:02} +0000] \"{} {} {}\" {} {} {} {}\n",
                    self.client,
                    self.method,
                    self.path.replace('"', "%22"),
                    self.version,
                    self.status,
                    self.bytes,
                    quoted(&self.referer),
                    quoted(&self.user_agent),
                )
            }
        }
    }
}

/// What the writer is sent.
enum Message {
    Line(String),
    /// Write what is queued, then end.
    Close,
}

/// Where lines go.
#[derive(Debug, Clone)]
enum Target {
    Stdout,
    File(PathBuf),
}

impl Target {
    /// Open for appending. A FIFO is opened without waiting for a reader (none: an error now,
    /// not a hang), then written with blocking writes: only the writer thread ever waits.
    fn open(&self) -> io::Result<Box<dyn Write + Send>> {
        use std::os::unix::fs::OpenOptionsExt;
        use std::os::unix::io::AsRawFd;
        let p = match self {
            Target::Stdout => return Ok(Box::new(io::stdout())),
            Target::File(p) => p,
        };
        let f = OpenOptions::new().create(true).append(true).custom_flags(libc::O_NONBLOCK).open(p).map_err(|e| {
            if e.raw_os_error() == Some(libc::ENXIO) {
                io::Error::other(format!("{}: a FIFO that no process reads", p.display()))
            } else {
                io::Error::new(e.kind(), format!("{}: {e}", p.display()))
            }
        })?;
        // SAFETY: fcntl on a descriptor this function owns, with flags it just read.
        unsafe {
            let fd = f.as_raw_fd();
            let flags = libc::fcntl(fd, libc::F_GETFL);
            if flags >= 0 {
                libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK);
            }
        }
        Ok(Box::new(f))
    }
}

/// The access log: a bounded channel to its writer thread.
pub struct AccessLog {
    format: Format,
    tx: SyncSender<Message>,
    reopen: Arc<AtomicBool>,
    dropped: IntCounter,
    writer: Mutex<Option<JoinHandle<()>>>,
}

/// Longest a written line waits in the writer's buffer before it is flushed.
const FLUSH_EVERY: Duration = Duration::from_millis(200);

impl AccessLog {
    /// Open `path` (`-`: stdout) for appending and start the writer; `buffer` lines wait for it
    /// at most. `written` counts lines written (and flushed), `dropped` those lost: the channel
    /// was full, or their write or flush failed.
    pub fn open(
        path: &str,
        format: Format,
        buffer: usize,
        written: IntCounter,
        dropped: IntCounter,
    ) -> io::Result<AccessLog> {
        let target = if path == "-" { Target::Stdout } else { Target::File(PathBuf::from(path)) };
        let out = target.open()?;
        let (tx, rx) = mpsc::sync_channel(buffer.max(1));
        let reopen = Arc::new(AtomicBool::new(false));
        let writer = {
            let (reopen, dropped) = (reopen.clone(), dropped.clone());
            std::thread::Builder::new()
                .name("textile-access-log".into())
                .spawn(move || write_lines(rx, out, target, &reopen, (&written, &dropped)))?
        };
        Ok(AccessLog { format, tx, reopen, dropped, writer: Mutex::new(Some(writer)) })
    }

    /// Hand a request's line to the writer, or drop it (counted) if the writer is behind.
    pub fn record(&self, e: &Entry) {
        match self.tx.try_send(Message::Line(e.line(self.format))) {
            Ok(()) => {}
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => self.dropped.inc(),
        }
    }

    /// Ask the writer to close and reopen its file (after the lines already queued).
    pub fn reopen(&self) {
        self.reopen.store(true, Ordering::Relaxed);
    }

    /// Write what is queued and stop the writer, waiting for it at most `deadline` (a writer
    /// stuck on a full pipe is left behind).
    pub fn close(&self, deadline: Duration) {
        let Some(writer) = self.writer.lock().ok().and_then(|mut w| w.take()) else { return };
        let end = std::time::Instant::now() + deadline;
        let mut msg = Message::Close;
        loop {
            match self.tx.try_send(msg) {
                Err(TrySendError::Full(m)) if std::time::Instant::now() < end => {
                    msg = m;
                    std::thread::sleep(Duration::from_millis(5));
                }
                _ => break,
            }
        }
        while !writer.is_finished() && std::time::Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
        if writer.is_finished() {
            let _ = writer.join();
        }
    }
}

/// Bytes of lines gathered before they are written together.
const BATCH: usize = 64 << 10;

/// Lines gathered and not yet written: written together, then counted as written — or, when
/// the write or its flush fails, every one of them counted as dropped.
struct Batch {
    bytes: Vec<u8>,
    lines: u64,
}

impl Batch {
    fn push(&mut self, line: &str) {
        self.bytes.extend_from_slice(line.as_bytes());
        self.lines += 1;
    }

    /// Write and flush the gathered lines; count them.
    fn write(&mut self, out: &mut dyn Write, written: &IntCounter, dropped: &IntCounter) -> io::Result<()> {
        let done = if self.lines == 0 { Ok(()) } else { out.write_all(&self.bytes).and_then(|()| out.flush()) };
        match &done {
            Ok(()) => written.inc_by(self.lines),
            Err(_) => dropped.inc_by(self.lines),
        }
        self.bytes.clear();
        self.lines = 0;
        done
    }
}

/// The writer thread: gather lines, write them when the channel runs dry (or every
/// [`FLUSH_EVERY`], or [`BATCH`] bytes), reopen the file when asked. A line counts as written
/// once its write and flush succeeded; lines a failed write or flush held count as dropped.
fn write_lines(
    rx: Receiver<Message>,
    mut out: Box<dyn Write + Send>,
    target: Target,
    reopen: &AtomicBool,
    (written, dropped): (&IntCounter, &IntCounter),
) {
    let mut batch = Batch { bytes: Vec::with_capacity(BATCH), lines: 0 };
    let mut last_error: Option<String> = None;
    let mut complain = |e: io::Error| {
        let e = e.to_string();
        if last_error.as_ref() != Some(&e) {
            tracing::warn!("access log: {e}");
            last_error = Some(e);
        }
    };
    loop {
        let msg = match rx.recv_timeout(FLUSH_EVERY) {
            Ok(m) => Some(m),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => Some(Message::Close),
        };
        let mut next = msg;
        while let Some(m) = next.take() {
            match m {
                Message::Line(l) => {
                    batch.push(&l);
                    if batch.bytes.len() >= BATCH {
                        if let Err(e) = batch.write(&mut out, written, dropped) {
                            complain(e);
                        }
                    }
                }
                Message::Close => {
                    let _ = batch.write(&mut out, written, dropped);
                    return;
                }
            }
            next = rx.try_recv().ok();
        }
        if let Err(e) = batch.write(&mut out, written, dropped) {
            complain(e);
        }
        if reopen.swap(false, Ordering::Relaxed) {
            match target.open() {
                Ok(f) => {
                    out = f;
                    tracing::info!("access log reopened");
                }
                Err(e) => complain(e),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry() -> Entry {
        Entry {
            ts_ms: 971_211_336_042,
            client: "127.0.0.1".into(),
            method: "GET".into(),
            path: "/tiles/gravel/7/1/1.png?seed=2".into(),
            version: "HTTP/1.1",
            status: 200,
            bytes: 81_605,
            ms: 1.2345,
            cache: "hit",
            aborted: false,
            referer: None,
            user_agent: Some("curl/8 \"x\"".into()),
        }
    }

    #[test]
    fn lines_carry_the_arrival_in_milliseconds() {
        let j: serde_json::Value = serde_json::from_str(&entry().line(Format::Json)).unwrap();
        assert_eq!(j["ts"], 971_211_336_042u64);
        assert_eq!(j["time"], "2000-10-10T20:55:36.042Z");
        assert_eq!(j["path"], "/tiles/gravel/7/1/1.png?seed=2");
        assert_eq!(j["ms"], 1.235);
        // The line as written, whole (its keys in order), and read back as the same record.
        let line = entry().line(Format::Json);
        assert_eq!(
            line,
            "{\"bytes\":81605,\"cache\":\"hit\",\"client\":\"127.0.0.1\",\"method\":\"GET\",\"ms\":1.235,\
             \"path\":\"/tiles/gravel/7/1/1.png?seed=2\",\"status\":200,\"time\":\"2000-10-10T20:55:36.042Z\",\
             \"ts\":971211336042}\n"
        );
        let back: JsonRecord = serde_json::from_str(&line).unwrap();
        assert_eq!(
            (back.path.as_deref(), back.ts, back.status),
            (Some("/tiles/gravel/7/1/1.png?seed=2"), Some(971_211_336_042), 200)
        );
        let c = entry().line(Format::Combined);
        assert_eq!(
            c,
            "127.0.0.1 - - [10/Oct/2000:20:55:36 +0000] \"GET /tiles/gravel/7/1/1.png?seed=2 HTTP/1.1\" 200 81605 \"-\" \"curl/8 \\\"x\\\"\"\n"
        );
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }
}
