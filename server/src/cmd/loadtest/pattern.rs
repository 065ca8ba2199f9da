//! The request paths of `textile loadtest`'s patterns: `pan` (a 1920×1080 viewport dragged
//! across the plane), `zoom` (in and out around a drifting centre), `random` (uniform tiles and
//! zooms), `hot` (one tile) and `replay` (the paths of a file, cycled).

use std::path::Path;

use crate::access_log::JsonRecord;
use std::sync::Arc;
use textile_core::error::clip;

/// An endless (or, for `replay`, cycled) sequence of request paths.
pub type Paths = Box<dyn Iterator<Item = String> + Send>;

/// Tiles of a `w × h` viewport whose top-left is texel-at-zoom `(x, y)`.
fn viewport(x: i64, y: i64, w: i64, h: i64) -> impl Iterator<Item = (i64, i64)> {
    let (tx0, ty0) = (x.div_euclid(256), y.div_euclid(256));
    let (tx1, ty1) = ((x + w - 1).div_euclid(256), (y + h - 1).div_euclid(256));
    (ty0..=ty1).flat_map(move |ty| (tx0..=tx1).map(move |tx| (tx, ty)))
}

/// SplitMix64, for reproducible random patterns.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        textile_core::hash::mix(self.0)
    }
    fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % (hi - lo + 1) as u64) as i64
    }
}

/// The request paths of a pattern (endless except `replay`, which cycles its lines, or plays
/// them once when `once`).
pub fn pattern(
    name: &str,
    id: &str,
    native: u32,
    minzoom: u32,
    query: &str,
    (lines, once): (Vec<Box<str>>, bool),
    seed: u64,
) -> Paths {
    let q = if query.is_empty() { String::new() } else { format!("?{query}") };
    let id = id.to_string();
    let tile = move |z: u32, x: i64, y: i64| format!("/tiles/{id}/{z}/{x}/{y}.png{q}");
    let tile = Arc::new(tile);
    match name {
        "hot" => {
            let t = tile.clone();
            Box::new(std::iter::repeat_with(move || t(native, 0, 0)))
        }
        "random" => {
            let mut rng = Rng(seed);
            let t = tile.clone();
            Box::new(std::iter::repeat_with(move || {
                let z = rng.range(minzoom as i64, native as i64) as u32;
                t(z, rng.range(-(1 << 20), 1 << 20), rng.range(-(1 << 20), 1 << 20))
            }))
        }
        "zoom" => {
            // Zoom out from native to minzoom and back in, centred on a point that drifts by
            // three screens per cycle; every step requests the visible tiles.
            let t = tile.clone();
            let zooms: Vec<u32> = (minzoom..=native).rev().chain(minzoom + 1..native).collect();
            Box::new((0i64..).flat_map(move |cycle| {
                let t = t.clone();
                let (cx, cy) = (cycle * 3 * 1920, cycle * 1080);
                zooms.clone().into_iter().flat_map(move |z| {
                    let t = t.clone();
                    let k = native - z;
                    let (x, y) = ((cx >> k) - 960, (cy >> k) - 540);
                    viewport(x, y, 1920, 1080).map(move |(tx, ty)| t(z, tx, ty))
                })
            }))
        }
        "replay" if once => Box::new(lines.into_iter().map(String::from)),
        "replay" => Box::new(lines.into_iter().cycle().map(String::from)),
        _ => {
            // pan: drag a 1920×1080 viewport right and slightly down, 64 px per frame; request
            // each tile the first time it becomes visible (a browser caches the rest).
            let t = tile.clone();
            let mut seen = std::collections::HashSet::new();
            Box::new((0i64..).flat_map(move |f| {
                let (x, y) = (64 * f - 960, 16 * f - 540);
                viewport(x, y, 1920, 1080)
                    .filter(|c| seen.insert(*c))
                    .map(|(tx, ty)| t(native, tx, ty))
                    .collect::<Vec<_>>()
            }))
        }
    }
}

/// The path (and query) of an `http` or `https` URL, or of a `/path`; `None` for anything
/// else (another scheme, a relative reference, white space).
pub fn path_of(s: &str) -> Option<String> {
    match reqwest::Url::parse(s) {
        Ok(u) if matches!(u.scheme(), "http" | "https") => {
            Some(format!("{}{}", u.path(), u.query().map(|q| format!("?{q}")).unwrap_or_default()))
        }
        Ok(_) => None,
        Err(_) if s.starts_with('/') && !s.contains(char::is_whitespace) => Some(s.to_string()),
        Err(_) => None,
    }
}

/// The URL of request path `path` (with its query) on the server at `root`: always that
/// server, whatever the path holds (`//host/…`, `@host`, a scheme): the path and query are set
/// on a copy of `root`, never parsed as a URL of their own.
pub fn target(root: &reqwest::Url, path: &str) -> reqwest::Url {
    let mut u = root.clone();
    let (p, q) = match path.split_once('?') {
        Some((p, q)) => (p, Some(q)),
        None => (path, None),
    };
    let base = root.path().trim_end_matches('/');
    u.set_path(&format!("{base}{p}"));
    u.set_query(q);
    u.set_fragment(None);
    u
}

/// One line of a replay file: the path (and query) to request, and when the log saw it
/// (seconds since the Unix epoch; access-log lines only).
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Path and query.
    pub path: Box<str>,
    /// The log's timestamp.
    pub at: Option<f64>,
}

/// Why lines of a replay file were left out, counted, with the first malformed ones named.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LeftOut {
    /// Access-log lines of a method other than GET or HEAD.
    pub method: u64,
    /// Access-log lines whose status `--replay-status` does not list.
    pub status: u64,
    /// Lines that are no request (neither a URL, a `/path`, nor an access-log line).
    pub malformed: u64,
    /// Access-log lines whose time is before 1970 or after 2100.
    pub time: u64,
    /// The first few malformed lines: `FILE:LINE: why`.
    pub examples: Vec<String>,
}

impl LeftOut {
    /// How many malformed lines are named.
    const EXAMPLES: usize = 3;

    /// Lines left out in all.
    pub fn total(&self) -> u64 {
        self.method + self.status + self.malformed + self.time
    }

    /// As the JSON report gives it.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "method": self.method, "status_filter": self.status, "malformed": self.malformed,
            "time_out_of_range": self.time, "malformed_lines": self.examples,
        })
    }

    /// One line of the text report, if any line was left out.
    pub fn line(&self) -> Option<String> {
        if self.total() == 0 {
            return None;
        }
        let mut parts = Vec::new();
        for (n, why) in [
            (self.method, "not GET or HEAD"),
            (self.status, "status not asked for"),
            (self.malformed, "malformed"),
            (self.time, "time out of range"),
        ] {
            if n > 0 {
                parts.push(format!("{n} {why}"));
            }
        }
        let examples =
            if self.examples.is_empty() { String::new() } else { format!(" ({})", self.examples.join("; ")) };
        Some(format!("replay: {} lines left out: {}{examples}", self.total(), parts.join(", ")))
    }

    fn malformed(&mut self, at: String) {
        self.malformed += 1;
        if self.examples.len() < Self::EXAMPLES {
            self.examples.push(at);
        }
    }
}

/// Seconds since the epoch of 2100-01-01: later access-log times are out of range.
const LATEST: f64 = 4_102_444_800.0;

/// Month numbers of access-log dates.
const MONTHS: [&str; 12] = ["Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"];

/// Days since 1970-01-01 of a civil date (proleptic Gregorian).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// An access-log time, `10/Oct/2000:13:55:36 -0700`, as seconds since the epoch.
fn log_time(s: &str) -> Option<f64> {
    let (dt, tz) = s.split_once(' ')?;
    let mut p = dt.splitn(4, [':', '/']);
    let (d, mon, y) = (p.next()?.parse::<i64>().ok()?, p.next()?, p.next()?.parse::<i64>().ok()?);
    let m = MONTHS.iter().position(|x| *x == mon)? as i64 + 1;
    let mut hms = p.next()?.split(':').map(|v| v.parse::<f64>().ok());
    let (h, mi, sec) = (hms.next()??, hms.next()??, hms.next()??);
    let (sign, tz) = match tz.as_bytes().first()? {
        b'+' => (1.0, &tz[1..]),
        b'-' => (-1.0, &tz[1..]),
        _ => return None,
    };
    if tz.len() != 4 || !(1..=31).contains(&d) {
        return None;
    }
    let off = sign * (tz[..2].parse::<f64>().ok()? * 3600.0 + tz[2..].parse::<f64>().ok()? * 60.0);
    Some(days_from_civil(y, m, d) as f64 * 86_400.0 + h * 3600.0 + mi * 60.0 + sec - off)
}

/// A combined or common access-log line (nginx, Apache): `HOST - USER [TIME] "METHOD PATH
/// PROTO" STATUS SIZE …` → (method, path, status, time).
fn access_log(l: &str) -> Option<(&str, &str, u16, f64)> {
    let (_, rest) = l.split_once('[')?;
    let (time, rest) = rest.split_once(']')?;
    let rest = rest.trim_start().strip_prefix('"')?;
    let (request, rest) = rest.split_once('"')?;
    let mut r = request.split(' ');
    let (method, path) = (r.next()?, r.next()?);
    let status = rest.split_whitespace().next()?.parse().ok()?;
    Some((method, path, status, log_time(time)?))
}

/// A line of textile's own JSON access log (`access_log_format = "json"`) → (method, path,
/// status, time): `ts` is the request's arrival in Unix milliseconds.
fn json_log(l: &str) -> Result<(String, String, u16, f64), String> {
    let r: JsonRecord = serde_json::from_str(l).map_err(|e| format!("not a JSON access-log line: {e}"))?;
    let path = r.path.ok_or("a JSON access-log line without \"path\"")?;
    let ts = r.ts.ok_or("a JSON access-log line without \"ts\" (milliseconds)")?;
    Ok((r.method, path, r.status, ts as f64 / 1000.0))
}

/// The entries of a replay file, read line by line (never the whole file at once): one URL,
/// `/path`, access-log line (nginx or Apache combined or common) or line of textile's JSON access
/// log per line; blank lines and `#` comments skipped. Access-log lines other than GET or HEAD,
/// whose status is not in `statuses` (when given), or whose time is out of range are left out,
/// and so are malformed lines: each counted by reason ([`LeftOut`]). A log whose every line has
/// a time is played in the order of those times (a log is written as answers end, so its lines
/// are not quite in arrival order).
pub fn replay_lines(f: &Path, statuses: &[u16]) -> Result<(Vec<Entry>, LeftOut), String> {
    use std::io::BufRead;
    let file = std::fs::File::open(f).map_err(|e| format!("{}: {e}", f.display()))?;
    let mut v = Vec::new();
    let mut left = LeftOut::default();
    let mut line = String::new();
    let mut reader = std::io::BufReader::new(file);
    for n in 1.. {
        line.clear();
        match reader.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(e) => return Err(format!("{}:{n}: {e}", f.display())),
        }
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let logged = if l.starts_with('{') {
            match json_log(l) {
                Ok(x) => Some(x),
                Err(e) => {
                    left.malformed(format!("{}:{n}: {e}", f.display()));
                    continue;
                }
            }
        } else {
            access_log(l).map(|(m, p, s, t)| (m.to_owned(), p.to_owned(), s, t))
        };
        if let Some((method, path, status, at)) = logged {
            if !path.starts_with('/') {
                left.malformed(format!(
                    "{}:{n}: the request path '{}' does not start with '/'",
                    f.display(),
                    clip(&path)
                ));
            } else if !matches!(method.as_str(), "GET" | "HEAD") {
                left.method += 1;
            } else if !statuses.is_empty() && !statuses.contains(&status) {
                left.status += 1;
            } else if !(0.0..LATEST).contains(&at) {
                left.time += 1;
            } else {
                v.push(Entry { path: path.into(), at: Some(at) });
            }
            continue;
        }
        match path_of(l) {
            Some(path) => v.push(Entry { path: path.into(), at: None }),
            None => left.malformed(format!(
                "{}:{n}: '{}' is neither an http(s) URL, a /path, nor a combined or common access-log line",
                f.display(),
                clip(l)
            )),
        }
    }
    if v.is_empty() {
        let why = left.line().map(|l| format!(" ({l})")).unwrap_or_default();
        return Err(format!("{}: no requests to replay{why}", f.display()));
    }
    if v.iter().all(|e| e.at.is_some()) {
        v.sort_by(|a, b| a.at.partial_cmp(&b.at).unwrap_or(std::cmp::Ordering::Equal));
    }
    v.shrink_to_fit();
    Ok((v, left))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_log_lines_are_read() {
        let l = r#"127.0.0.1 - frank [10/Oct/2000:13:55:36 -0700] "GET /tiles/a/7/0/0.png?seed=2 HTTP/1.1" 200 2326 "-" "curl/8""#;
        let (m, p, s, t) = access_log(l).unwrap();
        assert_eq!((m, p, s), ("GET", "/tiles/a/7/0/0.png?seed=2", 200));
        assert_eq!(t, 971_211_336.0, "2000-10-10 20:55:36 UTC");
        assert!(access_log("/tiles/a/7/0/0.png").is_none());
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
    }

    #[test]
    fn textile_json_log_lines_are_read_in_arrival_order() {
        let dir = std::env::temp_dir().join(format!("textile-replay-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("access.log");
        std::fs::write(
            &f,
            concat!(
                r#"{"ts":1000250,"method":"GET","path":"/b?x=1","status":200}"#,
                "\n",
                r#"{"ts":1000000,"method":"GET","path":"/a","status":200}"#,
                "\n",
                r#"{"ts":1000100,"method":"POST","path":"/textures","status":201}"#,
                "\n",
                r#"{"ts":1000300,"method":"GET","path":"/c","status":404}"#,
                "\n",
            ),
        )
        .unwrap();
        let (e, left) = replay_lines(&f, &[200]).unwrap();
        let got: Vec<(&str, f64)> = e.iter().map(|e| (&*e.path, e.at.unwrap())).collect();
        assert_eq!(got, [("/a", 1000.0), ("/b?x=1", 1000.25)]);
        assert_eq!((left.method, left.status, left.total()), (1, 1, 2));
        std::fs::write(&f, "{\"ts\":1}\n").unwrap();
        assert!(replay_lines(&f, &[]).unwrap_err().contains(":1: a JSON access-log line without \"path\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn requests_stay_on_the_server_whatever_the_line() {
        let root = reqwest::Url::parse("http://127.0.0.1:8080").unwrap();
        for line in ["x:@127.0.0.9:9/p", "mailto:@127.0.0.9/p", "ftp://127.0.0.9/p", "tiles/a/0/0/0.png"] {
            assert_eq!(path_of(line), None, "{line}");
        }
        for path in ["//127.0.0.9:9/p", "/@127.0.0.9:9/p", "/p?q=//127.0.0.9", "/a/../../b"] {
            let u = target(&root, path);
            assert_eq!((u.host_str(), u.port()), (Some("127.0.0.1"), Some(8080)), "{path}: {u}");
        }
        assert_eq!(
            target(&root, "/tiles/a/7/0/0.png?seed=2").as_str(),
            "http://127.0.0.1:8080/tiles/a/7/0/0.png?seed=2"
        );
    }
}
